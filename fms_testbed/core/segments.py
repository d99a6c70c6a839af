"""Path segments: the one horizontal geometry shared by the map, guidance, monitor and plots.

A path is an ordered chain of :class:`Line` (a WGS-84 geodesic between two points) and
:class:`Arc` (points at constant geodesic distance ``radius_m`` from a centre) segments, as in
Danilin (2017), Fig. 2: a straight segment is its end coordinates, an arc its centre, radius,
start azimuth and subtended angle. Turn sign convention everywhere: positive = right turn
(clockwise seen from above), curvature positive to the right.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360


@dataclass(frozen=True, slots=True)
class Line:
    """Geodesic from ``start`` to ``end`` (deg, WGS-84).

    Derived (not init) fields: ``length_m`` (m), ``start_course_deg`` and ``end_course_deg``
    (geodesic azimuths at the ends, deg true).
    """

    start_lat_deg: float
    start_lon_deg: float
    end_lat_deg: float
    end_lon_deg: float
    _len_m: float = field(init=False, repr=False, compare=False)
    _az1: float = field(init=False, repr=False, compare=False)
    _az2: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        s, a1, a2 = inverse(self.start_lat_deg, self.start_lon_deg,
                            self.end_lat_deg, self.end_lon_deg)
        object.__setattr__(self, "_len_m", s)
        object.__setattr__(self, "_az1", wrap360(a1))
        object.__setattr__(self, "_az2", wrap360(a2))

    kind = "line"

    def length_m(self) -> float:
        """Geodesic length, m."""
        return self._len_m

    @property
    def start_course_deg(self) -> float:
        """Course (true azimuth) at the start, deg."""
        return self._az1

    @property
    def end_course_deg(self) -> float:
        """Course (true azimuth) at the end, deg."""
        return self._az2

    @property
    def start(self) -> tuple[float, float]:
        """Start point (lat_deg, lon_deg)."""
        return self.start_lat_deg, self.start_lon_deg

    @property
    def end(self) -> tuple[float, float]:
        """End point (lat_deg, lon_deg)."""
        return self.end_lat_deg, self.end_lon_deg

    def point_at(self, s_m: float) -> tuple[float, float]:
        """Point at distance ``s_m`` (m) from the start along the geodesic, (lat_deg, lon_deg)."""
        lat, lon, _ = direct(self.start_lat_deg, self.start_lon_deg, self._az1, s_m)
        return lat, lon

    def course_at(self, s_m: float) -> float:
        """Course at distance ``s_m`` (m) from the start, deg true."""
        return wrap360(direct(self.start_lat_deg, self.start_lon_deg, self._az1, s_m)[2])


@dataclass(frozen=True, slots=True)
class Arc:
    """Circular arc about a centre on WGS-84.

    Parameters
    ----------
    centre_lat_deg, centre_lon_deg : centre, deg
    radius_m : geodesic radius, m (> 0)
    start_radial_deg : azimuth from the centre to the start point, deg true
    sweep_deg : subtended angle Ω, deg, signed: positive = clockwise = right turn; |sweep| may
        exceed 180° (coded turn direction the long way) and reach 360° (full circle).
    """

    centre_lat_deg: float
    centre_lon_deg: float
    radius_m: float
    start_radial_deg: float
    sweep_deg: float
    _start: tuple = field(init=False, repr=False, compare=False)
    _end: tuple = field(init=False, repr=False, compare=False)

    kind = "arc"

    def __post_init__(self):
        if not self.radius_m > 0:
            raise ValueError(f"Arc radius must be positive, got {self.radius_m} m")
        object.__setattr__(self, "_start", self._radial_point(self.start_radial_deg))
        object.__setattr__(self, "_end", self._radial_point(self.start_radial_deg + self.sweep_deg))

    def _radial_point(self, radial_deg: float) -> tuple[float, float, float]:
        """(lat_deg, lon_deg, outward radial azimuth at the point, deg)."""
        return direct(self.centre_lat_deg, self.centre_lon_deg, radial_deg, self.radius_m)

    @property
    def turn(self) -> str:
        """Turn direction, 'R' (clockwise) or 'L'."""
        return "R" if self.sweep_deg >= 0 else "L"

    @property
    def centre(self) -> tuple[float, float]:
        """Centre (lat_deg, lon_deg)."""
        return self.centre_lat_deg, self.centre_lon_deg

    @property
    def start(self) -> tuple[float, float]:
        """Start point (lat_deg, lon_deg)."""
        return self._start[0], self._start[1]

    @property
    def end(self) -> tuple[float, float]:
        """End point (lat_deg, lon_deg)."""
        return self._end[0], self._end[1]

    @property
    def end_radial_deg(self) -> float:
        """Azimuth from the centre to the end point, deg true."""
        return wrap360(self.start_radial_deg + self.sweep_deg)

    def length_m(self) -> float:
        """Arc length R·|Ω|, m."""
        return self.radius_m * math.radians(abs(self.sweep_deg))

    def _course_from_radial(self, radial_at_point_deg: float) -> float:
        """Tangent course from the outward radial azimuth *at the point* (not at the centre:
        the two differ by the meridian convergence, 0.05° for an 18-km arc at 50°N)."""
        return wrap360(radial_at_point_deg + (90.0 if self.sweep_deg >= 0 else -90.0))

    @property
    def start_course_deg(self) -> float:
        """Tangent course at the start, deg true."""
        return self._course_from_radial(self._start[2])

    @property
    def end_course_deg(self) -> float:
        """Tangent course at the end, deg true."""
        return self._course_from_radial(self._end[2])

    def radial_at(self, s_m: float) -> float:
        """Radial (azimuth from the centre) at arc distance ``s_m`` (m) from the start, deg."""
        sign = 1.0 if self.sweep_deg >= 0 else -1.0
        return self.start_radial_deg + sign * math.degrees(s_m / self.radius_m)

    def point_at(self, s_m: float) -> tuple[float, float]:
        """Point at arc distance ``s_m`` (m) from the start, (lat_deg, lon_deg)."""
        lat, lon, _ = self._radial_point(self.radial_at(s_m))
        return lat, lon

    def course_at(self, s_m: float) -> float:
        """Tangent course at arc distance ``s_m`` (m), deg true."""
        return self._course_from_radial(self._radial_point(self.radial_at(s_m))[2])


Segment = Line | Arc


def project(segment: Segment, lat_deg: float, lon_deg: float
            ) -> tuple[float, float, float, float]:
    """Project a position on a segment (cross-track/along-track decomposition).

    Parameters
    ----------
    segment : Line or Arc
    lat_deg, lon_deg : position, deg (WGS-84)

    Returns
    -------
    along_m : distance along the segment from its start to the foot point, m (negative before
        the start, above ``length_m()`` past the end)
    xtk_m : cross-track distance, m, positive when the position is right of the path
    desired_track_rad : path course at the foot point, rad true, in [0, 2π)
    curvature_1pm : path curvature at the foot point, 1/m (0 for a line, ±1/R for an arc,
        positive for a right turn)

    Notes
    -----
    Line: the foot point on the geodesic is found by Newton iteration on the along-track distance
    (each step solves the inverse problem from the current foot point; 2-4 steps reach 1 mm).
    Arc: ``xtk = ±(R - r)`` with ``r`` the geodesic distance from the centre.
    """
    if isinstance(segment, Line):
        s = 0.0
        lat0, lon0, crs = segment.start_lat_deg, segment.start_lon_deg, segment.start_course_deg
        xtk = 0.0
        for _ in range(6):
            d, az, _ = inverse(lat0, lon0, lat_deg, lon_deg)
            da = math.radians(az - crs)
            ds = d * math.cos(da)
            xtk = d * math.sin(da)
            s += ds
            if abs(ds) < 1e-3:
                break
            lat0, lon0, crs = direct(segment.start_lat_deg, segment.start_lon_deg,
                                     segment.start_course_deg, s)
        return s, xtk, math.radians(wrap360(crs)), 0.0
    r, az, az_out = inverse(segment.centre_lat_deg, segment.centre_lon_deg, lat_deg, lon_deg)
    right = segment.sweep_deg >= 0
    if right:
        dtheta = wrap360(az - segment.start_radial_deg)
    else:
        dtheta = wrap360(segment.start_radial_deg - az)
    # Place the foot before the start when it is nearer to the start than the arc's far side.
    span = abs(segment.sweep_deg)
    if dtheta > span and dtheta - span > (360.0 - dtheta):
        dtheta -= 360.0
    along = segment.radius_m * math.radians(dtheta)
    xtk = (segment.radius_m - r) if right else (r - segment.radius_m)
    trk = wrap360(az_out + (90.0 if right else -90.0))  # radial azimuth at the point
    curv = (1.0 if right else -1.0) / segment.radius_m
    return along, xtk, math.radians(trk), curv


def turn_angle_deg(course_in_deg: float, course_out_deg: float, direction: str | None = None
                   ) -> float:
    """Signed track change from ``course_in`` to ``course_out``, deg (positive right).

    ``direction`` 'L' or 'R' forces the sense of the turn (the coded turn direction wins even
    above 180°); ``None`` or 'E' takes the short way.
    """
    d = wrap180(course_out_deg - course_in_deg)
    if direction == "R" and d < 0:
        d += 360.0
    elif direction == "L" and d > 0:
        d -= 360.0
    return d
