"""Fly a scenario: trim, then the closed loop JSBSim → navigation → guidance/laws → inner loops.

Rates: JSBSim at 120 Hz, the inner loops inside it every ``inner_loops.frames_per_update`` frames
(aircraft file, default 60 Hz); navigation, guidance, heading hold and the vertical law at
``outer_rate_hz`` (default 10 Hz); logging at ``log_rate_hz`` (default 10 Hz).

A run ends with a status: ``ok`` (duration flown or guidance finished) or ``diverged`` with a
reason (non-finite state, ground contact, stall, overspeed) — never a hang or a bare traceback.
"""

from __future__ import annotations

import logging
import math
import time
from array import array
from typing import Any

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig, load_aircraft
from fms_testbed.config.scenario import Scenario
from fms_testbed.control import VERTICAL_LAWS
from fms_testbed.core.atmosphere import cas_to_tas, tas_to_cas
from fms_testbed.core.contracts import Guidance, GuidanceOutput
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import FT_M, KT_MPS, SLUG_KG
from fms_testbed.loop.log import build_frame
from fms_testbed.loop.procedure import PreparedProcedure
from fms_testbed.loop.steps import (WIND_RAMP_S, ConfigStep, EventQueue, FrameSampling,
                                    LateralStep, NavHold, Targets, VerticalStep, WindRamp,
                                    apply_event, flap_index_for_cas, merge_guidance)
from fms_testbed.navigation import make_source
from fms_testbed.sim.divergence import Divergence
from fms_testbed.sim.jsbsim_core import RAW, JSBSimAircraft

log = logging.getLogger(__name__)

_TURB_SEVERITY = {"light": (3, 25.0), "moderate": (4, 50.0), "severe": (6, 75.0)}  # (index, kt@20ft)


