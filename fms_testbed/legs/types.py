"""The 23 ARINC-424 path terminators: one small class each, one table code -> class.

Every class turns the current leg (``b.leg``, a :class:`~.builder.ResolvedLeg`) and the planned
aircraft state into segments via the :class:`~.builder.LegBuilder` moves, and returns the end
state and the leg's :class:`~.model.Termination` (kept as data for guidance). Conditional legs end
where the planned aircraft meets the condition: altitude from the aircraft's climb gradient at the
planned speed, DME distance and radial by bounded ray intersection, intercepts against the next
leg's path, manual terminations after ``BuildParams.manual_leg_m``.
"""

from __future__ import annotations

from dataclasses import replace

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.construct import ray_circle_distance, ray_geodesic_intersection, turn_to_course
from fms_testbed.legs.model import FlightState, Termination


class LegError(Exception):
    """The leg cannot be built as coded (missing field or fix); the message says why."""


def _course(b: LegBuilder) -> float:
    c = b.leg.course_true_deg
    if c is None:
        raise LegError(f"{b.leg.pt} leg without a course (column 71)")
    return c


def _fix(b: LegBuilder):
    f = b.leg.fix
    if f is None:
        raise LegError(f"{b.leg.pt} leg without a fix (column 30)")
    return f


def _navaid(b: LegBuilder):
    n = b.leg.navaid
    if n is None:
        raise LegError(f"{b.leg.pt} leg without a recommended navaid (column 51)")
    return n


def _dme_pos(n) -> tuple[float, float]:
    if n.dme_lat_deg is not None and n.dme_lon_deg is not None:
        return n.dme_lat_deg, n.dme_lon_deg
    return n.lat_deg, n.lon_deg


def _alt(b: LegBuilder) -> float:
    a = b.leg.rec.alt1_m
    if a is None:
        raise LegError(f"{b.leg.pt} leg without a termination altitude (column 85)")
    return a


def _fix_term(f) -> Termination:
    return Termination("fix", f.lat_deg, f.lon_deg, fix_ident=f.ident)


class Leg:
    """Base: ``build(b, state) -> (state, termination)``; ``target(leg)`` for intercepts."""

    code = ""

    @classmethod
    def build(cls, b: LegBuilder, s: FlightState) -> tuple[FlightState, Termination]:
        """Append the leg's segments to ``b`` and return its end.

        Parameters
        ----------
        b : the transition's builder; ``b.leg`` is this leg (fixes resolved, course true, deg),
            ``b.speed_mps``/``b.radius_m`` the planned TAS (m/s) and turn radius (m)
        s : planned state where the previous leg ended (deg, deg true, m)

        Returns
        -------
        (state, termination): the planned state at the leg's end and how the leg ends.

        Raises
        ------
        LegError when a field the leg needs is missing (the transition is then impossible).
        """
        raise NotImplementedError

    @classmethod
    def target(cls, leg) -> tuple | None:
        """What a CI/VI leg before this one intercepts: ('line', lat, lon, course_deg at the
        point, must_be_before_the_point) or ('circle', lat, lon, radius_m), or None."""
        return None


# --------------------------------------------------------------------------- fix-terminated
class IF(Leg):
    """Initial fix: the path starts (or restarts, with a discontinuity) at the fix."""

    code = "IF"

    @classmethod
    def build(cls, b, s):
        f = _fix(b)
        if s.track_deg is not None or b.segments:
            s = b.connect(s, f.lat_deg, f.lon_deg, f"IF {f.ident} away from the previous leg")
        return b.fix_state(s, f), _fix_term(f)


