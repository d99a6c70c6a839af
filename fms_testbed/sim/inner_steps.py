"""Step responses of the inner loops on JSBSim, their metrics, and a small gain search.

Used by the tests (each shipped aircraft must meet its ``inner_spec``) and by
``fms-testbed inner --aircraft NAME [--tune]`` when a new aircraft is added.

Metrics: settling time is the last time the response is outside ±5 % of the step size around the
target (s, from the step); overshoot is the peak beyond the target in % of the step size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.config.aircraft import AircraftConfig, EnvelopePoint, PIDGains
from fms_testbed.sim.jsbsim_core import JSBSimAircraft


@dataclass(frozen=True)
class StepSpec:
    """A required step response of one loop: amplitude and limits."""

    loop: str               # bank | ny | nx
    amplitude: float        # rad for bank, g for ny/nx
    duration_s: float
    settle_max_s: float
    overshoot_max_pct: float


def specs_for(cfg: AircraftConfig) -> tuple[StepSpec, ...]:
    """The step specs of ``cfg`` (its ``inner_spec`` block; defaults are the issue's values)."""
    sp = cfg.inner_spec
    bank = math.radians(sp.bank_step_deg)
    return (
        StepSpec("bank", bank, 12.0, sp.bank_settle_max_s, sp.overshoot_max_pct),
        StepSpec("ny", sp.ny_step, 6.0, sp.ny_settle_max_s, sp.overshoot_max_pct),
        StepSpec("ny", -sp.ny_step, 6.0, sp.ny_settle_max_s, sp.overshoot_max_pct),
        StepSpec("nx", sp.nx_step, 6.0, sp.nx_settle_max_s, sp.nx_overshoot_max_pct),
        StepSpec("nx", -sp.nx_step, 6.0, sp.nx_settle_max_s, sp.nx_overshoot_max_pct),
    )


_KEY = {"bank": "roll_rad", "ny": "ny", "nx": "nx"}


@dataclass(frozen=True)
class StepResult:
    """Response of one loop to one step: time (s from the step), output, metrics."""

    spec: StepSpec
    t_s: np.ndarray
    y: np.ndarray
    target: float
    settle_s: float
    overshoot_pct: float

    @property
    def ok(self) -> bool:
        """True when settling time and overshoot meet the spec."""
        return (self.settle_s <= self.spec.settle_max_s
                and self.overshoot_pct <= self.spec.overshoot_max_pct)


def step_metrics(t_s: np.ndarray, y: np.ndarray, y0: float, target: float,
                 band: float = 0.05) -> tuple[float, float]:
    """Return (settling time s, overshoot % of step) of a step response from y0 to target."""
    step = target - y0
    err = np.abs(y - target)
    outside = np.nonzero(err > band * abs(step))[0]
    settle = float(t_s[outside[-1]]) if len(outside) else 0.0
    if outside.size and outside[-1] == len(t_s) - 1:
        settle = math.inf
    beyond = (y - target) * math.copysign(1.0, step)
    overshoot = max(0.0, float(np.max(beyond))) / abs(step) * 100.0
    return settle, overshoot


def step_response(ac: JSBSimAircraft, spec: StepSpec, point: EnvelopePoint,
                  lead_s: float = 1.0) -> StepResult:
    """Trim at ``point``, hold wings level at 1 g, then step one loop and record it.

    The other loops stay engaged and hold their trim targets (bank 0, n_y 1, n_x 0).
    """
    ac.trim(point.alt_m, point.tas_mps, heading_deg=90.0, lat_deg=45.0, lon_deg=0.0)
    ac.engage()
    ac.command(bank_rad=0.0, ny=1.0, nx=0.0)
    ac.run(int(round(lead_s / ac.dt_s)))
    key = _KEY[spec.loop]
    base = {"bank": 0.0, "ny": 1.0, "nx": 0.0}[spec.loop]
    target = base + spec.amplitude
    ac.command(**{"bank_rad" if spec.loop == "bank" else spec.loop: target})
    n = int(round(spec.duration_s / ac.dt_s))
    y = np.empty(n)
    for i in range(n):
        ac.run(1)
        y[i] = getattr(ac.state(), key)  # this frame's value (not the loops' sampled one)
    t = (np.arange(n) + 1) * ac.dt_s
    settle, over = step_metrics(t, y, base, target)
    return StepResult(spec, t, y, target, settle, over)


def check_aircraft(cfg: AircraftConfig, point: EnvelopePoint | None = None) -> list[StepResult]:
    """Run every spec of ``cfg`` at ``point`` (default: its default condition)."""
    ac = JSBSimAircraft(cfg)
    pt = point or cfg.default_condition
    return [step_response(ac, s, pt) for s in specs_for(cfg)]


def tune_loop(cfg: AircraftConfig, loop: str, max_evals: int = 60) -> tuple[PIDGains, float]:
    """Search kp, ki, kd of one loop (Nelder-Mead on log-gains) to minimise settling time with
    overshoot penalised beyond 5 %; return the gains and the cost. Deterministic."""
    from scipy.optimize import minimize

    specs = [s for s in specs_for(cfg) if s.loop == loop]
    ac = JSBSimAircraft(cfg)
    g0 = getattr(cfg.inner_loops, loop)
    use_kd = loop != "nx"
    x0 = np.log([g0.kp, max(g0.ki, 1e-3)] + ([max(g0.kd, 1e-3)] if use_kd else []))

    def gains_of(x):
        kp, ki = float(np.exp(x[0])), float(np.exp(x[1]))
        kd = float(np.exp(x[2])) if use_kd else 0.0
        return PIDGains(kp=kp, ki=ki, kd=kd)

    def cost(x):
        g = gains_of(x)
        ac.set_gains(replace_gains(cfg, loop, g))
        c = 0.0
        for s in specs:
            r = step_response(ac, s, cfg.default_condition)
            settle = min(r.settle_s, s.duration_s * 2)
            c += settle / s.settle_max_s + max(0.0, r.overshoot_pct - 5.0) ** 2 / 25.0
        return c

    simplex = np.vstack([x0] + [x0 + 0.7 * np.eye(len(x0))[i] for i in range(len(x0))])
    res = minimize(cost, x0, method="Nelder-Mead",
                   options={"maxfev": max_evals, "xatol": 0.02, "fatol": 1e-3,
                            "initial_simplex": simplex})
    return gains_of(res.x), float(res.fun)


def replace_gains(cfg: AircraftConfig, loop: str, gains: PIDGains) -> AircraftConfig:
    """Return a copy of ``cfg`` with one inner loop's gains replaced."""
    inner = cfg.inner_loops.model_copy(update={loop: gains})
    return cfg.model_copy(update={"inner_loops": inner})


__all__ = ["specs_for", "StepSpec", "StepResult", "step_metrics", "step_response", "check_aircraft",
           "tune_loop", "replace_gains"]
