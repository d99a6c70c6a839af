"""Fix-terminated legs: IF, TF, CF, DF and the coded arcs RF and AF.

Each ends at its database fix (``ends_at_fix``). TF, CF, RF and AF have a coded path (the
track between the fixes, the course into the fix, the arc of the coded radius about the centre
fix, the DME arc at rho); DF is flown from wherever the aircraft is and IF is a point, so they
have none (see :attr:`~.base.Leg.pde_reference`).
"""

from __future__ import annotations

from dataclasses import replace

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import NM_M
from fms_testbed.legs.base import (Leg, LegError, course_of, dme_position, fix_course,
                                   fix_of, fix_termination, navaid_of)
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.coded import CodedCircle, course_into, track_between
from fms_testbed.legs.model import FlightState


class IF(Leg):
    """Initial fix: the path starts (or restarts, with a discontinuity) at the fix."""

    code = "IF"
    ends_at_fix = True
    initial = True

    @classmethod
    def build(cls, b, s):
        f = fix_of(b)
        if s.track_deg is not None or b.segments:
            s = b.connect(s, f.lat_deg, f.lon_deg, f"IF {f.ident} away from the previous leg")
        return b.fix_state(s, f), fix_termination(f)


class TF(Leg):
    """Track to fix: the great-circle track from the previous fix to this one."""

    code = "TF"
    ends_at_fix = True
    track_to_fix = True
    pde_reference = "the geodesic from the previous leg's fix to the fix"

    @classmethod
    def build(cls, b, s):
        f = fix_of(b)
        prev = b.prev_fixes[b.i]
        if prev is None or s.fix_ident != prev.ident:
            if prev is not None and s.track_deg is not None:
                _, az1, az2 = inverse(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
                s = b.join_course(s, f, az2, b.turn_dir(), not b.leg.rec.fly_over)
                return b.fix_state(s, f), fix_termination(f)
            s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)
            return b.fix_state(s, f), fix_termination(f)
        if b.can_cut(s, inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[1], b.turn_dir()):
            s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)   # fly-by corner
        else:  # over the previous fix (or after an arc): turn and rejoin the TF track
            _, _, az2 = inverse(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
            s = b.join_course(s, f, az2, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), fix_termination(f)

    @classmethod
    def coded_path(cls, b, term):
        prev, f = b.prev_fixes[b.i], b.leg.fix
        if prev is None or f is None:
            return None  # a TF after a leg that ends nowhere coded has no coded track
        return track_between(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)


class CF(Leg):
    """Course to fix: join the coded course into the fix and fly it."""

    code = "CF"
    ends_at_fix = True
    track_to_fix = True
    pde_reference = "the geodesic into the fix on the coded course"

    @classmethod
    def build(cls, b, s):
        f, c = fix_of(b), course_of(b)
        if s.track_deg is None:
            s = replace(s, track_deg=c)
        s = b.join_course(s, f, c, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), fix_termination(f)

    @classmethod
    def target(cls, leg):
        fc = fix_course(leg)
        return None if fc is None else ("line", *fc, True)

    @classmethod
    def coded_path(cls, b, term):
        fc = fix_course(b.leg)
        return None if fc is None else course_into(*fc)


class DF(Leg):
    """Direct to fix from wherever the previous leg ended, turning the coded way.

    No coded path: the record codes only the fix, the track starts wherever the aircraft is
    (ARINC-424: an unspecified track from an undefined position), so the built direct track
    is the definition and its PDE would be zero by construction — it is NaN."""

    code = "DF"
    ends_at_fix = True
    track_to_fix = True
    direct_to = True

    @classmethod
    def build(cls, b, s):
        f = fix_of(b)
        s = b.direct_to(s, f, b.turn_dir(), not b.leg.rec.fly_over)
        return b.fix_state(s, f), fix_termination(f)


def _corner_onto(b: LegBuilder, s: FlightState, arc: Arc) -> None:
    """Mark a non-tangent entry onto a coded arc as a fly-by corner when the state allows it
    (the segmentation then fits a line-to-arc fillet)."""
    if b.segments and isinstance(b.segments[-1].geom, Line) and \
            b.can_cut(s, arc.start_course_deg, None) and \
            abs(wrap180(arc.start_course_deg - s.track_deg)) >= 0.5:
        b._corner_pending = True


def _arc_to_fix(b: LegBuilder, s: FlightState, clat: float, clon: float, f, why: str
                ) -> FlightState:
    """The arc about (clat, clon) from the radial of the present position to the fix, at the
    fix's range, the coded way; a gap to the arc is bridged with a connector."""
    d = b.turn_dir()
    if d is None:
        raise LegError(f"{b.leg.pt} leg without a turn direction (column 44)")
    r_end, rad_end, _ = inverse(clat, clon, f.lat_deg, f.lon_deg)
    _, rad_start, _ = inverse(clat, clon, s.lat_deg, s.lon_deg)
    start_pt = direct(clat, clon, rad_start, r_end)
    s = b.connect(s, start_pt[0], start_pt[1], why)
    sweep = wrap360(rad_end - rad_start) if d == "R" else -wrap360(rad_start - rad_end)
    if abs(sweep) > 0.01:
        arc = Arc(clat, clon, r_end, rad_start, sweep)
        _corner_onto(b, s, arc)
        s = b.arc(s, arc, role="leg")
    return b.fix_state(replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg), f)


