"""The leg builder's working state: emits tagged segments and offers the moves legs are made of.

A leg class (:mod:`.types`) calls these moves: start a course (as a fly-by corner when the
previous fix allows it, else as a turn from the present position), fly straight, go direct to a
fix, join a course line with a 45° intercept, climb along the distance flown. Every move appends
:class:`~.model.PathSegment` objects and returns the new :class:`~.model.FlightState`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.core.geodesy import direct, wrap360
from fms_testbed.core.segments import Arc, Line
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
CF_OFF_COURSE_DEG = 20.0
"""A CF's own straight more than this off its coded course is not the coded leg, deg."""
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
        self.flown_before_m = 0.0
        """Path length built before this builder's first segment, m (the builder of a
        fly-over rejoin starts mid-path)."""
        self.params0 = params
        self.leg_params: dict[int, BuildParams] = {}
        """The settings each leg was built with (the wind at its planned altitude)."""
        self.leg_alt_m: dict[int, float] = {}
        """Each leg's planned start altitude, m."""
        self.dep_elev_m: float | None = None
        """Elevation of the runway a departure is planned from, m (None: not a departure from
        a runway: no departure speed schedule)."""
        self.dep_accel_s_m: float | None = None
        """Path distance at which the planned climb passed the acceleration height, m (None:
        not yet)."""
        self.dep_prev: tuple[float, float] | None = None
        """(path distance m, height above the runway m) at the previous leg's start."""
        self.dep_legs: set[int] = set()
        """Indices of the legs planned under the departure schedule."""
        self.dep_cas_mps: float | None = None
        """The departure schedule's CAS the current leg is planned under, m/s (None: none)."""

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

    def finding(self, category: str, message: str, branch: str = "",
                leg_index: int | None = None) -> None:
        """Record a finding against leg ``leg_index`` (default: the current leg)."""
        self.findings.append(Finding(self.i if leg_index is None else leg_index, category,
                                     message, branch))

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
        if not changes:                     # the common case, built without dataclasses.replace
            return FlightState(lat_deg=state.lat_deg, lon_deg=state.lon_deg,
                               track_deg=state.track_deg, alt_m=alt, flyby=state.flyby,
                               fix_ident=state.fix_ident)
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

    # ------------------------------------------------------------------ primitives
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
