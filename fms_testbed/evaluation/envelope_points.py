"""Design points of the envelope tuning: the grid, the linear goals, the optimiser, the
nonlinear check.

At each design point (:class:`~fms_testbed.sim.linearise.DesignPoint`) the JSBSim aircraft is
trimmed and linearised and the loops of :mod:`fms_testbed.control.loops` are built. The
coupled law's (T_V, ξ_V, T_H, ξ_H) and its n_y-trim time constant are tuned there with SLSQP (scipy) against

* hard goals (constraints, with the buffers :data:`TUNE_BUFFER`), on the loops broken at the thrust (n_x) and elevator (n_y)
  channels and at the inner loops' actuators: gain margin ≥ :data:`GM_MIN_DB`, phase margin ≥
  :data:`PM_MIN_DEG`, disk margin ≥ :data:`DM_MIN`, closed-loop damping ≥ :data:`ZETA_MIN`;
* soft goals (cost), on the linear closed loop's responses to an altitude step ``dH`` and a
  speed step ``dV``: tracking (integral of |error| over the step, in step sizes × 10 s),
  decoupling ((max|ΔV| / 0.5 km/h)² + (max|ΔH| / 0.75 m)², half the nonlinear goals), path
  tracking (the steady altitude error on a :data:`RAMP_MPS` descent path read ahead by the
  guidance's lead, the tuning's own 2 ξ_H T_H as VNAV reads it from the schedule in flight,
  / :data:`RAMP_ERR_M`, squared: what is left is the inner loops' lag), gust rejection
  (:func:`gust_rejection`: |ΔV| and |ΔH| integrated after an updraft and a headwind step), and
  activity (peak throttle in 0.3 of its range and peak elevator in 0.1, per step), plus a pull
  towards the starting tuning (:data:`REG_WEIGHT`).

The margins inside the optimiser are read from the loop's frequency response on a grid
(:func:`grid_margins`); the reported ones are python-control's (:func:`~.loops.margins`).
:func:`verify` flies the two steps on the nonlinear JSBSim aircraft with the law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import control as ct
import numpy as np
from scipy.linalg import expm
from scipy.optimize import minimize

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.control.coupled_law import CoupledLaw, CoupledLawParams
from fms_testbed.control.loops import (GUST_INPUTS, LON_BREAKS, LateralLaw, PointLoops,
                                       closed_loop_damping, inner_gains, with_gusts)
from fms_testbed.core.atmosphere import isa
from fms_testbed.core.errors import TrimError
from fms_testbed.core.units import KMH_MPS
from fms_testbed.sim.linearise import AirframeModel, DesignPoint, trim_point

GM_MIN_DB = 6.0
"""Hard goal: gain margin of every loop, dB."""
PM_MIN_DEG = 45.0
"""Hard goal: phase margin of every loop, deg."""
DM_MIN = 0.67
"""Hard goal: balanced disk margin α of every loop (α = 2/3 guarantees ±6 dB alone)."""
ZETA_MIN = 0.4
"""Hard goal: damping ratio of every oscillatory closed-loop pole."""
TUNE_BUFFER = {"gm_db": 1.0, "pm_deg": 5.0, "dm": 0.05, "zeta": 0.05}
"""The tuner's constraints are the hard goals plus these buffers (dB, deg, α, -): the schedule's
fit residual and the nonlinear loop must not take a point below the goals."""
BOUNDS = {"T_V_s": (4.0, 15.0), "xi_V": (0.6, 1.5), "T_H_s": (5.0, 20.0), "xi_H": (0.6, 1.5),
          "ny_trim_tau_s": (1.0, 8.0)}
"""Tuning box: time constants in s, damping ratios dimensionless (``ny_trim_tau_s``: the law's
n_y tracking-error integrator, the element that sets the elevator channel's phase margin at
low dynamic pressure)."""
NAMES = tuple(BOUNDS)
REG_WEIGHT = 2.0
"""Weight of the pull towards the starting tuning, ``REG_WEIGHT Σ ((x - x0)/(hi - lo))²``: the
soft cost is flat near its optimum, and without the pull neighbouring points land on unrelated
optima (a jagged schedule)."""
NY_TRIM_WEIGHT = 200.0
"""Weight of the penalty ``NY_TRIM_WEIGHT max(0, (τ - τ_file)/(hi - lo))²`` on an n_y-trim
time constant slower than the file's: a slower n_y trim lets the n_y tracking error stand
longer in turbulence (the vertical path error grows), so it is raised only where the hard
goals need it."""
DH_STEP_M = 100.0
"""Altitude step of the soft goals and of the nonlinear check, m (inside the ±dH limit)."""
DV_STEP_FRAC = 0.10
"""Speed step of the soft goals and of the nonlinear check, fraction of the TAS."""
T_STEP_S = 120.0
RAMP_MPS = 5.0
"""Soft goal: altitude-command ramp (a descent path), m/s."""
RAMP_ERR_M = 5.0
"""Soft goal: the ramp's steady altitude error is scored against this, m."""
_DT_S = 0.1
GUST_MPS = 1.0
"""Size of the updraft and headwind steps of the gust-rejection goal, m/s."""
GUST_WEIGHT = 1.0
"""Weight of :func:`gust_rejection` in the soft cost."""
_OMEGA = np.logspace(-3, 2, 400)


