"""Plot a built procedure transition like Danilin (2017), Fig. 2: legs labelled with their path
terminator codes, arcs visible with their centres, fixes marked, and the planned altitude with
the coded constraints below. Plotting never computes the path; it only draws the segments it is
given, in an azimuthal-equidistant plane about the first fix.

Units (the aviation edge, as every flight plot of :mod:`fms_testbed.viz`): horizontal distances
in NM, altitudes in ft.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from fms_testbed.core.geodesy import LocalFrame
from fms_testbed.core.segments import Arc
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.legs.model import ProcedurePath
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.viz.figure import subplots

_STYLE = {"leg": ("tab:blue", "-"), "turn": ("tab:orange", "-"), "flyby": ("tab:red", "-"),
          "hold": ("tab:purple", "-"), "connector": ("grey", ":")}


def _xy(fr: LocalFrame, lat: float, lon: float) -> tuple[float, float]:
    x, y = fr.to_xy(lat, lon)
    return x / NM_M, y / NM_M


def plot_path(path: ProcedurePath) -> Figure:
    """Draw a built path: ground track (NM) with the legs labelled, and, when the path has a
    planned profile, the planned altitude (ft) with the coded constraints.

    Parameters
    ----------
    path : the built (and monitored) procedure path

    Returns
    -------
    matplotlib Figure (save it with :func:`fms_testbed.viz.figure.save`)
    """
    if not path.segments:
        raise ValueError(f"{path.name}: nothing to plot (no segments)")
    lat0, lon0 = path.segments[0].geom.start
    fr = LocalFrame(lat0, lon0)
    prof = path.profile
    if prof is not None and len(prof.along_m) > 1:
        fig, (ax, axv) = subplots(2, 1, figsize=(9, 10.5),
                                      gridspec_kw={"height_ratios": [3.2, 1]})
    else:
        fig, ax = subplots(figsize=(9, 8))
        axv = None
    used: set[str] = set()
    _draw_segments(ax, fr, path, used)
    _label_legs(ax, fr, path)
    _mark_fixes(ax, fr, path, used)
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    first = path.legs[0].record.fix if path.legs else None
    origin = first.ident if first is not None and LEG_TYPES[path.legs[0].path_term].initial \
        else "start"
    ax.set_xlabel(f"east of {origin}, NM")
    ax.set_ylabel(f"north of {origin}, NM")
    ax.set_title(f"{path.name} — monitor {path.status}, {path.length_m() / NM_M:.1f} NM, "
                 f"{len(path.legs)} legs\n"
                 + " ".join(f"{lg.path_term}" for lg in path.legs), fontsize=10)
    ax.legend(loc="best", fontsize=8)
    if axv is not None:
        _profile_panel(axv, path)
    fig.tight_layout()
    return fig


def _draw_segments(ax, fr: LocalFrame, path: ProcedurePath, used: set[str]) -> None:
    """Each segment by role (leg, fly-by, join ...) as lines and arcs in NM, arc centres marked;
    ``used`` collects the legend labels already drawn."""
    for seg in path.segments:
        g = seg.geom
        n = max(2, int(abs(g.sweep_deg) / 3) + 2) if isinstance(g, Arc) else 2
        pts = [g.point_at(g.length_m() * k / (n - 1)) for k in range(n)]
        xs, ys = zip(*(_xy(fr, *p) for p in pts))
        colour, ls = _STYLE.get(seg.role, ("black", "-"))
        label = None
        kind = f"{seg.role} {'arc' if isinstance(g, Arc) else 'line'}"
        if kind not in used:
            used.add(kind)
            label = kind
        ax.plot(xs, ys, color=colour, ls=ls, lw=2 if seg.role == "leg" else 1.5, label=label)
        if isinstance(g, Arc) and seg.role == "leg":
            cx, cy = _xy(fr, *g.centre)
            ax.plot(cx, cy, "+", color="tab:green", ms=9,
                    label=None if "arc centre" in used else "arc centre")
            used.add("arc centre")


def _label_legs(ax, fr: LocalFrame, path: ProcedurePath) -> None:
    """Each leg's number and path terminator at the middle of its longest own segment."""
    for lg in path.legs:
        segs = [s for s in path.segments if s.leg_index == lg.index and s.role != "flyby"]
        if not segs:
            continue
        mid = max(segs, key=lambda s: s.geom.length_m())
        x, y = _xy(fr, *mid.geom.point_at(0.5 * mid.geom.length_m()))
        ax.annotate(f"{lg.index + 1}:{lg.path_term}", (x, y), fontsize=8, color="navy",
                    xytext=(4, 4), textcoords="offset points",
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="navy", alpha=0.7))


def _mark_fixes(ax, fr: LocalFrame, path: ProcedurePath, used: set[str]) -> None:
    """The terminating fixes, fly-by (filled triangle) or fly-over (open circle), named."""
    marked = set()
    for lg in path.legs:
        f = lg.record.fix
        t = lg.termination
        if f is None or t.lat_deg is None or f.ident in marked or t.kind not in (
                "fix", "circuit", "manual", "altitude") or not t.fix_ident and t.kind != "fix":
            continue
        marked.add(f.ident)
        x, y = _xy(fr, t.lat_deg, t.lon_deg)
        fo = lg.record.fly_over
        ax.plot(x, y, marker="^" if not fo else "o", color="k", mfc="none" if fo else "k",
                ms=7, ls="none",
                label=None if ("fly-over fix" if fo else "fly-by fix") in used
                else ("fly-over fix" if fo else "fly-by fix"))
        used.add("fly-over fix" if fo else "fly-by fix")
        ax.annotate(f.ident, (x, y), fontsize=8, xytext=(5, -10), textcoords="offset points")


def _profile_panel(ax, path: ProcedurePath) -> None:
    """Planned altitude along the path with the coded altitude windows."""
    prof = path.profile
    ax.plot(prof.along_m / NM_M, prof.alt_m / FT_M, "-", color="tab:blue",
            label="planned altitude")
    for name, sel, marker in (("at or above", lambda w: w.lo_m is not None and w.hi_m is None,
                               "^"),
                              ("at or below", lambda w: w.hi_m is not None and w.lo_m is None,
                               "v"),
                              ("at / window", lambda w: w.lo_m is not None
                               and w.hi_m is not None, "s")):
        ws = [w for w in prof.windows if sel(w)]
        if not ws:
            continue
        xs = [w.along_m / NM_M for w in ws]
        ys = [(w.lo_m if w.lo_m is not None else w.hi_m) / FT_M for w in ws]
        ax.plot(xs, ys, marker, color="k", mfc="none", ls="none", label=name)
        for w, x, y in zip(ws, xs, ys):
            if w.fix_ident:
                ax.annotate(w.fix_ident, (x, y), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
    ax.set_xlabel("distance along the path, NM")
    ax.set_ylabel("altitude, ft")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
