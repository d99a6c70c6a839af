"""Plots of the inner-loop step checks (``fms-testbed inner``): one figure per loop, one panel
per step of that loop, the response against the command with the spec drawn.

Plotting only: it draws :class:`~fms_testbed.sim.inner_steps.StepResult` objects (time from the
step, response, metrics) and returns a matplotlib Figure.

Units: an engineering plot of one subsystem, in the units the specs are written in — bank in
deg, load factors in g, time in s from the step.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from fms_testbed.sim.inner_steps import StepResult
from fms_testbed.viz.figure import subplots

LOOP_LABEL = {"bank": ("bank angle φ", "deg"), "ny": ("normal load factor n_y", "g"),
              "nx": ("tangential load factor n_x", "g")}
_BASE = {"bank": 0.0, "ny": 1.0, "nx": 0.0}
BAND = 0.05
"""Half-width of the settling band, fraction of the step (:func:`~fms_testbed.sim.inner_steps
.step_metrics`)."""


def _scale(loop: str) -> float:
    return math.degrees(1.0) if loop == "bank" else 1.0


def settle_text(r: StepResult) -> str:
    """Settling as printed: 'settling 1.23 s', or 'not settled' when the response is still
    outside the band at the end of the run."""
    return f"settling {r.settle_s:.2f} s" if math.isfinite(r.settle_s) else "not settled"


def plot_loop_steps(loop: str, runs: list[tuple[str, StepResult]], aircraft: str) -> Figure:
    """Step responses of one inner loop: one panel per step direction (up/down), each flown
    condition a line; command dashed, the ±5 % settling band shaded, the overshoot limit dotted,
    the spec's settling limit a vertical line and each measured settling time a marker.

    Parameters
    ----------
    loop : ``"bank"``, ``"ny"`` or ``"nx"``
    runs : (condition label, step result) pairs of this loop, e.g. ``("3000 m, 120 m/s", r)``
    aircraft : aircraft name for the title

    Returns
    -------
    matplotlib Figure; its title gives the worst settling time and overshoot against the spec
    """
    name, unit = LOOP_LABEL[loop]
    k = _scale(loop)
    amps = sorted({r.spec.amplitude for _, r in runs}, reverse=True)
    fig, axes = subplots(1, len(amps), figsize=(5.2 * len(amps), 4.6), squeeze=False)
    base = _BASE[loop]
    for ax, amp in zip(axes[0], amps):
        mine = [(lab, r) for lab, r in runs if r.spec.amplitude == amp]
        spec = mine[0][1].spec
        target = base + amp
        t_end = max(float(r.t_s[-1]) for _, r in mine)
        lo, hi = sorted((target - BAND * abs(amp), target + BAND * abs(amp)))
        ax.axhspan(lo * k, hi * k, color="tab:green", alpha=0.15,
                   label=f"settling band ±{BAND * 100:.0f} % of the step")
        over = target + math.copysign(spec.overshoot_max_pct / 100.0 * abs(amp), amp)
        ax.axhline(over * k, color="tab:red", ls=":", lw=1.0,
                   label=f"overshoot limit {spec.overshoot_max_pct:g} %")
        ax.axvline(spec.settle_max_s, color="tab:red", lw=1.0,
                   label=f"settling limit {spec.settle_max_s:g} s")
        ax.plot([-0.5, 0.0, 0.0, t_end], np.array([base, base, target, target]) * k, "k--",
                lw=1.0, label="command")
        for j, (lab, r) in enumerate(mine):
            c = f"C{j}"
            t = np.r_[0.0, r.t_s]
            y = np.r_[base, r.y]
            ax.plot(t, y * k, color=c, lw=1.5,
                    label=f"{lab}: {settle_text(r)}, overshoot {r.overshoot_pct:.1f} %")
            if math.isfinite(r.settle_s):
                ys = float(np.interp(r.settle_s, r.t_s, r.y))
                ax.plot(r.settle_s, ys * k, "o", color=c, ms=6, mfc="none")
        ax.set_xlabel("time from the step, s")
        ax.set_ylabel(f"{name}, {unit}")
        ax.set_title(f"step {amp * k:+g} {unit}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    worst_settle = max((r.settle_s for _, r in runs), default=math.nan)
    worst_over = max((r.overshoot_pct for _, r in runs), default=math.nan)
    ok = all(r.ok for _, r in runs)
    spec = runs[0][1].spec
    settle = f"{worst_settle:.2f} s" if math.isfinite(worst_settle) else "not settled"
    fig.suptitle(f"{aircraft}: {name} loop — {'PASS' if ok else 'FAIL'}: worst settling: "
                 f"{settle} (spec ≤ {spec.settle_max_s:g} s); worst overshoot: "
                 f"{worst_over:.1f} % (spec ≤ {spec.overshoot_max_pct:g} %)", fontsize=11)
    fig.tight_layout()
    return fig


__all__ = ["LOOP_LABEL", "plot_loop_steps", "settle_text"]
