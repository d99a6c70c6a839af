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


def tse_headline(summary: dict) -> str:
    """The figure that matters for a procedure flight, for a title: TSE95 and max TSE (the
    true position's error from the path) and the RNP verdict; FTE after it (FTE alone hides a
    navigation error: a flight 5 km off track with FTE95 4 m)."""
    err = summary.get("errors", {})
    tse = err.get("tse", {}).get("all", {})
    fte = err.get("fte", {}).get("all", {})
    rnp = summary.get("rnp", {})
    verdict = ("RNP contained" if rnp.get("contained") else
               f"NOT contained (legs {rnp.get('legs_not_contained')})") if rnp else "no RNP"

    def m(v):
        return "n/a" if v is None else f"{v:.0f} m" if v >= 10 else f"{v:.1f} m"
    return (f"TSE95 {m(tse.get('p95_m'))}, max {m(tse.get('max_m'))} vs RNP "
            f"{rnp.get('min_rnp_nm')} NM: {verdict} (FTE95 {m(fte.get('p95_m'))})")


def plot_ground_track(df, summary, fp, flown_paths=()) -> Figure:
    """Ground track (true, and navigation when it differs) over the path flown for — the built
    path, whose bridges over discontinuities are the direct-tos flown, and the paths rebuilt in
    flight — NM from the start; each leg is labelled '<n> <code> <fix>' at its middle; fixes
    marked; TSE and the RNP verdict in the title (:func:`tse_headline`)."""
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
                ls="--" if seg.role == "connector" else "-",
                label="path flown for (colour = leg)" if k == 0 else None)
    if any(seg.role == "connector" for seg in path.segments):
        ax.plot([], [], color="0.5", lw=3.0, alpha=0.45, ls="--",
                label="direct-to over a discontinuity")
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
    ax.set_title(f"{path.name} ({summary.get('aircraft', '')}): ground track\n"
                 f"{tse_headline(summary)}", fontsize=10)
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
        _constraint_windows(ax, prof)
    ax.plot([], [], "k^", label="constraint: ▲ at/above  ▼ at/below  ◆ at  | between")
    ax.set_ylabel("altitude, ft")
    ax.grid(alpha=0.3)
    cons = summary.get("constraints", [])
    missed = sum(c.get("ok") is False for c in cons)
    thr = summary.get("threshold") or {}
    title = (f"{fp.path.name}: vertical profile — {len(cons)} constraints checked, "
             f"{missed} missed")
    if thr.get("crossed"):
        title += _threshold_mark(ax, df, thr)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="best")
    _speed_panel(ax2, df, summary, prof, s_nm)
    fig.tight_layout()
    return fig


def _constraint_windows(ax, prof) -> None:
    """The coded altitude windows of the planned profile, in ft along the path in NM."""
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


def _threshold_mark(ax, df, thr: dict) -> str:
    """Mark the threshold crossing (height ft, angle deg, CAS kt) on the altitude panel and
    return the title line with its deviations from TCH, VPA and Vapp ("" when incomplete)."""
    row = np.searchsorted(df["t_s"].to_numpy(), thr["t_s"])
    x = df["along_m"].to_numpy()[min(row, len(df) - 1)] / NM_M
    h_ft = float(np.interp(thr["t_s"], df["t_s"], df["alt_m"])) / FT_M
    ax.plot(x, h_ft, "g*", ms=12, label=f"threshold {thr['runway']} crossed: "
            f"{thr['height_ft']:.0f} ft (TCH {thr['tch_ft']}), "
            f"{thr['path_angle_deg'] if thr['path_angle_deg'] is not None else float('nan'):.2f}°"
            f" (VPA {thr['vpa_deg']}), {thr['cas_kt']:.0f} kt")
    return (f"\nthreshold: CAS − Vapp {thr['cas_minus_vapp_kt']:+.1f} kt, "
            f"height − TCH {thr['height_minus_tch_ft']:+.0f} ft, "
            f"angle − VPA {thr['path_angle_minus_vpa_deg']:+.2f}°, "
            f"{'configured' if thr['configured'] else 'NOT configured'}"
            if thr.get("cas_minus_vapp_kt") is not None
            and thr.get("height_minus_tch_ft") is not None
            and thr.get("path_angle_minus_vpa_deg") is not None else "")


def _speed_panel(ax2, df, summary, prof, s_nm) -> None:
    """Flown and planned CAS (kt) along the path, configuration changes and the coded speed
    limits."""
    ax2.plot(s_nm, df["cas_mps"] / KT_MPS, color="crimson", lw=1.2, label="flown CAS")
    sp = getattr(prof, "speed", None) if prof is not None else None
    if sp is not None:
        ax2.plot(np.asarray(sp.along_m) / NM_M, np.asarray(sp.cas_mps) / KT_MPS, "b-",
                 lw=0.9, alpha=0.6, label=f"planned CAS (decelerations; Vapp "
                                          f"{sp.vapp_cas_mps / KT_MPS:.0f} kt)")
    _config_marks(ax2, df, summary)
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


