"""Closed-loop tuning of the coupled law's (T_V, ξ_V, T_H, ξ_H) on JSBSim with scipy.optimize.

Each evaluation flies two short JSBSim runs at the operating point — an unclipped altitude step
(``dH_m`` ≤ the ±dH limit, so the linear prediction applies) and a speed step — and scores them
against stated criteria (:func:`cost`):

* speed: 2 % settling times, normalised by the pure second-order settling at the lower bounds
  (T_V = 5 s, T_H = 6 s, ξ = 1) — faster is better;
* overshoot beyond 2 % of the step is penalised;
* interaction: max |ΔV| during the altitude step against 0.5 km/h, max |ΔH| during the speed step
  against 0.75 m (half the issue's goals), squared;
* throttle activity (mean |d throttle/dt|) against 0.01 /s;
* limits: any throttle saturation, n_y at its limits, or a diverged run adds a large penalty.

Nelder-Mead (bounded, T_V ∈ [5, 15] s, T_H ∈ [6, 20] s, ξ ∈ [0.6, 1.5]) runs for at most
``max_evals`` evaluations. The inner-loop lags are identified from JSBSim step responses so the
linear model (:mod:`.linear`) can be overlaid on the tuned JSBSim response.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import minimize

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import mps_to_kmh
from fms_testbed.config.scenario import parse_scenario
from fms_testbed.loop.flight import fly
from fms_testbed.control.coupled_law import CoupledLaw, CoupledLawParams, params_from_config
from fms_testbed.control.linear import closed_loop, step_responses
from fms_testbed.control.metrics import StepMetrics, step_metrics
from fms_testbed.control.pointmass import CommandEvent, PointMassParams, simulate

BOUNDS = {"T_V_s": (5.0, 15.0), "xi_V": (0.6, 1.5), "T_H_s": (6.0, 20.0), "xi_H": (0.6, 1.5)}
"""Search box: time constants in s, damping ratios dimensionless (T_V ≥ 5 s, T_H ≥ 6 s: the coupled law's design bounds, docs/coupled-law.md)."""
NAMES = tuple(BOUNDS)
_T_STEP_S = 5.0


@dataclass(frozen=True, slots=True)
class OperatingPoint:
    """Where the law is tuned: altitude (m), TAS (m/s), and the step sizes (m, m/s)."""

    alt_m: float
    tas_mps: float
    dH_m: float = 100.0
    dV_mps: float = 0.0

    @property
    def speed_step_mps(self) -> float:
        """Speed step, m/s (default 10 % of the TAS)."""
        return self.dV_mps if self.dV_mps > 0 else 0.1 * self.tas_mps


@dataclass
class Evaluation:
    """One scored candidate."""

    params: CoupledLawParams
    cost: float
    alt: StepMetrics | None
    speed: StepMetrics | None
    runs: dict[str, pd.DataFrame] = field(default_factory=dict, repr=False)
    note: str = ""

    def row(self) -> dict:
        """Flat dict for the report table."""
        p = self.params
        d = {"T_V_s": p.T_V_s, "xi_V": p.xi_V, "T_H_s": p.T_H_s, "xi_H": p.xi_H,
             "cost": self.cost, "note": self.note}
        if self.alt and self.speed:
            d.update(alt_settling_s=self.alt.settling_s, alt_overshoot_pct=self.alt.overshoot_pct,
                     max_dV_kmh=mps_to_kmh(self.alt.max_cross_dev),
                     speed_settling_s=self.speed.settling_s,
                     speed_overshoot_pct=self.speed.overshoot_pct,
                     max_dH_m=self.speed.max_cross_dev,
                     throttle_activity_ps=max(self.alt.throttle_activity_ps,
                                              self.speed.throttle_activity_ps))
        return d


def _step_scenario(cfg: AircraftConfig, op: OperatingPoint, kind: str, duration_s: float) -> dict:
    ev = ({"t_s": _T_STEP_S, "alt_m": op.alt_m + op.dH_m} if kind == "alt"
          else {"t_s": _T_STEP_S, "tas_mps": op.tas_mps + op.speed_step_mps})
    return {"name": f"tune-{kind}-step", "aircraft": cfg.source_file or cfg.name,
            "initial": {"alt_m": op.alt_m, "tas_mps": op.tas_mps, "lat_deg": 47.0,
                        "heading_deg": 90.0},
            "duration_s": duration_s, "vertical_law": "coupled", "hold": True, "events": [ev]}


def fly_steps(cfg: AircraftConfig, params: CoupledLawParams, op: OperatingPoint,
              duration_s: float = 100.0, plant: str = "jsbsim") -> tuple[dict, str]:
    """Fly the altitude and the speed step with ``params``.

    Parameters
    ----------
    cfg : aircraft configuration;  params : law tuning;  op : operating point and steps
    duration_s : length of each run, s;  plant : ``"jsbsim"`` or ``"pointmass"``

    Returns
    -------
    ({"alt": df, "speed": df}, status) — status ``"ok"`` or the divergence reason
    """
    runs, status = {}, "ok"
    for kind in ("alt", "speed"):
        if plant == "pointmass":
            ev = (CommandEvent(t_s=_T_STEP_S, alt_m=op.alt_m + op.dH_m) if kind == "alt" else
                  CommandEvent(t_s=_T_STEP_S, tas_mps=op.tas_mps + op.speed_step_mps))
            runs[kind] = simulate(CoupledLaw(params=params), PointMassParams(0.8, 0.5),
                                  op.alt_m, op.tas_mps, duration_s, [ev])
            continue
        df, summary = fly(parse_scenario(_step_scenario(cfg, op, kind, duration_s)), cfg=cfg,
                          vertical_law=CoupledLaw(params=params), progress=False)
        runs[kind] = df
        if summary["status"] != "ok":
            status = f"{kind} step: {summary['reason']}"
    return runs, status


def cost(alt: StepMetrics, speed: StepMetrics, cfg: AircraftConfig) -> tuple[float, str]:
    """Score a candidate (lower is better); see the module docstring.

    Parameters
    ----------
    alt, speed : metrics of the altitude and the speed step;  cfg : aircraft (its n_y limits)

    Returns
    -------
    (cost, dimensionless; note naming any violated limit)
    """
    ref_h = 5.834 * BOUNDS["T_H_s"][0]      # 2 % settling of a critically damped 2nd order
    ref_v = 5.834 * BOUNDS["T_V_s"][0]
    note = []
    j = 0.0
    for m, ref in ((alt, ref_h), (speed, ref_v)):
        if not math.isfinite(m.settling_s):
            j += 10.0
            note.append(f"{m.channel} not settled")
        else:
            j += m.settling_s / ref
        j += max(0.0, m.overshoot_pct - 2.0) / 2.0
    j += (mps_to_kmh(alt.max_cross_dev) / 0.5) ** 2 + (speed.max_cross_dev / 0.75) ** 2
    j += max(alt.throttle_activity_ps, speed.throttle_activity_ps) / 0.01
    if alt.throttle_sat_frac > 0.0 or speed.throttle_sat_frac > 0.0:
        j += 100.0
        note.append("throttle saturated")
    lim = cfg.limits
    if min(alt.ny_min, speed.ny_min) <= lim.ny_min + 1e-3 or \
            max(alt.ny_max, speed.ny_max) >= lim.ny_max - 1e-3:
        j += 100.0
        note.append("n_y limit reached")
    return j, "; ".join(note)


def evaluate(cfg: AircraftConfig, params: CoupledLawParams, op: OperatingPoint,
             duration_s: float = 100.0, plant: str = "jsbsim") -> Evaluation:
    """Fly both steps with ``params`` and score them with :func:`cost`.

    Parameters
    ----------
    cfg, params, op, duration_s, plant : as in :func:`fly_steps` (duration in s)
    """
    runs, status = fly_steps(cfg, params, op, duration_s, plant)
    if status != "ok":
        return Evaluation(params, 1e3, None, None, runs, status)
    lo, hi = cfg.inner_loops.throttle_min, cfg.inner_loops.throttle_max
    a = step_metrics(runs["alt"], "alt", throttle_min=lo, throttle_max=hi)
    s = step_metrics(runs["speed"], "speed", throttle_min=lo, throttle_max=hi)
    j, note = cost(a, s, cfg)
    return Evaluation(params, j, a, s, runs, note)


def identify_lags(cfg: AircraftConfig, op: OperatingPoint) -> tuple[float, float]:
    """Equivalent first-order lags of the n_x and n_y inner loops, s (63 % rise time on JSBSim).

    Two short runs with direct inner-loop targets: n_x 0 → 0.03 and n_y 1 → 1.05 at t = 2 s.

    Parameters
    ----------
    cfg : aircraft configuration;  op : operating point (altitude, TAS)

    Returns
    -------
    (tau_nx_s, tau_ny_s), s
    """
    taus = []
    for col, ev in (("nx", {"t_s": 2.0, "nx": 0.03}), ("ny", {"t_s": 2.0, "ny": 1.05})):
        scn = {"name": f"identify-{col}", "aircraft": cfg.source_file or cfg.name,
               "initial": {"alt_m": op.alt_m, "tas_mps": op.tas_mps, "lat_deg": 47.0},
               "duration_s": 8.0, "events": [ev]}
        df, _ = fly(parse_scenario(scn), cfg=cfg, progress=False)
        t, y = df["t_s"].to_numpy(), df[col].to_numpy()
        i0 = int(np.searchsorted(t, 2.0))
        y0 = float(np.mean(y[max(0, i0 - 20):i0]))
        target = y0 + (0.03 if col == "nx" else 0.05)
        hit = np.flatnonzero((y[i0:] - y0) >= 0.632 * (target - y0))
        taus.append(float(t[i0 + hit[0]] - t[i0]) if len(hit) else float("nan"))
    return taus[0], taus[1]


def linear_prediction(params: CoupledLawParams, op: OperatingPoint, tau_nx_s: float,
                      tau_ny_s: float, t_end_s: float) -> dict[str, pd.DataFrame]:
    """Linear closed-loop responses (:mod:`.linear`) to the tuning steps, in the runner's columns.

    Parameters
    ----------
    params : law tuning;  op : operating point and steps
    tau_nx_s, tau_ny_s : inner-loop lags, s;  t_end_s : end time, s (steps at 5 s)
    """
    t = np.linspace(0.0, t_end_s - _T_STEP_S, int((t_end_s - _T_STEP_S) * 20) + 1)
    sys = closed_loop(params, op.tas_mps, tau_nx_s, tau_ny_s)
    sv, sh = step_responses(sys, t, op.speed_step_mps, op.dH_m)
    out = {}
    for kind, y, dv, dh in (("alt", sh, 0.0, op.dH_m), ("speed", sv, op.speed_step_mps, 0.0)):
        out[kind] = pd.DataFrame({
            "t_s": t + _T_STEP_S, "alt_m": op.alt_m + y[1], "tas_mps": op.tas_mps + y[0],
            "cmd_alt_m": op.alt_m + dh, "cmd_tas_mps": op.tas_mps + dv})
    return out


@dataclass
class TuneResult:
    """Outcome of :func:`tune`: the best evaluation, the start, and the history."""

    best: Evaluation
    start: Evaluation
    history: list[Evaluation]
    op: OperatingPoint
    lags_s: tuple[float, float]


def tune(cfg: AircraftConfig, op: OperatingPoint, max_evals: int = 40, duration_s: float = 100.0,
         plant: str = "jsbsim", start: CoupledLawParams | None = None,
         progress=None) -> TuneResult:
    """Optimise (T_V, ξ_V, T_H, ξ_H) on the closed loop with bounded Nelder-Mead.

    Parameters
    ----------
    cfg : aircraft configuration (limits, inner loops, starting gains)
    op : operating point and step sizes
    max_evals : evaluation budget (each = two runs of ``duration_s``)
    plant : ``"jsbsim"`` or ``"pointmass"`` (point mass with 0.8 s / 0.5 s lags; fast, for tests)
    start : starting tuning (default: the config's, clipped into the search box)
    progress : optional callable(Evaluation) called after each evaluation
    """
    if max_evals < 1:
        raise UserError("tune: --max-evals must be at least 1")
    base = start or (params_from_config(cfg) if cfg.coupled_law else CoupledLawParams(
        T_V_s=6.0, xi_V=1.0, T_H_s=8.0, xi_H=1.0, ny_min=cfg.limits.ny_min,
        ny_max=cfg.limits.ny_max, throttle_min=cfg.inner_loops.throttle_min,
        throttle_max=cfg.inner_loops.throttle_max))
    lo = np.array([BOUNDS[n][0] for n in NAMES])
    hi = np.array([BOUNDS[n][1] for n in NAMES])
    x0 = np.clip(np.array([getattr(base, n) for n in NAMES]), lo, hi)
    history: list[Evaluation] = []
    cache: dict[tuple, Evaluation] = {}

    def to_params(u: np.ndarray) -> CoupledLawParams:
        x = lo + np.clip(u, 0.0, 1.0) * (hi - lo)
        return replace(base, **{n: round(float(v), 2) for n, v in zip(NAMES, x)})

    def f(u: np.ndarray) -> float:
        p = to_params(u)
        key = tuple(getattr(p, n) for n in NAMES)
        if key not in cache:
            ev = evaluate(cfg, p, op, duration_s, plant)
            ev.runs = {}
            cache[key] = ev
            history.append(ev)
            if progress:
                progress(ev)
        return cache[key].cost

    u0 = (x0 - lo) / (hi - lo)
    f(u0)
    if max_evals > 1:
        simplex = [u0] + [np.clip(u0 + np.eye(4)[i] * (0.15 if u0[i] < 0.85 else -0.15), 0, 1)
                          for i in range(4)]
        minimize(f, u0, method="Nelder-Mead", bounds=[(0.0, 1.0)] * 4,
                 options={"maxfev": max_evals - 1, "initial_simplex": np.array(simplex),
                          "xatol": 0.01, "fatol": 0.01})
    best = min(history, key=lambda e: e.cost)
    best = evaluate(cfg, best.params, op, duration_s, plant)        # keep its runs
    lags = identify_lags(cfg, op) if plant == "jsbsim" else (0.8, 0.5)
    return TuneResult(best, history[0], history, op, lags)


def gains_yaml(p: CoupledLawParams) -> str:
    """The ``coupled_law`` block in the aircraft-config format (one line)."""
    return (f"coupled_law: {{T_V_s: {p.T_V_s:.2f}, xi_V: {p.xi_V:.2f}, T_H_s: {p.T_H_s:.2f}, "
            f"xi_H: {p.xi_H:.2f}, dH_limit_m: {p.dH_limit_m:.1f}}}")


def write_gains_to_config(path: str | Path, p: CoupledLawParams) -> None:
    """Replace the ``coupled_law`` block of an aircraft YAML file, leaving the rest untouched.

    Handles the one-line flow style (``coupled_law: {...}``) and an indented block; appends the
    block when there is none.

    Parameters
    ----------
    path : aircraft YAML file;  p : tuning whose T_V_s, xi_V, T_H_s, xi_H, dH_limit_m are written
    """
    path = Path(path)
    lines = path.read_text().splitlines(keepends=True)
    out, i, done = [], 0, False
    while i < len(lines):
        ln = lines[i]
        if re.match(r"^coupled_law\s*:", ln):
            out.append(gains_yaml(p) + "\n")
            done = True
            i += 1
            if not re.match(r"^coupled_law\s*:\s*\{", ln):
                while i < len(lines) and (lines[i].startswith((" ", "\t")) or not lines[i].strip()):
                    i += 1
            continue
        out.append(ln)
        i += 1
    if not done:
        if out and not out[-1].endswith("\n"):
            out[-1] += "\n"
        out.append(gains_yaml(p) + "\n")
    path.write_text("".join(out))
