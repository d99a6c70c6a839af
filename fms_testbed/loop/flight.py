"""Fly a scenario: trim, then the closed loop JSBSim → navigation → guidance/laws → inner loops.

Rates: JSBSim at 120 Hz, the inner loops inside it every ``inner_loops.frames_per_update`` frames
(aircraft file, default 60 Hz); navigation, guidance, heading hold and the vertical law at
``outer_rate_hz`` (default 10 Hz); logging at ``log_rate_hz`` (default 10 Hz).

A run ends with a status: ``ok`` (duration flown or guidance finished) or ``diverged`` with a
reason (non-finite state, ground contact, stall, overspeed) — never a hang or a bare traceback.
"""

from __future__ import annotations

import json
import logging
import math
from array import array
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig, load_aircraft
from fms_testbed.core.atmosphere import cas_to_tas, cas_to_tas_scalar
from fms_testbed.core.errors import UserError
from fms_testbed.sim.jsbsim_core import FT, RAW, JSBSimAircraft
from fms_testbed.navigation import make_source
from fms_testbed.config.scenario import Event, Scenario, load_scenario, parse_scenario
from fms_testbed.core.contracts import Guidance, GuidanceOutput
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.control import VERTICAL_LAWS
from fms_testbed.loop.log import build_frame
from fms_testbed.loop.procedure import PreparedProcedure

log = logging.getLogger(__name__)

#: The scenario's steady wind grows linearly from zero to its value over this time after trim, s.
WIND_RAMP_S = 20.0

_TURB_SEVERITY = {"light": (3, 25.0), "moderate": (4, 50.0), "severe": (6, 75.0)}  # (index, kt@20ft)


@dataclass
class _Targets:
    bank_rad: float = 0.0
    heading_rad: float | None = None
    ny: float = 1.0
    nx: float | None = None
    throttle: float | None = None
    alt_m: float | None = None
    speed_kind: str = "tas"
    speed_mps: float | None = None
    vertical: bool = False