class RF(Leg):
    """Constant-radius arc about the coded centre fix, in the coded direction, to the fix."""

    code = "RF"
    ends_at_fix = True
    arc_centre = "fix"
    radius_tol_m = 0.05 * NM_M
    """The FAA data agree with the coded radius within 0.049 NM at every RF end."""
    pde_reference = "the circle of the coded radius (col. 57-62) about the centre fix"

    @classmethod
    def build(cls, b, s):
        f, c = fix_of(b), b.leg.centre
        if c is None:
            raise LegError("RF leg without a centre fix (column 107)")
        if b.turn_dir() is None:
            raise LegError("RF leg without a turn direction (column 44)")
        return _arc_to_fix(b, s, c.lat_deg, c.lon_deg, f, "RF start not on the arc"), \
            fix_termination(f)

    @classmethod
    def coded_radius_m(cls, rec):
        return rec.arc_radius_m

    @classmethod
    def coded_path(cls, b, term):
        c, r = b.leg.centre, b.leg.rec.arc_radius_m
        if c is None or not r:
            return None
        return CodedCircle(c.lat_deg, c.lon_deg, r)


class AF(Leg):
    """Arc to fix: DME arc about the recommended navaid, coded direction, ending at the fix.

    Flown at the fix's range from the DME; the coded path is the arc at rho, so the PDE is the
    difference of the two (the FAA data: median 0.025 NM, up to 0.6 NM)."""

    code = "AF"
    ends_at_fix = True
    arc_centre = "navaid"
    radius_tol_m = 0.6 * NM_M
    pde_reference = "the circle of rho (col. 67-70) about the recommended navaid's DME"

    @classmethod
    def build(cls, b, s):
        f, n = fix_of(b), navaid_of(b)
        nlat, nlon = dme_position(n)
        return _arc_to_fix(b, s, nlat, nlon, f, "AF start not on the DME arc"), \
            fix_termination(f)

    @classmethod
    def target(cls, leg):
        if leg.navaid is None or (leg.rec.rho_m is None and leg.fix is None):
            return None
        lat, lon = dme_position(leg.navaid)
        r = leg.rec.rho_m   # the arc is flown at the fix's range (see build): intercept that
        if leg.fix is not None:
            r = inverse(lat, lon, leg.fix.lat_deg, leg.fix.lon_deg)[0]
        return ("circle", lat, lon, r)

    @classmethod
    def coded_radius_m(cls, rec):
        return rec.rho_m

    @classmethod
    def coded_path(cls, b, term):
        n, r = b.leg.navaid, b.leg.rec.rho_m
        if n is None or not r:
            return None
        return CodedCircle(*dme_position(n), r)
