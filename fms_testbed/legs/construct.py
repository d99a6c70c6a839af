"""Geometric constructions the leg builder is made of, on WGS-84.

Each function takes every input explicitly (position in deg, courses in deg true, distances in m)
and returns path segments or distances. Intersections start from a planar estimate in a local
azimuthal-equidistant frame and are refined on the ellipsoid by Newton steps on the exact
geodesic cross-track distance, so they are accurate to centimetres at any range; every search is
bounded (``max_m``) and returns ``None`` when the event never happens.
"""

from __future__ import annotations

import math

from fms_testbed.core.geodesy import LocalFrame, direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, turn_angle_deg
from fms_testbed.core.units import NM_M

#: Search bound for intercepts, radials and DME distances, m (100 NM).
MAX_SEARCH_M = 100 * NM_M


def turn_arc(lat_deg: float, lon_deg: float, track_deg: float, sweep_deg: float,
             radius_m: float) -> Arc:
    """Arc that starts at a point with a given track and turns by ``sweep_deg`` (+ right)."""
    side = 90.0 if sweep_deg >= 0 else -90.0
    clat, clon, caz = direct(lat_deg, lon_deg, track_deg + side, radius_m)
    return Arc(clat, clon, radius_m, wrap360(caz + 180.0), sweep_deg)


def turn_to_course(lat_deg: float, lon_deg: float, track_deg: float, course_deg: float,
                   direction: str | None, radius_m: float, min_deg: float = 0.5
                   ) -> Arc | None:
    """Turn from ``track_deg`` onto ``course_deg`` (coded ``direction`` 'L'/'R' wins); None if aligned."""
    sweep = turn_angle_deg(track_deg, course_deg, direction)
    if abs(sweep) < min_deg or abs(sweep) > 360.0 - min_deg:
        return None
    return turn_arc(lat_deg, lon_deg, track_deg, sweep, radius_m)


def direct_to_arc(lat_deg: float, lon_deg: float, track_deg: float, tlat_deg: float,
                  tlon_deg: float, direction: str | None, radius_m: float
                  ) -> tuple[Arc | None, bool]:
    """Turn from the present track until the aircraft points at a target fix.

    Returns
    -------
    (arc, reachable): ``arc`` None when already pointing at the target; ``reachable`` False when
    the target lies inside the turn circle (the caller flies ahead and retries).
    """
    s, az, _ = inverse(lat_deg, lon_deg, tlat_deg, tlon_deg)
    rel = wrap180(az - track_deg)
    if direction not in ("L", "R"):
        if abs(rel) < 0.5:
            return None, True
        direction = "R" if rel >= 0 else "L"
    elif abs(rel) < 0.5:
        return None, True
    sign = 1.0 if direction == "R" else -1.0
    clat, clon, caz = direct(lat_deg, lon_deg, track_deg + 90.0 * sign, radius_m)
    r0 = wrap360(caz + 180.0)
    d, b, _ = inverse(clat, clon, tlat_deg, tlon_deg)
    if d <= radius_m * 1.001:
        return None, False
    alpha = math.degrees(math.acos(radius_m / d))
    theta = b - alpha if sign > 0 else b + alpha
    sweep = wrap360(theta - r0) if sign > 0 else -wrap360(r0 - theta)
    if abs(sweep) < 0.05 or abs(sweep) > 359.95:
        return None, True
    return Arc(clat, clon, radius_m, r0, sweep), True


def _foot(qlat: float, qlon: float, qcrs: float, lat: float, lon: float
          ) -> tuple[float, float, float]:
    """Along (m), cross-track (m, right +) and course (deg) of a point w.r.t. the geodesic
    through (qlat, qlon) with azimuth ``qcrs`` there (extended both ways)."""
    s = 0.0
    flat, flon, fcrs = qlat, qlon, qcrs
    xtk = 0.0
    for _ in range(5):
        d, az, _ = inverse(flat, flon, lat, lon)
        if d < 1e-6:
            return s, 0.0, fcrs
        da = math.radians(az - fcrs)
        ds = d * math.cos(da)
        xtk = d * math.sin(da)
        s += ds
        if abs(ds) < 1e-3:
            break
        flat, flon, fcrs = direct(qlat, qlon, qcrs, s)
    return s, xtk, fcrs


