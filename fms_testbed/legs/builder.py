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
from fms_testbed.core.segments import Arc, Line, turn_angle_deg
from fms_testbed.core.units import NM_M
from fms_testbed.legs.construct import _foot, direct_to_arc, ray_geodesic_intersection, turn_to_course
from fms_testbed.procedures.legrecord import LegRecord
from fms_testbed.legs.model import BuildParams, Finding, FlightState, PathSegment, Performance
from fms_testbed.procedures.records import Fix

CLOSE_S = 3.0
"""A gap the aircraft covers in less than this at the planned speed (its roll-in to a 20° bank
at 5°/s plus the bank loop's lag) is closed in the geometry, never flown as a direct-to, s."""
DIRECT_XTK_M = 50.0
"""A course into a fix whose line passes within this of the present position is flown as the
straight to the fix (courses referenced to an old station declination differ from the fixes'
bearing by up to ~5° in the FAA data; beyond this offset the coded course is intercepted), m."""
CF_FROM_FIX_DEG = 1.0
"""A course into a fix whose leg starts over the previous fix, with that fix this close to the
course (the angle its offset subtends from the fix, deg), is flown as the line between the two
fixes: the coded course is the chart's rounding of that line (KBIS I31: WIGAG 133 m beside the
311° course into ICONO, 0.33° from 23 km), and intercepting it would put an S-turn of a few
hundred metres where the turn onto the course needs its fly-by."""
CF_FROM_FIX_TURN_MAX_DEG = 120.0
""":data:`CF_FROM_FIX_DEG` applies to a fly-by turn onto the course; a sharper one (a course
reversal over the fix, e.g. a missed approach coded back along the final) keeps the course
join, so the monitor still sees the reversal."""
PARALLEL_TOL_M = 30.0
"""A turn from over a fix that ends closer than this to the coded course line out of the fix
is left parallel to it; beyond, the line is rejoined with a 45° intercept, m."""


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