def qbar_ratio(cfg: AircraftConfig, qbar_pa: float) -> float:
    """q̄_ref / q̄ of the inner loops' schedule at ``qbar_pa`` (Pa); the reference is the aircraft
    ``cfg``'s default condition."""
    _, _, rho = isa(cfg.default_condition.alt_m)
    return 0.5 * float(rho) * cfg.default_condition.tas_mps ** 2 / qbar_pa


def point_loops(cfg: AircraftConfig, model: AirframeModel, law: CoupledLawParams,
                lateral: LateralLaw | None = None, delay_s: float = 0.0) -> PointLoops:
    """The loops of ``model`` with the aircraft's inner loops, the law and the path law.

    Parameters
    ----------
    cfg : aircraft;  model : linear airframe;  law : coupled-law tuning
    lateral : path-law tuning (default ω 0.1 rad/s, ζ 0.9);  delay_s : actuator delay, s
    """
    return PointLoops(model.lon, model.lat, inner_gains(cfg, qbar_ratio(cfg, model.qbar_pa)),
                      law, lateral or LateralLaw(), model.trim.tas_mps, delay_s)


def freq_response(sys, omega_rps: np.ndarray) -> np.ndarray:
    """SISO frequency response C (jωI - A)⁻¹ B + D of ``sys`` on ``omega_rps`` (rad/s), via the
    eigen-decomposition of A (vectorised over ω), or python-control's response when A is
    (nearly) defective."""
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) > 1e8:         # defective A (repeated integrators): python-control
        return np.asarray(ct.frequency_response(sys, omega_rps).complex).ravel()
    cb = (C @ V).ravel() * np.linalg.solve(V, B).ravel()
    return (cb[None, :] / (1j * omega_rps[:, None] - lam[None, :])).sum(axis=1) + D[0, 0]


def grid_margins(L, omega_rps: np.ndarray = _OMEGA) -> tuple[float, float, float]:
    """(GM dB, PM deg, disk margin α) of a loop transfer ``L`` from its response on the grid
    ``omega_rps`` (rad/s): GM at the phase crossovers (Im L changes sign with Re L < 0), PM at
    |L| = 1, α = min 2|1+L|/|1-L|."""
    h = freq_response(L, omega_rps)
    cross = np.flatnonzero((np.sign(h.imag[:-1]) != np.sign(h.imag[1:])) & (h.real[:-1] < 0))
    gms = [abs(20 * math.log10(abs(h.real[i]))) for i in cross if h.real[i] != 0]
    mag = np.abs(h)
    up = np.flatnonzero(np.sign(mag[:-1] - 1) != np.sign(mag[1:] - 1))
    pms = [180.0 - abs(math.degrees(np.angle(h[i]))) for i in up]
    dm = float(np.min(2 * np.abs(1 + h) / np.maximum(np.abs(1 - h), 1e-12)))
    return (min(gms) if gms else 60.0), (min(pms) if pms else 180.0), dm