def _wrap_pi(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _wind_ned(scn: Scenario) -> tuple[float, float, float]:
    if scn.wind is None:
        return (0.0, 0.0, 0.0)
    to = math.radians(scn.wind.from_deg + 180.0)
    return (scn.wind.speed_ms * math.cos(to), scn.wind.speed_ms * math.sin(to), 0.0)


class _EventQueue:
    """Timed and conditional events, each fired once, in file order."""

    def __init__(self, events: list[Event]):
        self.pending = list(events)

    def due(self, t_s: float, alt_m: float) -> list[Event]:
        fired, keep = [], []
        for ev in self.pending:
            if ev.t_s is not None:
                ok = t_s + 1e-9 >= ev.t_s
            else:
                w = ev.when
                ok = ((w.alt_m_above is None or alt_m >= w.alt_m_above)
                      and (w.alt_m_below is None or alt_m <= w.alt_m_below)
                      and (w.t_s_after is None or t_s >= w.t_s_after))
            (fired if ok else keep).append(ev)
        self.pending = keep
        return fired


def _apply(ev: Event, tg: _Targets) -> None:
    if ev.bank_deg is not None:
        tg.bank_rad, tg.heading_rad = math.radians(ev.bank_deg), None
    if ev.heading_deg is not None:
        tg.heading_rad = math.radians(ev.heading_deg)
    if ev.ny is not None:
        tg.ny, tg.vertical = ev.ny, False
    if ev.nx is not None:
        tg.nx, tg.throttle, tg.vertical = ev.nx, None, False
    if ev.throttle is not None:
        tg.throttle, tg.nx, tg.vertical = ev.throttle, None, False
    if ev.altitude_m is not None:
        tg.alt_m, tg.vertical = ev.altitude_m, True
    kind, spd = ev.speed
    if spd is not None:
        tg.speed_kind, tg.speed_mps, tg.vertical = kind, spd, True


class _Divergence:
    """The run-ending checks, with the aircraft's limits converted once (SI, rad)."""

    def __init__(self, cfg: AircraftConfig):
        lim = cfg.limits
        self.stall_alpha_deg = lim.stall_alpha_deg
        self.stall_rad = math.radians(lim.stall_alpha_deg)
        self.cas_max_mps = lim.cas_max_mps
        self.mach_max = lim.mach_max
        self.roll_max_rad, self.pitch_max_rad = math.radians(75), math.radians(45)

    def __call__(self, s: AircraftState, wow: float) -> str | None:
        """None while the flight is sound, else the reason it must end."""
        if not math.isfinite(s.alt_m + s.tas_mps + s.roll_rad + s.pitch_rad + s.alpha_rad + s.ny):
            return "non-finite state (JSBSim diverged)"
        if s.agl_m < 1.0 or wow > 0.5:
            return f"ground contact at t={s.t_s:.1f} s"
        if s.alpha_rad > self.stall_rad:
            return (f"stall: alpha {math.degrees(s.alpha_rad):.1f} deg > {self.stall_alpha_deg} deg "
                    f"at t={s.t_s:.1f} s")
        if s.cas_mps > self.cas_max_mps * 1.1:
            return (f"overspeed: CAS {s.cas_mps / 0.514444:.0f} kt > 1.1 x VMO "
                    f"{self.cas_max_mps / 0.514444:.0f} kt at t={s.t_s:.1f} s")
        if s.mach > self.mach_max + 0.05:
            return f"overspeed: Mach {s.mach:.3f} > MMO + 0.05 at t={s.t_s:.1f} s"
        if abs(s.roll_rad) > self.roll_max_rad or abs(s.pitch_rad) > self.pitch_max_rad:
            return (f"upset: roll {math.degrees(s.roll_rad):.0f} deg, "
                    f"pitch {math.degrees(s.pitch_rad):.0f} deg")
        return None


class _NavHold:
    """Apply the last navigation errors to truth between navigation updates."""

    def __init__(self, source, dt_s: float):
        self.source, self.dt_s = source, dt_s
        self.next_t = 0.0
        self.err = None
        self.errors: dict[str, float] = {}

    def __call__(self, s: AircraftState) -> NavSolution:
        if self.err is None or s.t_s + 1e-9 >= self.next_t:
            nav = self.source.update(s)
            self.err = (nav.lat_rad - s.lat_rad, nav.lon_rad - s.lon_rad, nav.alt_m - s.alt_m,
                        nav.v_enu_mps - s.v_enu_mps, nav.roll_rad - s.roll_rad,
                        nav.pitch_rad - s.pitch_rad, _wrap_pi(nav.heading_rad - s.heading_rad))
            self.errors = dict(nav.errors)
            self.next_t = s.t_s + self.dt_s
            return nav
        e = self.err
        return NavSolution(t_s=s.t_s, lat_rad=s.lat_rad + e[0], lon_rad=s.lon_rad + e[1],
                           alt_m=s.alt_m + e[2], v_enu_mps=s.v_enu_mps + e[3],
                           roll_rad=s.roll_rad + e[4], pitch_rad=s.pitch_rad + e[5],
                           heading_rad=_wrap_pi(s.heading_rad + e[6]) % (2 * math.pi),
                           errors=self.errors)


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
        tas0 = float(cas_to_tas(spd, ini.altitude_m)) if kind == "cas" else spd
        # Trim in calm air: JSBSim 1.3.3 fails to trim in wind, and run_ic() resets the
        # atmosphere's wind to the initial condition's. The steady wind is ramped in after the
        # trim (WIND_RAMP_S).
        ac.trim(ini.altitude_m, tas0, heading_deg=ini.heading_deg, lat_deg=ini.lat_deg,
                lon_deg=ini.lon_deg)
        if scn.turbulence is not None:  # after trim: JSBSim cannot trim in turbulence
            idx, w20 = _TURB_SEVERITY[scn.turbulence.severity]
            ac.fdm["atmosphere/turb-type"] = 4
            ac.fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = w20 * 1.6878
            ac.fdm["atmosphere/turbulence/milspec/severity"] = idx
        ac.engage()
        ac.command(bank_rad=0.0, ny=1.0, nx=0.0)

        nav_spec = scn.navigation or {}
        try:
            source = make_source(nav_spec, seed=int(nav_spec.get("seed", self.seed)))
        except UserError as exc:
            where = scn.source_file or scn.name or "scenario"
            raise type(exc)(f"{where}: {exc}") from None
        self.navigation = source
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
        """The outer loop as a generator: one ``yield`` per outer step (locals stay fast)."""
        scn, cfg, ac, guidance = self.scn, self.cfg, self.aircraft, self.guidance
        law, rows, extra_rows, bar = self.vertical_law, self.rows, self.extra_rows, self._bar
        raw_log = self.raw_log
        no_errors: dict = {}
        ini = scn.initial
        kind, spd = ini.speed
        nav_spec = scn.navigation or {}
        nav_dt = float(nav_spec.get("dt_s", 0.1)) if nav_spec.get("source") == "sins" else 0.0
        n_outer, dt_outer = self.n_frames, self.dt_outer_s
        # hold the navigation errors between updates only when navigation runs slower than
        # guidance
        navigate = (_NavHold(self.navigation, nav_dt) if nav_dt > dt_outer + 1e-9
                    else self.navigation.update)
        tg = _Targets()
        if scn.hold:
            tg.alt_m, tg.speed_kind, tg.speed_mps, tg.vertical = ini.altitude_m, kind, spd, True
        events = _EventQueue(scn.events)
        log_every = max(1, int(round(1.0 / (scn.log_rate_hz * dt_outer))))
        n_total = int(math.ceil(scn.duration_s / dt_outer))
        lim = cfg.limits
        bank_max = math.radians(lim.bank_max_deg)
        roll_step = math.radians(lim.roll_rate_max_dps) * dt_outer
        heading_kp = cfg.inner_loops.heading_kp
        wind_ned = _wind_ned(scn)
        wind_on = any(wind_ned)
        pm = ac.fdm.get_property_manager()
        wind_nodes = [pm.get_node(f"atmosphere/wind-{c}-fps", False)
                      for c in ("north", "east", "down")]
        i_wow = RAW["wow"]
        diverged = _Divergence(cfg)
        last_bank = 0.0
        law_engaged = False
        cmd_nx = cmd_ny = nan = float("nan")
        raw = ac.read_raw()
        for k in range(n_total + 1):
            s = ac.state(raw)
            why = diverged(s, raw[i_wow])
            if why:
                self.status, self.reason = "diverged", why
                return
            if wind_on and s.t_s <= WIND_RAMP_S + dt_outer:
                frac = min(1.0, s.t_s / WIND_RAMP_S)
                for node, w in zip(wind_nodes, wind_ned):
                    node.set_double_value(frac * w / FT)
            nav = navigate(s)
            if events.pending:
                for ev in events.due(s.t_s, s.alt_m):
                    _apply(ev, tg)
            gout = guidance.update(dt_outer, nav, s) if guidance is not None else None
            if gout is not None:
                if gout.bank_rad is not None:
                    tg.bank_rad, tg.heading_rad = gout.bank_rad, None
                if gout.alt_m is not None:
                    tg.alt_m, tg.vertical = gout.alt_m, True
                if gout.tas_mps is not None:
                    tg.speed_kind, tg.speed_mps, tg.vertical = "tas", gout.tas_mps, True
            # lateral: heading hold on the navigation heading, else bank hold
            hdg_cmd = tg.heading_rad
            if hdg_cmd is not None:
                err = _wrap_pi(hdg_cmd - nav.heading_rad)
                bank_cmd = max(-bank_max, min(bank_max, heading_kp * err))
            else:
                bank_cmd = tg.bank_rad
            if hdg_cmd is not None or gout is not None:
                # guidance/heading-hold bank commands are rate limited (passenger-comfort rate)
                bank_cmd = min(max(bank_cmd, last_bank - roll_step), last_bank + roll_step)
            last_bank = bank_cmd
            # vertical: the law when an altitude/speed target is active
            if tg.vertical:
                if tg.alt_m is None:
                    tg.alt_m = s.alt_m
                alt_cmd = tg.alt_m
                if tg.speed_mps is None:
                    tg.speed_kind, tg.speed_mps = "tas", s.tas_mps
                tas_cmd = (cas_to_tas_scalar(tg.speed_mps, s.alt_m) if tg.speed_kind == "cas"
                           else tg.speed_mps)
                if not law_engaged:
                    law.engage(s, alt_cmd, tas_cmd)
                    law_engaged = True
                # the law works in the vertical plane: it returns the vertical component of n_y
                cmd_nx, ny_vert = law.update(dt_outer, s, alt_cmd, tas_cmd)
                cmd_ny = ny_vert / max(math.cos(s.roll_rad), 0.5)
                ac.command(bank_rad=bank_cmd, ny=cmd_ny, nx=cmd_nx)
            else:
                law_engaged = False
                alt_cmd = tas_cmd = nan
                cmd_ny = tg.ny
                if tg.throttle is not None:
                    cmd_nx = nan
                    ac.command(bank_rad=bank_cmd, ny=cmd_ny, throttle=tg.throttle)
                else:
                    cmd_nx = tg.nx if tg.nx is not None else 0.0
                    ac.command(bank_rad=bank_cmd, ny=cmd_ny, nx=cmd_nx)
            if k % log_every == 0:
                # what is at hand only; converted to the timeseries' units once, at the end
                raw_log.extend(raw)
                rows.append((bank_cmd, hdg_cmd, cmd_nx, cmd_ny, tg.throttle, alt_cmd, tas_cmd,
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
            if not ac.run(n_outer):
                self.status, self.reason = "diverged", "JSBSim stopped"
                return
            raw = ac.read_raw()
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
            "scenario": scn.name, "aircraft": cfg.name, "jsbsim_model": cfg.jsbsim_model,
            "status": status, "reason": reason,
            "seed": self.seed,
            "duration_s": round(flown, 3), "wall_time_s": round(wall, 3),
            "real_time_factor": round(flown / wall, 1) if wall > 0 else None,
            "loop_wall_time_s": round(loop_wall, 4),
            "loop_steps_per_s": round(flown / ac.dt_s / loop_wall) if loop_wall > 0 else None,
            "trim": {"alt_m": trim.alt_m, "tas_mps": round(trim.tas_mps, 3),
                     "alpha_deg": round(trim.alpha_deg, 3), "pitch_deg": round(trim.pitch_deg, 3),
                     "throttle": round(trim.throttle, 4), "elevator": round(trim.elevator, 4)},
            "metrics": _metrics(df),
        }
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
