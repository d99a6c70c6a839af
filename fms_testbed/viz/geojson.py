"""GeoJSON export of a built procedure transition (one Feature per path segment) and of a flown
track (``track.geojson``: the designed path, the flown 3-D track, the navigation track).

Properties per path feature (units in names): leg_index (0-based), path_terminator, fix_ident,
segment_type ('line'/'arc'), role, start/end coordinates (deg), centre (deg, arcs),
radius_m, turn_direction ('L'/'R'), subtended_angle_deg, planned_speed_kt, bank_deg,
altitude constraint (descriptor, alt1_ft, alt2_ft), speed limit (kt). Arc geometry is sampled
every ~2° so any GeoJSON viewer draws it; coordinates are [lon, lat] as GeoJSON requires, and
[lon, lat, alt_m] (altitude above mean sea level, m) for the flown tracks.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from fms_testbed.core.segments import Arc
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.legs.model import ProcedurePath

TRACK_STEP_S = 1.0
"""Spacing of the exported track points, s of flight (the log's 10 Hz thinned to 1 Hz)."""
NAV_DIFFERS_DEG = 1e-5
"""The navigation track is exported when its latitude or longitude differs from the true one by
more than this somewhere (1e-5 deg ≈ 1 m), or its altitude by more than 1 m."""


def segment_coords(geom) -> list[list[float]]:
    """[lon, lat] (deg, 7 decimals) of a Line's ends, or of an Arc sampled every ~2°."""
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
            props.update(along_start_nm=round(s0 / NM_M, 4), along_end_nm=round(s1 / NM_M, 4),
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
                      "geometry": {"type": "LineString", "coordinates": segment_coords(g)}})
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
            "length_nm": round(path.length_m() / NM_M, 3),
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




def track_points(df: pd.DataFrame, nav: bool = False, step_s: float = TRACK_STEP_S) -> np.ndarray:
    """Track points ``(n, 3)`` as [lon_deg, lat_deg, alt_m] (altitude MSL, m), one every
    ``step_s`` s of flight plus the last one; the navigation solution's with ``nav``."""
    cols = ("nav_lon_deg", "nav_lat_deg", "nav_alt_m") if nav else ("lon_deg", "lat_deg", "alt_m")
    d = df.dropna(subset=list(cols))
    if d.empty:
        return np.empty((0, 3))
    bucket = np.floor((d["t_s"].to_numpy() - d["t_s"].iloc[0]) / step_s)
    keep = np.r_[True, bucket[1:] != bucket[:-1]]
    keep[-1] = True
    return d.loc[keep, list(cols)].to_numpy(dtype=float)


def nav_differs(df: pd.DataFrame) -> bool:
    """True when the navigation track differs from the true one (:data:`NAV_DIFFERS_DEG`)."""
    if not {"nav_lat_deg", "nav_lon_deg", "nav_alt_m"} <= set(df.columns):
        return False
    dlat = np.nanmax(np.abs(df["nav_lat_deg"] - df["lat_deg"]), initial=0.0)
    dlon = np.nanmax(np.abs(df["nav_lon_deg"] - df["lon_deg"]), initial=0.0)
    dalt = np.nanmax(np.abs(df["nav_alt_m"] - df["alt_m"]), initial=0.0)
    return bool(max(dlat, dlon) > NAV_DIFFERS_DEG or dalt > 1.0)


def _line(points: np.ndarray, props: dict) -> dict:
    coords = [[round(lon, 7), round(lat, 7), round(alt, 1)] for lon, lat, alt in points]
    return {"type": "Feature", "properties": props,
            "geometry": {"type": "LineString", "coordinates": coords}}


def track_collection(df: pd.DataFrame, summary: dict, path: ProcedurePath | None = None,
                     rebuilt: tuple = ()) -> dict:
    """GeoJSON FeatureCollection of a flight, each feature with a ``layer`` property:
    ``designed path`` (one feature per segment, :func:`to_feature_collection`'s properties),
    ``rebuilt in flight`` (paths rebuilt when a conditional leg ended; ``leg_index`` counts from
    the rebuilt path's first leg, ``leg_offset`` is that leg's index in the whole procedure),
    ``flown (truth)`` (3-D:
    [lon, lat, alt_m MSL]) and ``navigation solution`` (3-D, only where it differs).

    Parameters
    ----------
    df : the flight's timeseries (``t_s``, ``lat_deg``, ``lon_deg``, ``alt_m``, ``nav_*``)
    summary : the flight's summary (scenario, aircraft, status)
    path : the designed procedure path (None for a flight without a procedure)
    rebuilt : :class:`~fms_testbed.path.plan.FlyablePath` objects rebuilt in flight
    """
    feats = []
    if path is not None:
        for f in to_feature_collection(path)["features"]:
            f["properties"] = {"layer": "designed path", **f["properties"]}
            feats.append(f)
    for j, fp in enumerate(rebuilt):
        for f in to_feature_collection(fp.path)["features"]:
            f["properties"] = {"layer": "rebuilt in flight", "rebuild": j,
                               "leg_offset": fp.leg_offset, **f["properties"]}
            feats.append(f)
    t0, t1 = float(df["t_s"].iloc[0]), float(df["t_s"].iloc[-1])
    feats.append(_line(track_points(df), {"layer": "flown (truth)", "t_start_s": t0,
                                          "t_end_s": t1, "altitude": "m above mean sea level"}))
    if nav_differs(df):
        feats.append(_line(track_points(df, nav=True),
                           {"layer": "navigation solution", "t_start_s": t0, "t_end_s": t1,
                            "altitude": "m above mean sea level"}))
    return {"type": "FeatureCollection",
            "properties": {"name": path.name if path is not None else summary.get("scenario"),
                           "aircraft": summary.get("aircraft"), "status": summary.get("status"),
                           "duration_s": None if summary.get("duration_s") is None
                           else float(summary["duration_s"])},
            "features": feats}


def write_track_geojson(out_file: str | Path, df: pd.DataFrame, summary: dict,
                        path: ProcedurePath | None = None, rebuilt: tuple = ()) -> Path:
    """Write :func:`track_collection` to ``out_file`` (strict JSON); return its path."""
    out = Path(out_file)
    out.write_text(json.dumps(track_collection(df, summary, path, rebuilt), allow_nan=False))
    return out
