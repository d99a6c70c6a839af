"""Figures of a regression run (plotting only: each function takes the ``flights`` table, or
counts made from it, and returns a matplotlib Figure; nothing is saved here).

Units: FTE/TSE in m (the path-error convention of every flight plot); counts are cases.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.campaign.rows import STATUSES
from fms_testbed.core.units import NM_M
from fms_testbed.viz.figure import subplots

STATUS_COLOURS = {
    "ok": "#4daf4a", "diverged": "#e41a1c", "incomplete": "#ff7f00",
    "envelope_exceeded": "#a65628", "not_contained": "#984ea3",
    "constraints_missed": "#377eb8", "degraded": "#999999", "impossible": "#dede00",
    "timeout": "#f781bf", "error": "#000000",
}
"""One colour per status, the same in every figure."""


def _stacked(counts: pd.DataFrame, title: str, ylabel: str, height: float) -> Figure:
    """Horizontal bars of ``counts`` (rows: categories, columns: statuses), stacked."""
    fig, ax = subplots(figsize=(9.0, height))
    left = np.zeros(len(counts))
    y = np.arange(len(counts))
    for st in [s for s in STATUSES if s in counts.columns]:
        v = counts[st].to_numpy(dtype=float)
        ax.barh(y, v, left=left, color=STATUS_COLOURS[st], label=st, edgecolor="white", lw=0.3)
        left += v
    ax.set_yticks(y, [str(i) for i in counts.index], fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("cases")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), title="status",
              title_fontsize=8)
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    return fig


def status_counts(df: pd.DataFrame, by: str) -> pd.DataFrame:
    """Cases per (``by`` value, status), statuses in :data:`STATUSES` order.

    Parameters
    ----------
    df : a table with a ``status`` column; by : the column to group by
    """
    c = df.groupby([by, "status"]).size().unstack(fill_value=0)
    return c[[s for s in STATUSES if s in c.columns]]


def plot_outcomes_by_type(df: pd.DataFrame) -> Figure:
    """Outcome counts per procedure type; the title gives the share ``ok``.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    c = status_counts(df, "type")
    ok = 100.0 * (df["status"] == "ok").mean() if len(df) else float("nan")
    return _stacked(c, f"Outcome by procedure type: {len(df)} cases, {ok:.1f} % ok",
                    "procedure type", 1.6 + 0.45 * len(c))


def plot_outcomes_by_airport(df: pd.DataFrame, top: int = 30) -> Figure:
    """Outcome counts of the ``top`` airports with the most cases not ``ok`` (all airports
    when there are no more).

    Parameters
    ----------
    df : the ``flights`` table; top : airports drawn at most
    """
    c = status_counts(df, "airport")
    bad = c.drop(columns=["ok"], errors="ignore").sum(axis=1)
    order = bad.sort_values(ascending=False, kind="stable").index[:top]
    c = c.loc[order]
    n_air = df["airport"].nunique()
    title = (f"Outcome by airport ({len(c)} of {n_air} airports, most failures first)"
             if n_air > len(c) else f"Outcome by airport ({n_air} airports, most failures first)")
    return _stacked(c, title, "airport", 1.6 + 0.28 * len(c))


def leg_code_counts(df: pd.DataFrame) -> pd.DataFrame:
    """Cases per (leg code present in the case, status): a case counts once for each distinct
    path terminator it flies.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    codes = df["leg_codes"].fillna("").str.split().apply(lambda xs: sorted(set(xs)))
    long = pd.DataFrame({"code": codes, "status": df["status"]}).explode("code")
    long = long.dropna(subset=["code"])
    if not len(long):
        return pd.DataFrame()
    return status_counts(long, "code")


def plot_outcomes_by_leg_code(df: pd.DataFrame) -> Figure:
    """Outcome counts per path terminator flown (a case counts once per distinct code); the
    title names the code with the highest share not ``ok``.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    c = leg_code_counts(df)
    if not len(c):
        fig, ax = subplots(figsize=(6, 2))
        ax.set_title("Outcome by leg code: no leg flown")
        ax.set_xlabel("cases")
        ax.set_ylabel("leg code")
        return fig
    tot = c.sum(axis=1)
    share = 1.0 - c.get("ok", 0) / tot
    c = c.loc[tot.sort_values(ascending=False).index]
    worst = share.idxmax()
    return _stacked(c, f"Outcome by leg code (cases flying it); most failing: {worst} "
                       f"{100 * share[worst]:.0f} % not ok", "path terminator",
                    1.6 + 0.3 * len(c))


