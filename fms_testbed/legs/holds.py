"""Course reversals: the racetrack holds HA, HF, HM and the procedure turn PI.

A hold is entered from the arrival track (direct entry within 90° of the inbound course, else a
teardrop), then flown as racetrack circuits over the fix on the coded inbound course: outbound
turn, outbound leg (coded distance, else coded time — default 1 min at or below 14,000 ft,
1.5 min above — at the timed-leg speed), inbound turn, inbound leg back to the fix. The way to
the fix and the entry are transitions onto the racetrack (role 'turn'); the circuits are the
leg's coded path (:class:`~.coded.Racetrack`, with the planned turn radius: ARINC-424 codes
none). The procedure turn is a manoeuvre of the aircraft's choosing within the protected area:
no coded path.
"""

from __future__ import annotations

from dataclasses import replace

from fms_testbed.core.geodesy import inverse, wrap180, wrap360
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.legs.base import Leg, altitude_of, course_of, fix_course, fix_of
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.coded import racetrack
from fms_testbed.legs.construct import turn_to_course
from fms_testbed.legs.course_legs import from_fix
from fms_testbed.legs.model import FlightState, Termination


def timed_speed_mps(b: LegBuilder) -> float:
    """Speed for timed legs: the coded speed limit's planned speed, else 210 kt, m/s."""
    return b.speed_mps if b.leg.rec.speed_limit_mps else b.params.timed_speed_mps


def hold_leg_m(b: LegBuilder, alt_m: float) -> float:
    """Outbound leg of a hold, m: the coded distance, else the coded time (default 1 min at or
    below 14,000 ft, 1.5 min above) at the timed-leg speed."""
    rec = b.leg.rec
    if rec.distance_m is not None:
        return rec.distance_m
    t = rec.time_s if rec.time_s is not None else (60.0 if alt_m <= 14000 * FT_M else 90.0)
    return t * timed_speed_mps(b)


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
    """A racetrack hold at the leg's fix on its coded inbound course."""

    ends_at_fix = True
    hold = True
    course_reversal = True
    pde_reference = ("the racetrack on the coded inbound course into the fix, coded turn "
                     "direction and leg length, planned turn radius")

    @classmethod
    def _enter(cls, b, s):
        """Get to the fix and through the entry; returns (state over the fix, fix, inbound
        course deg, turn direction, leg length m)."""
        f, c = fix_of(b), course_of(b)
        n0 = len(b.segments)
        if s.track_deg is None:
            s = replace(b.fix_state(s, f), track_deg=c)
        elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
            s = b.direct_to(s, f, None, False)
        s = replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg)
        d = b.turn_dir() or "R"
        s = _entry(b, s, f, c, d, hold_leg_m(b, s.alt_m))
        b.as_transition(n0)
        return s, f, c, d, hold_leg_m(b, s.alt_m)

    @classmethod
    def coded_path(cls, b, term):
        fc = fix_course(b.leg)
        if fc is None or not term.distance_m:
            return None
        return racetrack(*fc, b.turn_dir() or "R", term.distance_m, b.radius_m)


class HM(_Hold):
    """Hold to manual termination: one circuit drawn; the crew ends it."""

    code = "HM"

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m = cls._enter(b, s)
        s = _circuit(b, s, f, c, d, leg_m)
        return b.fix_state(s, f), Termination("manual", f.lat_deg, f.lon_deg, fix_ident=f.ident,
                                              distance_m=leg_m)


class HF(_Hold):
    """Hold to fix: one circuit, leaving over the fix."""

    code = "HF"

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m = cls._enter(b, s)
        s = _circuit(b, s, f, c, d, leg_m)
        return replace(b.fix_state(s, f), flyby=False), Termination(
            "circuit", f.lat_deg, f.lon_deg, fix_ident=f.ident, distance_m=leg_m)


class HA(_Hold):
    """Hold to altitude: as many circuits as the climb needs (bounded), leaving over the fix
    (guidance leaves it at the end of the first circuit flown with the altitude reached)."""

    code = "HA"
    altitude_terminated = True
    MAX_CIRCUITS = 10

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m = cls._enter(b, s)
        alt = altitude_of(b)
        n = 0
        while n < 1 or (s.alt_m < alt - 0.5 and b.climbing):
            if n >= cls.MAX_CIRCUITS:
                b.finding("impossible", f"altitude {alt / FT_M:.0f} ft not reached after "
                          f"{cls.MAX_CIRCUITS} hold circuits")
                break
            s = _circuit(b, s, f, c, d, leg_m)
            n += 1
        s = replace(s, alt_m=max(s.alt_m, alt))
        return replace(b.fix_state(s, f), flyby=False), Termination(
            "altitude", f.lat_deg, f.lon_deg, fix_ident=f.ident, alt_m=alt, distance_m=leg_m)


class PI(Leg):
    """Procedure turn (45°/180°): outbound from the fix, 45° turn the coded way, one minute,
    180° turn the other way, and a 45° intercept of the inbound course (next leg).

    No coded path: only the outbound course and the distance limit are coded; the turn is
    flown as the aircraft chooses within the protected area."""

    code = "PI"
    course_reversal = True
    OUTBOUND_MIN_M = 4.3 * NM_M

    @classmethod
    def build(cls, b, s):
        s = replace(s, flyby=False)   # a course reversal starts over its fix
        s, c = from_fix(b, s, None)   # the coded direction is the procedure turn's
        d = b.turn_dir() or "L"
        sign = 1.0 if d == "R" else -1.0
        limit = b.leg.rec.distance_m or 10 * NM_M
        out_m = max(cls.OUTBOUND_MIN_M - 2.0 * b.radius_m, 0.25 * limit - b.radius_m, NM_M)
        s = b.straight(s, c, out_m)
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, c + 45.0 * sign, d, b.radius_m)
        s = b.arc(s, arc)
        s = b.straight(s, s.track_deg, 60.0 * timed_speed_mps(b))
        other = "L" if d == "R" else "R"
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg,
                             wrap360(c + 45.0 * sign + 180.0), other, b.radius_m)
        s = b.arc(s, arc)
        s = replace(s, flyby=False, fix_ident="")
        return s, Termination("intercept", s.lat_deg, s.lon_deg, next_leg=b.i + 1)
