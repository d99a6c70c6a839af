"""The leg builder's moves: free functions of a :class:`~.builder.LegBuilder` that append
segments and findings and return the new :class:`~.model.FlightState`.

A move that tries something it may reject — an intercept that lands beyond the fix, an upstream
join point whose fly-by does not fit, the intercept angle of a rejoin — builds it as a
*candidate* on a trial copy of the builder (:func:`trial`: the segments so far, the corners,
the pending corner, no findings) and either keeps it (:func:`commit`: the candidate's segments,
corners and findings become the builder's) or drops it; nothing built is ever taken back. A
rejoin that would recurse gets its depth as an argument (``upstream``), not from a counter.

Moves: :func:`can_cut`, :func:`start_course`, :func:`direct_to`, :func:`join_course` (with
:func:`join_upstream` and :func:`direct_no_room`), :func:`join_from_fix`, :func:`connect`,
and the record helpers :func:`fix_state`, :func:`turn_dir`, :func:`altitude_distance_m`.
"""

from __future__ import annotations

import math
from dataclasses import replace

from fms_testbed.core.geodesy import direct, inverse, wrap180, wrap360
from fms_testbed.core.planning import DECEL_MPS2
from fms_testbed.core.segments import Arc, Line, turn_angle_deg
from fms_testbed.core.units import KT_MPS, NM_M
from fms_testbed.legs.builder import (CF_FROM_FIX_DEG, CF_FROM_FIX_TURN_MAX_DEG, CF_OFF_COURSE_DEG,
                                      CLOSE_S, DIRECT_XTK_M, PARALLEL_TOL_M, LegBuilder,
                                      intercept_angle_deg)
from fms_testbed.legs.construct import (_foot, direct_to_arc, ray_geodesic_intersection,
                                        turn_to_course)
from fms_testbed.legs.model import FlightState, isa_tas_mps, turn_radius_m
from fms_testbed.procedures.records import Fix

_STATE = ("i", "speed_mps", "radius_m", "climbing", "gradient", "alt_cap_m", "params",
          "params0", "leg_params", "leg_alt_m", "_corner_pending")


def trial(b: LegBuilder) -> LegBuilder:
    """A trial copy of ``b`` to build a candidate on: the same context and planned state, a
    copy of its segments and corners, no findings; ``b`` is not touched until
    :func:`commit`."""
    t = LegBuilder(b.legs, b.perf, b.params, b.g, b.prev_fixes)
    for name in _STATE:
        setattr(t, name, getattr(b, name))
    t.segments, t.corners = list(b.segments), set(b.corners)
    return t


def commit(b: LegBuilder, t: LegBuilder) -> None:
    """Keep the candidate built on ``t`` (:func:`trial` of ``b``): its segments, corners,
    pending corner and findings become ``b``'s."""
    b.segments, b.corners = t.segments, t.corners
    b._corner_pending = t._corner_pending
    b.findings.extend(t.findings)


def fix_state(b: LegBuilder, state: FlightState, fix: Fix) -> FlightState:
    """State placed at a fix with its fly-over/fly-by flag from the current record."""
    return FlightState(lat_deg=fix.lat_deg, lon_deg=fix.lon_deg, track_deg=state.track_deg,
                       alt_m=state.alt_m, flyby=not b.leg.rec.fly_over, fix_ident=fix.ident)


def turn_dir(b: LegBuilder) -> str | None:
    """Coded turn direction of the current leg ('L'/'R') or None."""
    d = b.leg.rec.turn_dir
    return d if d in ("L", "R") else None


def altitude_distance_m(b: LegBuilder, state: FlightState, alt_target_m: float) -> float:
    """Path distance to climb from the planned altitude to ``alt_target_m`` (m) at the
    planned gradient, m (0 when already there)."""
    dh = alt_target_m - state.alt_m
    return max(dh, 0.0) / max(b.gradient, 1e-3)