def step_matrices(sys, dt_s: float = _DT_S) -> tuple[np.ndarray, np.ndarray]:
    """Zero-order-hold discretisation (Φ, Γ) of ``sys`` at ``dt_s`` (s) with ``expm``."""
    A, B = np.asarray(sys.A), np.asarray(sys.B)
    n, m = A.shape[0], B.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A * dt_s, B * dt_s
    E = expm(M)
    return E[:n, :n], E[:n, n:]


def step_outputs(sys, u: np.ndarray, t_end_s: float = T_STEP_S, dt_s: float = _DT_S) -> np.ndarray:
    """Outputs (time × outputs) of ``sys`` for a constant input vector ``u`` from rest, at
    ``t_k = k dt_s``, k = 1 … ``t_end_s / dt_s``.

    With A = V diag(λ) V⁻¹ the response is evaluated in closed form, vectorised over time::

        y(t) = Re(C V diag(g(t)) V⁻¹ B u) + D u,   g_i(t) = (e^{λ_i t} - 1) / λ_i  (t at λ_i = 0)

    (exact for a constant input, equal to the zero-order-hold recursion); a (nearly) defective
    A is stepped with the ``expm`` discretisation (:func:`step_matrices`) instead.
    """
    A, B = np.asarray(sys.A), np.asarray(sys.B)
    C, D = np.asarray(sys.C), np.asarray(sys.D)
    n = int(t_end_s / dt_s)
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) < 1e8:
        z = np.linalg.solve(V, B @ u)
        t = dt_s * np.arange(1, n + 1)
        small = np.abs(lam) < 1e-9
        lt = np.where(small, 1.0, lam)
        g = np.where(small[None, :], t[:, None], np.expm1(lam[None, :] * t[:, None]) / lt[None, :])
        return ((g * z[None, :]) @ (C @ V).T).real + D @ u
    Phi, Gam = step_matrices(sys, dt_s)
    x = np.zeros(Phi.shape[0])
    out = np.empty((n, C.shape[0]))
    gu = Gam @ u
    for k in range(n):
        x = Phi @ x + gu
        out[k] = C @ x + D @ u
    return out


@dataclass(frozen=True, slots=True)
class LinearGoals:
    """Hard and soft goals of one tuning at one design point (linear models).

    gm_db, pm_deg, dm : smallest over the longitudinal loops (dB, deg, α);  zeta : smallest
    closed-loop damping;  max_dv_kmh : max|ΔV| in the altitude step, km/h;  max_dh_m :
    max|ΔH| in the speed step, m;  cost : soft-goal cost (dimensionless);  h_rise_s : time
    from the altitude step to 90 % of it, s (the altitude loop's speed);  h_overshoot :
    overshoot of that step, fraction of the step (its damping)
    """

    gm_db: float
    pm_deg: float
    dm: float
    zeta: float
    max_dv_kmh: float
    max_dh_m: float
    cost: float
    h_rise_s: float = math.nan
    h_overshoot: float = math.nan


