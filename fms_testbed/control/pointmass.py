"""The paper's point-mass plant (eq. 1) with optional inner-loop/engine lags, closed with a law.

    V' = g (n_x - sin θ),   θ' = (g / V)(n_y - cos θ),   H' = V sin θ           (eq. 1)

with g the local normal gravity at the equator (load factors stay referred to g0, as JSBSim's).
The load factors the plant feels follow the commands through first-order lags (``tau_nx_s``,
``tau_ny_s``; zero = the paper's lag-free realisation, "безынерционная отработка") and n_x is
limited to ``[nx_idle, nx_max]`` (thrust limits). A pseudo-throttle 0..1 maps the n_x command onto
that range so the laws' saturation logic sees a saturated throttle exactly when the command is
outside what the engines can give. This is the "ideal point-mass closed-loop response of the same
law" against which JSBSim runs are judged, and the fast plant for tests and tuning previews.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from fms_testbed.control.coupled_law import gravity_ratio
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import G0_MPS2

_ZERO3 = np.zeros(3)


@dataclass(frozen=True, slots=True)
class PointMassParams:
    """Plant options.

    tau_nx_s : first-order lag of the n_x realisation (engine + n_x loop), s; 0 = none
    tau_ny_s : first-order lag of the n_y realisation (short period + n_y loop), s; 0 = none
    nx_idle, nx_max : tangential load factor available at idle / max throttle, g
    """

    tau_nx_s: float = 0.0
    tau_ny_s: float = 0.0
    nx_idle: float = -0.08
    nx_max: float = 0.25


@dataclass(frozen=True, slots=True)
class CommandEvent:
    """A change of target: at ``t_s`` or when the altitude crosses ``alt_above_m``/``alt_below_m``.

    alt_m, tas_mps : new targets (``None`` keeps the current one)
    """

    alt_m: float | None = None
    tas_mps: float | None = None
    t_s: float | None = None
    alt_above_m: float | None = None
    alt_below_m: float | None = None

    def due(self, t_s: float, alt_m: float) -> bool:
        """Whether the event fires at time ``t_s`` (s) and altitude ``alt_m`` (m)."""
        if self.t_s is not None and t_s + 1e-9 < self.t_s:
            return False
        if self.alt_above_m is not None and alt_m <= self.alt_above_m:
            return False
        if self.alt_below_m is not None and alt_m >= self.alt_below_m:
            return False
        return True


def make_state(t_s: float, tas_mps: float, gamma_rad: float, alt_m: float, nx: float, ny: float,
               throttle: float) -> AircraftState:
    """An :class:`AircraftState` carrying the point-mass quantities (others zero).

    Parameters
    ----------
    t_s : time, s;  tas_mps : airspeed, m/s;  gamma_rad : flight-path angle, rad
    alt_m : altitude, m;  nx, ny : realised load factors, g;  throttle : pseudo-throttle, 0..1
    """
    vs = tas_mps * math.sin(gamma_rad)
    return AircraftState(
        t_s=t_s, lat_rad=0.0, lon_rad=0.0, alt_m=alt_m, tas_mps=tas_mps, cas_mps=tas_mps,
        gs_mps=tas_mps * math.cos(gamma_rad), vs_mps=vs, v_enu_mps=_ZERO3, roll_rad=0.0,
        pitch_rad=gamma_rad, heading_rad=0.0, track_rad=0.0, alpha_rad=0.0, beta_rad=0.0,
        gamma_rad=gamma_rad, p_rps=0.0, q_rps=0.0, r_rps=0.0, nx=nx, ny=ny, f_body_mps2=_ZERO3,
        mach=0.0, agl_m=alt_m, throttle=throttle, mass_kg=0.0)


def _derivs(x: np.ndarray, nx_cmd: float, ny_cmd: float, pm: PointMassParams) -> np.ndarray:
    """State derivative of [V, θ, H, n_x, n_y] (eq. 1 plus lags)."""
    V, th, H, nx, ny = x
    gr = gravity_ratio(0.0, H)
    d = np.empty(5)
    d[0] = G0_MPS2 * (nx - gr * math.sin(th))
    d[1] = G0_MPS2 / V * (ny - gr * math.cos(th))
    d[2] = V * math.sin(th)
    d[3] = (nx_cmd - nx) / pm.tau_nx_s if pm.tau_nx_s > 0 else 0.0
    d[4] = (ny_cmd - ny) / pm.tau_ny_s if pm.tau_ny_s > 0 else 0.0
    return d


def simulate(law, pm: PointMassParams, alt0_m: float, tas0_mps: float, duration_s: float,
             events: list[CommandEvent] = (), dt_s: float = 1.0 / 40, substeps: int = 3
             ) -> pd.DataFrame:
    """Fly a vertical law on the point-mass plant from trimmed level flight.

    Parameters
    ----------
    law : object with ``engage(state, alt_cmd_m, tas_cmd_mps)`` and
        ``update(dt_s, state, alt_cmd_m, tas_cmd_mps) -> (nx_cmd, ny_cmd)``
    pm : plant options
    alt0_m, tas0_mps : initial altitude (m) and airspeed (m/s); the law holds them until an event
    duration_s : simulated time, s
    events : target changes
    dt_s : law update period, s;  substeps : RK4 plant steps per law step

    Returns
    -------
    DataFrame with the runner's column names: t_s, alt_m, tas_mps, vs_mps, gamma_deg, nx, ny,
    throttle, cmd_alt_m, cmd_tas_mps, cmd_nx, cmd_ny.
    """
    x = np.array([tas0_mps, 0.0, alt0_m, 0.0, gravity_ratio(0.0, alt0_m)])
    alt_cmd, tas_cmd = alt0_m, tas0_mps
    pending = list(events)
    n = int(round(duration_s / dt_s)) + 1
    out = np.zeros((n, 12))
    span = pm.nx_max - pm.nx_idle

    def throttle_of(c: float) -> float:
        return min(max((c - pm.nx_idle) / span, 0.0), 1.0)

    thr = throttle_of(0.0)
    law.engage(make_state(0.0, x[0], x[1], x[2], x[3], x[4], thr), alt_cmd, tas_cmd)
    h = dt_s / substeps
    for k in range(n):
        t = k * dt_s
        for ev in [e for e in pending if e.due(t, x[2])]:
            alt_cmd = ev.alt_m if ev.alt_m is not None else alt_cmd
            tas_cmd = ev.tas_mps if ev.tas_mps is not None else tas_cmd
            pending.remove(ev)
        st = make_state(t, x[0], x[1], x[2], x[3], x[4], thr)
        nx_c, ny_c = law.update(dt_s, st, alt_cmd, tas_cmd)
        thr = throttle_of(nx_c)
        nx_real = min(max(nx_c, pm.nx_idle), pm.nx_max)
        if pm.tau_nx_s <= 0:
            x[3] = nx_real
        if pm.tau_ny_s <= 0:
            x[4] = ny_c
        out[k] = (t, x[2], x[0], x[0] * math.sin(x[1]), math.degrees(x[1]), x[3], x[4], thr,
                  alt_cmd, tas_cmd, nx_c, ny_c)
        for _ in range(substeps):
            k1 = _derivs(x, nx_real, ny_c, pm)
            k2 = _derivs(x + 0.5 * h * k1, nx_real, ny_c, pm)
            k3 = _derivs(x + 0.5 * h * k2, nx_real, ny_c, pm)
            k4 = _derivs(x + h * k3, nx_real, ny_c, pm)
            x = x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    cols = ["t_s", "alt_m", "tas_mps", "vs_mps", "gamma_deg", "nx", "ny", "throttle",
            "cmd_alt_m", "cmd_tas_mps", "cmd_nx", "cmd_ny"]
    return pd.DataFrame(out, columns=cols)


def second_order_step(t_s: np.ndarray, T_s: float, xi: float) -> np.ndarray:
    """Unit-step response of ``1 / (T² p² + 2 ξ T p + 1)`` (the desired dynamics of eq. 2/5).

    Parameters
    ----------
    t_s : times after the step, s
    T_s : time constant T, s;  xi : damping ratio ξ
    """
    t = np.asarray(t_s, dtype=float)
    w = 1.0 / T_s
    if abs(xi - 1.0) < 1e-9:
        return 1.0 - (1.0 + w * t) * np.exp(-w * t)
    if xi < 1.0:
        wd = w * math.sqrt(1.0 - xi ** 2)
        return 1.0 - np.exp(-xi * w * t) * (np.cos(wd * t) + xi * w / wd * np.sin(wd * t))
    r = math.sqrt(xi ** 2 - 1.0)
    p1, p2 = -w * (xi - r), -w * (xi + r)
    return 1.0 - (p2 * np.exp(p1 * t) - p1 * np.exp(p2 * t)) / (p2 - p1)