def can_cut(b: LegBuilder, state: FlightState, course_deg: float, direction: str | None
            ) -> bool:
    """True when the turn onto ``course_deg`` (deg true) at the present fix may be flown
    fly-by."""
    if state.track_deg is None or not state.flyby:
        return False
    if b.segments and isinstance(b.segments[-1].geom, Arc) and b.segments[-1].role != "leg":
        return False  # a turn's end is no corner: the next turn starts after it
    short = wrap180(course_deg - state.track_deg)
    if abs(short) > b.params.flyby_max_deg:
        return False
    if direction == "R" and short < -1.0 or direction == "L" and short > 1.0:
        return False  # coded direction the long way round: flown over the fix
    return True


def start_course(b: LegBuilder, state: FlightState, course_deg: float,
                 direction: str | None = None) -> FlightState:
    """Get onto ``course_deg`` (deg true) at the present position (fly-by corner or turn
    arc of the planned radius)."""
    if state.track_deg is None:
        return replace(state, track_deg=course_deg)
    if can_cut(b, state, course_deg, direction):
        b._corner_pending = abs(wrap180(course_deg - state.track_deg)) >= 0.5
        return replace(state, track_deg=course_deg)
    arc = turn_to_course(state.lat_deg, state.lon_deg, state.track_deg, course_deg,
                         direction, b.radius_m)
    if arc is None:
        return replace(state, track_deg=course_deg)
    return b.arc(state, arc)


def direct_to(b: LegBuilder, state: FlightState, fix: Fix, direction: str | None,
              flyby_end: bool) -> FlightState:
    """Turn toward a fix (bounded retries when it is inside the turn circle) and fly to it."""
    if state.track_deg is not None:
        s, az, _ = inverse(state.lat_deg, state.lon_deg, fix.lat_deg, fix.lon_deg)
        if s < 1.0:
            return replace(state, flyby=flyby_end, fix_ident=fix.ident)
        if can_cut(b, state, az, direction):
            b._corner_pending = abs(wrap180(az - state.track_deg)) >= 0.5
        else:
            for _ in range(b.params.max_iterations):
                arc, ok = direct_to_arc(state.lat_deg, state.lon_deg, state.track_deg,
                                        fix.lat_deg, fix.lon_deg, direction, b.radius_m)
                if ok:
                    if arc is not None:
                        state = b.arc(state, arc)
                    break
                state = b.straight(state, state.track_deg, 2.0 * b.radius_m)
            else:
                b.finding("no-intercept", f"cannot turn onto {fix.ident}: it stays "
                          "inside the turn circle; flown straight at it")
    return b.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)


def at_previous_fix(b: LegBuilder, state: FlightState) -> bool:
    """True when ``state`` lies over the fix the previous leg ended at (within 1 m)."""
    prev = b.prev_fixes[b.i] if b.i < len(b.prev_fixes) else None
    if prev is None or not state.fix_ident or state.fix_ident != prev.ident:
        return False
    return inverse(state.lat_deg, state.lon_deg, prev.lat_deg, prev.lon_deg)[0] <= 1.0


def _on_line(b: LegBuilder, state: FlightState, fix: Fix, fcrs: float, along: float,
             direction: str | None, flyby_end: bool) -> FlightState | None:
    """On the course line already (within :data:`DIRECT_XTK_M`) but heading elsewhere (the
    end of an intercept): turn onto it here and fly to the fix; None when there is no room
    for the turn before the fix."""
    here = Fix(ident="", region="", section="", lat_deg=state.lat_deg, lon_deg=state.lon_deg)
    t = trial(b)
    n0 = len(t.segments)
    st = join_from_fix(t, state, here, fcrs, direction, max_along_m=-along)
    if st is None:
        return None
    commit(b, t)
    if len(b.segments) > n0:
        b.as_transition(n0)
    return b.line_to(st, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)