class TF(Leg):
    """Track to fix: the great-circle track from the previous fix to this one."""

    code = "TF"

    @classmethod
    def build(cls, b, s):
        f = _fix(b)
        prev = b.prev_fixes[b.i]
        if prev is None or s.fix_ident != prev.ident:
            if prev is not None and s.track_deg is not None:
                _, az1, az2 = inverse(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
                s = b.join_course(s, f, az2, b.turn_dir(), not b.leg.rec.fly_over)
                return b.fix_state(s, f), _fix_term(f)
            s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)
            return b.fix_state(s, f), _fix_term(f)
        if b.can_cut(s, inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[1], b.turn_dir()):
            s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)   # fly-by corner
        else:  # over the previous fix (or after an arc): turn and rejoin the TF track
            _, _, az2 = inverse(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
            s = b.join_course(s, f, az2, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), _fix_term(f)

    @classmethod
    def target(cls, leg):
        return None


class CF(Leg):
    """Course to fix: join the coded course into the fix and fly it."""

    code = "CF"

    @classmethod
    def build(cls, b, s):
        f, c = _fix(b), _course(b)
        if s.track_deg is None:
            s = replace(s, track_deg=c)
        s = b.join_course(s, f, c, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), _fix_term(f)

    @classmethod
    def target(cls, leg):
        if leg.fix is None or leg.course_true_deg is None:
            return None
        return ("line", leg.fix.lat_deg, leg.fix.lon_deg, leg.course_true_deg, True)


class DF(Leg):
    """Direct to fix from wherever the previous leg ended, turning the coded way."""

    code = "DF"

    @classmethod
    def build(cls, b, s):
        f = _fix(b)
        s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), _fix_term(f)


def _corner_onto(b: LegBuilder, s: FlightState, arc: Arc) -> None:
    """Mark a non-tangent entry onto a coded arc as a fly-by corner when the state allows it
    (the segmentation then fits a line-to-arc fillet)."""
    if b.segments and isinstance(b.segments[-1].geom, Line) and \
            b.can_cut(s, arc.start_course_deg, None) and \
            abs(wrap180(arc.start_course_deg - s.track_deg)) >= 0.5:
        b._corner_pending = True


class RF(Leg):
    """Constant-radius arc about the coded centre fix, in the coded direction, to the fix."""

    code = "RF"

    @classmethod
    def build(cls, b, s):
        f, c = _fix(b), b.leg.centre
        if c is None:
            raise LegError("RF leg without a centre fix (column 107)")
        d = b.turn_dir()
        if d is None:
            raise LegError("RF leg without a turn direction (column 44)")
        r_end, rad_end, _ = inverse(c.lat_deg, c.lon_deg, f.lat_deg, f.lon_deg)
        _, rad_start, _ = inverse(c.lat_deg, c.lon_deg, s.lat_deg, s.lon_deg)
        start_pt = direct(c.lat_deg, c.lon_deg, rad_start, r_end)
        s = b.connect(s, start_pt[0], start_pt[1], "RF start not on the arc")
        sweep = wrap360(rad_end - rad_start) if d == "R" else -wrap360(rad_start - rad_end)
        if abs(sweep) > 0.01:
            arc = Arc(c.lat_deg, c.lon_deg, r_end, rad_start, sweep)
            _corner_onto(b, s, arc)
            s = b.arc(s, arc, role="leg")
        return b.fix_state(replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg), f), _fix_term(f)


class AF(Leg):
    """Arc to fix: DME arc about the recommended navaid, coded direction, ending at the fix."""

    code = "AF"

    @classmethod
    def build(cls, b, s):
        f, n = _fix(b), _navaid(b)
        d = b.turn_dir()
        if d is None:
            raise LegError("AF leg without a turn direction (column 44)")
        nlat, nlon = _dme_pos(n)
        r_end, rad_end, _ = inverse(nlat, nlon, f.lat_deg, f.lon_deg)
        _, rad_start, _ = inverse(nlat, nlon, s.lat_deg, s.lon_deg)
        start_pt = direct(nlat, nlon, rad_start, r_end)
        s = b.connect(s, start_pt[0], start_pt[1], "AF start not on the DME arc")
        sweep = wrap360(rad_end - rad_start) if d == "R" else -wrap360(rad_start - rad_end)
        if abs(sweep) > 0.01:
            arc = Arc(nlat, nlon, r_end, rad_start, sweep)
            _corner_onto(b, s, arc)
            s = b.arc(s, arc, role="leg")
        return b.fix_state(replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg), f), _fix_term(f)

    @classmethod
    def target(cls, leg):
        if leg.navaid is None or (leg.rec.rho_m is None and leg.fix is None):
            return None
        lat, lon = _dme_pos(leg.navaid)
        r = leg.rec.rho_m   # the arc is flown at the fix's range (see build): intercept that
        if leg.fix is not None:
            r = inverse(lat, lon, leg.fix.lat_deg, leg.fix.lon_deg)[0]
        return ("circle", lat, lon, r)