class Flight:
    """A closed-loop flight, loaded and trimmed, flown one outer step at a time.

    ``Flight(scn).run()`` flies the whole scenario; :meth:`step` advances it by outer steps
    (``1 / outer_rate_hz`` s of simulated time each), so a notebook or a benchmark can stop,
    look and go on. :meth:`result` builds the timeseries and the summary of what was flown.

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
        before the procedure does, ``diverged`` when guidance abandons it
    """

    def __init__(self, scn: Scenario, cfg: AircraftConfig | None = None, seed: int | None = None,
                 guidance: Guidance | None = None, progress: bool | None = None,
                 vertical_law=None, procedure: PreparedProcedure | None = None):
        self.scn = scn
        self.procedure = procedure
        self.seed = 0 if seed is None else int(seed)
        self.cfg = cfg = cfg or load_aircraft(scn.aircraft)
        if procedure is not None and guidance is None:
            guidance, law = procedure.guidance(scn, cfg)
            vertical_law = vertical_law or law
        self._wall0 = time.perf_counter()
        self.aircraft = ac = JSBSimAircraft(cfg)
        ac.fdm["simulation/randomseed"] = self.seed
        ini = scn.initial
        kind, spd = ini.speed
        ac.set_isa_dev(scn.isa_dev_c)        # the day's temperature, before the trim
        tas0 = float(cas_to_tas(spd, ini.altitude_m, scn.isa_dev_c)) if kind == "cas" else spd
        # Trim in calm air: JSBSim 1.3.3 fails to trim in wind, and run_ic() resets the
        # atmosphere's wind to the initial condition's. The steady wind is ramped in after the
        # trim (WIND_RAMP_S).
        # a procedure flight: terrain at its airport; an aircraft with approach settings starts
        # with the flaps its start speed has out on the approach schedule
        terrain = procedure.terrain_elev_m if procedure is not None else 0.0
        ap = cfg.approach if procedure is not None else None
        k0 = flap_index_for_cas(ap, float(tas_to_cas(tas0, ini.altitude_m))) \
            if ap is not None else 0
        # a SID from the runway: at rest on its threshold instead (loop/takeoff.py)
        self.takeoff = procedure.takeoff_start(cfg) if procedure is not None else None
        if self.takeoff is not None:
            self.takeoff.start(ac)
        else:
            ac.trim(ini.altitude_m, tas0, heading_deg=ini.heading_deg, lat_deg=ini.lat_deg,
                    lon_deg=ini.lon_deg, terrain_elev_m=terrain,
                    flap_cmd_norm=ap.flaps[k0].cmd_norm if ap is not None else 0.0)
        self.config_step = None
        if ap is not None and guidance is not None:
            if self.takeoff is None:      # a takeoff builds its own (loop/takeoff.py)
                self.config_step = ConfigStep(ap, ac, k0, False,
                                              getattr(guidance, "events", None))
                if procedure.path.path.proc_type == "D":
                    # a SID started airborne after its takeoff: clean, and only ever
                    # retracting (the approach schedule put the gear down at 35 ft above the
                    # runway and flaps out when the climb slowed the aircraft)
                    self.config_step.departure()
            if hasattr(guidance, "set_mass"):
                guidance.set_mass(float(ac.fdm["inertia/mass-slugs"]) * SLUG_KG)
        if scn.turbulence is not None:  # after trim: JSBSim cannot trim in turbulence
            idx, w20 = _TURB_SEVERITY[scn.turbulence.severity]
            ac.fdm["atmosphere/turb-type"] = 4
            ac.fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20 / FT_M * KT_MPS
            ac.fdm["atmosphere/turbulence/milspec/severity"] = idx
        ac.engage()
        ac.command(bank_rad=0.0, ny=1.0, nx=0.0)

        nav_spec = scn.navigation_spec
        # navigation.seed, when the scenario gives one, seeds the navigation errors
        self.navigation_seed = int(nav_spec.get("seed", self.seed))
        try:
            source = make_source(nav_spec, seed=self.navigation_seed)
        except UserError as exc:
            where = scn.source_file or scn.name or "scenario"
            raise type(exc)(f"{where}: {exc}") from None
        self.navigation = source
        faults = [ev.fault.model_dump(exclude_none=True) for ev in scn.events if ev.fault]
        if faults and not hasattr(source, "inject"):
            raise UserError(f"{scn.source_file or scn.name or 'scenario'}: events.fault needs a "
                            f"navigation source that takes faults (ins_gnss), not "
                            f"{nav_spec.get('source')!r}")
        for fault in faults:
            source.check_fault(fault)
        self.vertical_law = vertical_law or VERTICAL_LAWS[scn.vertical_law](cfg)
        self.guidance = guidance
        self.n_frames = max(1, int(round(1.0 / (scn.outer_rate_hz * ac.dt_s))))
        self.dt_outer_s = self.n_frames * ac.dt_s
        # JSBSim reads, row after row in jsbsim_core._READ order: a flat float buffer, so the
        # log adds no object the garbage collector must walk (lists of floats would)
        self.raw_log = array("d")
        self.rows: list[tuple] = []              # timeseries.LOG_FIELDS
        self.extra_rows: list[dict] = []
        self.status, self.reason = "ok", "duration flown"
        self.done = False
        self._loop_wall_s = 0.0
        self._bar = None
        if progress is not False:
            from tqdm import tqdm
            # appears only after 2 s of wall time, and (unless forced) only on a terminal
            self._bar = tqdm(total=int(scn.duration_s), unit="sim s", delay=2.0, leave=False,
                             disable=None if progress is None else False, desc=scn.name or "run")
        self.targets = Targets()
        self._steps = self._loop()

    def step(self, n: int = 1) -> bool:
        """Fly ``n`` outer steps; return False once the flight has ended (status in
        :attr:`status` / :attr:`reason`)."""
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

    def run(self) -> tuple[pd.DataFrame, dict[str, Any]]:
        """Fly to the end; return :meth:`result`."""
        while self.step(1 << 30):
            pass
        return self.result()

    def _loop(self):
        """The outer loop as a generator, one ``yield`` per outer step, calling the named steps of
        :mod:`fms_testbed.loop.steps` in order: read → check → wind → navigate → events → guide
        → lateral → vertical/command → log (the steps are bound to locals: the loop is hot)."""
        if self.takeoff is not None and not (yield from self.takeoff.fly(self)):
            return                            # the takeoff failed (status and reason set)
        scn, ac, guide = self.scn, self.aircraft, self.guidance
        rows, extra_rows, raw_log, bar = self.rows, self.extra_rows, self.raw_log, self._bar
        no_errors: dict = {}
        n_outer, dt_outer = self.n_frames, self.dt_outer_s
        nav_spec = scn.navigation_spec
        nav_dt = float(nav_spec.get("dt_s", 0.1)) if nav_spec.get("source") == "sins" else 0.0
        # hold the navigation errors between updates only when navigation runs slower than
        # guidance
        sampling = FrameSampling(self.navigation, ac)
        navigate = (NavHold(self.navigation, nav_dt) if nav_dt > dt_outer + 1e-9
                    else sampling)
        tg = self.targets
        ini = scn.initial
        if scn.hold:
            kind, spd = ini.speed
            tg.alt_m, tg.speed_kind, tg.speed_mps, tg.vertical = ini.altitude_m, kind, spd, True
        events = EventQueue(scn.events)
        log_every = max(1, int(round(1.0 / (scn.log_rate_hz * dt_outer))))
        n_total = int(math.ceil(scn.duration_s / dt_outer))
        check = Divergence(self.cfg)
        wind = WindRamp(ac.fdm, scn, dt_outer)
        wind_end_s = wind.end_s if wind.active else -1.0
        wind_varies = wind.varies
        lateral = LateralStep(self.cfg, dt_outer)
        vertical = VerticalStep(self.vertical_law, ac, dt_outer)
        i_wow = RAW["wow"]
        configure = self.config_step
        go_around = (lambda: guide.go_around_active) if hasattr(guide, "go_around_active") \
            else (lambda: False)
        state, read, run = ac.state, ac.read_raw, sampling.run
        raw = read()
        for k in range(n_total + 1):
            s = state(raw)                                  # read
            why = check(s, raw[i_wow])                      # check
            if why:
                self.status, self.reason = "diverged", why
                return
            if s.t_s <= wind_end_s or wind_varies:          # wind (ramp; profile: altitude)
                wind(s.t_s, s.alt_m)
            nav = navigate(s)                               # navigate
            if events.pending:                              # events
                for ev in events.due(s.t_s, s.alt_m):
                    apply_event(ev, tg)
                    if ev.fault is not None:                # navigation fault injection
                        self.navigation.inject(ev.fault.model_dump(exclude_none=True), s.t_s)
            gout = guide.update(dt_outer, nav, s) if guide is not None else None   # guide
            if gout is not None:
                merge_guidance(gout, tg)
            bank_cmd = lateral(tg, nav, gout is not None)   # lateral
            cmd_nx, cmd_ny, alt_cmd, tas_cmd = vertical(s, tg, bank_cmd)   # vertical + command
            if configure is not None:                       # flaps and gear
                configure(s, tg, go_around())
            if k % log_every == 0:                          # log: what is at hand, raw
                raw_log.extend(raw)
                rows.append((bank_cmd, tg.heading_rad, cmd_nx, cmd_ny, tg.throttle, alt_cmd, tas_cmd,
                             nav.lat_rad, nav.lon_rad, nav.alt_m, nav.heading_rad, nav.roll_rad,
                             nav.pitch_rad))
                if gout is not None:
                    extra_rows.append({**nav.errors, **gout.log})
                else:  # str -> float dicts are not tracked by the GC; an empty one is shared
                    extra_rows.append(nav.errors or no_errors)
            if gout is not None and gout.done:
                self.reason = "guidance complete"
                return
            if k == n_total:
                return
            if not run(n_outer):
                self.status, self.reason = "diverged", "JSBSim stopped"
                return
            raw = read()
            if bar is not None and k % 200 == 0:
                bar.n = int(raw[0])
                bar.refresh()
            yield k

    def result(self) -> tuple[pd.DataFrame, dict[str, Any]]:
        """The timeseries (:data:`~fms_testbed.core.timeseries.COLUMNS`, then navigation-error and
        guidance columns) and the summary of what has been flown so far."""
        scn, cfg, ac = self.scn, self.cfg, self.aircraft
        wall = time.perf_counter() - self._wall0
        loop_wall = self._loop_wall_s
        df = build_frame(self.raw_log, self.rows)
        if self.extra_rows and any(self.extra_rows):
            df = pd.concat([df, pd.DataFrame.from_records(self.extra_rows)], axis=1)
        flown = float(df["t_s"].iloc[-1]) if len(df) else 0.0
        trim = ac.trim_result
        status, reason = self.status, self.reason if self.done else "in flight"
        g = self.guidance
        if self.procedure is not None and g is not None:
            if g.abort_reason:
                status, reason = "diverged", g.abort_reason
            elif self.done and status == "ok" and not g.done:
                status = "incomplete"
                reason = (f"duration {scn.duration_s:.0f} s ended on leg {g.leg + 1} of "
                          f"{len(self.procedure.path.seq.legs)}")
        summary = {
            "scenario": scn.name, "aircraft": cfg.name, "aircraft_file": cfg.source_file,
            "jsbsim_model": cfg.jsbsim_model,
            "status": status, "reason": reason,
            "seed": self.seed, "navigation_seed": self.navigation_seed,
            "duration_s": round(flown, 3), "wall_time_s": round(wall, 3),
            "real_time_factor": round(flown / wall, 1) if wall > 0 else None,
            "loop_wall_time_s": round(loop_wall, 4),
            "loop_steps_per_s": round(flown / ac.dt_s / loop_wall) if loop_wall > 0 else None,
            "trim": {"alt_m": trim.alt_m, "tas_mps": round(trim.tas_mps, 3),
                     "alpha_deg": round(trim.alpha_deg, 3), "pitch_deg": round(trim.pitch_deg, 3),
                     "throttle": round(trim.throttle, 4), "elevator": round(trim.elevator, 4)},
            "metrics": _metrics(df),
        }
        if self.takeoff is not None:
            summary["takeoff"] = self.takeoff.summary()
        return df, summary