def _intercept(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float, xtk: float,
               fcrs: float, direction: str | None, flyby_end: bool) -> FlightState | None:
    """The candidate intercept of the course into ``fix``: turn to α off the course
    (:func:`~.builder.intercept_angle_deg`), fly to the line (role 'turn'), fly-by onto it
    and on to the fix. Kept when the line is reached before the fix with room for the turn
    onto it; else None (nothing built)."""
    t = trial(b)
    n0 = len(t.segments)
    alpha = intercept_angle_deg(abs(xtk), t.radius_m)
    for _ in range(2):
        heading = wrap360(fcrs - math.copysign(alpha, xtk))
        state = start_course(t, state, heading, direction)
        direction = None
        _, xtk2, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                              state.lon_deg)
        done = abs(xtk2) < 30.0 or math.copysign(1.0, xtk2) == math.copysign(1.0, xtk)
        xtk = xtk2
        if done:
            break
    hit = ray_geodesic_intersection(state.lat_deg, state.lon_deg, state.track_deg,
                                    fix.lat_deg, fix.lon_deg, course_deg)
    lead = t.radius_m * math.tan(math.radians(alpha) / 2.0)
    room = lead if len(t.segments) > n0 else 2.0 * lead
    if hit is None or hit[1] > -lead or hit[0] < 0.99 * room:
        return None
    # the intercept is a transition onto the course line (no PDE); the course is the leg
    state = t.straight(state, state.track_deg, hit[0], role="turn")
    state = replace(state, flyby=True)
    t._corner_pending = True
    commit(b, t)
    return b.line_to(state, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)


def join_course(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float,
                direction: str | None, flyby_end: bool, upstream: bool = True,
                course_leg: bool = False) -> FlightState:
    """Join the course line into ``fix`` (course ``course_deg`` deg true at the fix), then
    fly it.

    Within :data:`~.builder.DIRECT_XTK_M` of the line: straight to the fix. Otherwise the
    intercept (:func:`_intercept`: α = 45°, or for a small offset y the S-turn angle
    α = 2 asin √(y / 4R) whose two fly-by turns just fit). When the intercept would fall
    beyond the fix (or leave no room for the turn onto the course), the line is joined
    upstream instead (:func:`join_upstream`; ``upstream`` False — a join made from an
    upstream reversal — flies direct instead): so the leg's straight lies on its coded
    course. ``course_leg``: the course is the leg's own path (CF), so no room to join it is
    not flown direct (:func:`direct_no_room`).
    """
    along, xtk, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                             state.lon_deg)
    own = course_deg if course_leg else None
    if along < 0 and at_previous_fix(b, state) and \
            math.degrees(math.atan2(abs(xtk), -along)) <= CF_FROM_FIX_DEG and \
            (state.track_deg is None or
             abs(wrap180(fcrs - state.track_deg)) <= CF_FROM_FIX_TURN_MAX_DEG):
        return direct_to(b, state, fix, direction, flyby_end)
    toward = state.track_deg is None or abs(wrap180(state.track_deg - fcrs)) < 10.0
    if along < 0 and abs(xtk) <= DIRECT_XTK_M:
        if toward:   # on the course line already (within the tolerance): to the fix
            return direct_to(b, state, fix, direction, flyby_end)
        got = _on_line(b, state, fix, fcrs, along, direction, flyby_end)
        if got is not None:
            return got
        if abs(wrap180(state.track_deg - fcrs)) < 90.0:
            return direct_no_room(b, state, fix, direction, flyby_end, own)
    got = _intercept(b, state, fix, course_deg, xtk, fcrs, direction, flyby_end)
    if got is not None:
        return got
    if not upstream:
        return direct_to(b, state, fix, direction, flyby_end)
    return join_upstream(b, state, fix, course_deg, direction, flyby_end, course_leg)