# --------------------------------------------------------------------------- conditional
def _climb_to(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    alt = _alt(b)
    dist = b.altitude_distance_m(s, alt)
    s = b.straight(s, course, dist)
    s = replace(s, alt_m=max(s.alt_m, alt), flyby=False, fix_ident="")
    return s, Termination("altitude", s.lat_deg, s.lon_deg, alt_m=alt)


def _to_dme(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    n = _navaid(b)
    dist = b.leg.rec.distance_m
    if dist is None:
        raise LegError(f"{b.leg.pt} leg without a DME distance (column 75)")
    nlat, nlon = _dme_pos(n)
    along = ray_circle_distance(s.lat_deg, s.lon_deg, course, nlat, nlon, dist)
    if along is None:
        b.finding("no-intercept", f"DME {dist / 1852:.1f} NM from {n.ident} never reached on "
                  f"course {course:.0f}°T; flown {b.params.manual_leg_m / 1852:.0f} NM")
        along = b.params.manual_leg_m
    s = b.straight(s, course, along)
    s = replace(s, flyby=False, fix_ident="")
    return s, Termination("dme", s.lat_deg, s.lon_deg, dme_m=dist, navaid_lat_deg=nlat,
                          navaid_lon_deg=nlon)


def _to_radial(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    n = _navaid(b)
    if b.leg.rec.theta_deg is None:
        raise LegError(f"{b.leg.pt} leg without a radial (theta, column 63)")
    radial = wrap360(b.leg.rec.theta_deg + n.magvar_deg)
    hit = ray_geodesic_intersection(s.lat_deg, s.lon_deg, course, n.lat_deg, n.lon_deg, radial)
    if hit is None or hit[1] < 0:
        b.finding("no-intercept", f"radial {b.leg.rec.theta_deg:.0f} of {n.ident} never crossed "
                  f"on course {course:.0f}°T; flown {b.params.manual_leg_m / 1852:.0f} NM")
        along = b.params.manual_leg_m
    else:
        along = hit[0]
    s = b.straight(s, course, along)
    s = replace(s, flyby=False, fix_ident="")
    return s, Termination("radial", s.lat_deg, s.lon_deg, radial_deg=radial,
                          navaid_lat_deg=n.lat_deg, navaid_lon_deg=n.lon_deg)


def _manual(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    s = b.straight(s, course, b.params.manual_leg_m)
    s = replace(s, flyby=False, fix_ident="")
    return s, Termination("manual", s.lat_deg, s.lon_deg, distance_m=b.params.manual_leg_m)


def _intercept(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    nxt = b.next_leg
    tgt = LEG_TYPES[nxt.pt].target(nxt) if nxt is not None else None
    along = None
    if tgt is not None and tgt[0] == "line":
        hit = ray_geodesic_intersection(s.lat_deg, s.lon_deg, course, tgt[1], tgt[2], tgt[3])
        if hit is not None and (hit[1] < 0 or not tgt[4]):
            along = hit[0]
    elif tgt is not None:
        along = ray_circle_distance(s.lat_deg, s.lon_deg, course, tgt[1], tgt[2], tgt[3])
    if along is None:
        what = f"{nxt.pt} {nxt.fix.ident if nxt and nxt.fix else ''}" if nxt else "nothing"
        b.finding("no-intercept", f"course {course:.0f}°T never intercepts the next leg "
                  f"({what}) within 100 NM; the next leg joins from here")
        return replace(s, flyby=False, fix_ident=""), Termination(
            "intercept", s.lat_deg, s.lon_deg, next_leg=b.i + 1)
    s = b.straight(s, course, along)
    s = replace(s, flyby=True, fix_ident="")
    return s, Termination("intercept", s.lat_deg, s.lon_deg, next_leg=b.i + 1)


def _from_fix(b: LegBuilder, s: FlightState, direction: str | None = "coded"
              ) -> tuple[FlightState, float]:
    """Get to the leg's fix (direct, turning the coded way) and onto its course from there.

    The coded turn direction applies to the first turn of the leg: the turn toward the fix when
    the aircraft is elsewhere, else the turn onto the course at the fix."""
    f, c = _fix(b), _course(b)
    d = b.turn_dir() if direction == "coded" else direction
    if s.track_deg is None:
        s = replace(b.fix_state(s, f), track_deg=c)
    elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
        s = b.direct_to(s, f, d, not b.leg.rec.fly_over)
        s = b.fix_state(s, f)
        d = None
    return b.start_course(s, c, d), c


class _CourseLeg(Leg):
    """Course (C*) or heading (V*) from the present position to a condition."""

    end = staticmethod(_climb_to)

    @classmethod
    def build(cls, b, s):
        c = _course(b)
        s = b.start_course(s, c, b.turn_dir())
        return cls.end(b, s, c)


class CA(_CourseLeg):
    """Course to altitude."""

    code = "CA"
    end = staticmethod(_climb_to)


class VA(CA):
    """Heading to altitude (heading = course with no wind at build time)."""

    code = "VA"


class CD(_CourseLeg):
    """Course to DME distance."""

    code = "CD"
    end = staticmethod(_to_dme)


class VD(CD):
    """Heading to DME distance."""

    code = "VD"


class CR(_CourseLeg):
    """Course to radial."""

    code = "CR"
    end = staticmethod(_to_radial)


class VR(CR):
    """Heading to radial."""

    code = "VR"


class CI(_CourseLeg):
    """Course to intercept the next leg."""

    code = "CI"
    end = staticmethod(_intercept)


class VI(CI):
    """Heading to intercept the next leg."""

    code = "VI"


class VM(_CourseLeg):
    """Heading to manual termination."""

    code = "VM"
    end = staticmethod(_manual)


class _FixCourseLeg(Leg):
    """From the fix along the coded course to a condition."""

    end = staticmethod(_climb_to)

    @classmethod
    def build(cls, b, s):
        s, c = _from_fix(b, s)
        return cls.end(b, s, c)

    @classmethod
    def target(cls, leg):
        if leg.fix is None or leg.course_true_deg is None:
            return None
        return ("line", leg.fix.lat_deg, leg.fix.lon_deg, leg.course_true_deg, False)


class FA(_FixCourseLeg):
    """Fix to altitude."""

    code = "FA"
    end = staticmethod(_climb_to)


class FD(_FixCourseLeg):
    """Fix to DME distance."""

    code = "FD"
    end = staticmethod(_to_dme)


class FM(_FixCourseLeg):
    """Fix to manual termination."""

    code = "FM"
    end = staticmethod(_manual)


class FC(_FixCourseLeg):
    """Track from the fix for the coded distance."""

    code = "FC"

    @classmethod
    def build(cls, b, s):
        s, c = _from_fix(b, s)
        d = b.leg.rec.distance_m
        if d is None:
            raise LegError("FC leg without a distance (column 75)")
        s = b.straight(s, c, d)
        s = replace(s, flyby=True, fix_ident="")
        return s, Termination("distance", s.lat_deg, s.lon_deg, distance_m=d)


# --------------------------------------------------------------------------- holds, PI
def _timed_speed(b: LegBuilder) -> float:
    """Speed for timed legs: the coded speed limit's planned speed, else 210 kt."""
    return b.speed_mps if b.leg.rec.speed_limit_mps else b.params.timed_speed_mps


def _hold_leg_m(b: LegBuilder, alt_m: float) -> float:
    """Outbound leg of a hold, m: the coded distance, else the coded time (default 1 min at or
    below 14,000 ft, 1.5 min above) at the timed-leg speed."""
    rec = b.leg.rec
    if rec.distance_m is not None:
        return rec.distance_m
    t = rec.time_s if rec.time_s is not None else (60.0 if alt_m <= 14000 * 0.3048 else 90.0)
    return t * _timed_speed(b)


def _circuit(b: LegBuilder, s: FlightState, f, inbound: float, d: str, leg_m: float
             ) -> FlightState:
    """One racetrack circuit from over the fix on the inbound course: outbound turn, outbound
    leg, inbound turn, inbound leg back to the fix."""
    arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, wrap360(inbound + 180.0), d,
                         b.radius_m)
    if arc is not None:
        s = b.arc(s, arc, role="hold")
    s = b.straight(s, s.track_deg, leg_m)
    arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, inbound, d, b.radius_m)
    if arc is not None:
        s = b.arc(s, arc, role="hold")
    return b.direct_to(s, f, None, False)


def _entry(b: LegBuilder, s: FlightState, f, inbound: float, d: str, leg_m: float
           ) -> FlightState:
    """Hold entry from the arrival track: direct entry when arriving within 90° of the inbound
    course, else a teardrop (outbound 30° off the reciprocal toward the holding side), ending
    over the fix on the inbound course."""
    if s.track_deg is None or abs(wrap180(s.track_deg - inbound)) <= 90.0:
        return s
    sign = 1.0 if d == "R" else -1.0
    tear = wrap360(inbound + 180.0 - 30.0 * sign)
    arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, tear, None, b.radius_m)
    if arc is not None:
        s = b.arc(s, arc, role="hold")
    s = b.straight(s, s.track_deg, leg_m)
    arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, inbound, d, b.radius_m)
    if arc is not None:
        s = b.arc(s, arc, role="hold")
    s = b.direct_to(s, f, None, False)
    return replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg)


