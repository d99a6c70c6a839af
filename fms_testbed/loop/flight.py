"""Fly a scenario: trim (or stand on the runway), then the one flight loop JSBSim → navigation →
air data → guidance/laws → inner loops, phase by phase (:mod:`.phases`: takeoff, airborne).

Rates: JSBSim at 120 Hz, the inner loops inside it every ``inner_loops.frames_per_update`` frames
(aircraft file, default 60 Hz); navigation, air data, guidance, heading hold and the vertical
law at ``outer_rate_hz`` (default 10 Hz); logging at ``log_rate_hz`` (default 10 Hz,
:class:`~.log.FlightLog`).

A loop ends with an :class:`~fms_testbed.core.contracts.Ending`: the duration flown, the
guidance's path flown to its end, abandoned by the guidance, the duration ended before the path
(``incomplete``), or ``diverged`` with a reason (non-finite state, ground contact, stall,
overspeed, a failed takeoff) — never a hang or a bare traceback.
"""

from __future__ import annotations

import logging
import math
import time
from typing import Iterator

import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig, load_aircraft
from fms_testbed.config.scenario import Scenario
from fms_testbed.control import VERTICAL_LAWS
from fms_testbed.core.atmosphere import cas_to_tas, tas_to_cas
from fms_testbed.core.contracts import Ending, Guidance, GuidanceOutput
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import FT_M, KT_MPS, SLUG_KG
from fms_testbed.loop.log import FlightLog, log_every
from fms_testbed.loop.phases import AirbornePhase, LoopParts
from fms_testbed.loop.procedure import PreparedProcedure
from fms_testbed.loop.record import FlightRecord, Metrics, TrimRecord
from fms_testbed.loop.steps import (WIND_RAMP_S, ConfigStep, EventQueue, FrameSampling,
                                    LateralStep, NavHold, Targets, VerticalStep, WindRamp,
                                    apply_event, flap_index_for_cas, merge_guidance)
from fms_testbed.loop.takeoff import TakeoffPhase, start_on_runway
from fms_testbed.navigation import make_source
from fms_testbed.sensors.air_data import AirDataComputer
from fms_testbed.sim.jsbsim_core import JSBSimAircraft

log = logging.getLogger(__name__)

_TURB_SEVERITY = {"light": (3, 25.0), "moderate": (4, 50.0), "severe": (6, 75.0)}  # (index, kt@20ft)
PROGRESS_EVERY = 200
"""Outer steps between two progress-bar updates."""


