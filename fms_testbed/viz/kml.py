"""KML export of a flight for Google Earth / QGIS (``track.kml``, written with simplekml).

The document holds up to three folders:

* ``designed path`` — one placemark per leg of the procedure, named ``<n> <code> <fix>``
  (1-based leg number, ARINC-424 path terminator, the fix it ends at), a line over the leg's
  segments (arcs sampled every ~2°) clamped to the ground; a leg without segments (the ``IF``
  that starts a procedure) is a point at its fix. The description gives the leg's length (NM)
  and its coded altitude constraint (ft) and speed limit (kt).
* ``rebuilt in flight`` — the paths guidance rebuilt when a conditional leg ended, a placemark
  per leg named ``rebuild <k>: <n> <code> <fix>`` (n counted in the whole procedure).
* ``flight`` — the flown track (truth) as a 3-D line, altitude mode absolute (m above mean sea
  level, KML's unit), the navigation solution's track where it differs from the truth, and the
  start and end points.

Drawing only: every coordinate comes from the built path or the timeseries.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import simplekml

from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.legs.model import ProcedurePath
from fms_testbed.viz.geojson import nav_differs, segment_coords, track_points

_DESIGNED = "ff00c8ff"      # KML colours are aabbggrr: amber
_REBUILT = "ff888888"       # grey
_FLOWN = "ff3c14dc"         # crimson
_NAV = "ffff901e"           # blue


def _style(colour: str, width: float) -> simplekml.Style:
    st = simplekml.Style()
    st.linestyle.color = colour
    st.linestyle.width = width
    return st


def leg_name(leg, offset: int = 0) -> str:
    """``'<n> <code> <fix>'`` of a built leg: n is its 1-based number in the whole procedure
    (``offset``: index of the path's first leg, non-zero for a path rebuilt in flight)."""
    fix = leg.termination.fix_ident or (leg.record.fix.ident if leg.record.fix else "")
    return f"{leg.index + offset + 1} {leg.path_term} {fix}".strip()


_ALT_DESC = {"": "at", "@": "at", "+": "at or above", "-": "at or below", "B": "between"}


def _leg_description(leg, length_m: float | None) -> str:
    """Leg code and length (NM; None: a leg without segments), coded constraints (ft, kt)."""
    r = leg.record
    parts = [f"{leg.path_term} leg" + ("" if length_m is None else f", {length_m / NM_M:.2f} NM")]
    if r.alt1_m is not None:
        alt = f"{r.alt1_m / FT_M:.0f} ft"
        if r.alt2_m is not None:
            alt += f" and {r.alt2_m / FT_M:.0f} ft"
        how = _ALT_DESC.get(r.alt_desc, f"(descriptor {r.alt_desc})")
        parts.append(f"altitude {how} {alt}")
    if r.speed_limit_mps is not None:
        parts.append(f"speed limit {r.speed_desc or 'at'} {r.speed_limit_mps / KT_MPS:.0f} kt")
    return "; ".join(parts)


def _add_path(folder, path: ProcedurePath, style: simplekml.Style, offset: int = 0,
              prefix: str = "") -> int:
    """One placemark per leg of ``path`` into ``folder`` (named ``prefix`` + :func:`leg_name`);
    return the number added."""
    n = 0
    for lg in path.legs:
        segs = path.segments[lg.seg_first:lg.seg_first + lg.seg_count]
        if segs:
            coords: list[tuple[float, float]] = []
            for seg in segs:
                c = [tuple(p) for p in segment_coords(seg.geom)]
                coords += c[1:] if coords else c
            pm = folder.newlinestring(name=prefix + leg_name(lg, offset), coords=coords,
                                      description=_leg_description(
                                          lg, sum(s.geom.length_m() for s in segs)))
            pm.altitudemode = simplekml.AltitudeMode.clamptoground
            pm.tessellate = 1
            pm.style = style
        elif lg.termination.lat_deg is not None:
            folder.newpoint(name=prefix + leg_name(lg, offset), coords=[(lg.termination.lon_deg,
                                                        lg.termination.lat_deg)],
                            description=_leg_description(lg, None))
        else:
            continue
        n += 1
    return n


def _add_track(folder, points, name: str, description: str, style) -> None:
    pm = folder.newlinestring(name=name, description=description,
                              coords=[tuple(p) for p in points])
    pm.altitudemode = simplekml.AltitudeMode.absolute
    pm.style = style


def track_kml(df: pd.DataFrame, summary: dict, path: ProcedurePath | None = None,
              rebuilt: tuple = ()) -> simplekml.Kml:
    """The KML document of a flight (module docstring).

    Parameters
    ----------
    df : the flight's timeseries (``t_s``, ``lat_deg``, ``lon_deg``, ``alt_m`` in m MSL,
        ``nav_*``)
    summary : the flight's summary (scenario, aircraft, status, errors)
    path : the designed procedure path (None for a flight without a procedure)
    rebuilt : :class:`~fms_testbed.path.plan.FlyablePath` objects rebuilt in flight
    """
    title = path.name if path is not None else (summary.get("scenario") or "flight")
    kml = simplekml.Kml(name=f"{title} — {summary.get('aircraft', '')}")
    if path is not None:
        _add_path(kml.newfolder(name="designed path"), path, _style(_DESIGNED, 4))
    if rebuilt:
        f = kml.newfolder(name="rebuilt in flight")
        st = _style(_REBUILT, 2)
        for j, fp in enumerate(rebuilt):
            _add_path(f, fp.path, st, fp.leg_offset, f"rebuild {j + 1}: ")
    f = kml.newfolder(name="flight")
    pts = track_points(df)
    err = summary.get("errors", {})
    fte = err.get("fte", {}).get("all", {}).get("p95_m")
    tse = err.get("tse", {}).get("all", {}).get("p95_m")
    desc = (f"{summary.get('aircraft', '')}, {summary.get('status')}: "
            f"{float(df['t_s'].iloc[-1] - df['t_s'].iloc[0]):.0f} s flown; altitude m MSL"
            + (f"; FTE95 {fte} m, TSE95 {tse} m" if fte is not None else ""))
    _add_track(f, pts, "flown (truth)", desc, _style(_FLOWN, 3))
    if nav_differs(df):
        _add_track(f, track_points(df, nav=True), "navigation solution",
                   "the navigation source's position (guidance flies it); altitude m MSL",
                   _style(_NAV, 2))
    for label, p in (("start", pts[0]), ("end", pts[-1])):
        pm = f.newpoint(name=label, coords=[tuple(p)])
        pm.altitudemode = simplekml.AltitudeMode.absolute
    return kml


def write_track_kml(out_file: str | Path, df: pd.DataFrame, summary: dict,
                    path: ProcedurePath | None = None, rebuilt: tuple = ()) -> Path:
    """Write :func:`track_kml` to ``out_file``; return its path."""
    out = Path(out_file)
    track_kml(df, summary, path, rebuilt).save(str(out))
    return out


__all__ = ["leg_name", "track_kml", "write_track_kml"]