def ray_geodesic_intersection(plat: float, plon: float, pcrs: float, qlat: float, qlon: float,
                              qcrs: float, max_m: float = MAX_SEARCH_M
                              ) -> tuple[float, float] | None:
    """Where a ray from P (course ``pcrs``) crosses the geodesic through Q (azimuth ``qcrs``).

    Returns
    -------
    (s_ray_m, s_line_m): distance along the ray (≥ 0, ≤ ``max_m``) and signed distance along
    the target geodesic from Q; ``None`` if the ray never crosses it within ``max_m`` or runs
    parallel (crossing angle below 1°).
    """
    fr = LocalFrame(qlat, qlon)
    px, py = fr.to_xy(plat, plon)
    ux, uy = math.sin(math.radians(pcrs)), math.cos(math.radians(pcrs))
    vx, vy = math.sin(math.radians(qcrs)), math.cos(math.radians(qcrs))
    den = ux * vy - uy * vx
    if abs(den) < math.sin(math.radians(1.0)):
        return None
    s1 = (-px * vy + py * vx) / den  # solve P + s1 u = s2 v
    if s1 < -1.0 or s1 > max_m * 1.5:
        return None
    s1 = max(s1, 0.0)
    for _ in range(6):
        xlat, xlon, xcrs = direct(plat, plon, pcrs, s1)
        s2, xtk, fcrs = _foot(qlat, qlon, qcrs, xlat, xlon)
        sn = math.sin(math.radians(xcrs - fcrs))
        if abs(sn) < 1e-3:
            return None
        ds = -xtk / sn  # d(xtk)/ds = sin(ray course - line course)
        s1 += ds
        if abs(ds) < 0.01:
            break
    if s1 < -1.0 or s1 > max_m:
        return None
    return max(s1, 0.0), s2


def ray_circle_distance(plat: float, plon: float, pcrs: float, clat: float, clon: float,
                        radius_m: float, max_m: float = MAX_SEARCH_M) -> float | None:
    """First distance along a ray from P at which the geodesic distance to C equals ``radius_m``.

    Used for DME terminations (CD/FD/VD) and for intercepting a DME arc. ``None`` when the
    ray never reaches that range within ``max_m``.
    """
    fr = LocalFrame(clat, clon)
    px, py = fr.to_xy(plat, plon)
    ux, uy = math.sin(math.radians(pcrs)), math.cos(math.radians(pcrs))
    b = px * ux + py * uy
    c = px * px + py * py - radius_m * radius_m
    disc = b * b - c
    if disc < 0:
        return None
    roots = sorted((-b - math.sqrt(disc), -b + math.sqrt(disc)))
    s = next((r for r in roots if r >= -1.0), None)
    if s is None or s > max_m * 1.5:
        return None
    s = max(s, 0.0)
    for _ in range(6):
        xlat, xlon, xcrs = direct(plat, plon, pcrs, s)
        d, _, az_out = inverse(clat, clon, xlat, xlon)
        rate = math.cos(math.radians(xcrs - az_out))  # d(range)/ds
        if abs(rate) < 1e-3:
            break
        ds = (radius_m - d) / rate
        s += ds
        if abs(ds) < 0.01:
            break
    if s < -1.0 or s > max_m:
        return None
    return max(s, 0.0)


def centre_through(p: tuple[float, float], f: tuple[float, float], centre: tuple[float, float]
                   ) -> tuple[float, float, float]:
    """The centre nearest to ``centre`` of the circle through the points ``p`` and ``f``.

    An arc coded about a centre (RF centre fix, AF DME) whose two ends lie at slightly
    different distances from it (the previous leg ends a few metres off the circle, an IF at
    a range that differs from the end fix's) is closed in the geometry by this circle: it
    starts exactly where the aircraft is and ends exactly at the fix. The centre lies on the
    perpendicular bisector of the chord p–f, at the foot of the coded centre on it (planar
    estimate in the azimuthal-equidistant plane about the coded centre), then refined on the
    ellipsoid by secant steps along the bisector until the two geodesic distances agree to a
    millimetre.

    Parameters
    ----------
    p, f : start and end points (lat_deg, lon_deg)
    centre : the coded centre (lat_deg, lon_deg)

    Returns
    -------
    (lat_deg, lon_deg, radius_m) of the circle through both points.
    """
    fr = LocalFrame(*centre)
    px, py = fr.to_xy(*p)
    fx, fy = fr.to_xy(*f)
    mx, my = 0.5 * (px + fx), 0.5 * (py + fy)
    cx, cy = fx - px, fy - py
    chord = math.hypot(cx, cy)
    if chord < 1e-6:
        r = inverse(*centre, *p)[0]
        return centre[0], centre[1], r
    nx, ny = -cy / chord, cx / chord
    t = -(mx * nx + my * ny)

    def diff(tt: float) -> tuple[float, tuple[float, float]]:
        c = fr.to_latlon(mx + tt * nx, my + tt * ny)
        return inverse(*c, *p)[0] - inverse(*c, *f)[0], c

    d0, c0 = diff(t)
    t1 = t + 1.0
    for _ in range(8):
        if abs(d0) < 1e-3:
            break
        d1, c1 = diff(t1)
        if abs(d1 - d0) < 1e-12:
            break
        t, t1 = t1, t1 - d1 * (t1 - t) / (d1 - d0)
        d0, c0 = d1, c1
    return c0[0], c0[1], inverse(*c0, *p)[0]


def gap_m(a: tuple[float, float], b: tuple[float, float]) -> float:
    """Geodesic distance between two (lat_deg, lon_deg) points, m."""
    return inverse(a[0], a[1], b[0], b[1])[0]