class Flight:
    """A closed-loop flight, loaded and trimmed, flown one outer step at a time.

    ``Flight(scn).run()`` flies the whole scenario; :meth:`step` advances it by outer steps
    (``1 / outer_rate_hz`` s of simulated time each), so a notebook or a benchmark can stop,
    look and go on. :meth:`result` gives the timeseries and the :class:`~.record.FlightRecord`
    of what was flown.

    Parameters
    ----------
    scn : validated scenario
    cfg : aircraft configuration (default: the one the scenario names)
    seed : seed for every stochastic part (turbulence, navigation errors); default 0
    guidance : optional path guidance (sets bank and vertical targets every outer step)
    progress : show a progress bar (default: when stderr is a terminal)
    vertical_law : a vertical-law instance overriding ``scn.vertical_law``
    procedure : a built procedure (:func:`~fms_testbed.loop.procedure.prepare_procedure`): the
        flight is flown by its procedure guidance and ends ``incomplete`` when the duration ends
        before the procedure does
    """

    def __init__(self, scn: Scenario, cfg: AircraftConfig | None = None, seed: int | None = None,
                 guidance: Guidance | None = None, progress: bool | None = None,
                 vertical_law=None, procedure: PreparedProcedure | None = None):
        self.scn, self.procedure = scn, procedure
        self.seed = 0 if seed is None else int(seed)
        self.cfg = cfg = cfg or load_aircraft(scn.aircraft)
        if procedure is not None and guidance is None:
            guidance, law = procedure.guidance(scn, cfg)
            vertical_law = vertical_law or law
        self.guidance = guidance
        self._wall0 = time.perf_counter()
        self.aircraft = JSBSimAircraft(cfg)
        runway, flap_index = self._start()
        if guidance is not None:
            guidance.set_mass(float(self.aircraft.fdm["inertia/mass-slugs"]) * SLUG_KG)
        self._turbulence()
        self.aircraft.engage()
        self.aircraft.command(bank_rad=0.0, ny=1.0, nx=0.0)
        self.navigation, self.navigation_seed = self._navigation()
        self.air_data = AirDataComputer()
        self.vertical_law = vertical_law or VERTICAL_LAWS[scn.vertical_law](cfg)
        self.n_frames = max(1, int(round(1.0 / (scn.outer_rate_hz * self.aircraft.dt_s))))
        self.dt_outer_s = self.n_frames * self.aircraft.dt_s
        self.log = FlightLog(log_every(scn.log_rate_hz, self.dt_outer_s), guidance)
        self.targets = Targets()
        if scn.hold:
            kind, spd = scn.initial.speed
            t = self.targets
            t.alt_m, t.speed_kind, t.speed_mps, t.vertical = scn.initial.altitude_m, kind, spd, True
        self.events = EventQueue(scn.events)
        self.phase = self._first_phase(runway, flap_index)
        self.takeoff = self.phase if isinstance(self.phase, TakeoffPhase) else None
        self.ending = Ending("in_flight", "in flight")
        self.done = False
        self._loop_wall_s = 0.0
        self._bar = _progress_bar(scn, progress)
        self._steps = self._loop()

    # ------------------------------------------------------------------ building it
    def _start(self):
        """Load the day and put the aircraft at its start: trimmed in the air, or at rest on
        the runway of a SID flown from a takeoff. Returns (the departure runway or None, the
        flap detent the start speed has out on the approach schedule)."""
        scn, cfg, ac, proc = self.scn, self.cfg, self.aircraft, self.procedure
        ac.fdm["simulation/randomseed"] = self.seed
        ini = scn.initial
        kind, spd = ini.speed
        ac.set_isa_dev(scn.isa_dev_c)        # the day's temperature, before the trim
        tas0 = float(cas_to_tas(spd, ini.altitude_m, scn.isa_dev_c)) if kind == "cas" else spd
        # trimmed in calm air (JSBSim 1.3.3 cannot trim in wind); the wind is ramped in after
        # it (steps.WindRamp). A procedure flight: terrain at its airport, and an aircraft with
        # approach settings starts with the flaps its start speed has out on the schedule
        ap = cfg.approach if proc is not None else None
        k0 = flap_index_for_cas(ap, float(tas_to_cas(tas0, ini.altitude_m))) if ap else 0
        if proc is not None and proc.path.path.proc_type == "D":
            k0 = 0   # a SID is planned clean (climb-out CAS >= 1.15 x the minimum clean CAS)
        runway = proc.takeoff_runway() if proc is not None else None
        if runway is not None:
            start_on_runway(ac, runway, cfg)
        else:
            ac.trim(ini.altitude_m, tas0, heading_deg=ini.heading_deg, lat_deg=ini.lat_deg,
                    lon_deg=ini.lon_deg,
                    terrain_elev_m=proc.terrain_elev_m if proc is not None else 0.0,
                    flap_cmd_norm=ap.flaps[k0].cmd_norm if ap is not None else 0.0)
        return runway, k0

    def _turbulence(self) -> None:
        """The scenario's turbulence (after the trim: JSBSim cannot trim in turbulence)."""
        if self.scn.turbulence is None:
            return
        idx, w20 = _TURB_SEVERITY[self.scn.turbulence.severity]
        fdm = self.aircraft.fdm
        fdm["atmosphere/turb-type"] = 4
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20 / FT_M * KT_MPS
        fdm["atmosphere/turbulence/milspec/severity"] = idx

    def _navigation(self):
        """The scenario's navigation source and its seed (``navigation.seed`` when given),
        with the scenario's faults checked against it."""
        scn = self.scn
        spec = scn.navigation_spec
        seed = int(spec.get("seed", self.seed))
        where = scn.source_file or scn.name or "scenario"
        try:
            source = make_source(spec, seed=seed)
            install = getattr(source, "install_imu", None)
            if install is not None:                  # a strapdown IMU off the CG
                install(self.cfg.imu_lever_arm_m)
            for ev in scn.events:
                if ev.fault:
                    source.check_fault(ev.fault.model_dump(exclude_none=True))
        except UserError as exc:
            raise type(exc)(f"{where}: {exc}") from None
        return source, seed

    def _first_phase(self, runway, flap_index: int):
        """The shared loop parts and the phase the flight starts in."""
        cfg, ac, guide, proc = self.cfg, self.aircraft, self.guidance, self.procedure
        dt = self.dt_outer_s
        sampling = FrameSampling(self.navigation, ac)
        spec = self.scn.navigation_spec
        nav_dt = float(spec.get("dt_s", 0.1)) if spec.get("source") == "sins" else 0.0
        # hold the navigation errors between updates when navigation runs slower than guidance
        self._navigate = (NavHold(self.navigation, nav_dt) if nav_dt > dt + 1e-9 else
                          sampling if sampling.getters else self.navigation.update)
        parts = LoopParts(cfg, ac, self.targets, LateralStep(cfg, dt),
                          WindRamp(ac.fdm, self.scn, dt, None if runway is not None else 0.0),
                          sampling, self.n_frames, dt,
                          guide.events if guide is not None else None)
        go_around = (lambda: guide.go_around_active) if guide is not None else (lambda: False)

        def airborne(config: ConfigStep | None) -> AirbornePhase:
            return AirbornePhase(parts, VerticalStep(self.vertical_law, ac, dt), config,
                                 go_around)

        if runway is not None:
            return TakeoffPhase(parts, runway, guide is not None, airborne)
        ap = cfg.approach if proc is not None else None
        config = None
        if ap is not None and guide is not None:
            config = ConfigStep(ap, ac, flap_index, False, guide.events)
            if proc.path.path.proc_type == "D":
                # a SID started airborne after its takeoff: clean, and only ever retracting
                config.departure()
        return airborne(config)

    # ------------------------------------------------------------------ flying it
    def step(self, n: int = 1) -> bool:
        """Fly ``n`` outer steps; return False once the flight has ended (how: :attr:`ending`)."""
        if self.done:
            return False
        t0 = time.perf_counter()
        steps = self._steps
        for _ in range(n):
            if next(steps, None) is None:
                self.done = True
                break
        self._loop_wall_s += time.perf_counter() - t0
        if self.done and self._bar is not None:
            self._bar.close()
        return not self.done

    def run(self) -> tuple[pd.DataFrame, FlightRecord]:
        """Fly to the end; return :meth:`result`."""
        while self.step(1 << 30):
            pass
        return self.result()

    def stop(self, reason: str) -> None:
        """End the flight from outside (a wall-time limit: ending ``stopped``, status
        ``timeout``); what was flown stays for :meth:`result`."""
        if not self.done:
            where = self.guidance.position_text() if self.guidance is not None else ""
            self.ending = Ending("stopped", f"{reason} after {self.aircraft.fdm.get_sim_time():.0f}"
                                            f" s simulated" + (f", on {where}" if where else ""))
            self.done = True

    def _loop(self) -> Iterator[int]:
        """The outer loop as a generator, one ``yield`` per outer step, calling the steps in
        order: read → check → wind → navigate → air data → events → guide → phase change →
        command → log → advance (:mod:`.phases`; the steps are bound to locals: the loop is
        hot)."""
        ac, guide, log, tg, events = self.aircraft, self.guidance, self.log, self.targets, \
            self.events
        read, state, navigate, air_data = ac.read_raw, ac.state, self._navigate, \
            self.air_data.update
        dt, bar, phase = self.dt_outer_s, self._bar, self.phase
        n_total = int(math.ceil(self.scn.duration_s / dt))
        every = log.every
        raws, cmds, errors, records = (log.raw.append, log.cmds.append, log.errors.append,
                                       log.records.append)
        windy = self.phase.parts.wind.active
        check, wind, guided, after, command, advance = _bind(phase, windy)
        for k in range(n_total + 1):
            raw = read()
            s = state(raw)                                           # read
            why = check(s, raw)                                      # check
            if why:
                return self._end("diverged", why)
            if windy:                                                # wind
                wind(s)
            nav = navigate(s)                                        # navigate
            air = air_data(s)                                        # air data
            if events.pending and phase.fires_events:                # events
                self._events_due(s)
            gout = None
            if guide is not None and (guided is None or guided(s)):  # guide
                gout = guide.update(dt, nav, air)
                merge_guidance(gout, tg)
            if after is not None:                                    # phase change
                nxt = after(s, gout)
                if nxt is not phase:
                    phase = self.phase = nxt
                    check, wind, guided, after, command, advance = _bind(phase, windy)
            fields = command(s, nav, air, gout)                      # command
            if k % every == 0:                                       # log
                raws(tuple(raw))
                cmds(fields)
                errors(nav.errors)
                records(None if gout is None else guide.log_record())
            if gout is not None and gout.done:
                return self._end("guidance_complete", "guidance complete")
            if k == n_total:
                return self._end("duration", "duration flown")
            why = advance()                                          # advance
            if why:
                return self._end("diverged", why)
            if bar is not None and k % PROGRESS_EVERY == 0:
                bar.n = int(s.t_s)
                bar.refresh()
            yield k

    def _events_due(self, s) -> None:
        """Scenario events due now: targets, navigation faults."""
        for ev in self.events.due(s.t_s, s.alt_m):
            apply_event(ev, self.targets)
            if ev.fault is not None:                                 # navigation fault
                self.navigation.inject(ev.fault.model_dump(exclude_none=True), s.t_s)

    def _end(self, kind: str, reason: str) -> None:
        """Record how the loop ended: a guidance that stopped early has abandoned its path; a
        procedure whose path is not flown when the duration ends is incomplete."""
        g = self.guidance
        if kind == "guidance_complete" and g.abort_reason:
            kind, reason = "abandoned", g.abort_reason
        elif kind == "duration" and self.procedure is not None and g is not None and not g.done:
            kind, reason = "incomplete", f"duration {self.scn.duration_s:.0f} s ended" + _on(g)
        self.ending = Ending(kind, reason)

    # ------------------------------------------------------------------ what was flown
    def result(self) -> tuple[pd.DataFrame, FlightRecord]:
        """The timeseries (:class:`~.log.FlightLog`) and the :class:`~.record.FlightRecord` of
        what has been flown so far."""
        scn, cfg, ac = self.scn, self.cfg, self.aircraft
        wall = time.perf_counter() - self._wall0
        loop_wall = self._loop_wall_s
        df = self.log.frame()
        flown = float(df["t_s"].iloc[-1]) if len(df) else 0.0
        tr = ac.trim_result
        takeoff = self.takeoff
        return df, FlightRecord(
            scn.name, cfg.name, cfg.source_file, cfg.jsbsim_model, self.ending.status,
            self.ending.reason, self.seed, self.navigation_seed, round(flown, 3), round(wall, 3),
            round(flown / wall, 1) if wall > 0 else None, round(loop_wall, 4),
            round(flown / ac.dt_s / loop_wall) if loop_wall > 0 else None,
            TrimRecord(tr.alt_m, round(tr.tas_mps, 3), round(tr.alpha_deg, 3),
                       round(tr.pitch_deg, 3), round(tr.throttle, 4), round(tr.elevator, 4)),
            Metrics.of(df), takeoff.record() if takeoff is not None else None)