class _Hold(Leg):
    @classmethod
    def _enter(cls, b, s):
        f, c = _fix(b), _course(b)
        if s.track_deg is None:
            s = replace(b.fix_state(s, f), track_deg=c)
        elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
            s = b.direct_to(s, f, None, False)
        s = replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg)
        d = b.turn_dir() or "R"
        s = _entry(b, s, f, c, d, _hold_leg_m(b, s.alt_m))
        return s, f, c, d


class HM(_Hold):
    """Hold to manual termination: one circuit drawn; the crew ends it."""

    code = "HM"

    @classmethod
    def build(cls, b, s):
        s, f, c, d = cls._enter(b, s)
        s = _circuit(b, s, f, c, d, _hold_leg_m(b, s.alt_m))
        return b.fix_state(s, f), Termination("manual", f.lat_deg, f.lon_deg, fix_ident=f.ident)


class HF(_Hold):
    """Hold to fix: one circuit, leaving over the fix."""

    code = "HF"

    @classmethod
    def build(cls, b, s):
        s, f, c, d = cls._enter(b, s)
        s = _circuit(b, s, f, c, d, _hold_leg_m(b, s.alt_m))
        return replace(b.fix_state(s, f), flyby=False), Termination(
            "circuit", f.lat_deg, f.lon_deg, fix_ident=f.ident)