def _upstream_point(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float,
                    direction: str | None, flyby_end: bool) -> FlightState | None:
    """The candidate joins at P on the course D = 2, 3, 4.5, 6.75 turn radii before the
    fix: direct to P (role 'turn'), fly-by onto the course, on to the fix — the first whose
    fly-by at P (lead R tan(Ω/2)) fits in the direct line before P and in half of D; None
    when none does."""
    for k in range(4):
        t = trial(b)
        n0 = len(t.segments)
        d_m = 2.0 * t.radius_m * 1.5 ** k
        plat, plon, _ = direct(fix.lat_deg, fix.lon_deg, course_deg + 180.0, d_m)
        target = Fix(ident="", region="", section="", lat_deg=plat, lon_deg=plon)
        st = direct_to(t, state, target, direction, True)
        last = t.segments[-1].geom if len(t.segments) > n0 else None
        run = last.length_m() if isinstance(last, Line) else 0.0
        into = last.end_course_deg if last is not None else st.track_deg
        omega = abs(wrap180(course_deg - into))
        if t.radius_m * math.tan(math.radians(min(omega, 179.0)) / 2.0) <= min(run, 0.5 * d_m):
            t.finding("info", f"course into {fix.ident} joined {d_m / NM_M:.1f} NM "
                      "before the fix (no intercept before it from here)")
            t.as_transition(n0)
            st = replace(st, flyby=True)
            t._corner_pending = True
            commit(b, t)
            return b.line_to(st, fix.lat_deg, fix.lon_deg, fix.ident, flyby_end)
    return None


def join_upstream(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float,
                  direction: str | None, flyby_end: bool, course_leg: bool = False
                  ) -> FlightState:
    """Join the course into ``fix`` upstream of the fix, where no intercept reaches it in
    time (the aircraft abeam or past the fix, or too close to it). Heading toward the fix
    (within 90° of the course) with less than two turn radii of course ahead, or with no
    upstream point that fits (:func:`_upstream_point`), there is no room without a loop: it
    flies direct to the fix (:func:`direct_no_room`). Heading away, the course is reversed
    onto: direct to Q, two radii beside P on the aircraft's side (P two radii upstream of the
    aircraft's abeam point), a 180° turn toward the course there, then the course joined
    (:func:`join_course`, no further upstream join) from where the turn ends.
    ``course_leg``: the course is the leg's own path (:func:`join_course`)."""
    own = course_deg if course_leg else None
    along, xtk, fcrs = _foot(fix.lat_deg, fix.lon_deg, course_deg, state.lat_deg,
                             state.lon_deg)
    away = state.track_deg is not None and abs(wrap180(state.track_deg - fcrs)) >= 90.0
    if state.track_deg is not None:
        # the fix abeam or behind: a direct-to would turn back anyway — reverse onto the
        # course instead of arriving at the fix across it
        brg = inverse(state.lat_deg, state.lon_deg, fix.lat_deg, fix.lon_deg)[1]
        away = away or abs(wrap180(brg - state.track_deg)) > 90.0
    if not away and -along < 2.0 * b.radius_m:
        return direct_no_room(b, state, fix, direction, flyby_end, own)
    got = _upstream_point(b, state, fix, course_deg, direction, flyby_end)
    if got is not None:
        return got
    if not away:
        return direct_no_room(b, state, fix, direction, flyby_end, own)
    side = 1.0 if xtk >= 0 else -1.0
    n0 = len(b.segments)
    # P beyond the aircraft when it flies away from the fix, so that Q lies ahead of it
    d_m = 2.0 * b.radius_m + max(0.0, -along)
    plat, plon, _ = direct(fix.lat_deg, fix.lon_deg, course_deg + 180.0, d_m)
    qlat, qlon, _ = direct(plat, plon, course_deg + 90.0 * side, 2.0 * b.radius_m)
    target = Fix(ident="", region="", section="", lat_deg=qlat, lon_deg=qlon)
    st = direct_to(b, state, target, direction, False)
    arc = turn_to_course(st.lat_deg, st.lon_deg, st.track_deg, course_deg,
                         "R" if side > 0 else "L", b.radius_m)
    if arc is not None:
        st = b.arc(st, arc)
    b.finding("info", f"course into {fix.ident} joined by a course reversal "
              f"{d_m / NM_M:.1f} NM before the fix")
    b.as_transition(n0)
    _, xtk2, _ = _foot(fix.lat_deg, fix.lon_deg, course_deg, st.lat_deg, st.lon_deg)
    if abs(xtk2) <= DIRECT_XTK_M:
        return direct_to(b, st, fix, None, flyby_end)
    return join_course(b, replace(st, flyby=False), fix, course_deg, None, flyby_end,
                       upstream=False)


