"""Plot of the reference-description monitor against majority voting in one flight: the
horizontal NSE of each output and every unit's distance from its reference description.
Plotting only: the columns come from the flight's timeseries."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.navigation.reference_description import ReferenceTuning
from fms_testbed.viz.figure import subplots


def plot_reference_comparison(df: pd.DataFrame, title: str = "",
                              k_sigma: float = ReferenceTuning().k_sigma,
                              fault_t_s: float | None = None) -> Figure:
    """Two panels over time (min): horizontal NSE √(E² + N²) of the reference-description output
    (``nse_ref_*``) and of majority voting (``nse_vote_*``), m, with their NSE95 in the legend;
    and ``refdesc_d_ins1..3`` (σ of each unit's reference description) with the threshold
    ``k_sigma`` and the exclusions read from ``ins_used_ref``.

    Parameters
    ----------
    df : a flight's timeseries with those columns;  title : figure title
    k_sigma : the monitor's threshold, σ;  fault_t_s : time of the injected fault, s (a marker)
    """
    t = df["t_s"].to_numpy(float) / 60.0
    fig, (a, b) = subplots(2, 1, figsize=(9.0, 6.5), sharex=True)
    for pre, name, style in (("nse_ref", "reference description", "-"),
                             ("nse_vote", "majority voting", "--")):
        h = np.hypot(df[f"{pre}_east_m"], df[f"{pre}_north_m"]).to_numpy(float)
        a.plot(t, h, style, lw=1.2, label=f"{name} (NSE95 {np.nanpercentile(h, 95):.1f} m)")
    if "nav_mode" in df:
        coast = df["nav_mode"].to_numpy() == 1
        if coast.any():
            a.fill_between(t, 0, 1, where=coast, transform=a.get_xaxis_transform(),
                           color="0.85", label="GNSS outage (coasting)")
    a.set_yscale("log")
    a.set_ylim(bottom=0.1)
    a.set_ylabel("horizontal NSE, m")
    a.legend(loc="upper left", fontsize=8)
    a.grid(True, which="both", alpha=0.3)
    for i in (1, 2, 3):
        col = f"refdesc_d_ins{i}"
        if col in df:
            b.plot(t, df[col], lw=1.0, label=f"INS {i}")
    b.axhline(k_sigma, color="k", ls=":", label=f"k = {k_sigma:g}σ (outside declared performance)")
    if "ins_used_ref" in df:
        m = df["ins_used_ref"].to_numpy()
        ch = np.flatnonzero(np.diff(m) != 0) + 1
        for j in ch:
            b.axvline(t[j], color="r", lw=0.8)
            b.annotate(f"ref. output: mask {int(m[j])}", (t[j], k_sigma * 1.05), fontsize=7,
                       color="r")
    if fault_t_s is not None:
        for ax in (a, b):
            ax.axvline(fault_t_s / 60.0, color="m", lw=0.8, ls="--")
        b.annotate("fault", (fault_t_s / 60.0, 0.2), color="m", fontsize=7)
    b.set_ylabel("distance from reference\ndescription, σ")
    b.set_xlabel("time, min")
    b.legend(loc="upper left", fontsize=8)
    b.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


__all__ = ["plot_reference_comparison"]