class HA(_Hold):
    """Hold to altitude: as many circuits as the climb needs (bounded), leaving over the fix."""

    code = "HA"
    MAX_CIRCUITS = 10

    @classmethod
    def build(cls, b, s):
        s, f, c, d = cls._enter(b, s)
        alt = _alt(b)
        leg_m = _hold_leg_m(b, s.alt_m)
        n = 0
        while n < 1 or (s.alt_m < alt - 0.5 and b.climbing):
            if n >= cls.MAX_CIRCUITS:
                b.finding("impossible", f"altitude {alt / 0.3048:.0f} ft not reached after "
                          f"{cls.MAX_CIRCUITS} hold circuits")
                break
            s = _circuit(b, s, f, c, d, leg_m)
            n += 1
        s = replace(s, alt_m=max(s.alt_m, alt))
        return replace(b.fix_state(s, f), flyby=False), Termination(
            "altitude", f.lat_deg, f.lon_deg, fix_ident=f.ident, alt_m=alt)


class PI(Leg):
    """Procedure turn (45°/180°): outbound from the fix, 45° turn the coded way, one minute,
    180° turn the other way, and a 45° intercept of the inbound course (next leg)."""

    code = "PI"
    OUTBOUND_MIN_M = 4.3 * 1852.0

    @classmethod
    def build(cls, b, s):
        s = replace(s, flyby=False)   # a course reversal starts over its fix
        s, c = _from_fix(b, s, None)  # the coded direction is the procedure turn's
        d = b.turn_dir() or "L"
        sign = 1.0 if d == "R" else -1.0
        limit = b.leg.rec.distance_m or 10 * 1852.0
        out_m = max(cls.OUTBOUND_MIN_M - 2.0 * b.radius_m, 0.25 * limit - b.radius_m, 1852.0)
        s = b.straight(s, c, out_m)
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, c + 45.0 * sign, d, b.radius_m)
        s = b.arc(s, arc)
        s = b.straight(s, s.track_deg, 60.0 * _timed_speed(b))
        other = "L" if d == "R" else "R"
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg,
                             wrap360(c + 45.0 * sign + 180.0), other, b.radius_m)
        s = b.arc(s, arc)
        s = replace(s, flyby=False, fix_ident="")
        return s, Termination("intercept", s.lat_deg, s.lon_deg, next_leg=b.i + 1)


#: The table from path terminator to its class: all 23.
LEG_TYPES: dict[str, type[Leg]] = {cls.code: cls for cls in (
    IF, TF, CF, DF, FA, FC, FD, FM, CA, CD, CI, CR, RF, AF, VA, VD, VI, VM, VR, HA, HF, HM, PI)}