def min_speed_radius(b: LegBuilder, alt_m: float) -> tuple[float, float]:
    """(TAS m/s, radius m) of a turn at the aircraft's minimum speed at the bank limit:
    V = TAS of the minimum CAS at ``alt_m`` (m), R = (V + W)² / (g tan γ_max), W the planned
    wind speed."""
    v = isa_tas_mps(b.perf.tas_min_mps, alt_m, b.params.isa_dev_c)
    gmax = min(b.params.bank_limit_deg, b.perf.bank_max_deg)
    return v, turn_radius_m(v + b.wind_mps, gmax, b.g)


def direct_no_room(b: LegBuilder, state: FlightState, fix: Fix, direction: str | None,
                   flyby_end: bool, course_deg: float | None = None) -> FlightState:
    """Heading toward ``fix`` with no room to get onto its course without a loop at the
    planned radius (Danilin's class 1, the conditions).

    Any leg but a CF (a TF joined away from its first fix) flies direct to the fix, and an
    'info' finding says its track is not flown. A leg whose path is the course (CF:
    ``course_deg`` given, deg true) flies direct when the direct line's straight is within
    :data:`~.builder.CF_OFF_COURSE_DEG` of the course, or when the path behind is shorter than
    the distance to slow to the minimum speed, (V² − V_min²) / (2 a) (V: the planned TAS; on a
    departure no more than its climb-out speed, which it can have held) with a
    :data:`~fms_testbed.core.planning.DECEL_MPS2` (the monitor then reports the course not flown); else
    it joins the course at the aircraft's minimum speed at the bank limit
    (:func:`min_speed_radius`; branch V,γ, a correction) when that radius leaves room; else
    the coded course cannot be flown before the fix and the leg is 'impossible' with the
    reason (the direct line to the fix is kept as its geometry)."""
    why = (f"no room to join the course into {fix.ident} at the planned radius "
           f"{b.radius_m:.0f} m: flown direct to the fix")
    if course_deg is None:
        b.finding("info", why)
        return direct_to(b, state, fix, direction, flyby_end)
    t = trial(b)
    n0 = len(t.segments)
    st = direct_to(t, state, fix, direction, flyby_end)
    lines = [sg.geom for sg in t.segments[n0:] if isinstance(sg.geom, Line)]
    if not lines or abs(wrap180(lines[-1].end_course_deg - course_deg)) <= CF_OFF_COURSE_DEG:
        # at the fix already (a zero-length leg), or the direct line lies along the course
        commit(b, t)
        b.finding("info", why)
        return st
    v_min, r_min = min_speed_radius(b, state.alt_m)
    flown = b.flown_before_m + sum(sg.geom.length_m() for sg in b.segments)
    v_from = b.speed_mps
    if b.dep_cas_mps is not None and b.perf.departure_cas_mps is not None:
        # a departure can have held its climb-out speed since the acceleration height
        v_from = min(v_from, isa_tas_mps(b.perf.departure_cas_mps, state.alt_m,
                                         b.params.isa_dev_c))
    slow_m = max(v_from ** 2 - v_min ** 2, 0.0) / (2.0 * DECEL_MPS2)
    if flown < slow_m:
        # no distance behind to slow down in (a SID just after the runway): flown direct,
        # the monitor reports the coded course not flown
        commit(b, t)
        b.finding("info", f"{why} (no room to slow to the minimum speed "
                  f"{v_min / KT_MPS:.0f} kt: {slow_m / NM_M:.1f} NM needed, "
                  f"{flown / NM_M:.1f} NM flown)")
        return st
    if r_min < 0.99 * b.radius_m:
        t = trial(b)
        t.speed_mps, t.radius_m = min(t.speed_mps, v_min), r_min
        st = join_course(t, state, fix, course_deg, direction, flyby_end, course_leg=True)
        if not any(f.category == "impossible" for f in t.findings):
            commit(b, t)
            if b.dep_cas_mps is not None:   # a departure flies the leg at that speed
                b.dep_cas_mps = min(b.dep_cas_mps, b.perf.tas_min_mps)
            b.finding("correction", f"course into {fix.ident} joined at the minimum speed "
                      f"{t.speed_mps / KT_MPS:.0f} kt, radius {r_min:.0f} m (no room at the "
                      f"planned radius {b.radius_m:.0f} m)", "V,γ")
            return st
    b.finding("impossible", f"no room to join the course {course_deg:.1f}° into {fix.ident} "
              f"before the fix even at the minimum speed (radius {min(r_min, b.radius_m):.0f} "
              f"m at the bank limit): the coded course cannot be flown (line {b.leg.rec.line})")
    return direct_to(b, state, fix, direction, flyby_end)


