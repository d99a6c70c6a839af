"""The leg builder's working state: emits tagged segments and offers the moves legs are made of.

A leg class (:mod:`.types`) calls these moves: start a course (as a fly-by corner when the
previous fix allows it, else as a turn from the present position), fly straight, go direct to a
fix, join a course line with a 45° intercept, climb along the distance flown. Every move appends
:class:`~.model.PathSegment` objects and returns the new :class:`~.model.FlightState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import NM_M
from fms_testbed.legs.construct import _foot, direct_to_arc, ray_geodesic_intersection, turn_to_course
from fms_testbed.procedures.legrecord import LegRecord
from fms_testbed.legs.model import BuildParams, Finding, FlightState, PathSegment, Performance
from fms_testbed.procedures.records import Fix


@dataclass(frozen=True, slots=True)
class ResolvedLeg:
    """A leg record with its referenced fixes looked up and its course turned true.

    course_true_deg: coded course + variation (deg true, None if not coded); magvar_deg: the
    variation used (recommended VHF navaid's declination, else the airport's), east positive.
    """

    rec: LegRecord
    fix: Fix | None
    navaid: Fix | None
    centre: Fix | None
    course_true_deg: float | None
    magvar_deg: float

    @property
    def pt(self) -> str:
        """Path terminator."""
        return self.rec.path_term

    def to_true(self, bearing_deg: float | None) -> float | None:
        """Magnetic bearing (or already-true when the record says so) to true, deg."""
        if bearing_deg is None:
            return None
        return wrap360(bearing_deg + (0.0 if self.rec.course_true else self.magvar_deg))


class LegBuilder:
    """Mutable builder for one procedure transition (one instance per build).

    Attributes
    ----------
    segments : list of PathSegment built so far
    corners : indices of segments whose start is a sharp fly-by corner to be rounded
    findings : list of Finding
    """

    def __init__(self, legs: list[ResolvedLeg], perf: Performance, params: BuildParams,
                 g_mps2: float, prev_fixes: list[Fix | None]):
        self.legs = legs
        self.perf = perf
        self.params = params
        self.g = g_mps2
        self.segments: list[PathSegment] = []
        self.corners: set[int] = set()
        self.findings: list[Finding] = []
        self.prev_fixes = prev_fixes
        self.i = 0
        self.speed_mps = perf.tas_plan_mps
        self.radius_m = 1000.0
        self.climbing = True
        self.gradient = 0.05
        self._corner_pending = False

    # ------------------------------------------------------------------ context
    @property
    def leg(self) -> ResolvedLeg:
        """The leg being built."""
        return self.legs[self.i]

    @property
    def next_leg(self) -> ResolvedLeg | None:
        """The leg after the current one, if any."""
        return self.legs[self.i + 1] if self.i + 1 < len(self.legs) else None

    def finding(self, category: str, message: str, branch: str = "") -> None:
        """Record a finding against the current leg."""
        self.findings.append(Finding(self.i, category, message, branch))

    def _tag(self) -> tuple[str, str]:
        f = self.leg.fix
        return self.leg.pt, f.ident if f else ""

    # ------------------------------------------------------------------ emit
    def emit(self, geom, role: str = "leg") -> None:
        """Append a segment tagged with the current leg (zero-length lines are dropped)."""
        if isinstance(geom, Line) and geom.length_m() < 0.01:
            return
        pt, ident = self._tag()
        bank = 0.0
        if isinstance(geom, Arc):
            bank = math.degrees(math.atan(self.speed_mps ** 2 / (geom.radius_m * self.g)))
        if self._corner_pending:
            self.corners.add(len(self.segments))
        self._corner_pending = False
        self.segments.append(PathSegment(geom, self.i, pt, ident, role, self.speed_mps, bank))

    def advance(self, state: FlightState, dist_m: float, **changes) -> FlightState:
        """Move the planned altitude along ``dist_m`` of path (climb or descent) and update."""
        alt = state.alt_m
        if self.climbing:
            alt += dist_m * self.gradient
        return replace(state, alt_m=alt, **changes)

    def as_transition(self, first: int) -> None:
        """Tag the segments emitted since index ``first`` as a transition onto the leg's coded
        path (role 'turn': a direct-to the leg's fix, a hold entry): they have no PDE."""
        for k in range(first, len(self.segments)):
            if self.segments[k].role in ("leg", "hold"):
                self.segments[k] = replace(self.segments[k], role="turn")

    def settle(self, state: FlightState) -> FlightState:
        """End of a leg: a fly-by corner that no line consumed (a zero-length leg) is dropped,
        and the planned track goes back to the track actually flown."""
        if self._corner_pending and self.segments:
            self._corner_pending = False
            return replace(state, track_deg=self.segments[-1].geom.end_course_deg)
        self._corner_pending = False
        return state

    # ------------------------------------------------------------------ moves
    def arc(self, state: FlightState, arc: Arc, role: str = "turn") -> FlightState:
        """Fly an arc from the present position."""
        self.emit(arc, role)
        lat, lon = arc.end
        return self.advance(state, arc.length_m(), lat_deg=lat, lon_deg=lon,
                            track_deg=arc.end_course_deg, flyby=False, fix_ident="")

    def straight(self, state: FlightState, course_deg: float, dist_m: float,
                 role: str = "leg") -> FlightState:
        """Fly ``dist_m`` along the geodesic leaving the present position on ``course_deg``."""
        if dist_m <= 0.01:
            return replace(state, track_deg=course_deg)
        lat, lon, az2 = direct(state.lat_deg, state.lon_deg, course_deg, dist_m)
        self.emit(Line(state.lat_deg, state.lon_deg, lat, lon), role)
        return self.advance(state, dist_m, lat_deg=lat, lon_deg=lon, track_deg=wrap360(az2),
                            flyby=False, fix_ident="")

    def line_to(self, state: FlightState, lat: float, lon: float, fix_ident: str = "",
                flyby: bool = False) -> FlightState:
        """Fly the geodesic from the present position to a point."""
        seg = Line(state.lat_deg, state.lon_deg, lat, lon)
        if seg.length_m() < 0.01:
            return replace(state, lat_deg=lat, lon_deg=lon, fix_ident=fix_ident, flyby=flyby)
        self.emit(seg)
        return self.advance(state, seg.length_m(), lat_deg=lat, lon_deg=lon,
                            track_deg=seg.end_course_deg, flyby=flyby, fix_ident=fix_ident)

    def can_cut(self, state: FlightState, course_deg: float, direction: str | None) -> bool:
        """True when the turn onto ``course_deg`` at the present fix may be flown fly-by."""
        if state.track_deg is None or not state.flyby:
            return False
        if self.segments and isinstance(self.segments[-1].geom, Arc):
            return False  # corners are rounded between two lines only: turn after the arc
        short = wrap180(course_deg - state.track_deg)
        if abs(short) > self.params.flyby_max_deg:
            return False
        if direction == "R" and short < -1.0 or direction == "L" and short > 1.0:
            return False  # coded direction the long way round: flown over the fix
        return True

    def start_course(self, state: FlightState, course_deg: float,
                     direction: str | None = None) -> FlightState:
        """Get onto ``course_deg`` at the present position (fly-by corner or turn arc)."""
        if state.track_deg is None:
            return replace(state, track_deg=course_deg)
        if self.can_cut(state, course_deg, direction):
            self._corner_pending = abs(wrap180(course_deg - state.track_deg)) >= 0.5
            return replace(state, track_deg=course_deg)
        arc = turn_to_course(state.lat_deg, state.lon_deg, state.track_deg, course_deg,
                             direction, self.radius_m)
        if arc is None:
            return replace(state, track_deg=course_deg)
        return self.arc(state, arc)

    def direct_to(self, state: FlightState, fix: Fix, direction: str | None,
                  flyby_end: bool) -> FlightState:
        """Turn toward a fix (bounded retries when it is inside the turn circle) and fly to it."""
        if state.track_deg is not None:
            s, az, _ = inverse(state.lat_deg, state.lon_deg, fix.lat_deg, fix.lon_deg)
            if s < 1.0:
                return replace(state, flyby=flyby_end, fix_ident=fix.ident)
            if self.can_cut(state, az, direction):
                self._corner_pending = abs(wrap180(az - state.track_deg)) >= 0.5
            else:
                for _ in range(self.params.max_iterations):
                    arc, ok = direct_to_arc(state.lat_deg, state.lon_deg, state.track_deg,
                                            fix.lat_deg, fix.lon_deg, direction, self.radius_m)
                    if ok:
                        if arc is not None:
                            state = self.arc(state, arc)
                        break
                    state = self.straight(state, state.track_deg, 2.0 * self.radius_m)
                else:
                    self.finding("no-intercept", f"cannot turn onto {fix.ident}: it stays "
                                 "inside the turn circle; flown straight at it")
        return self.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)

    def join_course(self, state: FlightState, fix: Fix, course_deg: float,
                    direction: str | None, flyby_end: bool) -> FlightState:
        """Join the course line into ``fix`` (course ``course_deg`` at the fix), then fly it.

        On the line already: straight to the fix. Otherwise turn to a 45° intercept heading,
        fly to the line (role 'turn') and turn onto it (fly-by); if the intercept would fall
        beyond the fix, fly direct to the fix instead (recorded as a finding).
        """
        along, xtk, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                                 state.lon_deg)
        n0 = len(self.segments)
        trk = state.track_deg
        if along < 0 and math.degrees(math.atan2(abs(xtk), -along)) < 5.0:
            # within 5° of the course line seen from the fix (courses referenced to old station
            # declinations differ from the fixes' bearing by up to ~5° in the FAA data):
            # fly straight to the fix
            return self.direct_to(state, fix, direction, flyby_end)
        aligned = trk is None or abs(wrap180(trk - fcrs)) < 2.0
        if abs(xtk) < 30.0 and aligned and along < 0:
            if trk is not None and abs(wrap180(fcrs - trk)) >= 0.5:
                state = self.start_course(state, fcrs, direction)
            return self.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)
        if abs(xtk) < 30.0 and along < 0:
            state = self.start_course(state, fcrs, direction)
            return self.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)
        state0 = state
        for _ in range(2):
            heading = wrap360(fcrs - math.copysign(45.0, xtk))
            state = self.start_course(state, heading, direction)
            direction = None
            along, xtk2, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                                      state.lon_deg)
            if abs(xtk2) < 30.0 or math.copysign(1.0, xtk2) == math.copysign(1.0, xtk):
                xtk = xtk2
                break
            xtk = xtk2
        hit = ray_geodesic_intersection(state.lat_deg, state.lon_deg, state.track_deg,
                                        fix.lat_deg, fix.lon_deg, course_deg)
        lead = self.radius_m * math.tan(math.radians(22.5))
        if hit is None or hit[1] > -lead:
            if abs(xtk) > 30.0:
                self.finding("info", f"course into {fix.ident} joined too late for a 45° "
                             "intercept; flown direct to the fix")
            return self.direct_to(state, fix, None, flyby_end)
        if hit[0] < lead:
            # too close to the line for the 45° capture: turn onto the course now and let a
            # direct-to absorb the small offset
            if len(self.segments) == n0:      # nothing flown yet: drop the intercept heading
                state, self._corner_pending = state0, False
            arc = turn_to_course(state.lat_deg, state.lon_deg, state.track_deg, fcrs, None,
                                 self.radius_m)
            if arc is not None:
                self._corner_pending = False
                state = self.arc(state, arc)
            return self.direct_to(state, fix, None, flyby_end)
        # the 45° intercept is a transition onto the course line (no PDE); the course is the leg
        state = self.straight(state, state.track_deg, hit[0], role="turn")
        state = replace(state, flyby=True)
        self._corner_pending = True
        return self.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)

    def connect(self, state: FlightState, lat: float, lon: float, why: str) -> FlightState:
        """Bridge a gap (> 1 cm) with a connector line; a gap above 0.05 NM is also recorded
        as a discontinuity finding."""
        s, _, _ = inverse(state.lat_deg, state.lon_deg, lat, lon)
        if s <= 0.01:
            return replace(state, lat_deg=lat, lon_deg=lon)
        if s > 0.05 * NM_M:
            self.finding("discontinuity", f"{why}: gap of {s / NM_M:.2f} NM bridged")
        seg = Line(state.lat_deg, state.lon_deg, lat, lon)
        self.emit(seg, "connector")
        return self.advance(state, s, lat_deg=lat, lon_deg=lon, track_deg=seg.end_course_deg)

    def fix_state(self, state: FlightState, fix: Fix) -> FlightState:
        """State placed at a fix with its fly-over/fly-by flag from the current record."""
        return replace(state, lat_deg=fix.lat_deg, lon_deg=fix.lon_deg, fix_ident=fix.ident,
                       flyby=not self.leg.rec.fly_over)

    def turn_dir(self) -> str | None:
        """Coded turn direction of the current leg ('L'/'R') or None."""
        d = self.leg.rec.turn_dir
        return d if d in ("L", "R") else None

    def altitude_distance_m(self, state: FlightState, alt_target_m: float) -> float:
        """Path distance to climb from the planned altitude to ``alt_target_m`` at the
        planned gradient, m (0 when already there)."""
        dh = alt_target_m - state.alt_m
        return max(dh, 0.0) / max(self.gradient, 1e-3)