def linear_goals(pl: PointLoops, lead_s: float | None = None) -> LinearGoals:
    """Evaluate :class:`LinearGoals` for the loops ``pl`` (module docstring); ``lead_s`` is the
    guidance's altitude read-ahead, s (None: the law's own 2 ξ_H T_H, which VNAV reads from the
    schedule in flight: :func:`fms_testbed.guidance.vertical.scheduled_lead`)."""
    if lead_s is None:
        lead_s = 2.0 * pl.law.xi_H * pl.law.T_H_s
    ms = [grid_margins(pl.loop(b)) for b in LON_BREAKS]
    zeta, _ = closed_loop_damping(pl, "lon")
    sys = pl.closed("lon", ["V_cmd", "H_cmd"], ["V", "h", "throttle", "elevator"])
    dv = DV_STEP_FRAC * pl.V0_mps
    yh = step_outputs(sys, np.array([0.0, DH_STEP_M]))
    yv = step_outputs(sys, np.array([dv, 0.0]))
    track = (np.abs(yh[:, 1] - DH_STEP_M).sum() / DH_STEP_M
             + np.abs(yv[:, 0] - dv).sum() / dv) * _DT_S / 10.0
    max_dv = float(np.abs(yh[:, 0]).max() / KMH_MPS)
    max_dh = float(np.abs(yv[:, 1]).max())
    couple = (max_dv / 0.5) ** 2 + (max_dh / 0.75) ** 2
    # a descent path read ahead by the guidance's lead L: H_cmd = r (t + L); LTI, so the
    # response is r (∫ y_step dt + L y_step) / ΔH; its error from the path r t at the end
    y = yh[:, 1] / DH_STEP_M
    e_end = RAMP_MPS * (np.sum(y) * _DT_S + lead_s * y[-1] - len(y) * _DT_S)
    couple += (float(e_end) / RAMP_ERR_M) ** 2
    act = (np.abs(yv[:, 2]).max() + np.abs(yh[:, 2]).max()) / 0.3 + \
        (np.abs(yv[:, 3]).max() + np.abs(yh[:, 3]).max()) / 0.1
    hit = np.flatnonzero(y >= 0.9)
    rise = float((hit[0] + 1) * _DT_S) if len(hit) else math.inf
    return LinearGoals(min(m[0] for m in ms), min(m[1] for m in ms), min(m[2] for m in ms),
                       zeta, max_dv, max_dh,
                       float(track + couple + 0.5 * act + GUST_WEIGHT * gust_rejection(pl)),
                       rise, max(0.0, float(y.max()) - 1.0))


def gust_rejection(pl: PointLoops) -> float:
    """Disturbance-rejection soft goal of the loops ``pl``: the closed loop's integral of |ΔV|
    (m/s·s) and |ΔH| (m·s) after a :data:`GUST_MPS` updraft step and a headwind step
    (:func:`fms_testbed.control.loops.with_gusts`), each over :data:`T_STEP_S`, in units of
    (1 m/s or 1 m) × 10 s per m/s of gust::

        J = Σ_gust (∫|ΔV| dt / (1 m/s · 10 s) + ∫|ΔH| dt / (1 m · 10 s)) / w_gust
    """
    sys = replace(pl, lon=with_gusts(pl.lon, pl.V0_mps)).closed("lon", list(GUST_INPUTS),
                                                               ["V", "h"])
    j = 0.0
    for u in (np.array([GUST_MPS, 0.0]), np.array([0.0, GUST_MPS])):
        y = step_outputs(sys, u)
        j += float(np.abs(y).sum() * _DT_S / 10.0 / GUST_MPS)
    return j


H_RISE_TOL = 0.02
"""Altitude-loop goal: the 90 % rise time of the altitude step may exceed the file law's at the
same point by at most this fraction."""
H_OVERSHOOT_TOL = 0.01
"""Altitude-loop goal: the altitude step's overshoot may exceed the file law's at the same point
by at most this, fraction of the step."""