REJOIN_ANGLES_DEG = (45.0, 35.0, 25.0, 15.0, 60.0, 75.0, 90.0)
"""Intercept angles a turn from over a fix tries, in order, to rejoin the course out of it:
the standard 45° first, shallower ones where its intercept leaves no room for the fly-by,
steeper ones where it falls beyond the end of the leg, deg."""


def _rejoin_intercept(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float,
                      sweep: float, max_along_m: float = math.inf
                      ) -> tuple[LegBuilder, FlightState, tuple, float] | None:
    """The candidate turn from over ``fix`` continued α past the course
    (:data:`REJOIN_ANGLES_DEG`: the first whose intercept leaves room for its fly-by, and
    whose fly-by ends within ``max_along_m`` of the fix along the course): (trial builder, state at the end of the
    turn, the intercept (distance, along), lead m), or None."""
    turn = "R" if sweep > 0 else "L"
    for alpha in REJOIN_ANGLES_DEG:
        t = trial(b)
        over = wrap360(course_deg + math.copysign(alpha, sweep))
        arc = turn_to_course(state.lat_deg, state.lon_deg, state.track_deg, over, turn,
                             t.radius_m)
        st = t.arc(state, arc) if arc is not None else replace(state, track_deg=over)
        hit = ray_geodesic_intersection(st.lat_deg, st.lon_deg, st.track_deg, fix.lat_deg,
                                        fix.lon_deg, course_deg)
        lead = t.radius_m * math.tan(math.radians(alpha) / 2.0)
        if hit is not None and hit[0] >= lead and hit[1] + lead <= max_along_m:
            return t, st, hit, lead
    return None