def fly(scn: Scenario, cfg: AircraftConfig | None = None, seed: int | None = None,
        guidance: Guidance | None = None, progress: bool | None = None,
        vertical_law=None) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Fly a validated scenario and return (timeseries DataFrame, summary dict).

    The parameters are :class:`Flight`'s; this is ``Flight(...).run()``.
    """
    return Flight(scn, cfg=cfg, seed=seed, guidance=guidance, progress=progress,
                  vertical_law=vertical_law).run()


def _metrics(df: pd.DataFrame) -> dict[str, float]:
    if df.empty:
        return {}
    out = {
        "alt_min_m": df["alt_m"].min(), "alt_max_m": df["alt_m"].max(),
        "tas_min_mps": df["tas_mps"].min(), "tas_max_mps": df["tas_mps"].max(),
        "roll_max_abs_deg": df["roll_deg"].abs().max(), "alpha_max_deg": df["alpha_deg"].max(),
        "ny_min": df["ny"].min(), "ny_max": df["ny"].max(),
        "throttle_min": df["throttle"].min(), "throttle_max": df["throttle"].max(),
        "distance_flown_m": float(np.sum(df["gs_mps"].to_numpy()[1:] * np.diff(df["t_s"]))),
    }
    e = df["alt_m"] - df["cmd_alt_m"]
    if e.notna().any():
        out["alt_err_final_m"] = float(e.dropna().iloc[-1])
    e = df["tas_mps"] - df["cmd_tas_mps"]
    if e.notna().any():
        out["tas_err_final_mps"] = float(e.dropna().iloc[-1])
    return {k: round(float(v), 4) for k, v in out.items()}


__all__ = ["fly", "Flight", "Guidance", "GuidanceOutput", "WIND_RAMP_S"]
