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

import math
from dataclasses import replace

from fms_testbed.core.geodesy import LocalFrame, inverse, wrap180, wrap360
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.legs.base import Leg, altitude_of, course_of, fix_course, fix_of
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.coded import racetrack
from fms_testbed.legs.construct import _foot, turn_to_course
from fms_testbed.legs.course_legs import from_fix
from fms_testbed.legs.model import FlightState, Termination, turn_radius_m
from fms_testbed.legs.moves import (commit, direct_to, fix_state, join_course, join_from_fix,
                                    trial, turn_dir)


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
    return direct_to(b, s, f, None, False)


ALIGNED_DEG = 1.0
"""An arrival this close to the inbound course needs no entry: the circuit starts at once."""


def entry_kind(arrival_deg: float | None, inbound_deg: float, d: str) -> str:
    """ICAO hold entry sector of an arrival track (deg true) for a hold on ``inbound_deg``
    turning ``d``: 'none' (no track, or within :data:`ALIGNED_DEG` of the inbound course),
    'direct' (track − inbound within −70°..+110° toward the holding side), 'teardrop' (the 70°
    beyond) or 'parallel' (the other 110°)."""
    if arrival_deg is None:
        return "none"
    rel = wrap180(arrival_deg - inbound_deg)
    if abs(rel) <= ALIGNED_DEG:
        return "none"
    rel *= 1.0 if d == "R" else -1.0
    if -70.0 <= rel <= 110.0:
        return "direct"
    return "teardrop" if rel > 110.0 else "parallel"


def _hold_frame(f, inbound: float, lat: float, lon: float) -> tuple[float, float]:
    """(lateral m, right of the inbound course; along m, along it) of a point, the fix at 0."""
    x, y = LocalFrame(f.lat_deg, f.lon_deg).to_xy(lat, lon)
    a = math.radians(inbound)
    return x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)


def _entry_theta_deg(r_m: float, x0_m: float, leg_m: float) -> float:
    """The outbound heading offset θ (deg, bisection in −60°..90°) for which the final turn
    of radius R ends on the inbound line: R (1 + cos θ) − x₀ = L sin θ (``x0_m`` the lateral
    offset toward the σ side where the outbound leg starts, L = ``leg_m``); the nearer bound
    when there is no root there."""
    def miss(t: float) -> float:
        rt = math.radians(t)
        return r_m * (1.0 + math.cos(rt)) - x0_m - leg_m * math.sin(rt)

    lo, hi = -60.0, 90.0
    if miss(lo) * miss(hi) > 0:
        return lo if abs(miss(lo)) < abs(miss(hi)) else hi
    m_lo = miss(lo)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        m_mid = miss(mid)
        if m_lo * m_mid > 0:
            lo, m_lo = mid, m_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _entry(b: LegBuilder, s: FlightState, f, inbound: float, d: str, leg_m: float
           ) -> tuple[FlightState, bool]:
    """Hold entry from over the fix, ending over the fix on the inbound course.

    The ICAO sector (:func:`entry_kind`) sets the side of the final turn σ — the holding side
    for a direct or teardrop entry, the other side for a parallel one — and the first turn
    (the holding direction for a direct entry, the shorter way otherwise). The outbound heading
    is the reciprocal of the inbound course turned θ toward the σ side, θ chosen (bisection in
    −60°..90°) so that after the first turn and ``leg_m`` of outbound leg the final turn of
    radius R in the σ direction ends on the inbound course line:
    ``R (1 + cos θ) − σ x₀ = L sin θ`` (x₀ the lateral offset where the outbound leg starts).
    Then the inbound course is flown to the fix. So the first circuit, or the exit, starts on
    the coded course. Returns (state over the fix on the inbound course, entry flown)."""
    kind = entry_kind(s.track_deg, inbound, d)
    if kind == "none":
        return replace(s, track_deg=s.track_deg if s.track_deg is not None else inbound), False
    h = 1.0 if d == "R" else -1.0
    sigma = -h if kind == "parallel" else h
    first = d if kind == "direct" else None
    final = "R" if sigma > 0 else "L"
    outbound = wrap360(inbound + 180.0)
    r = b.radius_m

    def head(theta: float) -> float:   # outbound heading turned θ toward the σ side
        return wrap360(outbound - sigma * theta)

    def first_turn(theta: float):   # a candidate first turn: (trial builder, state, x₀ m)
        t = trial(b)
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, head(theta), first, r)
        st = t.arc(s, arc, role="turn") if arc is not None else replace(s, track_deg=head(theta))
        return t, st, _hold_frame(f, inbound, st.lat_deg, st.lon_deg)[0]

    theta = 0.0
    for _ in range(3):
        x0 = first_turn(theta)[2]
        theta = _entry_theta_deg(r, sigma * x0, leg_m)
    t, st, x0 = first_turn(theta)
    commit(b, t)
    # the straight that puts the final turn's end on the inbound line (planar, exact heading)
    psi = math.radians(wrap360(st.track_deg - inbound))
    xs, _ = _hold_frame(f, inbound, st.lat_deg, st.lon_deg)
    run = leg_m
    if abs(math.sin(psi)) > 1e-3:
        run = (sigma * r * (1.0 - math.cos(psi)) - xs) / math.sin(psi)
        if not 0.0 <= run <= 3.0 * leg_m + 4.0 * r:
            run = leg_m
    st = b.straight(st, st.track_deg, run, role="turn")
    arc = turn_to_course(st.lat_deg, st.lon_deg, st.track_deg, inbound, final, r)
    if arc is not None:
        st = b.arc(st, arc, role="turn")
    st = join_course(b, st, f, inbound, None, False)
    return replace(st, lat_deg=f.lat_deg, lon_deg=f.lon_deg, track_deg=inbound), True


