"""Figures of a Monte-Carlo report (:class:`fms_testbed.evaluation.montecarlo.McReport`): times to
detect and exclude per fault, and the output's horizontal NSE distribution with and without GNSS.
Plotting only: every number comes from the report."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from fms_testbed.navigation.montecarlo import _NSE_EDGES_M
from fms_testbed.viz.figure import subplots


def plot_montecarlo(report) -> Figure:
    """Left: per fault phase, the median (marker) and 5-95 % range (bar) of the time from the
    fault to detection and to exclusion of the faulty unit, s, with the fraction excluded.
    Right: empirical CDF of the output's horizontal NSE (all phases pooled), with a GNSS fix used
    and coasting, m, log scale, and the RNP."""
    fig, (a, b) = subplots(1, 2, figsize=(12.0, 5.0))
    fig.subplots_adjust(left=0.13, right=0.97, wspace=0.25)
    df = report.to_pandas()
    faults = [(k, r) for k, r in report.phases.items() if r.fault is not None]
    for j, (label, r) in enumerate(faults):
        u, t0 = r.fault.unit, r.fault.t_s
        for off, arr, colour, name in ((-0.15, r.t_detect_s - t0, "tab:blue", "detected"),
                                       (0.15, r.t_exclude_s[:, u] - t0, "tab:red", "excluded")):
            x = arr[np.isfinite(arr)]
            if x.size:
                lo, med, hi = np.percentile(x, [5, 50, 95])
                a.errorbar([med], [j + off], xerr=[[med - lo], [hi - med]], fmt="o",
                           color=colour, label=name if j == 0 else None, capsize=3)
        frac = float(np.isfinite(r.t_exclude_s[:, u]).mean())
        a.annotate(f"{100 * frac:.0f} % excl.", (1.0, j), xycoords=("axes fraction", "data"),
                   ha="right", va="center", fontsize=8)
    a.set_yticks(range(len(faults)), [k.replace("_bias_step", "").replace("deg/h", "°/h")
                                      .replace("ug", "µg") for k, _ in faults], fontsize=8)
    a.set_xscale("log")
    a.set_xlim(0.05, 2000.0)
    a.set_ylim(-0.6, max(len(faults), 1) - 0.4)
    a.set_xlabel("time from fault, s (first navigation step after it: 0.1 s)")
    a.set_title("fault on INS 2: time to detect / exclude (median, 5-95 %)")
    a.grid(True, which="both", alpha=0.3)
    if a.get_legend_handles_labels()[0]:
        a.legend(loc="lower left")
    centres = _NSE_EDGES_M[1:]
    for attr, colour, name in (("hist_gnss", "tab:green", "GNSS used"),
                               ("hist_coast", "tab:orange", "coasting (no fix used)")):
        h = sum(getattr(r, attr) for r in report.phases.values())
        if h.sum() > 0.001 * sum(r.hist_gnss.sum() + r.hist_coast.sum()
                                 for r in report.phases.values()):
            c = np.cumsum(h) / h.sum()
            p95 = centres[np.searchsorted(c, 0.95)]
            b.plot(centres, c, color=colour, label=f"{name}: NSE95 {p95:.3g} m")
    b.axvline(report.cfg.rnp_m, color="k", ls="--", label=f"RNP {report.cfg.rnp_m:.0f} m")
    b.axhline(0.95, color="grey", lw=0.8)
    b.set_xscale("log")
    b.set_xlim(1e-2, max(10 * report.cfg.rnp_m, 10))
    b.set_xlabel("horizontal NSE of the output, m")
    b.set_ylabel("fraction of samples")
    n = int(df["runs"].sum())
    b.set_title(f"output NSE, {n} realisations, seed {report.seed}")
    b.grid(True, which="both", alpha=0.3)
    b.legend(loc="lower right", fontsize=8)
    return fig


__all__ = ["plot_montecarlo"]