def intercept_angle_deg(offset_m: float, radius_m: float) -> float:
    """Intercept angle for joining a course line ``offset_m`` away with two fly-by turns of
    radius R: 45°, or less for a small offset — the S-turn whose turns exactly fill the
    intercept, y = 4 R sin²(α/2) → α = 2 asin √(y / 4R), deg."""
    q = min(max(offset_m, 0.0) / (4.0 * radius_m), 1.0)
    return max(min(45.0, math.degrees(2.0 * math.asin(math.sqrt(q)))), 1.0)


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
        self.alt_cap_m = math.inf
        """The highest altitude the climb of the current leg may reach, m (the climb planner's
        :func:`~fms_testbed.path.profile.climb_caps_m` at the leg's end)."""
        self._corner_pending = False
        self._upstream_depth = 0
        self.joined = True
        self.params0 = params
        self.leg_params: dict[int, BuildParams] = {}
        """The settings each leg was built with (the wind at its planned altitude)."""
        self.leg_alt_m: dict[int, float] = {}
        """Each leg's planned start altitude, m."""

    # ------------------------------------------------------------------ context
    @property
    def leg(self) -> ResolvedLeg:
        """The leg being built."""
        return self.legs[self.i]

    @property
    def next_leg(self) -> ResolvedLeg | None:
        """The leg after the current one, if any."""
        return self.legs[self.i + 1] if self.i + 1 < len(self.legs) else None

    @property
    def wind_mps(self) -> float:
        """The planned wind speed, m/s: turns whose tracks are not known yet (a leg's turns, a
        hold's 180° turns) are planned for TAS + wind, the most ground speed they can see."""
        return self.params.wind_speed_mps

    def use_leg_params(self, leg_index: int) -> BuildParams:
        """Build with the settings leg ``leg_index`` was built with (its wind; the corners
        are rounded after all legs are built) and return them."""
        self.params = self.leg_params.get(leg_index, self.params0)
        return self.params

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
            bank = math.degrees(math.atan((self.speed_mps + self.wind_mps) ** 2
                                          / (geom.radius_m * self.g)))
        if self._corner_pending:
            self.corners.add(len(self.segments))
        self._corner_pending = False
        self.segments.append(PathSegment(geom, self.i, pt, ident, role, self.speed_mps, bank))

    def advance(self, state: FlightState, dist_m: float, **changes) -> FlightState:
        """Move the planned altitude along ``dist_m`` of path and update: a climb at the
        planned gradient up to :attr:`alt_cap_m` (never down to it)."""
        alt = state.alt_m
        if self.climbing:
            alt = min(alt + dist_m * self.gradient, max(self.alt_cap_m, alt))
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
        if self.segments and isinstance(self.segments[-1].geom, Arc) and \
                self.segments[-1].role != "leg":
            return False  # a turn's end is no corner: the next turn starts after it
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

        Within :data:`DIRECT_XTK_M` of the line: straight to the fix. Otherwise turn to an
        intercept heading α off the course — 45°, or for a small offset y the S-turn angle
        α = 2 asin √(y / 4R) whose two fly-by turns just fit (:func:`intercept_angle_deg`) —
        fly to the line (role 'turn') and turn onto it (fly-by). When the intercept would fall
        beyond the fix (or leave no room for the turn onto the course), the line is joined
        upstream instead (:meth:`_join_upstream`): so the leg's straight always lies on its
        coded course.
        """
        along, xtk, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                                 state.lon_deg)
        if along < 0 and self._at_previous_fix(state) and \
                math.degrees(math.atan2(abs(xtk), -along)) <= CF_FROM_FIX_DEG and \
                (state.track_deg is None or
                 abs(wrap180(fcrs - state.track_deg)) <= CF_FROM_FIX_TURN_MAX_DEG):
            return self.direct_to(state, fix, direction, flyby_end)
        toward = state.track_deg is None or abs(wrap180(state.track_deg - fcrs)) < 10.0
        if along < 0 and abs(xtk) <= DIRECT_XTK_M:
            if toward:   # on the course line already (within the tolerance): to the fix
                return self.direct_to(state, fix, direction, flyby_end)
            # on the line, heading elsewhere (the end of an intercept): turn onto it here
            here = Fix(ident="", region="", section="", lat_deg=state.lat_deg,
                       lon_deg=state.lon_deg)
            n0 = len(self.segments)
            st = self.join_from_fix(state, here, fcrs, direction, max_along_m=-along)
            if self.joined:
                if len(self.segments) > n0:
                    self.as_transition(n0)
                return self.line_to(st, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)
            if abs(wrap180(state.track_deg - fcrs)) < 90.0:
                return self._direct_no_room(state, fix, direction, flyby_end)
        n0 = len(self.segments)
        state0, dir0, corner0 = state, direction, self._corner_pending
        alpha = intercept_angle_deg(abs(xtk), self.radius_m)
        for _ in range(2):
            heading = wrap360(fcrs - math.copysign(alpha, xtk))
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
        lead = self.radius_m * math.tan(math.radians(alpha) / 2.0)
        room = lead if len(self.segments) > n0 else 2.0 * lead
        if hit is None or hit[1] > -lead or hit[0] < 0.99 * room:
            del self.segments[n0:]
            self._corner_pending = corner0
            if self._upstream_depth > 0:
                return self.direct_to(state0, fix, dir0, flyby_end)
            return self._join_upstream(state0, fix, course_deg, dir0, flyby_end)
        # the intercept is a transition onto the course line (no PDE); the course is the leg
        state = self.straight(state, state.track_deg, hit[0], role="turn")
        state = replace(state, flyby=True)
        self._corner_pending = True
        return self.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)

    def _at_previous_fix(self, state: FlightState) -> bool:
        """True when ``state`` lies over the fix the previous leg ended at (within 1 m)."""
        prev = self.prev_fixes[self.i] if self.i < len(self.prev_fixes) else None
        if prev is None or not state.fix_ident or state.fix_ident != prev.ident:
            return False
        return inverse(state.lat_deg, state.lon_deg, prev.lat_deg, prev.lon_deg)[0] <= 1.0

    def _join_upstream(self, state: FlightState, fix: Fix, course_deg: float,
                       direction: str | None, flyby_end: bool) -> FlightState:
        """Join the course into ``fix`` upstream of the fix, where no intercept reaches it in
        time (the aircraft abeam or past the fix, or too close to it). When the aircraft heads
        toward the fix (within 90° of the course) with less than two turn radii of course ahead
        of it, or no upstream point fits, there is no room without a loop: it flies direct to
        the fix (:meth:`_direct_no_room`).

        Direct to a point P on the course D before the fix (role 'turn'), fly-by onto the
        course there, then the course to the fix; D is 2, 3, 4.5 and 6.75 turn radii until the
        fly-by at P (lead R tan(Ω/2), Ω the turn at P as built) fits both in the direct line
        before P and in half of D. When it never fits (the aircraft would reach P heading away
        from the fix), the course is reversed onto: direct to Q, two radii beside P on the
        aircraft's side (P two radii upstream of the aircraft's abeam point), a 180° turn
        toward the course there, then the course joined (:meth:`join_course`) from where the
        turn ends."""
        n0, corner0 = len(self.segments), self._corner_pending
        along, xtk, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                                 state.lon_deg)
        away = state.track_deg is not None and abs(wrap180(state.track_deg - fcrs)) >= 90.0
        if state.track_deg is not None:
            # the fix abeam or behind: a direct-to would turn back anyway — reverse onto the
            # course instead of arriving at the fix across it
            brg = inverse(state.lat_deg, state.lon_deg, fix.lat_deg, fix.lon_deg)[1]
            away = away or abs(wrap180(brg - state.track_deg)) > 90.0
        if not away and -along < 2.0 * self.radius_m:
            return self._direct_no_room(state, fix, direction, flyby_end)
        for k in range(4):
            del self.segments[n0:]
            self._corner_pending = corner0
            d_m = 2.0 * self.radius_m * 1.5 ** k
            plat, plon, _ = direct(fix.lat_deg, fix.lon_deg, course_deg + 180.0, d_m)
            target = Fix(ident="", region="", section="", lat_deg=plat, lon_deg=plon)
            st = self.direct_to(state, target, direction, True)
            last = self.segments[-1].geom if len(self.segments) > n0 else None
            run = last.length_m() if isinstance(last, Line) else 0.0
            into = last.end_course_deg if last is not None else st.track_deg
            omega = abs(wrap180(course_deg - into))
            if self.radius_m * math.tan(math.radians(min(omega, 179.0)) / 2.0) \
                    <= min(run, 0.5 * d_m):
                self.finding("info", f"course into {fix.ident} joined {d_m / NM_M:.1f} NM "
                             "before the fix (no intercept before it from here)")
                self.as_transition(n0)
                st = replace(st, flyby=True)
                self._corner_pending = True
                return self.line_to(st, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)
        del self.segments[n0:]
        self._corner_pending = corner0
        if not away:
            return self._direct_no_room(state, fix, direction, flyby_end)
        side = 1.0 if xtk >= 0 else -1.0
        # P beyond the aircraft when it flies away from the fix, so that Q lies ahead of it
        d_m = 2.0 * self.radius_m + max(0.0, -along)
        plat, plon, _ = direct(fix.lat_deg, fix.lon_deg, course_deg + 180.0, d_m)
        qlat, qlon, _ = direct(plat, plon, course_deg + 90.0 * side, 2.0 * self.radius_m)
        target = Fix(ident="", region="", section="", lat_deg=qlat, lon_deg=qlon)
        st = self.direct_to(state, target, direction, False)
        arc = turn_to_course(st.lat_deg, st.lon_deg, st.track_deg, course_deg,
                             "R" if side > 0 else "L", self.radius_m)
        if arc is not None:
            st = self.arc(st, arc)
        self.finding("info", f"course into {fix.ident} joined by a course reversal "
                     f"{d_m / NM_M:.1f} NM before the fix")
        self.as_transition(n0)
        _, xtk2, _ = _foot(fix.lat_deg, fix.lon_deg, course_deg, st.lat_deg, st.lon_deg)
        if abs(xtk2) <= DIRECT_XTK_M or self._upstream_depth > 0:
            return self.direct_to(st, fix, None, flyby_end)
        self._upstream_depth += 1
        try:
            return self.join_course(replace(st, flyby=False), fix, course_deg, None, flyby_end)
        finally:
            self._upstream_depth -= 1

    def _direct_no_room(self, state: FlightState, fix: Fix, direction: str | None,
                        flyby_end: bool) -> FlightState:
        """Heading toward ``fix`` with no room to get onto its course without a loop (at the
        planned radius: Danilin's class 1, the conditions): fly direct to it; a finding says
        the coded course is not flown."""
        self.finding("info", f"no room to join the course into {fix.ident} at the planned "
                     f"radius {self.radius_m:.0f} m: flown direct to the fix")
        return self.direct_to(state, fix, direction, flyby_end)

    def join_from_fix(self, state: FlightState, fix: Fix, course_deg: float,
                      direction: str | None, max_along_m: float = math.inf) -> FlightState:
        """From over (or at the fly-by corner of) ``fix``, get onto the geodesic that leaves the
        fix on ``course_deg`` (F* legs, the procedure turn's outbound leg).

        A fly-by corner is cut as usual (the next straight starts on the line). A turn flown
        from over the fix ends R(1 − cos Δ) beside the coded course; when that is more than
        :data:`PARALLEL_TOL_M` the turn is continued by α past the course (45°, less — 35, 25,
        15° — when the intercept would leave no room for its fly-by), the intercept flown to
        the line (role 'turn') and the course joined with a fly-by: the leg's straight then lies
        on its coded course line, not parallel to it.

        ``max_along_m``: the intercept must fall (with the lead of its fly-by) within this
        distance from the fix (a TF's length), m; when it cannot, the state is returned
        unchanged with the intercept segments removed and ``self.joined`` False.

        Returns the state on the line (track ``course_deg``) or, when it may be cut, at the fix.
        """
        self.joined = True
        if state.track_deg is None:
            return replace(state, track_deg=course_deg)
        if self.can_cut(state, course_deg, direction):
            return self.start_course(state, course_deg, direction)
        sweep = turn_angle_deg(state.track_deg, course_deg, direction)
        if abs(sweep) < 0.5 or abs(sweep) > 359.5:
            return replace(state, track_deg=course_deg)
        if self.radius_m * (1.0 - math.cos(math.radians(min(abs(sweep), 180.0)))) \
                < PARALLEL_TOL_M:
            return self.start_course(state, course_deg, direction)
        n0 = len(self.segments)
        turn = "R" if sweep > 0 else "L"
        st = hit = None
        for alpha in (45.0, 35.0, 25.0, 15.0):
            del self.segments[n0:]
            over = wrap360(course_deg + math.copysign(alpha, sweep))
            arc = turn_to_course(state.lat_deg, state.lon_deg, state.track_deg, over, turn,
                                 self.radius_m)
            st = self.arc(state, arc) if arc is not None else replace(state, track_deg=over)
            hit = ray_geodesic_intersection(st.lat_deg, st.lon_deg, st.track_deg, fix.lat_deg,
                                            fix.lon_deg, course_deg)
            lead = self.radius_m * math.tan(math.radians(alpha) / 2.0)
            if hit is not None and hit[0] >= lead:
                break
        else:
            # no room for the intercept: back to the plain turn onto the course
            del self.segments[n0:]
            return self.start_course(state, course_deg, direction)
        if hit[1] + lead > max_along_m:
            del self.segments[n0:]
            self.joined = False
            return state
        st = self.straight(st, st.track_deg, hit[0], role="turn")
        self._corner_pending = True
        return replace(st, track_deg=course_deg, flyby=True)

    def connect(self, state: FlightState, lat: float, lon: float, why: str) -> FlightState:
        """Bridge a gap (> 1 cm) to a point; a gap above 0.05 NM is also recorded as a
        discontinuity finding.

        The bridge is built here, as flown, so that the corner at its end is rounded like any
        other fly-by (the segments carry role 'connector': no PDE):

        * a gap shorter than the turn anticipation L = R tan(Ω/2) of the turn toward it (Ω the
          track change to its bearing, R the planned radius), and than the roll-in distance
          V · :data:`CLOSE_S`, is closed in the geometry: the
          last line moves its end onto the point when it does not end at a fix, else a short
          straight bridge is flown through (never a direct-to with turns larger than the gap);
        * a longer gap (vectors to the next fix, an intercept that never happens) is a
          direct-to from the present track: a turn at the planned radius, then the line.
        """
        s, az, _ = inverse(state.lat_deg, state.lon_deg, lat, lon)
        if s <= 0.01:
            return replace(state, lat_deg=lat, lon_deg=lon)
        if s > 0.05 * NM_M:
            self.finding("discontinuity", f"{why}: gap of {s / NM_M:.2f} NM bridged")
        omega = abs(wrap180(az - state.track_deg)) if state.track_deg is not None else 0.0
        # the turn anticipation a direct-to onto the gap would need — the roll-in distance
        # (V · CLOSE_S) bounds it: a larger gap is flown as a real direct-to
        lead = min(self.radius_m * math.tan(math.radians(min(omega, 179.0)) / 2.0),
                   self.speed_mps * CLOSE_S)
        last = self.segments[-1] if self.segments else None
        if s < lead and last is not None and isinstance(last.geom, Line) and \
                not state.fix_ident and last.geom.length_m() > 4.0 * s:
            moved = Line(last.geom.start_lat_deg, last.geom.start_lon_deg, lat, lon)
            self.segments[-1] = replace(last, geom=moved)
            return self.advance(state, s, lat_deg=lat, lon_deg=lon,
                                track_deg=moved.end_course_deg)
        if s < lead or state.track_deg is None:
            seg = Line(state.lat_deg, state.lon_deg, lat, lon)
            self.emit(seg, "connector")
            return self.advance(state, s, lat_deg=lat, lon_deg=lon,
                                track_deg=seg.end_course_deg)
        n0 = len(self.segments)
        target = Fix(ident="", region="", section="", lat_deg=lat, lon_deg=lon)
        state = self.direct_to(replace(state, flyby=False), target, None, False)
        for k in range(n0, len(self.segments)):
            self.segments[k] = replace(self.segments[k], role="connector")
        return replace(state, lat_deg=lat, lon_deg=lon)

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