class _Hold(Leg):
    """A racetrack hold at the leg's fix on its coded inbound course."""

    ends_at_fix = True
    hold = True
    course_reversal = True
    pde_reference = ("the racetrack on the coded inbound course into the fix, coded turn "
                     "direction and leg length, planned turn radius")

    @classmethod
    def _enter(cls, b, s):
        """Get to the fix and through the entry (:func:`_entry`); returns (state over the fix
        on the inbound course, fix, inbound course deg, turn direction, leg length m, whether
        an entry was flown)."""
        f, c = fix_of(b), course_of(b)
        n0 = len(b.segments)
        if s.track_deg is None:
            s = replace(fix_state(b, s, f), track_deg=c)
        elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
            s = direct_to(b, s, f, None, False)
        s = replace(s, lat_deg=f.lat_deg, lon_deg=f.lon_deg)
        d = turn_dir(b) or "R"
        s, flown = _entry(b, s, f, c, d, hold_leg_m(b, s.alt_m))
        b.as_transition(n0)
        return s, f, c, d, hold_leg_m(b, s.alt_m), flown

    @classmethod
    def coded_path(cls, b, term):
        fc = fix_course(b.leg)
        if fc is None or not term.distance_m:
            return None
        return racetrack(*fc, turn_dir(b) or "R", term.distance_m, b.radius_m)


class HM(_Hold):
    """Hold to manual termination: one circuit drawn; the crew ends it."""

    code = "HM"
    manual_end = True

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m, _ = cls._enter(b, s)
        s = _circuit(b, s, f, c, d, leg_m)
        return fix_state(b, s, f), Termination("manual", f.lat_deg, f.lon_deg, fix_ident=f.ident,
                                              distance_m=leg_m)


class HF(_Hold):
    """Hold to fix: the course reversal ends at the first crossing of the fix on the inbound
    course after the entry (one circuit when the arrival needs no entry)."""

    code = "HF"

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m, flown = cls._enter(b, s)
        if not flown:
            s = _circuit(b, s, f, c, d, leg_m)
        return replace(fix_state(b, s, f), flyby=False), Termination(
            "circuit", f.lat_deg, f.lon_deg, fix_ident=f.ident, distance_m=leg_m)


