"""The threshold crossing of an approach: how the aircraft arrived over the runway.

Along-track distance is measured on the final approach course (the course at the end of the
MAP leg's last segment) from the runway threshold (landing threshold point), positive past it,
in the local tangent plane of the threshold. The crossing is the last place where that
distance changes sign from negative to positive within :data:`CROSS_TRACK_MAX_M` of the
extended centre line,
interpolated linearly between the two samples around it; a flight that ends less than
:data:`EXTRAPOLATE_MAX_M` before the threshold (guidance stops abeam the MAP) is extrapolated
from its last two samples (``extrapolated_m`` says how far). At the crossing:

* ``cas_kt`` and ``cas_minus_vapp_kt`` (Vapp of the flight's mass);
* ``height_ft`` above the threshold elevation and ``height_minus_tch_ft`` (coded TCH);
* ``gamma_deg``: the flight-path angle at the crossing (ground-referenced, negative down), and
  ``path_angle_deg``: the mean descent angle over the last :data:`PATH_FIT_M` before the
  threshold (least-squares slope of altitude on distance, positive down), against the coded
  VPA (``path_angle_minus_vpa_deg``);
* ``flaps`` / ``gear_down`` / ``configured``: the flap position at the landing detent
  (within :data:`FLAP_TOL`) and the gear fully down (fixed gear: always).

Verdicts (``ok``): CAS within :data:`CAS_TOL_KT` of Vapp, path angle within
:data:`ANGLE_TOL_DEG` of the VPA, height within :data:`HEIGHT_TOL_FT` of the TCH, configured.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fms_testbed.core.earth import MEAN_RADIUS_M
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.evaluation.records import ThresholdChecks, ThresholdCrossing

CAS_TOL_KT = 5.0
"""Threshold crossing CAS within this of Vapp, kt."""
ANGLE_TOL_DEG = 0.2
"""Mean path angle over the last PATH_FIT_M within this of the coded VPA, deg."""
HEIGHT_TOL_FT = 25.0
"""Threshold crossing height within this of the TCH, ft."""
FLAP_TOL = 0.02
"""Flap position (normalised) within this of the landing detent's command."""
PATH_FIT_M = 1.0 * NM_M
"""The path angle is fitted over this distance before the threshold, m."""
EXTRAPOLATE_MAX_M = 300.0
"""A flight ending at most this far before the threshold is extrapolated to it, m."""
CROSS_TRACK_MAX_M = 1000.0
"""A crossing counts only this close to the extended runway centre line, m."""


