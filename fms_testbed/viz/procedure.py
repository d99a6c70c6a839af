"""Plots of a procedure flight: ground track over the designed path with the legs labelled, the
vertical profile with the altitude constraints drawn, and the flight errors along the path.

Plotting only: every number comes from the timeseries, the summary or the built path; each
function returns a matplotlib Figure.

Units (the aviation edge, as every flight plot: see :mod:`fms_testbed.viz.run`): horizontal
positions in NM east/north of the procedure start (azimuthal-equidistant plane), distances
along the path in NM, altitudes in ft, CAS in kt; path errors (FTE/TSE/NSE/PDE) in m.
"""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.viz.figure import subplots
from fms_testbed.viz.run import local_en_nm


def _sample(geom, step_m: float = 200.0):
    n = max(2, int(geom.length_m() / step_m) + 1)
    pts = [geom.point_at(geom.length_m() * i / (n - 1)) for i in range(n)]
    return [p[0] for p in pts], [p[1] for p in pts]


def plot_ground_track(df, summary, fp, flown_paths=()) -> Figure:
    """Ground track (true, and navigation when it differs) over the designed path, NM from the
    start; each leg is labelled '<n> <code> <fix>' at its middle; fixes marked; FTE95 in the
    title."""
    path = fp.path
    s0 = path.segments[0].geom.start

    def xy_nm(lat, lon):
        return local_en_nm(np.asarray(lat, dtype=float), np.asarray(lon, dtype=float), *s0)

    fig, ax = subplots(figsize=(9, 8))
    colors = matplotlib.colormaps["tab10"].colors
    for k, seg in enumerate(path.segments):
        la, lo = _sample(seg.geom)
        x, y = xy_nm(la, lo)
        ax.plot(x, y, color=colors[seg.leg_index % 10], lw=3.0, alpha=0.45,
                label="designed path (colour = leg)" if k == 0 else None)
    for j, extra in enumerate(flown_paths):
        for k, seg in enumerate(extra.path.segments):
            la, lo = _sample(seg.geom)
            x, y = xy_nm(la, lo)
            ax.plot(x, y, "k--", lw=0.8, label="path rebuilt in flight" if j == k == 0 else None)
    x, y = xy_nm(df["lat_deg"], df["lon_deg"])
    ax.plot(x, y, color="crimson", lw=1.2, label="flown (truth)")
    if summary.get("procedure", {}).get("navigation", "truth") != "truth":
        xn, yn = xy_nm(df["nav_lat_deg"], df["nav_lon_deg"])
        ax.plot(xn, yn, color="navy", lw=0.8, ls=":", label="navigation solution")
    for lg in path.legs:
        if not lg.seg_count:
            continue
        segs = path.segments[lg.seg_first:lg.seg_first + lg.seg_count]
        longest = max(segs, key=lambda s: s.geom.length_m())
        la, lo = longest.geom.point_at(0.5 * longest.geom.length_m())
        xm, ym = xy_nm(la, lo)
        fix = lg.termination.fix_ident or (lg.record.fix.ident if lg.record.fix else "")
        ax.annotate(f"{lg.index + 1} {lg.path_term} {fix}".strip(), (float(xm), float(ym)),
                    fontsize=8, xytext=(4, 4), textcoords="offset points",
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "alpha": 0.7})
        t = lg.termination
        if t.kind == "fix" and t.lat_deg is not None:
            xf, yf = xy_nm(t.lat_deg, t.lon_deg)
            ax.plot(float(xf), float(yf), "k^", ms=5)
    ax.plot(0, 0, "go", ms=8, label="start")
    ax.plot([], [], "k^", ms=5, label="fix a leg ends at")
    ax.set_xlabel("east of start, NM")
    ax.set_ylabel("north of start, NM")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    err = summary.get("errors", {})
    e = err.get("fte", {}).get("all", {})
    tse = err.get("tse", {}).get("all", {}).get("p95_m")
    ax.set_title(f"{path.name}: ground track ({summary.get('aircraft', '')}, "
                 f"FTE95 {e.get('p95_m')} m, max {e.get('max_m')} m; TSE95 {tse} m)")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def plot_vertical(df, summary, fp) -> Figure:
    """Altitude and CAS along the path with the planned profile, the altitude command and the
    coded altitude constraints (▲ at or above, ▼ at or below, ◆ at, I between)."""
    prof = fp.path.profile
    fig, (ax, ax2) = subplots(2, 1, figsize=(10, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.3]})
    s_nm = df["along_m"].to_numpy() / NM_M
    ax.plot(s_nm, df["alt_m"] / FT_M, color="crimson", lw=1.3, label="flown altitude")
    ax.plot(s_nm, df["cmd_alt_m"] / FT_M, color="gray", lw=0.8, ls="--",
            label="altitude target to the law")
    if prof is not None:
        ax.plot(np.asarray(prof.along_m) / NM_M, np.asarray(prof.alt_m) / FT_M, "b-o", ms=3,
                lw=0.9, alpha=0.6, label="planned profile (builder; climbs flown at best rate to the climb top)")
        for w in prof.windows:
            x = w.along_m / NM_M
            lab = w.fix_ident or f"leg {w.leg_index + 1}"
            if w.lo_m is not None and w.hi_m is not None and abs(w.lo_m - w.hi_m) < 1:
                ax.plot(x, w.lo_m / FT_M, "kD", ms=7)
            elif w.lo_m is not None and w.hi_m is not None:
                ax.vlines(x, w.lo_m / FT_M, w.hi_m / FT_M, colors="k", lw=3)
            elif w.lo_m is not None:
                ax.plot(x, w.lo_m / FT_M, "k^", ms=8)
            else:
                ax.plot(x, w.hi_m / FT_M, "kv", ms=8)
            ref = w.lo_m if w.lo_m is not None else w.hi_m
            ax.annotate(lab, (x, ref / FT_M), fontsize=7, xytext=(3, -12),
                        textcoords="offset points")
    ax.plot([], [], "k^", label="constraint: ▲ at/above  ▼ at/below  ◆ at  | between")
    ax.set_ylabel("altitude, ft")
    ax.grid(alpha=0.3)
    cons = summary.get("constraints", [])
    missed = sum(c.get("ok") is False for c in cons)
    ax.set_title(f"{fp.path.name}: vertical profile — {len(cons)} constraints checked, "
                 f"{missed} missed")
    ax.legend(fontsize=8, loc="best")
    ax2.plot(s_nm, df["cas_mps"] / KT_MPS, color="crimson", lw=1.2, label="flown CAS")
    for c in summary.get("constraints", []):
        if "cas_kt" in c:
            lim = float(str(c["speed_limit_kt"]).lstrip("+-@"))
            row = df[df["leg_index"] == c["leg"] - 1]
            if len(row):
                ax2.plot(row["along_m"].iloc[-1] / NM_M, lim, "kv", ms=7)
                ax2.annotate(f"{c['fix']} {c['speed_limit_kt']} kt",
                             (row["along_m"].iloc[-1] / NM_M, lim), fontsize=7,
                             xytext=(3, 3), textcoords="offset points")
    ax2.set_ylabel("CAS, kt")
    ax2.set_xlabel("distance along the path, NM")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8, loc="best")
    fig.tight_layout()
    return fig


