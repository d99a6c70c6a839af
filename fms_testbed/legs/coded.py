"""The coded path of a leg: the path its ARINC-424 record defines, for the path definition error.

PDE (RNP, ICAO Doc 9613) is the distance of the built path — the path guidance flies — from the
path the database defines. Each leg class says how that coded path is made
(:attr:`~fms_testbed.legs.base.Leg.pde_reference`) and builds it once, at build time
(:meth:`~fms_testbed.legs.base.Leg.coded_path`), from the record's fields with the fixes
resolved and the course turned true. Three shapes cover every leg type that has one:

* :class:`CourseLine` — a geodesic: TF the track between the two fixes; CF the geodesic into the
  fix on the coded course; FA/FC/FD/FM the geodesic out of the fix on the coded course;
* :class:`CodedCircle` — RF the circle of the coded radius (col. 57-62) about the centre fix;
  AF the circle of rho (col. 67-70) about the recommended navaid's DME;
* :class:`Racetrack` — HA/HF/HM the holding pattern on the coded inbound course into the fix,
  turning the coded way, with the coded (or timed) leg length and the planned turn radius
  (ARINC-424 codes no hold radius), built on the ellipsoid as a circuit is flown
  (:func:`racetrack`).

Every shape answers ``distance_m(lat_deg, lon_deg)``: the unsigned distance of a point from it,
m; a course line also scores a piece flown backwards along it (:meth:`CourseLine.pde_m`). Course lines are extended beyond their ends (the distance is the cross-track of the
geodesic) and a circle is the whole circle — a built point is compared with where the record
puts the path, not with where the leg starts or ends; a racetrack is a closed curve.
"""

from __future__ import annotations

from dataclasses import dataclass

from fms_testbed.core.geodesy import direct, inverse
from fms_testbed.core.segments import Arc, Line, project
from fms_testbed.core.units import NM_M
from fms_testbed.legs.construct import turn_arc

COURSE_LINE_M = 10 * NM_M
"""Length of the geodesic drawn for a coded course (the distance does not depend on it), m."""


@dataclass(frozen=True, slots=True)
class CourseLine:
    """A coded straight path: the geodesic through ``line`` (extended beyond its ends)."""

    line: Line

    def distance_m(self, lat_deg: float, lon_deg: float) -> float:
        """Unsigned cross-track distance of a point (deg) from the geodesic, m."""
        return abs(project(self.line, lat_deg, lon_deg)[1])

    def pde_m(self, points: list[tuple[float, float]]) -> float:
        """PDE of a built piece through ``points`` (deg, in flying order), signed along the
        course: the larger of the largest cross-track distance and the distance flown back
        along the course (the along-track drop from the first point to the last), m — a
        piece flown backwards along the line scores its length, not zero."""
        along, xtk = zip(*(project(self.line, lat, lon)[:2] for lat, lon in points))
        return max(max(abs(x) for x in xtk), along[0] - along[-1], 0.0)


@dataclass(frozen=True, slots=True)
class CodedCircle:
    """A coded arc as its whole circle: centre (deg) and radius (m)."""

    centre_lat_deg: float
    centre_lon_deg: float
    radius_m: float

    def distance_m(self, lat_deg: float, lon_deg: float) -> float:
        """| geodesic distance from the centre − radius | of a point (deg), m."""
        return abs(inverse(self.centre_lat_deg, self.centre_lon_deg, lat_deg, lon_deg)[0]
                   - self.radius_m)


@dataclass(frozen=True, slots=True)
class Racetrack:
    """A holding pattern as the closed chain of its four segments (``segments``: outbound turn,
    outbound leg, inbound turn, inbound leg), made by :func:`racetrack`."""

    segments: tuple[Arc | Line, Arc | Line, Arc | Line, Arc | Line]

    def distance_m(self, lat_deg: float, lon_deg: float) -> float:
        """Unsigned distance of a point (deg) from the pattern: the least distance from one of
        its four segments, m."""
        return min(_segment_distance_m(g, lat_deg, lon_deg) for g in self.segments)


def _segment_distance_m(g: Arc | Line, lat_deg: float, lon_deg: float) -> float:
    """Distance of a point from a finite segment: |cross-track| where the foot point lies on
    it, else the distance to the nearer end, m."""
    along, xtk, _, _ = project(g, lat_deg, lon_deg)
    if 0.0 <= along <= g.length_m():
        return abs(xtk)
    return min(inverse(*end, lat_deg, lon_deg)[0] for end in (g.start, g.end))


def racetrack(fix_lat_deg: float, fix_lon_deg: float, inbound_deg: float, turn: str,
              leg_m: float, radius_m: float) -> Racetrack:
    """The racetrack of a hold (HA/HF/HM), built on the ellipsoid as a circuit is flown: from
    over the fix on the inbound course (true), a 180° turn of ``radius_m`` to the ``turn`` side
    ('L'/'R'), ``leg_m`` straight on, a 180° turn, the geodesic back into the fix."""
    sweep = 180.0 if turn == "R" else -180.0
    out_turn = turn_arc(fix_lat_deg, fix_lon_deg, inbound_deg, sweep, radius_m)
    o1 = out_turn.end
    o2 = direct(o1[0], o1[1], out_turn.end_course_deg, leg_m)
    outbound = Line(o1[0], o1[1], o2[0], o2[1])
    in_turn = turn_arc(o2[0], o2[1], outbound.end_course_deg, sweep, radius_m)
    inbound = Line(*in_turn.end, fix_lat_deg, fix_lon_deg)
    return Racetrack((out_turn, outbound, in_turn, inbound))


CodedPath = CourseLine | CodedCircle | Racetrack
"""What :meth:`~fms_testbed.legs.base.Leg.coded_path` returns (None: the leg has none)."""


def track_between(lat1_deg: float, lon1_deg: float, lat2_deg: float, lon2_deg: float
                  ) -> CourseLine | None:
    """The geodesic from one fix to the next (TF); None when the fixes coincide (< 1 m)."""
    if inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg)[0] < 1.0:
        return None
    return CourseLine(Line(lat1_deg, lon1_deg, lat2_deg, lon2_deg))


def course_into(lat_deg: float, lon_deg: float, course_deg: float) -> CourseLine:
    """The geodesic that reaches the fix (deg) on ``course_deg`` (true) there (CF)."""
    lat0, lon0, _ = direct(lat_deg, lon_deg, course_deg + 180.0, COURSE_LINE_M)
    return CourseLine(Line(lat0, lon0, lat_deg, lon_deg))


def course_from(lat_deg: float, lon_deg: float, course_deg: float) -> CourseLine:
    """The geodesic that leaves the fix (deg) on ``course_deg`` (true) (FA/FC/FD/FM)."""
    lat1, lon1, _ = direct(lat_deg, lon_deg, course_deg, COURSE_LINE_M)
    return CourseLine(Line(lat_deg, lon_deg, lat1, lon1))


def path_definition_error_m(coded: CodedPath, points: list[tuple[float, float]]) -> float:
    """PDE of a built piece of path: the largest distance of its points (deg, in flying order)
    from the coded path, m; along a coded course line signed along the course
    (:meth:`CourseLine.pde_m`)."""
    if isinstance(coded, CourseLine):
        return coded.pde_m(points)
    return max(coded.distance_m(lat, lon) for lat, lon in points)