def _config_marks(ax, df, summary) -> None:
    """Flap and gear changes (guidance events of kind 'config') as labelled ticks on the CAS
    panel, at the distance flown when they were commanded."""
    ev = [e for e in summary.get("guidance_events", []) if e.get("kind") == "config"]
    if not ev or df.empty:
        return
    t, s = df["t_s"].to_numpy(), df["along_m"].to_numpy() / NM_M
    cas = df["cas_mps"].to_numpy() / KT_MPS
    for k, e in enumerate(ev):
        i = min(int(np.searchsorted(t, e["t_s"])), len(t) - 1)
        ax.plot(s[i], cas[i], "|", color="darkgreen", ms=14, mew=2,
                label="flap / gear commanded" if k == 0 else None)
        ax.annotate(e["detail"], (s[i], cas[i]), fontsize=7, rotation=60, color="darkgreen",
                    xytext=(2, 6), textcoords="offset points")


def plot_errors(df, summary, fp) -> Figure:
    """The flight errors along the path, m, in three panels with their own axes: TSE (the true
    position's cross-track from the path, ± RNP and ± 2 RNP drawn), FTE (the navigation
    solution's cross-track from the path: what guidance flies), and the two distances that
    are no cross-track — NSE (navigation vs truth) and PDE (built vs coded path). Leg
    boundaries labelled; TSE and the RNP verdict in the title."""
    fig, (ax_t, ax_f, ax_n) = subplots(3, 1, figsize=(10, 8), sharex=True,
                                       gridspec_kw={"height_ratios": [2, 1.3, 1.3]})
    s_nm = df["along_m"].to_numpy() / NM_M
    fte = df["fte_m"] if "fte_m" in df else df["nav_xtk_m"]
    tse = df["tse_m"] if "tse_m" in df else df["xtk_m"]
    ax_t.plot(s_nm, tse, lw=1.0, color="crimson", label="TSE: true position's cross-track, m")
    t = tse.to_numpy(dtype=float)
    lim = max(1.3 * np.nanmax(np.abs(t)) if np.isfinite(t).any() else 0.0, 20.0)
    if "rnp_m" in df and np.isfinite(df["rnp_m"]).any():
        rnp = df["rnp_m"].to_numpy()
        shown = np.nanmin(rnp) <= lim
        for k, (lab, ls) in enumerate((("± RNP", "--"), ("± 2 RNP", ":"))):
            for sgn in (1, -1):
                ax_t.plot(s_nm, sgn * (k + 1) * rnp, color="k", lw=0.8, ls=ls,
                          label=lab if sgn > 0 and shown else None)
        if not shown:   # zoomed on the error: say where the RNP limit is
            ax_t.plot([], [], color="k", lw=0.8, ls="--",
                      label=f"± RNP = ± {np.nanmin(rnp):.0f} m (off this scale)")
    ax_t.set_ylim(-lim, lim)
    if "heading_leg" in df and (df["heading_leg"] == 1).any():
        ax_t.plot(s_nm, df["xtk_m"].where(df["heading_leg"] == 1), lw=0.8, color="gray",
                  label="heading legs: offset from the planned track (no defined path)")
    ax_f.plot(s_nm, fte, lw=1.0, color="C0", label="FTE: navigation cross-track, m")
    if "nse_m" in df:
        ax_n.plot(s_nm, df["nse_m"], lw=1.0, color="C2", label="NSE: |navigation − truth|, m")
    if "pde_m" in df and np.isfinite(df["pde_m"]).any():
        ax_n.plot(s_nm, df["pde_m"], lw=1.0, ls=":", color="C4",
                  label="PDE: |built − coded path|, m")
    dist = [df[c].to_numpy(dtype=float) for c in ("nse_m", "pde_m") if c in df]
    top = max([np.nanmax(v) for v in dist if np.isfinite(v).any()], default=0.0)
    # at least 10 m: round-off of a zero NSE (truth navigation) is not drawn as a signal
    ax_n.set_ylim(0.0, max(10.0, 1.1 * top))
    legs = df["leg_index"].to_numpy()
    codes = df["leg_code"].to_numpy()
    starts = np.flatnonzero(np.r_[True, legs[1:] != legs[:-1]])
    for ax in (ax_t, ax_f, ax_n):
        for i in starts:
            ax.axvline(s_nm[i], color="k", lw=0.5, alpha=0.3)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    for i in starts:
        ax_t.annotate(f"{legs[i] + 1} {codes[i]}", (s_nm[i], 1.0),
                      xycoords=("data", "axes fraction"), fontsize=7, rotation=90, va="top",
                      ha="right")
    ax_t.set_ylabel("TSE, m (+ right of path)")
    ax_f.set_ylabel("FTE, m (+ right)")
    ax_n.set_ylabel("distance, m")
    ax_n.set_xlabel("distance along the path, NM")
    ax_t.set_title(f"{fp.path.name}: flight errors\n{tse_headline(summary)}", fontsize=10)
    fig.tight_layout()
    return fig


def plot_procedure(df, summary, fp, flown_paths=()) -> dict:
    """The three procedure figures by file stem: ``procedure_track``, ``procedure_vertical``,
    ``procedure_errors``. ``df`` carries the error columns (``fte_m``, ``tse_m``, ``nse_m``)."""
    return {"procedure_track": plot_ground_track(df, summary, fp, flown_paths),
            "procedure_vertical": plot_vertical(df, summary, fp),
            "procedure_errors": plot_errors(df, summary, fp)}
