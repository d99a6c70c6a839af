"""Precomputed local-plane geometry of a built path, for cross-track at the outer rate without geodesy.

Each :class:`~fms_testbed.core.segments.Line` is cut into chunks of at most :data:`CHUNK_M` metres; each
chunk and each :class:`~fms_testbed.core.segments.Arc` gets a local tangent plane about an origin (chunk
start or arc centre) with the meridian and prime-vertical radii of curvature at that origin.
A position maps to the plane with the mid-latitude equirectangular approximation

    x = Δλ · N₀ cos φ_m,    y = Δφ · M₀,    φ_m = (φ + φ₀)/2

whose distance error is third order (cross-track within 1 m of :func:`fms_testbed.core.segments.project`
within 1.5 km of 4 km line chunks and RF arcs up to 18.5 km radius (latitudes to 70°), along-track within 0.2 % of an arc's
length, track within 0.16° — 0.1502° at 65° N on an 18 km arc:
``tests/guidance/test_guidance_geometry.py`` checks it). A line chunk is then the straight line
between its projected ends; an arc is a circle about the origin. Sign convention as in
:mod:`fms_testbed.path`: cross-track positive right of the path, curvature positive to the right.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.earth import radii_m
from fms_testbed.core.segments import Arc, Line

CHUNK_M = 4000.0
"""Longest straight piece with one tangent plane, m (keeps the plane's error below 1 m)."""


@dataclass(frozen=True, slots=True)
class LocalPiece:
    """One straight chunk or arc in its own tangent plane (all lengths m, angles rad).

    seg_index: index of the path segment it belongs to; s0_m: along-segment distance at its
    start; length_m: its length; lat0/lon0_rad: plane origin; m0/n0_m: radii at the origin;
    is_arc; for a line: unit direction (ux, uy) east/north and end (x1, y1);
    for an arc: radius_m, start angle th0_rad (math angle of the start point seen from the
    centre, counter-clockwise from east), sign (+1 right/clockwise, -1 left), curvature_1pm.
    """

    seg_index: int
    s0_m: float
    length_m: float
    lat0_rad: float
    lon0_rad: float
    m0_m: float
    n0_m: float
    is_arc: bool
    ux: float = 0.0
    uy: float = 0.0
    radius_m: float = 0.0
    th0_rad: float = 0.0
    sign: float = 0.0
    curvature_1pm: float = 0.0

    def to_xy(self, lat_rad: float, lon_rad: float) -> tuple[float, float]:
        """Position in this piece's plane (east, north), m."""
        return ((lon_rad - self.lon0_rad) * self.n0_m * math.cos(0.5 * (lat_rad + self.lat0_rad)),
                (lat_rad - self.lat0_rad) * self.m0_m)

    def project(self, lat_rad: float, lon_rad: float) -> tuple[float, float, float]:
        """Along-piece distance (m, from the piece start), cross-track (m, right positive)
        and desired track (rad true) of a position."""
        dlon = lon_rad - self.lon0_rad
        if dlon > math.pi:
            dlon -= 2 * math.pi
        elif dlon < -math.pi:
            dlon += 2 * math.pi
        x = dlon * self.n0_m * math.cos(0.5 * (lat_rad + self.lat0_rad))
        y = (lat_rad - self.lat0_rad) * self.m0_m
        if not self.is_arc:
            ux, uy = self.ux, self.uy
            return x * ux + y * uy, x * uy - y * ux, math.atan2(ux, uy) % (2 * math.pi)
        r = math.hypot(x, y)
        th = math.atan2(y, x)
        # clockwise (right turn) decreases the math angle
        d = ((self.th0_rad - th) * self.sign) % (2 * math.pi)
        span = self.length_m / self.radius_m
        if d > span + 0.5 * (2 * math.pi - span):  # nearer to the start than to the end
            d -= 2 * math.pi
        along = d * self.radius_m
        xtk = (self.radius_m - r) * self.sign
        # track: tangent direction; compass azimuth of the radial is pi/2 - th
        trk = (math.pi / 2 - th + self.sign * math.pi / 2) % (2 * math.pi)
        return along, xtk, trk


def _line_pieces(k: int, seg: Line) -> list[LocalPiece]:
    n = max(1, int(math.ceil(seg.length_m() / CHUNK_M)))
    length = seg.length_m()
    pts = [seg.start] + [seg.point_at(length * i / n) for i in range(1, n)] + [seg.end]
    out = []
    for i in range(n):
        lat0, lon0 = math.radians(pts[i][0]), math.radians(pts[i][1])
        m0, n0 = radii_m(lat0)
        p = LocalPiece(k, length * i / n, length / n, lat0, lon0, m0, n0, False)
        x1, y1 = p.to_xy(math.radians(pts[i + 1][0]), math.radians(pts[i + 1][1]))
        d = math.hypot(x1, y1) or 1.0
        out.append(LocalPiece(k, length * i / n, d, lat0, lon0, m0, n0, False, x1 / d, y1 / d))
    return out


def _arc_piece(k: int, seg: Arc) -> LocalPiece:
    lat0, lon0 = math.radians(seg.centre_lat_deg), math.radians(seg.centre_lon_deg)
    m0, n0 = radii_m(lat0)
    sign = 1.0 if seg.sweep_deg >= 0 else -1.0
    p = LocalPiece(k, 0.0, seg.length_m(), lat0, lon0, m0, n0, True)
    sx, sy = p.to_xy(math.radians(seg.start[0]), math.radians(seg.start[1]))
    r = math.hypot(sx, sy)
    return LocalPiece(k, 0.0, r * math.radians(abs(seg.sweep_deg)), lat0, lon0, m0, n0, True,
                      radius_m=r, th0_rad=math.atan2(sy, sx), sign=sign, curvature_1pm=sign / r)


def local_pieces(geoms: list[Line | Arc]) -> list[LocalPiece]:
    """Cut a chain of segments into local pieces (lines in ≤ CHUNK_M chunks, arcs whole)."""
    out: list[LocalPiece] = []
    for k, g in enumerate(geoms):
        if isinstance(g, Arc):
            out.append(_arc_piece(k, g))
        else:
            out.extend(_line_pieces(k, g))
    return out
