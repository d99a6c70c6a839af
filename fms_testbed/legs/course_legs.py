"""Course and heading legs to a condition: C* and V* from the present position, F* from a fix.

CA/CD/CR/CI/VA/VD/VR/VI/VM fly the coded course (C*) or heading (V*; the course with no wind
at build time) from wherever the previous leg ended; FA/FC/FD/FM fly the coded course out of
their fix. They end where the planned aircraft meets the condition: altitude from the climb
gradient at the planned speed, DME distance and radial by bounded ray intersection, intercepts
against the next leg's path, manual terminations after ``BuildParams.manual_leg_m``, FC after
its coded distance.

Coded path (for PDE): the F* legs' course line out of the fix. The C*/V* legs start wherever the
aircraft is, so the record codes a direction, not a path: no PDE.
"""

from __future__ import annotations

from dataclasses import replace

from fms_testbed.core.geodesy import inverse, wrap360
from fms_testbed.core.units import NM_M
from fms_testbed.legs.base import (LEG_TYPES, Leg, LegError, altitude_of, course_of,
                                   dme_position, fix_course, fix_of, navaid_of)
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.coded import course_from
from fms_testbed.legs.construct import ray_circle_distance, ray_geodesic_intersection
from fms_testbed.core.segments import Line
from fms_testbed.legs.model import FlightState, Termination, drift_track_deg
from fms_testbed.legs.moves import (altitude_distance_m, direct_to, fix_state, join_from_fix,
                                    start_course, turn_dir)