def _constraints(g: LinearGoals, ref: LinearGoals | None = None) -> np.ndarray:
    """Hard goals plus :data:`TUNE_BUFFER` as ``c ≥ 0`` (each scaled to about one unit); with
    ``ref`` (the file law's goals at the same point) also the altitude-loop goal: no slower
    and no less damped than ``ref``::

        t_90 ≤ (1 + H_RISE_TOL) t_90,ref,    overshoot ≤ overshoot_ref + H_OVERSHOOT_TOL
    """
    b = TUNE_BUFFER
    c = [(g.gm_db - GM_MIN_DB - b["gm_db"]) / 6.0,
         (g.pm_deg - PM_MIN_DEG - b["pm_deg"]) / 45.0,
         (g.dm - DM_MIN - b["dm"]) / DM_MIN, (g.zeta - ZETA_MIN - b["zeta"]) / ZETA_MIN]
    if ref is not None:
        c += [((1.0 + H_RISE_TOL) * ref.h_rise_s - g.h_rise_s) / ref.h_rise_s,
              (ref.h_overshoot + H_OVERSHOOT_TOL - g.h_overshoot) / 0.1]
    return np.array(c)


@dataclass(frozen=True)
class PointTuning:
    """Result of :func:`tune_point`: the tuning, its linear goals, start goals, evaluations."""

    params: CoupledLawParams
    goals: LinearGoals
    start: LinearGoals
    n_evals: int
    feasible: bool


def tune_point(cfg: AircraftConfig, model: AirframeModel, start: CoupledLawParams,
               max_iter: int = 30) -> PointTuning:
    """Tune (T_V, ξ_V, T_H, ξ_H, τ_ny-trim) at one design point (module docstring).

    From an infeasible start a Nelder-Mead search first maximises the smallest scaled hard-goal
    slack; SLSQP then minimises the soft cost with the hard goals as constraints. The result is
    the cheapest feasible tuning evaluated (else the least infeasible one).

    Parameters
    ----------
    cfg : aircraft;  model : linear airframe at the point
    start : starting tuning (clipped into :data:`BOUNDS`);  max_iter : SLSQP iterations
    """
    lo = np.array([BOUNDS[n][0] for n in NAMES])
    hi = np.array([BOUNDS[n][1] for n in NAMES])
    cache: dict[tuple, tuple[np.ndarray, LinearGoals]] = {}

    def params(u):
        x = lo + np.clip(u, 0.0, 1.0) * (hi - lo)
        return replace(start, **{n: round(float(v), 3) for n, v in zip(NAMES, x)})

    def goals(u) -> LinearGoals:
        key = tuple(np.round(np.clip(u, 0.0, 1.0), 4))
        if key not in cache:
            cache[key] = (np.array(key), linear_goals(point_loops(cfg, model, params(u))))
        return cache[key][1]

    u0 = (np.clip([getattr(start, n) for n in NAMES], lo, hi) - lo) / (hi - lo)
    g0 = goals(u0)
    ref = linear_goals(point_loops(cfg, model, start))

    def cons(g: LinearGoals) -> np.ndarray:
        return _constraints(g, ref)

    u = u0
    if np.min(cons(g0)) < 0:
        r = minimize(lambda v: -min(np.min(cons(goals(v))), 0.2), u0,
                     method="Nelder-Mead", options={"maxfev": 80, "xatol": 0.01, "fatol": 1e-3})
        u = np.clip(r.x, 0.0, 1.0)
    i_trim = NAMES.index("ny_trim_tau_s")

    def cost(v):
        vc = np.clip(v, 0, 1)
        return (goals(v).cost + REG_WEIGHT * float(np.sum((vc - u0) ** 2))
                + NY_TRIM_WEIGHT * max(0.0, float(vc[i_trim] - u0[i_trim])) ** 2)

    minimize(cost, u, method="SLSQP", bounds=[(0.0, 1.0)] * len(NAMES),
             constraints=[{"type": "ineq", "fun": lambda v: cons(goals(v))}],
             options={"maxiter": max_iter, "ftol": 1e-4, "eps": 1e-3})
    done = list(cache.values())
    feas = [(uu, g) for uu, g in done if np.min(cons(g)) >= 0]
    if feas:
        best_u, gb = min(feas, key=lambda e: cost(e[0]))
    else:
        best_u, gb = max(done, key=lambda e: np.min(cons(e[1])))
    return PointTuning(params(best_u), gb, g0, len(cache), bool(feas))