def plot_errors(df, summary, fp) -> Figure:
    """FTE, TSE, NSE and PDE (m) along the path, leg boundaries labelled, RNP stated."""
    fig, ax = subplots(figsize=(10, 5))
    s_nm = df["along_m"].to_numpy() / NM_M
    fte = df["fte_m"] if "fte_m" in df else df["nav_xtk_m"]
    tse = df["tse_m"] if "tse_m" in df else df["xtk_m"]
    ax.plot(s_nm, fte, lw=1.0, label="FTE (navigation vs path), m")
    ax.plot(s_nm, tse, lw=1.0, label="TSE (truth vs path), m")
    if "heading_leg" in df and (df["heading_leg"] == 1).any():
        ax.plot(s_nm, df["xtk_m"].where(df["heading_leg"] == 1), lw=0.8, color="gray",
                label="heading legs: drift from the calm-air line (no defined path), m")
    if "nse_m" in df:
        ax.plot(s_nm, df["nse_m"], lw=0.8, label="NSE (navigation vs truth), m")
    if "pde_m" in df and np.isfinite(df["pde_m"]).any():
        ax.plot(s_nm, df["pde_m"], lw=0.8, ls=":", label="PDE (built vs coded path), m")
    legs = df["leg_index"].to_numpy()
    codes = df["leg_code"].to_numpy()
    starts = np.flatnonzero(np.r_[True, legs[1:] != legs[:-1]])
    for i in starts:
        ax.axvline(s_nm[i], color="k", lw=0.5, alpha=0.4)
        ax.annotate(f"{legs[i] + 1} {codes[i]}", (s_nm[i], 1.0), xycoords=("data", "axes fraction"),
                    fontsize=7, rotation=90, va="top", ha="right")
    rnp = summary.get("rnp", {})
    ax.set_xlabel("distance along the path, NM")
    ax.set_ylabel("error, m (cross-track: + right of path)")
    ax.grid(alpha=0.3)
    ax.set_title(f"{fp.path.name}: flight errors — TSE95 {rnp.get('tse95_m')} m vs RNP "
                 f"{rnp.get('min_rnp_nm')} NM ({'contained' if rnp.get('contained') else 'NOT contained'})")
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    return fig


def plot_procedure(df, summary, fp, flown_paths=()) -> dict:
    """The three procedure figures by file stem: ``procedure_track``, ``procedure_vertical``,
    ``procedure_errors``. ``df`` carries the error columns (``fte_m``, ``tse_m``, ``nse_m``)."""
    return {"procedure_track": plot_ground_track(df, summary, fp, flown_paths),
            "procedure_vertical": plot_vertical(df, summary, fp),
            "procedure_errors": plot_errors(df, summary, fp)}