def _climb_to(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    alt = altitude_of(b)
    dist = altitude_distance_m(b, s, alt)
    s = b.straight(s, course, dist)
    s = replace(s, alt_m=max(s.alt_m, alt), flyby=False, fix_ident="")
    return s, Termination("altitude", s.lat_deg, s.lon_deg, alt_m=alt)


def _to_dme(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    n = navaid_of(b)
    dist = b.leg.rec.distance_m
    if dist is None:
        raise LegError(f"{b.leg.pt} leg without a DME distance (column 75)")
    nlat, nlon = dme_position(n)
    along = ray_circle_distance(s.lat_deg, s.lon_deg, course, nlat, nlon, dist)
    if along is None:
        b.finding("no-intercept", f"DME {dist / NM_M:.1f} NM from {n.ident} never reached on "
                  f"course {course:.0f}°T; flown {b.params.manual_leg_m / NM_M:.0f} NM")
        along = b.params.manual_leg_m
    s = b.straight(s, course, along)
    s = replace(s, flyby=False, fix_ident="")
    return s, Termination("dme", s.lat_deg, s.lon_deg, dme_m=dist, navaid_lat_deg=nlat,
                          navaid_lon_deg=nlon)


def _to_radial(b: LegBuilder, s: FlightState, course: float) -> tuple[FlightState, Termination]:
    n = navaid_of(b)
    if b.leg.rec.theta_deg is None:
        raise LegError(f"{b.leg.pt} leg without a radial (theta, column 63)")
    radial = wrap360(b.leg.rec.theta_deg + n.magvar_deg)
    hit = ray_geodesic_intersection(s.lat_deg, s.lon_deg, course, n.lat_deg, n.lon_deg, radial)
    if hit is None or hit[1] < 0:
        b.finding("no-intercept", f"radial {b.leg.rec.theta_deg:.0f} of {n.ident} never crossed "
                  f"on course {course:.0f}°T; flown {b.params.manual_leg_m / NM_M:.0f} NM")
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


def from_fix(b: LegBuilder, s: FlightState, direction: str | None = "coded"
             ) -> tuple[FlightState, float]:
    """Get to the leg's fix (direct, turning the coded way) and onto its course from there.

    The coded turn direction applies to the first turn of the leg: the turn toward the fix when
    the aircraft is elsewhere, else the turn onto the course at the fix. The way to the fix is
    a transition onto the leg's coded path (role 'turn', no PDE); a turn flown over the fix
    rejoins the coded course line (:meth:`~.builder.LegBuilder.join_from_fix`)."""
    f, c = fix_of(b), course_of(b)
    d = turn_dir(b) if direction == "coded" else direction
    if s.track_deg is None:
        s = replace(fix_state(b, s, f), track_deg=c)
    elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
        n0 = len(b.segments)
        s = direct_to(b, s, f, d, not b.leg.rec.fly_over)
        b.as_transition(n0)
        s = fix_state(b, s, f)
        d = None
    return join_from_fix(b, s, f, c, d), c


# --------------------------------------------------------------------------- C*, V*
class _CourseLeg(Leg):
    """Course (C*) or heading (V*) from the present position to a condition.

    A heading leg is built along the ground track its coded heading gives in the planned wind
    (:func:`~.model.drift_track_deg`: the drift is predicted, Danilin's current conditions), and
    its straights carry the heading to hold (``PathSegment.heading_deg``)."""

    end = staticmethod(_climb_to)

    @classmethod
    def build(cls, b, s):
        c = course_of(b)
        if not cls.heading_leg:
            s = start_course(b, s, c, turn_dir(b))
            return cls.end(b, s, c)
        trk = drift_track_deg(c, b.speed_mps, b.params.wind_speed_mps, b.params.wind_from_deg)
        n0 = len(b.segments)
        s = start_course(b, s, trk, turn_dir(b))
        s, term = cls.end(b, s, trk)
        for k in range(n0, len(b.segments)):
            sg = b.segments[k]
            if sg.role == "leg" and isinstance(sg.geom, Line):
                b.segments[k] = replace(sg, heading_deg=c)
        return s, term


class CA(_CourseLeg):
    """Course to altitude."""

    code = "CA"
    conditional = True
    altitude_terminated = True
    end = staticmethod(_climb_to)


class VA(CA):
    """Heading to altitude (heading = course with no wind at build time)."""

    code = "VA"
    heading_leg = True


class CD(_CourseLeg):
    """Course to DME distance."""

    code = "CD"
    conditional = True
    end = staticmethod(_to_dme)


class VD(CD):
    """Heading to DME distance."""

    code = "VD"
    heading_leg = True


class CR(_CourseLeg):
    """Course to radial."""

    code = "CR"
    conditional = True
    end = staticmethod(_to_radial)


class VR(CR):
    """Heading to radial."""

    code = "VR"
    heading_leg = True


class CI(_CourseLeg):
    """Course to intercept the next leg (ends where the built course meets it: no in-flight
    condition)."""

    code = "CI"
    end = staticmethod(_intercept)


class VI(CI):
    """Heading to intercept the next leg."""

    code = "VI"
    heading_leg = True


class VM(_CourseLeg):
    """Heading to manual termination."""

    code = "VM"
    heading_leg = True
    manual_end = True
    end = staticmethod(_manual)


# --------------------------------------------------------------------------- F*
class _FixCourseLeg(Leg):
    """From the fix along the coded course to a condition."""

    end = staticmethod(_climb_to)
    pde_reference = "the geodesic out of the fix on the coded course"

    @classmethod
    def build(cls, b, s):
        s, c = from_fix(b, s)
        return cls.end(b, s, c)

    @classmethod
    def target(cls, leg):
        fc = fix_course(leg)
        return None if fc is None else ("line", *fc, False)

    @classmethod
    def coded_path(cls, b, term):
        fc = fix_course(b.leg)
        return None if fc is None else course_from(*fc)


class FA(_FixCourseLeg):
    """Fix to altitude."""

    code = "FA"
    conditional = True
    altitude_terminated = True
    end = staticmethod(_climb_to)


class FD(_FixCourseLeg):
    """Fix to DME distance."""

    code = "FD"
    conditional = True
    end = staticmethod(_to_dme)


class FM(_FixCourseLeg):
    """Fix to manual termination."""

    code = "FM"
    manual_end = True
    end = staticmethod(_manual)


class FC(_FixCourseLeg):
    """Track from the fix for the coded distance."""

    code = "FC"

    @classmethod
    def build(cls, b, s):
        s, c = from_fix(b, s)
        d = b.leg.rec.distance_m
        if d is None:
            raise LegError("FC leg without a distance (column 75)")
        s = b.straight(s, c, d)
        s = replace(s, flyby=True, fix_ident="")
        return s, Termination("distance", s.lat_deg, s.lon_deg, distance_m=d)