@dataclass(frozen=True, slots=True)
class StepCheck:
    """Nonlinear JSBSim check of one tuning: max|ΔV| in the altitude step (km/h), max|ΔH| in the
    speed step (m), and the runs' time series (t_s, alt_m, tas_mps per step kind)."""

    max_dv_kmh: float
    max_dh_m: float
    runs: dict


def fly_step(cfg: AircraftConfig, point: DesignPoint, law: CoupledLaw, kind: str,
             duration_s: float = 90.0, outer_hz: float = 10.0, t_step_s: float = 2.0) -> np.ndarray:
    """Fly one step on the nonlinear JSBSim aircraft with ``law`` driving the n_x/n_y inner loops
    (wings level, calm air, the JSBSim state as the measurement).

    Parameters
    ----------
    cfg, point : aircraft and design point;  law : vertical law (``engage``/``update``)
    kind : ``"alt"`` (+:data:`DH_STEP_M`) or ``"speed"`` (+:data:`DV_STEP_FRAC` of the TAS)
    duration_s, outer_hz, t_step_s : run length (s), law rate (Hz), step time (s)

    Returns
    -------
    array (time × 4): t_s, alt_m, tas_mps, throttle
    """
    ac, tr = trim_point(cfg, point)
    ac.engage()
    n_frames = max(1, int(round(1.0 / (outer_hz * ac.dt_s))))
    st = ac.state()
    alt0, v0 = st.alt_m, st.tas_mps
    law.engage(st, alt0, v0)
    n = int(duration_s * outer_hz)
    out = np.empty((n, 4))
    for k in range(n):
        t = k / outer_hz
        alt_c = alt0 + (DH_STEP_M if kind == "alt" and t >= t_step_s else 0.0)
        v_c = v0 * (1 + (DV_STEP_FRAC if kind == "speed" and t >= t_step_s else 0.0))
        nx, ny = law.update(1.0 / outer_hz, st, alt_c, v_c)
        ac.command(bank_rad=0.0, ny=ny, nx=nx)
        if not ac.run(n_frames):
            return out[:k]
        st = ac.state()
        out[k] = (st.t_s, st.alt_m, st.tas_mps, st.throttle)
    return out


def excess_power_mps(cfg: AircraftConfig, point: DesignPoint, duration_s: float = 15.0,
                     avg_s: float = 3.0) -> float:
    """Specific excess power at full thrust at ``point``, m/s: from the trim, the throttle at
    the inner loop's maximum and the n_y loop holding 1 g, the energy rate per unit weight
    ``P_s = ḣ + V V̇ / g = (T_max - D) V / W`` averaged over the last ``avg_s`` of
    ``duration_s`` seconds (the engines have spooled up by then), at the speed reached then
    (it has risen by about g P_s t / V: little where the margin is small).

    The altitude step a point is verified with needs ``P_s ≥`` its peak climb rate at constant
    speed (:func:`step_climb_rate_mps`); below it the speed must give the energy.

    Parameters
    ----------
    cfg, point : aircraft and design point
    duration_s : run length, s;  avg_s : averaging window at its end, s
    """
    from fms_testbed.core.units import G0_MPS2

    ac, _ = trim_point(cfg, point)
    ac.engage(nx=False)
    ac.command(bank_rad=0.0, ny=1.0, throttle=cfg.inner_loops.throttle_max)
    n = int(duration_s / ac.dt_s)
    k0 = n - int(avg_s / ac.dt_s)
    e = []
    for k in range(n):
        if not ac.run(1):
            raise TrimError(f"{cfg.name} at {point.label()}: the full-thrust run stopped")
        if k >= k0:
            st = ac.state()
            e.append((st.t_s, st.alt_m + st.tas_mps ** 2 / (2.0 * G0_MPS2)))
    t, h_e = np.array(e).T
    return float(np.polyfit(t, h_e, 1)[0])


