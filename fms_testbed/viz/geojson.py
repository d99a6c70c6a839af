"""GeoJSON export of a built procedure transition: one Feature per path segment.

Properties per feature (units in names): leg_index (0-based), path_terminator, fix_ident,
segment_type ('line'/'arc'), role, start/end coordinates (deg), centre (deg, arcs),
radius_m, turn_direction ('L'/'R'), subtended_angle_deg, planned_speed_kt, bank_deg,
altitude constraint (descriptor, alt1_ft, alt2_ft), speed limit (kt). Arc geometry is sampled
every ~2° so any GeoJSON viewer draws it; coordinates are [lon, lat] as GeoJSON requires.
"""

from __future__ import annotations

import json
from pathlib import Path

from fms_testbed.core.segments import Arc
from fms_testbed.legs.model import ProcedurePath

FT_M = 0.3048
KT_MPS = 1852.0 / 3600.0


def _coords(geom) -> list[list[float]]:
    if isinstance(geom, Arc):
        n = max(2, int(abs(geom.sweep_deg) / 2.0) + 1)
        pts = [geom.point_at(geom.length_m() * k / (n - 1)) for k in range(n)]
    else:
        pts = [geom.start, geom.end]
    return [[round(lon, 7), round(lat, 7)] for lat, lon in pts]


def to_feature_collection(path: ProcedurePath) -> dict:
    """GeoJSON FeatureCollection (dict) of a built path, with the monitor outcome on top."""
    feats = []
    s0 = 0.0
    prof = path.profile
    for k, seg in enumerate(path.segments):
        g = seg.geom
        s1 = s0 + g.length_m()
        rec = path.legs[min(seg.leg_index, len(path.legs) - 1)].record if path.legs else None
        props = {
            "segment_index": k, "leg_index": seg.leg_index, "path_terminator": seg.path_term,
            "fix_ident": seg.fix_ident, "segment_type": g.kind, "role": seg.role,
            "start_lat_deg": g.start[0], "start_lon_deg": g.start[1],
            "end_lat_deg": g.end[0], "end_lon_deg": g.end[1],
            "length_m": round(g.length_m(), 2),
            "planned_speed_kt": round(seg.speed_mps / KT_MPS, 1),
            "bank_deg": round(seg.bank_deg, 2),
        }
        if prof is not None:
            props.update(along_start_nm=round(s0 / 1852.0, 4), along_end_nm=round(s1 / 1852.0, 4),
                         planned_alt_start_ft=round(float(prof.alt_at(s0)) / FT_M),
                         planned_alt_end_ft=round(float(prof.alt_at(s1)) / FT_M))
        s0 = s1
        if isinstance(g, Arc):
            props.update(centre_lat_deg=g.centre_lat_deg, centre_lon_deg=g.centre_lon_deg,
                         radius_m=round(g.radius_m, 2), turn_direction=g.turn,
                         subtended_angle_deg=round(abs(g.sweep_deg), 3))
        else:
            props.update(course_deg=round(g.start_course_deg, 2))
        if rec is not None:
            props.update(
                altitude_descriptor=rec.alt_desc,
                alt1_ft=None if rec.alt1_m is None else round(rec.alt1_m / FT_M),
                alt2_ft=None if rec.alt2_m is None else round(rec.alt2_m / FT_M),
                speed_limit_kt=None if rec.speed_limit_mps is None
                else round(rec.speed_limit_mps / KT_MPS),
                fly_over=rec.fly_over)
        feats.append({"type": "Feature", "properties": props,
                      "geometry": {"type": "LineString", "coordinates": _coords(g)}})
    return {
        "type": "FeatureCollection",
        "properties": {
            "name": path.name, "airport": path.airport, "procedure": path.proc_id,
            "transition": path.transition, "status": path.status,
            "legs": [f"{lg.path_term} {lg.record.fix.ident if lg.record.fix else ''}".strip()
                     for lg in path.legs],
            "findings": [f"leg {f.leg_index + 1}: {f.category}"
                         f"{' [' + f.branch + ']' if f.branch else ''}: {f.message}"
                         for f in path.findings],
            "length_nm": round(path.length_m() / 1852.0, 3),
        },
        "features": feats,
    }


def safe_name(path: ProcedurePath) -> str:
    """File-name stem for a path, e.g. 'KJFK_SID_DEEZZ5_RW04B'."""
    t = {"D": "SID", "E": "STAR", "F": "APP"}.get(path.proc_type, path.proc_type)
    parts = [path.airport, t, path.proc_id] + ([path.transition] if path.transition else [])
    return "_".join(p.replace("/", "-").replace(" ", "") for p in parts)


def write_geojson(path: ProcedurePath, out_dir: str | Path) -> Path:
    """Write ``<out_dir>/<name>.geojson``; return its path."""
    out = Path(out_dir) / f"{safe_name(path)}.geojson"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(to_feature_collection(path), indent=1, allow_nan=False))
    return out