class HA(_Hold):
    """Hold to altitude: as many circuits as the climb needs (bounded), leaving over the fix
    (guidance leaves it at the end of the first circuit flown with the altitude reached)."""

    code = "HA"
    altitude_terminated = True
    MAX_CIRCUITS = 10

    @classmethod
    def build(cls, b, s):
        s, f, c, d, leg_m, _ = cls._enter(b, s)
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
        return replace(fix_state(b, s, f), flyby=False), Termination(
            "altitude", f.lat_deg, f.lon_deg, fix_ident=f.ident, alt_m=alt, distance_m=leg_m)


class PI(Leg):
    """Procedure turn (45°/180°), as ARINC-424 codes it and charts draw it.

    The record's course (col. 71) is the course of the 45° leg, its turn direction (col. 44)
    the direction of the 180° turn, and its distance (col. 75) the limit within which the
    manoeuvre stays. Flown from over the fix: outbound on the reciprocal of the inbound course
    (the next CF's course; without a CF, the coded course ∓ 45° away from the 180° turn's
    side), the shorter 45° turn onto the coded course, the 45° leg, the 180° turn the coded way
    onto its reciprocal, which intercepts the inbound course at 45° (the next leg). The 45° leg
    thus lies on the side opposite the coded turn — the protected side of the chart's barb;
    FlyByWire's ``PILeg`` and the MSFS SDK's ``ProcedureTurnVectorBuilder`` read the fields the
    same way, and every PI of the FAA cycle 2301 codes its turn opposite its 45° side.

    Sizes (planar, R the planned turn radius): the 45° leg is one minute at the timed-leg speed,
    at least 2.2 R so the 180° turn ends on the outbound side of the inbound course with room for
    the 45° intercept; the intercept lies 3.24 R + d₁ beyond the fix, d₁ the outbound straight,
    which is one minute when the manoeuvre (farthest point |C₂| + R, C₂ the 180° turn's
    centre at (d₁ + 1.41 R + 0.71 L₁, 0.71 L₁ − 0.41 R)) fits in the
    coded limit, shorter when not, and long enough that the intercept falls at least
    :data:`INBOUND_MIN_M` outside the next leg's fix. A manoeuvre that does not fit is flown at
    the bank limit (monitor branch γ), else reported.

    No coded path: the record codes a manoeuvre of the aircraft's choosing within the protected
    area, not a track."""

    code = "PI"
    course_reversal = True
    INBOUND_MIN_M = 1.0 * NM_M
    """The inbound course is joined at least this far outside the next leg's fix, m."""

    @classmethod
    def _outbound_deg(cls, b: LegBuilder, c: float, d: str) -> tuple[float, float | None]:
        """(outbound course deg true, along-outbound distance of the next CF's fix from the PI
        fix m, or None)."""
        nxt = b.next_leg
        k = b.i + 1
        while nxt is not None and nxt.pt == "IF" and k + 1 < len(b.legs):
            k += 1
            nxt = b.legs[k]
        if nxt is not None and nxt.pt == "CF" and nxt.course_true_deg is not None \
                and abs(abs(wrap180(c - nxt.course_true_deg - 180.0)) - 45.0) < 20.0:
            out = wrap360(nxt.course_true_deg + 180.0)
            x_next = None
            first = b.legs[b.i + 1].fix   # the first fix after the PI (an IF, or the CF's)
            if first is not None and b.leg.fix is not None:
                s_m, az, _ = inverse(b.leg.fix.lat_deg, b.leg.fix.lon_deg, first.lat_deg,
                                     first.lon_deg)
                x_next = s_m * math.cos(math.radians(az - out))
            return out, x_next
        # the 45° leg lies on the side away from the coded 180° turn
        return wrap360(c + (45.0 if d == "R" else -45.0)), None

    @classmethod
    def _size(cls, b: LegBuilder, x_next: float | None, limit: float, timed: float,
              gmax: float) -> tuple:
        """The manoeuvre's sizes at the planned bank, else at ``gmax`` (class docstring):
        (bank deg or None for the planned one, R m, the 45° leg m, d₁ least m, d₁ most m, and
        the far point's offsets a, b m)."""
        for bank in (None, gmax):
            if bank is not None:
                b.radius_m = turn_radius_m(b.speed_mps + b.wind_mps, bank, b.g)
            r = b.radius_m
            leg45 = max(timed, 2.2 * r)
            d_min = max(0.0, (x_next or 0.0) + cls.INBOUND_MIN_M + r * math.tan(
                math.radians(22.5)) - 3.243 * r)
            # farthest point: the far side of the 180° turn, |C₂| + R from the fix, with
            # C₂ = (d₁ + 1.414 R + 0.707 L₁, 0.707 L₁ − 0.414 R) in (outbound, 45° side)
            a_m, b_m = 1.414 * r + 0.707 * leg45, 0.707 * leg45 - 0.414 * r
            reach = max(limit - r, 0.0) ** 2 - b_m * b_m
            d_max = math.sqrt(reach) - a_m if reach > 0 else -math.inf
            if d_min <= d_max:
                break
        return bank, r, leg45, d_min, d_max, a_m, b_m

    @classmethod
    def build(cls, b, s):
        f, c = fix_of(b), course_of(b)
        d = turn_dir(b) or "L"
        out, x_next = cls._outbound_deg(b, c, d)
        n0 = len(b.segments)
        s = replace(s, flyby=False)   # a course reversal starts over its fix
        if s.track_deg is None:
            s = replace(fix_state(b, s, f), track_deg=out, flyby=False)
        elif inverse(s.lat_deg, s.lon_deg, f.lat_deg, f.lon_deg)[0] > 1.0:
            s = direct_to(b, s, f, None, False)
            b.as_transition(n0)
        s = replace(fix_state(b, s, f), flyby=False)
        limit = b.leg.rec.distance_m or 10 * NM_M
        timed = 60.0 * timed_speed_mps(b)
        gmax = min(b.params.bank_limit_deg, b.perf.bank_max_deg)
        bank, r, leg45, d_min, d_max, a_m, b_m = cls._size(b, x_next, limit, timed, gmax)
        fits = d_min <= d_max
        if bank is not None and fits:
            b.finding("correction", f"procedure turn at {f.ident} kept within "
                      f"{limit / NM_M:.1f} NM at bank {gmax:.0f}° (radius {r:.0f} m)", "γ")
        elif not fits:
            b.finding("info", f"procedure turn at {f.ident} reaches "
                      f"{(math.hypot(d_min + a_m, b_m) + r) / NM_M:.1f} NM from the fix at "
                      f"the bank limit, beyond the coded {limit / NM_M:.1f} NM")
        d1 = max(d_min, min(d_max, timed)) if fits else d_min
        n1 = len(b.segments)
        s = join_from_fix(b, s, f, out, None)
        b.as_transition(n1)
        # the outbound straight is measured from the fix: a turn onto the outbound course
        # from over the fix already flew part of it
        joined, _, _ = _foot(f.lat_deg, f.lon_deg, out, s.lat_deg, s.lon_deg)
        if fits and joined > d_max:
            b.finding("info", f"procedure turn at {f.ident}: joining the outbound course takes "
                      f"{joined / NM_M:.1f} NM; the manoeuvre reaches beyond the coded "
                      f"{limit / NM_M:.1f} NM")
        run = max(d1 - max(joined, 0.0), 0.0)
        if run < 1.0 and b._corner_pending and b.segments:
            # no outbound straight left: turn from the intercept heading straight onto the 45°
            # leg (one turn) instead of a fly-by onto the outbound course and another turn
            b._corner_pending = False
            s = replace(s, track_deg=b.segments[-1].geom.end_course_deg)
        else:
            s = b.straight(s, out, run)
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, c, None, b.radius_m)
        if arc is not None:
            s = b.arc(s, arc, role="leg")
        s = b.straight(s, c, leg45)
        arc = turn_to_course(s.lat_deg, s.lon_deg, s.track_deg, wrap360(c + 180.0), d,
                             b.radius_m)
        s = b.arc(s, arc, role="leg")
        s = replace(s, flyby=False, fix_ident="")
        return s, Termination("intercept", s.lat_deg, s.lon_deg, next_leg=b.i + 1)