def step_climb_rate_mps(pl: PointLoops) -> float:
    """Peak climb rate of the linear closed loop ``pl`` in the +:data:`DH_STEP_M` altitude
    step, m/s (the specific excess power the step needs at constant speed)."""
    return float(np.max(_step_climb_mps(pl)))


def _step_climb_mps(pl: PointLoops) -> np.ndarray:
    h = step_outputs(pl.closed("lon", ["V_cmd", "H_cmd"], ["h"]),
                     np.array([0.0, DH_STEP_M]))[:, 0]
    return np.diff(h) / _DT_S


def thrust_margin(cfg: AircraftConfig, point: DesignPoint, pl: PointLoops) -> dict:
    """Whether the engines can give the +:data:`DH_STEP_M` step of the loops ``pl`` at
    ``point`` without the speed paying for it: ``ps_max_mps`` (:func:`excess_power_mps`),
    ``ps_step_mps`` (:func:`step_climb_rate_mps`), ``thrust_limited`` (ps_max < ps_step) and
    ``dv_energy_kmh``, the speed that following the step's linear climb V_y(t) at full thrust
    costs by the energy balance ``V dV/dt = g (P_s,max - V_y)``::

        ΔV = (g / V₀) ∫ max(0, V_y(t) - P_s,max) dt

    Parameters
    ----------
    cfg, point : aircraft and design point;  pl : the point's loops (scheduled gains)
    """
    from fms_testbed.core.units import G0_MPS2

    ps = excess_power_mps(cfg, point)
    vy = _step_climb_mps(pl)
    dv = G0_MPS2 / pl.V0_mps * float(np.sum(np.maximum(vy - ps, 0.0)) * _DT_S)
    return {"ps_max_mps": ps, "ps_step_mps": float(vy.max()),
            "thrust_limited": bool(ps < vy.max()), "dv_energy_kmh": dv / KMH_MPS}


def verify(cfg: AircraftConfig, point: DesignPoint, make_law, duration_s: float = 90.0
           ) -> StepCheck:
    """Fly the altitude and the speed step (:func:`fly_step`) with a fresh ``make_law()`` each.

    Parameters
    ----------
    cfg, point : aircraft and design point;  make_law : callable returning a vertical law
    duration_s : each run's length, s
    """
    a = fly_step(cfg, point, make_law(), "alt", duration_s)
    s = fly_step(cfg, point, make_law(), "speed", duration_s)
    dv = float(np.abs(a[:, 2] - a[0, 2]).max() / KMH_MPS)
    dh = float(np.abs(s[:, 1] - s[0, 1]).max())
    return StepCheck(dv, dh, {"alt": a, "speed": s})


TURN_KAPPA_PER_M = 1.0 / 5000.0
"""Lateral path-error goal: path curvature of the turn-entry step, 1/m (a 5 km turn radius)."""
PATH_ERR_TOL = 0.01
"""Lateral path-error goal: the turn entry's ∫|xtk| dt may exceed the file gains' at the same
point by at most this fraction."""


def path_error_ms(pl: PointLoops) -> float:
    """Lateral path error of the loops ``pl`` in a turn entry: ∫|xtk| dt (m·s) over
    :data:`T_STEP_S` after a step of the path curvature to :data:`TURN_KAPPA_PER_M`, all
    lateral loops closed (bank loop, yaw damper, path law)."""
    y = step_outputs(pl.closed("lat", ["kappa"], ["xtk"]), np.array([TURN_KAPPA_PER_M]))
    return float(np.abs(y[:, 0]).sum() * _DT_S)


