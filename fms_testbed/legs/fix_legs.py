"""Fix-terminated legs: IF, TF, CF, DF and the coded arcs RF and AF.

Each ends at its database fix (``ends_at_fix``). TF, CF, RF and AF have a coded path (the
track between the fixes, the course into the fix, the arc of the coded radius about the centre
fix, the DME arc at rho); DF is flown from wherever the aircraft is and IF is a point, so they
have none (see :attr:`~.base.Leg.pde_reference`).
"""

from __future__ import annotations

import math
from dataclasses import replace

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import NM_M
from fms_testbed.legs.base import (LEG_TYPES, Leg, LegError, course_of, dme_position, fix_course,
                                   fix_of, fix_termination, navaid_of)
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.coded import CodedCircle, course_into, track_between
from fms_testbed.legs.construct import centre_through
from fms_testbed.legs.model import FlightState
from fms_testbed.procedures.records import Fix
from fms_testbed.legs.moves import (can_cut, commit, connect, direct_to, fix_state, join_course,
                                    join_from_fix, trial, turn_dir)


class IF(Leg):
    """Initial fix: the path starts (or restarts, with a discontinuity) at the fix."""

    code = "IF"
    ends_at_fix = True
    initial = True

    @classmethod
    def build(cls, b, s):
        f = fix_of(b)
        prev = b.legs[b.i - 1] if b.i > 0 else None
        nxt = b.next_leg
        if prev is not None and prev.pt == "PI" and nxt is not None and nxt.pt == "CF" \
                and nxt.course_true_deg is not None and s.track_deg is not None:
            # the final's IF after a procedure turn lies on the inbound course the turn
            # intercepts: join that course through the IF (no direct-to onto it)
            s = join_course(b, s, f, nxt.course_true_deg, None, not b.leg.rec.fly_over)
        elif prev is not None and LEG_TYPES[prev.pt].manual_end:
            # vectors: after a manual termination the coded route resumes at the IF, flown
            # as a direct-to (the record's intent, not a gap in the coding)
            s = connect(b, s, f.lat_deg, f.lon_deg,
                        f"direct to IF {f.ident} after the manual termination of {prev.pt}", "info")
        elif s.track_deg is not None or b.segments:
            s = connect(b, s, f.lat_deg, f.lon_deg, f"IF {f.ident} away from the previous leg")
        return fix_state(b, s, f), fix_termination(f)


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
                s = join_course(b, s, f, az2, turn_dir(b), not b.leg.rec.fly_over)
                return fix_state(b, s, f), fix_termination(f)
            s = direct_to(b, s, f, turn_dir(b), not b.leg.rec.fly_over)
            return fix_state(b, s, f), fix_termination(f)
        if can_cut(b, s, inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[1], turn_dir(b)):
            s = direct_to(b, s, f, turn_dir(b), not b.leg.rec.fly_over)   # fly-by corner
        else:  # over the previous fix: turn there and rejoin the TF track out of it
            length, az1, az2 = inverse(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
            n0 = len(b.segments)
            s1 = join_from_fix(b, s, prev, az1, turn_dir(b), max_along_m=length)
            if s1 is not None:
                b.as_transition(n0)
                s = b.line_to(s1, f.lat_deg, f.lon_deg, f.ident, not b.leg.rec.fly_over)
            else:   # the track is too short to rejoin after the turn: join it upstream of f
                s = join_course(b, s, f, az2, turn_dir(b), not b.leg.rec.fly_over)
        return fix_state(b, s, f), fix_termination(f)

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
    course_to_fix = True
    pde_reference = "the geodesic into the fix on the coded course"

    @classmethod
    def build(cls, b, s):
        f, c = fix_of(b), course_of(b)
        if s.track_deg is None:
            s = replace(s, track_deg=c)
        s = join_course(b, s, f, c, turn_dir(b), not b.leg.rec.fly_over, course_leg=True)
        return fix_state(b, s, f), fix_termination(f)

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
        s = direct_to(b, s, f, turn_dir(b), not b.leg.rec.fly_over)
        return fix_state(b, s, f), fix_termination(f)


def _corner_onto(b: LegBuilder, s: FlightState, arc: Arc) -> None:
    """Mark a non-tangent entry onto a coded arc as a fly-by corner when the state allows it
    (the segmentation then fits a line-to-arc fillet)."""
    if b.segments and isinstance(b.segments[-1].geom, Line) and \
            can_cut(b, s, arc.start_course_deg, None) and \
            abs(wrap180(arc.start_course_deg - s.track_deg)) >= 0.5:
        b._corner_pending = True


def _arc_to_fix(b: LegBuilder, s: FlightState, clat: float, clon: float, f, why: str
                ) -> FlightState:
    """The arc about (clat, clon) from the radial of the present position to the fix, the coded
    way.

    The present position usually lies a little off the circle through the fix (an IF at a
    range that differs from the end fix's, the previous fix a few metres off an RF's radius:
    up to ~0.4 NM in the FAA data). A gap shorter than the turn anticipation a connector would
    need (its ±90° turns: one planned turn radius) and than a quarter of the arc radius is
    closed in the geometry: the arc is the circle through the present position and the fix
    whose centre is nearest the coded one (:func:`~.construct.centre_through`), so it starts
    where the aircraft is, ends at the fix and is never flown as a direct-to. A larger gap is
    a discontinuity, bridged by :meth:`~.builder.LegBuilder.connect` to the arc at the fix's
    range on the present radial."""
    d = turn_dir(b)
    if d is None:
        raise LegError(f"{b.leg.pt} leg without a turn direction (column 44)")
    r_end, rad_end, _ = inverse(clat, clon, f.lat_deg, f.lon_deg)
    r_now, rad_start, _ = inverse(clat, clon, s.lat_deg, s.lon_deg)
    gap = abs(r_now - r_end)
    if 0.01 < gap < min(b.radius_m, 0.25 * r_end):
        clat, clon, r_end = centre_through(s.pos, (f.lat_deg, f.lon_deg), (clat, clon))
        _, rad_end, _ = inverse(clat, clon, f.lat_deg, f.lon_deg)
        _, rad_start, _ = inverse(clat, clon, s.lat_deg, s.lon_deg)
    else:
        start_pt = direct(clat, clon, rad_start, r_end)
        s = connect(b, s, start_pt[0], start_pt[1], why)
    sweep = wrap360(rad_end - rad_start) if d == "R" else -wrap360(rad_start - rad_end)
    if abs(sweep) > 0.01:
        arc = Arc(clat, clon, r_end, rad_start, sweep)
        if _too_sharp(b, s, arc):
            return _join_arc_ahead(b, s, arc, f)
        _corner_onto(b, s, arc)
        s = b.arc(s, arc, role="leg")
    return fix_state(b, replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg), f)