def plot_error_distributions(df: pd.DataFrame) -> Figure:
    """Empirical distributions (1 − CDF, log scales) of FTE95, TSE95 and max TSE of the flown
    cases, with the RNP 0.3 / 1 NM lines; the title gives the medians. With navigation = truth
    FTE equals TSE: the wide FTE line is drawn under the dashed TSE one.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    fig, ax = subplots(figsize=(9.0, 5.0))
    med = []
    for col, label, colour, lw, ls in (("fte_p95_m", "FTE95", "tab:blue", 3.5, "-"),
                                       ("tse_p95_m", "TSE95", "tab:orange", 1.5, "--"),
                                       ("tse_max_m", "max TSE", "tab:red", 1.5, "-")):
        x = np.sort(df[col].to_numpy(dtype=float))
        x = x[np.isfinite(x) & (x > 0)]
        if not x.size:
            continue
        exceed = 1.0 - np.arange(x.size) / x.size
        ax.step(x, exceed, where="post", color=colour, lw=lw, ls=ls, alpha=0.8,
                label=f"{label} ({x.size} cases)")
        med.append(f"{label} {np.median(x):.1f} m")
    for rnp_nm, ls in ((0.3, "--"), (1.0, ":")):
        ax.axvline(rnp_nm * NM_M, color="k", ls=ls, lw=0.8, label=f"RNP {rnp_nm:g} NM")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("path error per case, m")
    ax.set_ylabel("share of cases above")
    ax.set_title("FTE / TSE per case (medians: " + (", ".join(med) or "none flown") + ")")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def finding_counts(df: pd.DataFrame) -> pd.Series:
    """Cases per monitor finding class (a case counts once per class it has).

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    cls = df["finding_classes"].fillna("").str.split(",").explode()
    cls = cls[cls != ""]
    return cls.value_counts()


def plot_findings(df: pd.DataFrame) -> Figure:
    """Monitor findings by class (cases with at least one), split by outcome ok / not ok.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    fig, ax = subplots(figsize=(9.0, 3.5))
    ok = finding_counts(df[df["status"] == "ok"])
    bad = finding_counts(df[df["status"] != "ok"])
    classes = sorted(set(ok.index) | set(bad.index))
    y = np.arange(len(classes))
    a = np.array([ok.get(c, 0) for c in classes], dtype=float)
    b = np.array([bad.get(c, 0) for c in classes], dtype=float)
    ax.barh(y, a, color=STATUS_COLOURS["ok"], label="flight ok")
    ax.barh(y, b, left=a, color=STATUS_COLOURS["diverged"], label="flight not ok")
    ax.set_yticks(y, classes)
    ax.set_xlabel("cases with a finding of this class")
    ax.set_ylabel("monitor finding class")
    n = int((df["monitor_findings"].fillna(0) > 0).sum())
    ax.set_title(f"Monitor findings by class: {n} of {len(df)} cases have one")
    ax.grid(axis="x", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_error_classes(counts: dict[str, int]) -> Figure:
    """Cases per Danilin error class (and the cases no class applies to but not ok).

    Parameters
    ----------
    counts : cases per label (:func:`fms_testbed.campaign.report.class_counts`)
    """
    fig, ax = subplots(figsize=(9.0, 3.0))
    names = list(counts)
    v = [counts[k] for k in names]
    ax.barh(np.arange(len(names)), v, color=["#377eb8", "#e41a1c", "#999999", "#dede00",
                                              "#000000"][:len(names)])
    ax.set_yticks(np.arange(len(names)), names, fontsize=8)
    ax.invert_yaxis()
    for i, x in enumerate(v):
        ax.annotate(str(x), (x, i), xytext=(3, 0), textcoords="offset points", va="center",
                    fontsize=8)
    ax.set_xlabel("cases")
    ax.set_ylabel("error class")
    ax.set_title(f"Error classes (Danilin): {sum(v)} cases not ok")
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    return fig


__all__ = ["STATUS_COLOURS", "finding_counts", "leg_code_counts", "plot_error_classes",
           "plot_error_distributions", "plot_findings", "plot_outcomes_by_airport",
           "plot_outcomes_by_leg_code", "plot_outcomes_by_type", "status_counts"]