def join_from_fix(b: LegBuilder, state: FlightState, fix: Fix, course_deg: float,
                  direction: str | None, max_along_m: float = math.inf
                  ) -> FlightState | None:
    """From over (or at the fly-by corner of) ``fix``, get onto the geodesic that leaves the
    fix on ``course_deg`` (deg true; F* legs, the procedure turn's outbound leg).

    A fly-by corner is cut as usual (the next straight starts on the line). A turn flown
    from over the fix ends R(1 − cos Δ) beside the coded course; when that is more than
    :data:`~.builder.PARALLEL_TOL_M` the turn is continued by α past the course
    (:func:`_rejoin_intercept`), the intercept flown to the line (role 'turn') and the course
    joined with a fly-by: the leg's straight then lies on its coded course line, not parallel
    to it. No intercept that fits: the plain turn onto the course.

    ``max_along_m``: the intercept must fall (with the lead of its fly-by) within this
    distance from the fix (a TF's length), m; when it cannot, nothing is built and None is
    returned.

    Returns the state on the line (track ``course_deg``) or, when it may be cut, at the fix.
    """
    if state.track_deg is None:
        return replace(state, track_deg=course_deg)
    if can_cut(b, state, course_deg, direction):
        return start_course(b, state, course_deg, direction)
    sweep = turn_angle_deg(state.track_deg, course_deg, direction)
    if abs(sweep) < 0.5 or abs(sweep) > 359.5:
        return replace(state, track_deg=course_deg)
    if b.radius_m * (1.0 - math.cos(math.radians(min(abs(sweep), 180.0)))) < PARALLEL_TOL_M:
        return start_course(b, state, course_deg, direction)
    got = _rejoin_intercept(b, state, fix, course_deg, sweep, max_along_m)
    if got is None:
        if _rejoin_intercept(b, state, fix, course_deg, sweep) is not None:
            return None   # the intercept falls beyond max_along_m: nothing built
        # no room for the intercept: back to the plain turn onto the course
        return start_course(b, state, course_deg, direction)
    t, st, hit, lead = got
    st = t.straight(st, st.track_deg, hit[0], role="turn")
    t._corner_pending = True
    commit(b, t)
    return replace(st, track_deg=course_deg, flyby=True)


def connect(b: LegBuilder, state: FlightState, lat: float, lon: float, why: str,
            category: str = "discontinuity") -> FlightState:
    """Bridge a gap (> 1 cm) to a point (deg); a gap above 0.05 NM is also recorded as a
    discontinuity finding.

    The bridge is built here, as flown, so that the corner at its end is rounded like any
    other fly-by (the segments carry role 'connector': no PDE):

    * a gap shorter than the turn anticipation L = R tan(Ω/2) of the turn toward it (Ω the
      track change to its bearing, R the planned radius), and than the roll-in distance
      V · :data:`~.builder.CLOSE_S`, is closed in the geometry: the last line moves its end
      onto the point when it does not end at a fix, else a short straight bridge is flown
      through (never a direct-to with turns larger than the gap);
    * a longer gap (vectors to the next fix, an intercept that never happens) is a
      direct-to from the present track: a turn at the planned radius, then the line.
    """
    s, az, _ = inverse(state.lat_deg, state.lon_deg, lat, lon)
    if s <= 0.01:
        return replace(state, lat_deg=lat, lon_deg=lon)
    if s > 0.05 * NM_M:
        b.finding(category, f"{why}: gap of {s / NM_M:.2f} NM bridged")
    omega = abs(wrap180(az - state.track_deg)) if state.track_deg is not None else 0.0
    # the turn anticipation a direct-to onto the gap would need — the roll-in distance
    # (V · CLOSE_S) bounds it: a larger gap is flown as a real direct-to
    lead = min(b.radius_m * math.tan(math.radians(min(omega, 179.0)) / 2.0),
               b.speed_mps * CLOSE_S)
    last = b.segments[-1] if b.segments else None
    if s < lead and last is not None and isinstance(last.geom, Line) and \
            not state.fix_ident and last.geom.length_m() > 4.0 * s:
        moved = Line(last.geom.start_lat_deg, last.geom.start_lon_deg, lat, lon)
        b.segments[-1] = replace(last, geom=moved)
        return b.advance(state, s, lat_deg=lat, lon_deg=lon, track_deg=moved.end_course_deg)
    if s < lead or state.track_deg is None:
        seg = Line(state.lat_deg, state.lon_deg, lat, lon)
        b.emit(seg, "connector")
        return b.advance(state, s, lat_deg=lat, lon_deg=lon, track_deg=seg.end_course_deg)
    n0 = len(b.segments)
    target = Fix(ident="", region="", section="", lat_deg=lat, lon_deg=lon)
    state = direct_to(b, replace(state, flyby=False), target, None, False)
    for k in range(n0, len(b.segments)):
        b.segments[k] = replace(b.segments[k], role="connector")
    return replace(state, lat_deg=lat, lon_deg=lon)