ARC_JOIN_DEG = 60.0
"""An arc entered at a corner too sharp for a fly-by is joined this far round it (at most 60 %
of its sweep), deg: the chord from its start meets the arc there at half that angle."""


def _too_sharp(b: LegBuilder, s: FlightState, arc: Arc) -> bool:
    """True when the corner from the present track onto a coded arc (more than 20°) cannot be
    rounded: the fly-by's lead R tan(Δ/2) exceeds the straight before it (or no straight)."""
    if s.track_deg is None:
        return False
    delta = abs(wrap180(arc.start_course_deg - s.track_deg))
    if delta <= 20.0:
        return False
    last = b.segments[-1].geom if b.segments else None
    room = last.length_m() if isinstance(last, Line) and can_cut(b, s, arc.start_course_deg,
                                                                      None) else 0.0
    return b.radius_m * math.tan(math.radians(min(delta, 179.0)) / 2.0) > 0.9 * room


def _join_arc_ahead(b: LegBuilder, s: FlightState, arc: Arc, f) -> FlightState:
    """Enter a coded arc whose start corner is too sharp (class 1: the planned radius does not
    fit): over its start, a direct-to (role 'turn') to a point Q round the arc, then a fly-by
    onto the arc there and the rest of the arc to the fix. Q is tried at
    :data:`ARC_JOIN_DEG`, then 30° steps further round (at most 80 % of the sweep), until the
    corner at Q, as the direct-to arrives there, fits its fly-by. A finding says so."""
    n0 = len(b.segments)
    for theta in (ARC_JOIN_DEG, 90.0, 120.0, 150.0):
        theta = min(theta, 0.8 * abs(arc.sweep_deg))
        t = trial(b)      # a candidate join point Q: kept when its corner fits
        rad_q = arc.start_radial_deg + math.copysign(theta, arc.sweep_deg)
        qlat, qlon, _ = direct(arc.centre_lat_deg, arc.centre_lon_deg, rad_q, arc.radius_m)
        target = Fix(ident="", region="", section="", lat_deg=qlat, lon_deg=qlon)
        st = direct_to(t, replace(s, flyby=False), target, None, True)
        rest = Arc(arc.centre_lat_deg, arc.centre_lon_deg, arc.radius_m, rad_q,
                   arc.sweep_deg - math.copysign(theta, arc.sweep_deg))
        if not _too_sharp(t, replace(st, flyby=True), rest) or \
                theta >= 0.8 * abs(arc.sweep_deg):
            break
    commit(b, t)
    b.finding("info", f"{b.leg.pt} entered {abs(wrap180(arc.start_course_deg - s.track_deg)):.0f}"
              f"° off its tangent: too sharp for a fly-by at {b.radius_m:.0f} m; the arc is "
              f"joined {theta:.0f}° round it")
    b.as_transition(n0)
    st = replace(st, flyby=True)
    _corner_onto(b, st, rest)
    st = b.arc(st, rest, role="leg")
    return fix_state(b, replace(st, lat_deg=f.lat_deg, lon_deg=f.lon_deg), f)


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
        if turn_dir(b) is None:
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