def _bind(phase, windy: bool) -> tuple:
    """The phase's steps as the loop calls them: (check, wind or None when there is no wind,
    guided or None when it flies every step guided, after_guidance or None when the phase never
    changes, command, advance)."""
    return (phase.check, phase.wind if windy else None,
            None if phase.always_guided else phase.guided,
            phase.after_guidance if phase.hands_over else None, phase.command, phase.advance)


def _on(guidance) -> str:
    """' on leg k of n' where the guidance says where it is ('' when it does not)."""
    where = guidance.position_text() if guidance is not None else ""
    return f" on {where}" if where else ""


def _progress_bar(scn: Scenario, progress: bool | None):
    """A tqdm bar in simulated seconds that appears after 2 s of wall time, and (unless forced)
    only on a terminal; None when ``progress`` is False."""
    if progress is False:
        return None
    from tqdm import tqdm

    return tqdm(total=int(scn.duration_s), unit="sim s", delay=2.0, leave=False,
                disable=None if progress is None else False, desc=scn.name or "run")


def fly(scn: Scenario, cfg: AircraftConfig | None = None, seed: int | None = None,
        guidance: Guidance | None = None, progress: bool | None = None,
        vertical_law=None) -> tuple[pd.DataFrame, FlightRecord]:
    """Fly a validated scenario and return (timeseries DataFrame, :class:`~.record.FlightRecord`):
    ``Flight(...).run()``.

    Parameters
    ----------
    scn, cfg, seed, guidance, progress, vertical_law : :class:`Flight`'s
    """
    return Flight(scn, cfg=cfg, seed=seed, guidance=guidance, progress=progress,
                  vertical_law=vertical_law).run()


__all__ = ["fly", "Flight", "Guidance", "GuidanceOutput", "WIND_RAMP_S"]