def along_track_m(lat_deg, lon_deg, thr_lat_deg: float, thr_lon_deg: float,
                  course_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(along, cross) track distances of the positions ``lat_deg``, ``lon_deg`` (deg, arrays)
    from the threshold at ``thr_lat_deg``, ``thr_lon_deg`` (deg) on ``course_deg`` (deg true):
    along positive past the threshold, cross positive to the right, m (equirectangular local
    plane: < 0.1 % error within 20 km)."""
    lat0 = math.radians(thr_lat_deg)
    x = np.radians(np.asarray(lon_deg) - thr_lon_deg) * math.cos(lat0) * MEAN_RADIUS_M
    y = np.radians(np.asarray(lat_deg) - thr_lat_deg) * MEAN_RADIUS_M
    c = math.radians(course_deg)
    return x * math.sin(c) + y * math.cos(c), x * math.cos(c) - y * math.sin(c)


def final_course_deg(path, map_leg: int) -> float | None:
    """Course at the end of the last built segment of leg ``map_leg`` (the MAP) of the built
    ``path``, deg true (None: no segment)."""
    segs = [s for s in path.segments if s.leg_index == map_leg]
    return float(segs[-1].geom.end_course_deg) % 360.0 if segs else None


def threshold_crossing(df: pd.DataFrame, path, runway, vapp_cas_mps: float | None,
                       approach) -> ThresholdCrossing | None:
    """The threshold-crossing record of a flight (module docstring); None when the flight is
    no approach to a known runway.

    Parameters
    ----------
    df : the timeseries (``lat_deg``, ``lon_deg``, ``alt_m``, ``cas_mps``, ``gamma_deg``,
        ``flap_pos_norm``, ``gear_pos_norm``)
    path : the built approach (``ProcedurePath``); runway : its
        :class:`~fms_testbed.path.runway.ApproachRunway`
    vapp_cas_mps : the flight's Vapp, m/s (None: the aircraft has no approach settings)
    approach : the aircraft's ``ApproachSettings`` (landing detent, fixed gear) or None
    """
    if runway is None or df.empty or runway.elev_m is None:
        return None
    crs = final_course_deg(path, runway.map_leg)
    if crs is None:
        return None
    s, xt = along_track_m(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(), runway.lat_deg,
                          runway.lon_deg, crs)
    out: dict = {"runway": runway.ident, "map_is_threshold": runway.map_is_threshold,
                 "vpa_deg": runway.vpa_deg,
                 "tch_ft": None if runway.tch_m is None else round(runway.tch_m / FT_M, 1),
                 "vapp_kt": None if vapp_cas_mps is None else round(vapp_cas_mps / KT_MPS, 1)}
    crossing = _crossing(s, xt)
    if crossing is None:
        out.update(crossed=False, reason=f"threshold not reached: the flight ended "
                   f"{-s[-1] / NM_M:.2f} NM before it")
        return ThresholdCrossing(**out)
    i0, i1, extrap = crossing
    out.update(_at_threshold(df, s, i0, i1, extrap, runway, vapp_cas_mps, approach))
    checks = {
        "cas": None if out["cas_minus_vapp_kt"] is None
        else abs(out["cas_minus_vapp_kt"]) <= CAS_TOL_KT,
        "path_angle": None if out["path_angle_minus_vpa_deg"] is None
        else abs(out["path_angle_minus_vpa_deg"]) <= ANGLE_TOL_DEG,
        "height": None if out["height_minus_tch_ft"] is None
        else abs(out["height_minus_tch_ft"]) <= HEIGHT_TOL_FT,
        "configured": out["configured"],
    }
    out["checks"] = ThresholdChecks(**checks)
    out["ok"] = all(v is not False for v in checks.values()) and \
        any(v is not None for v in checks.values())
    return ThresholdCrossing(**out)


def _crossing(s: np.ndarray, xt: np.ndarray) -> tuple[int, int, float] | None:
    """The samples (i0, i1) either side of the threshold and how far past the last sample it
    is extrapolated (m): the last crossing over it near the extended centre line, else the end
    of a flight that stops at most :data:`EXTRAPOLATE_MAX_M` short of it; None: neither."""
    cross = np.nonzero((s[1:] >= 0.0) & (s[:-1] < 0.0)
                       & (np.abs(xt[1:]) < CROSS_TRACK_MAX_M))[0] + 1
    if cross.size:
        j = int(cross[-1])
        return j - 1, j, 0.0
    if s.size < 2 or not -EXTRAPOLATE_MAX_M <= s[-1] < 0.0 or s[-1] <= s[-2] \
            or abs(xt[-1]) >= CROSS_TRACK_MAX_M:
        return None
    return s.size - 2, s.size - 1, float(-s[-1])


def _at_threshold(df: pd.DataFrame, s: np.ndarray, i0: int, i1: int, extrap: float, runway,
                  vapp_cas_mps: float | None, approach) -> dict:
    """The aircraft over the threshold, interpolated between samples ``i0`` and ``i1`` (along
    distances ``s``, m): time, CAS, height, γ, the path angle fitted over the last
    :data:`PATH_FIT_M`, the configuration."""
    f = (0.0 - s[i0]) / (s[i1] - s[i0]) if s[i1] != s[i0] else 0.0

    def at(col):
        v = df[col].to_numpy(dtype=float)
        return float(v[i0] + f * (v[i1] - v[i0]))

    h = at("alt_m") - runway.elev_m
    cas = at("cas_mps")
    # the run of samples flown toward the threshold over the last PATH_FIT_M before it
    k = i0
    while k > 0 and s[k - 1] < s[k] and s[k - 1] > -PATH_FIT_M:
        k -= 1
    sel = np.zeros(s.size, dtype=bool)
    sel[k:i0 + 1] = True
    sel &= s < 0.0
    ang = None
    if sel.sum() >= 5:
        slope = np.polyfit(s[sel], df["alt_m"].to_numpy(dtype=float)[sel], 1)[0]
        ang = math.degrees(math.atan(-slope))
    flap = at("flap_pos_norm") if "flap_pos_norm" in df else None
    gear = at("gear_pos_norm") if "gear_pos_norm" in df else None
    flaps_ok = gear_ok = None
    if approach is not None and flap is not None:
        land = approach.flaps[approach.index(approach.landing_flap)]
        flaps_ok = abs(flap - land.cmd_norm) <= FLAP_TOL
        gear_ok = True if approach.fixed_gear else bool(gear is not None and gear >= 0.99)
    return dict(
        crossed=True, extrapolated_m=round(extrap, 1), t_s=round(at("t_s"), 2),
        cas_kt=round(cas / KT_MPS, 2),
        cas_minus_vapp_kt=None if vapp_cas_mps is None else round((cas - vapp_cas_mps) / KT_MPS,
                                                                  2),
        height_ft=round(h / FT_M, 1),
        height_minus_tch_ft=None if runway.tch_m is None else round((h - runway.tch_m) / FT_M,
                                                                    1),
        gamma_deg=round(at("gamma_deg"), 3),
        path_angle_deg=None if ang is None else round(ang, 3),
        path_angle_minus_vpa_deg=None if ang is None or not runway.vpa_deg
        else round(ang - runway.vpa_deg, 3),
        flap_pos_norm=None if flap is None else round(flap, 3),
        gear_pos_norm=None if gear is None else round(gear, 3),
        flaps_landing=flaps_ok, gear_down=gear_ok,
        configured=None if flaps_ok is None else bool(flaps_ok and gear_ok))


__all__ = ["CAS_TOL_KT", "ANGLE_TOL_DEG", "HEIGHT_TOL_FT", "along_track_m",
           "final_course_deg", "threshold_crossing"]
