"""Flight-test attitude-reference plot, like seed 004's Fig. 2 (plotting only; the summary block
comes from :func:`fms_testbed.navigation.attitude_reference.attitude_reference_summary`).

``attitude_reference``: per angle (heading, roll, pitch — the paper's panels a, b, c) the error
of estimating the reference's error (estimate - injected, deg) against time, the filter's ±σ and
±3σ envelopes, the paper's goal lines (±0.06° heading, ±0.01° roll, ±0.02° pitch) and the time
from which the goal is judged; the panel titles give the largest error from then on.
"""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.viz.figure import subplots

_PANELS = (("heading", "a"), ("roll", "b"), ("pitch", "c"))


def plot_attitude_reference(df: pd.DataFrame, summary: dict) -> Figure:
    """Fig. 2 of seed 004 for one run: estimation error of each reference angle vs time with the
    filter's ±σ / ±3σ envelope and the goal lines (``summary['attitude_reference']``).

    Parameters
    ----------
    df : timeseries with ``t_s`` and ``att_ref_{err,est,sigma}_<angle>_deg``
    summary : the run summary (its ``attitude_reference`` block: goals, judging time, verdicts)
    """
    block = summary.get("attitude_reference") or {}
    goals = block.get("goal_deg", {})
    at_s = block.get("at_s")
    t = df["t_s"].to_numpy()
    fig, axes = subplots(3, 1, figsize=(8.5, 8.5), sharex=True)
    for ax, (a, letter) in zip(axes, _PANELS):
        e = df[f"att_ref_est_{a}_deg"] - df[f"att_ref_err_{a}_deg"]
        s = df[f"att_ref_sigma_{a}_deg"]
        ax.fill_between(t, -3 * s, 3 * s, color="tab:blue", alpha=0.12, lw=0, label="±3σ (filter)")
        ax.fill_between(t, -s, s, color="tab:blue", alpha=0.28, lw=0, label="±σ (filter)")
        ax.plot(t, e, color="k", lw=1.1, label="estimation error")
        title = f"{letter}) {a}"
        if a in goals:
            g = goals[a]
            ax.axhline(g, color="tab:red", ls="--", lw=1.0, label=f"goal ±{g:g}° (seed 004)")
            ax.axhline(-g, color="tab:red", ls="--", lw=1.0)
            # the y range: the goal band, with the error visible when it is larger
            lim = max(2.5 * g, min(float(e.abs().iloc[len(e) // 4:].max()) * 1.2, 20 * g))
            ax.set_ylim(-lim, lim)
        v = block.get("angles", {}).get(a)
        if v:
            title += (f" — max |error| after {at_s:g} s {v['max_abs_err_after_deg']:.4f}° "
                      f"({'meets' if v['meets_goal'] else 'misses'} goal, "
                      f"{'inside' if v['inside_3sigma'] else 'outside'} 3σ)")
        if at_s is not None:
            ax.axvline(at_s, color="0.4", ls=":", lw=1.0)
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_ylabel(f"{a} error of estimate, deg")
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=7, ncol=2)
    axes[-1].set_xlabel("time, s")
    fig.suptitle(f"{summary.get('scenario') or 'run'}: attitude-reference error estimation "
                 f"(estimate - injected)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_attitude_reference_run(df: pd.DataFrame, summary: dict) -> dict:
    """The figures of this mode by file stem (``attitude_reference``); empty without its
    columns."""
    if df.empty or "att_ref_err_roll_deg" not in df:
        return {}
    return {"attitude_reference": plot_attitude_reference(df, summary)}


__all__ = ["plot_attitude_reference", "plot_attitude_reference_run"]