def _bank_slack(cfg: AircraftConfig, models: list, gains, ref_path=None) -> np.ndarray:
    """Scaled slack of the bank loop's GM and PM goals (plus buffers) at every model and, with
    ``ref_path`` (the file gains' :func:`path_error_ms` per model), of the path-error goal
    ``∫|xtk| ≤ (1 + PATH_ERR_TOL) ∫|xtk|_file``."""
    from fms_testbed.sim.inner_steps import replace_gains

    c = replace_gains(cfg, "bank", gains)
    out = []
    for i, m in enumerate(models):
        pl = point_loops(c, m, start_law(cfg))
        gm, pm, _ = grid_margins(pl.loop("aileron"))
        out += [(gm - GM_MIN_DB - TUNE_BUFFER["gm_db"]) / 6.0,
                (pm - PM_MIN_DEG - TUNE_BUFFER["pm_deg"]) / 45.0]
        if ref_path is not None:
            out.append(((1.0 + PATH_ERR_TOL) * ref_path[i] - path_error_ms(pl)) / ref_path[i])
    return np.array(out)


def bank_path_errors(cfg: AircraftConfig, models: list, gains=None) -> list[float]:
    """:func:`path_error_ms` (m·s) at every model with the bank gains ``gains``.

    Parameters
    ----------
    cfg : aircraft;  models : linear airframes of the design points
    gains : bank-loop PID gains (None: the aircraft file's)
    """
    from fms_testbed.sim.inner_steps import replace_gains

    c = cfg if gains is None else replace_gains(cfg, "bank", gains)
    return [path_error_ms(point_loops(c, m, start_law(cfg))) for m in models]


def start_law(cfg: AircraftConfig) -> CoupledLawParams:
    """The coupled-law tuning of the aircraft file of ``cfg`` (the tuner's start)."""
    from fms_testbed.control.coupled_law import params_from_config

    return params_from_config(cfg)


def tune_bank_loop(cfg: AircraftConfig, models: list, max_evals: int = 60):
    """One bank-loop gain set (k_p, k_d of the aircraft file's ``inner_loops.bank``; the JSBSim
    system scales them with q̄_ref/q̄) meeting the GM/PM goals plus buffers at every design point
    without a larger lateral path error in a turn entry than the file's gains at any point
    (:func:`path_error_ms`, tolerance :data:`PATH_ERR_TOL`; weighted 10× the margins: margin is
    not bought with path error): Nelder-Mead on log-gains minimising the squared goal
    violations plus a pull ``0.05 Σ ln²(k/k0)`` towards the file's gains.

    Parameters
    ----------
    cfg : aircraft;  models : linear airframes of the design points
    max_evals : Nelder-Mead evaluations

    Returns
    -------
    (gains, smallest slack before, smallest slack after) — slack ≥ 0: every goal met
    """
    g0 = cfg.inner_loops.bank
    x0 = np.log([g0.kp, max(g0.kd, 1e-3)])

    def gains(x):
        return g0.model_copy(update={"kp": float(np.exp(x[0])), "kd": float(np.exp(x[1]))})

    ref = bank_path_errors(cfg, models)
    w = np.tile([1.0, 1.0, 10.0], len(models))

    def f(x):
        sl = _bank_slack(cfg, models, gains(x), ref)
        return float(np.sum(w * np.minimum(sl, 0.0) ** 2) * 100 + 0.05 * np.sum((x - x0) ** 2))

    before = float(np.min(_bank_slack(cfg, models, g0, ref)))
    if before >= 0:
        return g0, before, before
    r = minimize(f, x0, method="Nelder-Mead", options={"maxfev": max_evals, "xatol": 0.01})
    best = gains(r.x)
    best = best.model_copy(update={"kp": round(best.kp, 3), "kd": round(best.kd, 3)})
    return best, before, float(np.min(_bank_slack(cfg, models, best, ref)))
