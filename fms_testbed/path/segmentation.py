"""Segmentation of a procedure transition into geodesic lines and circular arcs.

:func:`build_sequence` resolves the legs, chooses the start (departure end of the runway for a
SID runway transition, else the first fix), runs each leg's class, then rounds every fly-by
corner with an arc of radius R = V²/(g tan γ) and turn anticipation L = R tan(Ω/2) (Danilin 2017,
Fig. 2). When the lead does not fit between the neighbouring fixes the paper's monitor
corrections apply in order (R; V,γ; V,γ,φ,λ) with the formulas

    R_geom = L_avail / tan(Ω/2)
    γ_reg  = atan(V² / (R_geom g))      (when ≤ γ_max: branch R, V kept)
    V_reg  = sqrt(R_geom g tan γ_max)   (branch V,γ, when V_reg ≥ V_min)

and, failing both, the turn is flown over the fix and rejoins (branch V,γ,φ,λ).
"""

from __future__ import annotations

import math
from dataclasses import replace

from fms_testbed.core.atmosphere import cas_to_tas, tas_to_cas
from fms_testbed.core.geodesy import direct, gravity_mps2, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.legs.builder import LegBuilder, ResolvedLeg
from fms_testbed.legs.construct import turn_arc
from fms_testbed.core.planning import ARC_BANK_MARGIN_DEG
from fms_testbed.path import departure
from fms_testbed.path.fillets import arc_line_fillet, line_arc_fillet, retarget_arc
from fms_testbed.path.profile import (PLAN_CLIMB_FRACTION, arrival_join_alt_m, climb_caps_m,
                                     climb_phases, path_climb_top_m)
from fms_testbed.procedures.database import Database, Sequence
from fms_testbed.procedures.records import Fix
from fms_testbed.legs.types import LEG_TYPES, LegError
from fms_testbed.legs.model import (BuildParams, BuiltLeg, Finding, FlightState, Performance, PathSegment,
                    approach_cas_caps, max_tailwind_mps,
                    ProcedurePath, isa_tas_mps, turn_radius_m)
from fms_testbed.legs.moves import join_course



def resolve_legs(db: Database, seq: Sequence) -> tuple[list[ResolvedLeg], list[Finding]]:
    """Look up the fixes of each leg and turn magnetic courses true."""
    apt = db.airports.get(seq.airport)
    apt_var = apt.magvar_deg if apt else 0.0
    out, findings = [], []
    for i, rec in enumerate(seq.legs):
        fix = db.find_fix(rec.fix, seq.airport)
        nav = db.find_fix(rec.navaid, seq.airport)
        ctr = db.find_fix(rec.centre, seq.airport)
        for ref, got in ((rec.fix, fix), (rec.navaid, nav), (rec.centre, ctr)):
            if ref is not None and got is None:
                findings.append(Finding(i, "impossible",
                                        f"fix {ref.ident} ({ref.region} {ref.section}) not in "
                                        f"the database (line {rec.line})"))
        var = nav.magvar_deg if nav is not None and nav.section in ("D ", "PI") else apt_var
        crs = None
        if rec.course_deg is not None:
            crs = wrap360(rec.course_deg + (0.0 if rec.course_true else var))
        out.append(ResolvedLeg(rec, fix, nav, ctr, crs, var))
    return out, findings


def runway_part(transition: str) -> str:
    """The runway element of a (merged) transition name: 'RW18C' of 'RW18C+AUDII' (a SID flown
    from its runway transition through the common route to an en-route transition), '' when
    it has none."""
    return next((t for t in transition.split("+") if t.startswith("RW")), "")


def runway_record(db: Database, airport: str, transition: str):
    """The runway threshold record (PG) of the runway part of ``transition`` (``RWxxB``: the
    first of its L/R/C runways), or None."""
    transition = runway_part(transition)
    if not transition:
        return None
    cands = db.terminal.get((airport, transition), [])
    for f in cands:
        if f.section == "PG":
            return f
    if transition.startswith("RW") and transition.endswith("B"):
        for suffix in ("L", "R", "C"):
            for f in db.terminal.get((airport, transition[:-1] + suffix), []):
                if f.section == "PG":
                    return f
    return None


def start_state(db: Database, seq: Sequence, legs: list[ResolvedLeg],
                perf: Performance | None = None) -> FlightState:
    """Planned start: a SID runway transition starts at the departure end of the runway
    (threshold + length along the runway's true bearing, 35 ft above the threshold); a SID
    joined at its first fix starts there at :func:`~fms_testbed.path.departure.sid_join_alt_m`; other transitions start at
    their first fix (STAR/approach altitude: the first coded altitude, else airport elevation
    + 10,000 ft / 3,000 ft, no higher than ``perf.alt_plan_max_m``); a SID without either
    starts over the airport."""
    apt = db.airports.get(seq.airport)
    elev = (apt.elev_m if apt and apt.elev_m is not None else 0.0)
    first = legs[0]
    if seq.proc_type == "D":
        rwy = runway_record(db, seq.airport, seq.transition)
        if rwy is not None and not LEG_TYPES[first.pt].initial:
            brg = wrap360((rwy.bearing_deg or 0.0) + (apt.magvar_deg if apt else 0.0))
            lat, lon, az = direct(rwy.lat_deg, rwy.lon_deg, brg, rwy.length_m or 0.0)
            alt = (rwy.elev_m if rwy.elev_m is not None else elev) + 35 * FT_M
            return FlightState(lat, lon, wrap360(az), alt)
        alt = departure.sid_join_alt_m(db, seq, first.fix, elev, perf)
    else:
        # the first coded altitude; of an 'between' window its middle (the top of it can
        # leave the next windows out of reach of the descent)
        alt = next((_descent_target(lg) for lg in legs if lg.rec.alt1_m is not None), None)
        if alt is None:
            alt = elev + (10000 if seq.proc_type == "E" else 3000) * FT_M
        if perf is not None:            # never above the aircraft's ceiling (less margin)
            alt = min(alt, perf.alt_plan_max_m)
    if first.fix is not None:
        return FlightState(first.fix.lat_deg, first.fix.lon_deg, None, alt,
                           fix_ident=first.fix.ident)
    if apt is not None:
        return FlightState(apt.lat_deg, apt.lon_deg, first.course_true_deg, alt)
    raise LegError(f"{seq.name}: no runway, fix or airport to start from")


def planned_speed_mps(perf: Performance, leg: ResolvedLeg, alt_m: float,
                      cas_cap_mps: float | None = None, isa_dev_c: float = 0.0) -> float:
    """Planned TAS: the aircraft's planned speed (flown as a CAS: its TAS at ``alt_m``; no more
    than ``cas_cap_mps``, an approach's planned speed: :func:`~fms_testbed.legs.model.
    approach_cas_caps`) capped by an 'at or below' speed limit, raised to
    an 'at or above' one, and equal to an 'at' one — the speed guidance will fly there, so turn
    radii are planned for it (limits are IAS, turned to TAS on a day ``isa_dev_c`` K off the
    ISA: a warm day flies a higher TAS for the same CAS, so a larger radius) — never above
    the aircraft's VMO / MMO there (:meth:`~fms_testbed.legs.model.Performance.tas_max_mps`),
    m/s."""
    v = isa_tas_mps(perf.tas_plan_mps if cas_cap_mps is None else
                    min(perf.tas_plan_mps, cas_cap_mps), alt_m, isa_dev_c)  # flown as a CAS
    lim = leg.rec.speed_limit_mps
    if lim is not None:
        lim_tas = isa_tas_mps(lim, alt_m, isa_dev_c)
        if leg.rec.speed_desc == "-":
            v = min(v, lim_tas)
        elif leg.rec.speed_desc == "+":
            v = max(v, lim_tas)
        else:
            v = lim_tas  # blank or '@': at
    return min(v, perf.tas_max_mps(alt_m, isa_dev_c))   # inside VMO / MMO


def leg_cls_hold(leg: ResolvedLeg) -> bool:
    """True for a hold leg (HA/HF/HM)."""
    return LEG_TYPES[leg.pt].hold


def build_sequence(db: Database, seq: Sequence, perf: Performance,
                   params: BuildParams | None = None, start: FlightState | None = None,
                   prev_fix: Fix | None = None, hold_legs: frozenset[int] = frozenset()
                   ) -> ProcedurePath:
    """Build one procedure transition into a :class:`ProcedurePath` (segments + legs).

    Parameters
    ----------
    db : the database the sequence comes from (fix look-ups)
    seq : the procedure transition
    perf : aircraft performance (planned TAS, climb gradient, bank limit)
    params : build settings; defaults :class:`BuildParams`
    start : planned start state (position deg, track deg true, altitude m); default
        :func:`start_state`. Guidance uses this to rebuild from the aircraft's actual state.
    prev_fix : the fix the first leg starts from (a leg rebuilt mid-way: a TF rejoins the track
        from it; its coded path is kept for the PDE); default none
    hold_legs : indices of departure legs planned at the climb-out speed (held since the
        acceleration height) instead of the departure schedule; a SID whose CF course cannot
        be flown at the schedule's speed (a fly-by onto it flown over, the fix reached
        against the course) is built again with its CFs held

    Returns
    -------
    ProcedurePath with findings from the builder and the fly-by corrections; the vertical
    profile and monitor outcome are added by :func:`fms_testbed.path.monitor.check_path`.
    """
    params = params or BuildParams()
    legs, findings = resolve_legs(db, seq)
    path = ProcedurePath(seq.name, seq.airport, seq.proc_type, seq.proc_id, seq.transition,
                         (), (), tuple(findings), status="impossible")
    if any(f.category == "impossible" for f in findings):
        return path
    try:
        state = start or start_state(db, seq, legs, perf)
        kind = "given" if start else _start_kind(db, seq, legs, state)
        state0 = state
    except LegError as exc:
        return replace(path, findings=path.findings + (Finding(-1, "impossible", str(exc)),))
    ref = legs[0].fix or db.airports.get(seq.airport)
    g = gravity_mps2(ref.lat_deg if ref else state.lat_deg)
    # a TF starts from the previous leg's fix when that leg ends at its fix
    prev_fixes = [prev_fix] + [lg.fix if LEG_TYPES[lg.pt].ends_at_fix else None
                               for lg in legs[:-1]]
    b = LegBuilder(legs, perf, params, g, prev_fixes)
    b.climbing = seq.proc_type == "D"
    b.dep_elev_m = departure.departure_elev_m(db, seq, kind,
                                             runway_record(db, seq.airport, seq.transition))
    bank = min(params.bank_plan_deg, params.bank_limit_deg, perf.bank_max_deg)
    built = _build_legs(b, seq.proc_type, state, bank, hold_legs)
    segs = round_corners(b, perf, params, bank)
    built = departure.departure_slowdowns(_attach_segments(built, segs), segs)
    status = "impossible" if any(f.category == "impossible" for f in b.findings) else "ok"
    out = replace(path, legs=tuple(built), segments=tuple(segs),
                  findings=path.findings + tuple(b.findings), status=status, start_kind=kind)
    hold = departure.cf_legs_to_hold(out, perf) - hold_legs
    if hold:
        return build_sequence(db, seq, perf, params, start, prev_fix, hold_legs | hold)
    if start is None and seq.proc_type in ("E", "F") and len(built) > 1:
        alt = _arrival_start_m(out, perf, params, state0.alt_m)
        if alt is not None:
            again = build_sequence(db, seq, perf, params, start=replace(state0, alt_m=alt))
            return replace(again, start_kind=kind)
    return out


def _build_legs(b: LegBuilder, proc_type: str, state: FlightState, bank_deg: float,
                hold_legs: frozenset[int] = frozenset()) -> list[BuiltLeg]:
    """Run every leg's class from ``state`` (each planned by :func:`_plan_leg`: its climb
    cap from :func:`~fms_testbed.path.profile.climb_caps_m`, its approach CAS cap); stop at
    the first leg that cannot be built (an 'impossible' finding). Returns the built legs."""
    legs, perf, params = b.legs, b.perf, b.params0
    recs = [lg.rec for lg in legs]
    caps = approach_cas_caps(recs, proc_type, perf.tas_min_mps)
    alt_caps = climb_caps_m(recs, climb_phases(recs, proc_type),
                            path_climb_top_m(proc_type, params.climb_top_m), perf.alt_plan_max_m)
    built: list[BuiltLeg] = []
    for i, leg in enumerate(legs):
        _plan_leg(b, i, state.alt_m, float(alt_caps[i + 1]), caps[i], bank_deg,
                  hold=i in hold_legs)
        start_st = state
        leg_cls = LEG_TYPES[leg.pt]
        snap = (len(b.segments), set(b.corners), len(b.findings), b._corner_pending)
        try:
            state, term = leg_cls.build(b, state)
            if departure.held_speed_helps(b, snap[2], proc_type):
                # a departure can have held its climb-out speed: the leg at that speed
                del b.segments[snap[0]:], b.findings[snap[2]:]
                b.corners, b._corner_pending = snap[1], snap[3]
                _plan_leg(b, i, start_st.alt_m, float(alt_caps[i + 1]), caps[i], bank_deg,
                          hold=True)
                state, term = leg_cls.build(b, start_st)
        except LegError as exc:
            b.finding("impossible", f"leg {i + 1} {leg.pt}: {exc} (line {leg.rec.line})")
            break
        state = b.settle(state)
        if not b.climbing and leg.rec.alt1_m is not None and term.kind == "fix":
            state = replace(state, alt_m=_descent_target(leg))
        if b.dep_cas_mps is not None:
            b.dep_legs.add(i)
        built.append(BuiltLeg(i, leg.rec, leg.pt, start_st, state, term, b.speed_mps,
                              coded=leg_cls.coded_path(b, term), resolved=leg,
                              from_fix=b.prev_fixes[i], departure_cas_mps=b.dep_cas_mps))
    return built


def _arrival_start_m(path: ProcedurePath, perf: Performance, params: BuildParams,
                     alt0_m: float) -> float | None:
    """The altitude an arrival built from ``alt0_m`` (m) is built again from, m, or None: it
    starts on the descent path planned back from its last constraint
    (:func:`~fms_testbed.path.profile.arrival_join_alt_m`), not above it at its first coded
    altitude (an 'at or below' far above the next fixes)."""
    alt = arrival_join_alt_m(path, params.descent_angle_deg, perf.tas_plan_mps,
                             PLAN_CLIMB_FRACTION * perf.descent_rate_max_mps, params.isa_dev_c)
    return alt if alt is not None and alt < alt0_m - 30.0 else None


def _plan_leg(b: LegBuilder, i: int, alt_m: float, alt_cap_m: float,
              cas_cap_mps: float | None, bank_deg: float, hold: bool = False) -> None:
    """Set the builder up for leg ``i`` planned from ``alt_m`` (m): its climb cap (m), its
    settings (the wind at its planned altitude; a hold in a climb: the strongest up to the
    climb top, planned at the top), its planned speed (m/s, under ``cas_cap_mps``), climb
    gradient and turn radius R = V²/(g tan γ) at ``bank_deg`` — for the faster of this leg
    and the one before (a turn at its start is entered at the previous leg's speed). A
    departure leg is planned under the departure schedule
    (:meth:`~fms_testbed.legs.model.Performance.departure_cas_at_mps`), or with ``hold`` at
    the climb-out speed held since the acceleration height (the legs before are slowed to it:
    :func:`~fms_testbed.path.departure.departure_slowdowns`)."""
    leg, params, perf = b.legs[i], b.params0, b.perf
    b.i, b.alt_cap_m = i, alt_cap_m
    if leg.rec.missed_approach_start:
        b.climbing = True
    speed_in = b.speed_mps if i and not hold else None
    alt_plan = alt_m
    b.params = params.for_altitude(alt_plan)
    if b.climbing and leg_cls_hold(leg) and params.climb_top_m is not None:
        # guidance climbs on to the top in the hold (an HA is left only at the end of a
        # circuit): its turns are planned for the TAS at the top (constant CAS: the largest)
        top = max(alt_plan, min(params.climb_top_m, b.alt_cap_m))
        b.params = params.for_band(alt_plan, top)
        alt_plan = top
    b.leg_params[i] = b.params
    b.leg_alt_m[i] = alt_plan
    b.dep_cas_mps = departure.departure_cas_mps(b, alt_m) if b.climbing else None
    if hold:
        b.dep_cas_mps = perf.departure_cas_mps
    v_climb = planned_speed_mps(perf, leg, alt_plan, cas_cap_mps, params.isa_dev_c)
    b.speed_mps = v_climb
    if b.dep_cas_mps is not None:
        cas_cap_mps = b.dep_cas_mps if cas_cap_mps is None else min(cas_cap_mps,
                                                                     b.dep_cas_mps)
        b.speed_mps = planned_speed_mps(perf, leg, alt_plan, cas_cap_mps, params.isa_dev_c)
    # the climb at the gradient of the speed without the departure schedule: the vertical
    # profile (:func:`~fms_testbed.path.profile.plan_profile`) climbs at that one too
    b.gradient = perf.climb_gradient_at(v_climb) if b.climbing else 0.0
    b.radius_m = turn_radius_m(max(b.speed_mps, speed_in or 0.0) + b.wind_mps, bank_deg, b.g)


def _start_kind(db: Database, seq: Sequence, legs: list[ResolvedLeg], st: FlightState) -> str:
    if st.track_deg is not None and seq.proc_type == "D" and not LEG_TYPES[legs[0].pt].initial \
            and runway_record(db, seq.airport, seq.transition):
        return "runway"
    return "fix" if legs[0].fix is not None else "airport"


def _descent_target(leg: ResolvedLeg) -> float:
    r = leg.rec
    if r.alt_desc == "B" and r.alt2_m is not None:
        return 0.5 * (r.alt1_m + r.alt2_m)
    return r.alt1_m


def _attach_segments(built: list[BuiltLeg], segs: list[PathSegment]) -> list[BuiltLeg]:
    first: dict[int, int] = {}
    count: dict[int, int] = {}
    for k, s in enumerate(segs):
        first.setdefault(s.leg_index, k)
        count[s.leg_index] = count.get(s.leg_index, 0) + 1
    return [replace(lg, seg_first=first.get(lg.index, first.get(lg.index - 1, 0)),
                    seg_count=count.get(lg.index, 0)) for lg in built]


def round_corners(b: LegBuilder, perf: Performance, params: BuildParams, bank_deg: float,
                  depth: int = 0) -> list[PathSegment]:
    """Replace every sharp fly-by corner by a tangent arc (with the monitor's corrections)."""
    segs = b.segments
    out: list[PathSegment] = []
    gmax = min(params.bank_limit_deg, perf.bank_max_deg)
    for k, seg in enumerate(segs):
        if k in b.corners and out and isinstance(seg.geom, Arc) \
                and isinstance(out[-1].geom, Line):
            out.extend(_line_arc_fillet(b, out, seg, perf, params, bank_deg))
            continue
        if k in b.corners and out and isinstance(seg.geom, Line) \
                and isinstance(out[-1].geom, Arc):
            avail = seg.geom.length_m() * (0.5 if (k + 1) in b.corners else 1.0)
            out.extend(_arc_line_fillet(b, out, seg, perf, params, bank_deg, avail))
            continue
        if k not in b.corners or not out or not isinstance(seg.geom, Line) \
                or not isinstance(out[-1].geom, Line):
            out.append(seg)
            continue
        _line_line_corner(b, out, seg, k, perf, params, bank_deg, gmax, depth)
    return out


def _line_line_corner(b: LegBuilder, out: list[PathSegment], seg: PathSegment, k: int,
                      perf: Performance, params: BuildParams, bank_deg: float, gmax: float,
                      depth: int) -> None:
    """Round the fly-by corner between the line ``out[-1]`` and the line ``seg`` (segment
    ``k``) with an arc of R = V²/(g tan γ), lead L = R tan(Ω/2); where L does not fit the
    monitor's branches R (R_geom = L_avail / tan(Ω/2)), V,γ (V_reg = √(R_geom g tan γ_max))
    and V,γ,φ,λ (flown over) in turn. Appends to ``out`` (its last line trimmed in place)."""
    a = out[-1]
    omega = wrap180(seg.geom.start_course_deg - a.geom.end_course_deg)
    if abs(omega) < 0.5:
        out.append(seg)
        return
    # the aircraft enters the turn at the inbound speed and leaves it at the outbound one:
    # plan the radius for the faster, which the bank limit must cover
    v = max(a.speed_mps, seg.speed_mps)
    # planned for the largest ground speed over the turn's tracks (class 1: the wind at
    # the corner, where the leg after it starts)
    cp = b.use_leg_params(seg.leg_index)
    w = max_tailwind_mps(cp.wind_speed_mps, cp.wind_from_deg, a.geom.end_course_deg, omega)
    r = turn_radius_m(v + w, bank_deg, b.g)
    t = math.tan(math.radians(abs(omega)) / 2.0)
    avail_a = a.geom.length_m()  # already trimmed by the previous corner, if any
    avail_c = seg.geom.length_m() * (0.5 if (k + 1) in b.corners else 1.0)
    l_avail = max(min(avail_a, avail_c), 0.0)
    bank = bank_deg
    fix = a.fix_ident or f"the intercept of {seg.path_term} {seg.fix_ident}"
    if r * t > l_avail:
        r_geom = l_avail / t
        why = conditions_text(v, w, cp.isa_dev_c, b.leg_alt_m.get(seg.leg_index, 0.0), r,
                              l_avail / t, bank_deg, b.g)
        if r_geom <= 1.0:
            out.extend(_flyover(b, a, seg, omega, turn_radius_m(v + w, gmax, b.g), depth))
            return
        g_reg = math.degrees(math.atan((v + w) ** 2 / (r_geom * b.g)))
        if g_reg <= gmax:
            b.finding("correction", f"fly-by at {fix}: radius {r:.0f} -> {r_geom:.0f} m, "
                      f"bank {bank_deg:.0f} -> {g_reg:.1f}° (turn {omega:+.0f}°){why}", "R",
                      leg_index=a.leg_index)
            r, bank = r_geom, g_reg
        else:
            v_reg = math.sqrt(r_geom * b.g * math.tan(math.radians(gmax))) - w
            if v_reg >= perf.tas_min_mps:
                b.finding("correction", f"fly-by at {fix}: speed {v / KT_MPS:.0f} -> "
                          f"{v_reg / KT_MPS:.0f} kt, bank {gmax:.0f}°, radius "
                          f"{r_geom:.0f} m (turn {omega:+.0f}°){why}", "V,γ",
                          leg_index=a.leg_index)
                r, bank, v = r_geom, gmax, v_reg
            else:
                # flown over at the bank limit and the speed flown there: slowing down
                # needs distance the corner does not have
                out.extend(_flyover(b, a, seg, omega, turn_radius_m(v + w, gmax, b.g),
                                    depth))
                return
    _fillet_lines(out, a, seg, omega, r, r * t, v, bank)


def _fillet_lines(out: list[PathSegment], a: PathSegment, seg: PathSegment, omega: float,
                  r: float, lead: float, v: float, bank: float) -> None:
    """The fly-by arc of radius ``r`` (m) and turn ``omega`` (deg) between the line ``a``
    (the last of ``out``, trimmed in place by ``lead`` m) and the line ``seg``; appended to
    ``out`` with the rest of ``seg`` (planned at ``v`` m/s and ``bank`` deg)."""
    la = a.geom.length_m()
    t1 = a.geom.point_at(la - lead)
    crs1 = a.geom.course_at(la - lead)
    arc = turn_arc(t1[0], t1[1], crs1, omega, r)
    new_a = Line(a.geom.start_lat_deg, a.geom.start_lon_deg, *arc.start)
    out[-1] = replace(a, geom=new_a)
    if new_a.length_m() < 0.01:
        out.pop()
    out.append(PathSegment(arc, a.leg_index, a.path_term, a.fix_ident, "flyby", v, bank,
                           lead))
    t2 = seg.geom.point_at(lead)
    # end the arc exactly where the next line resumes
    fixed = retarget_arc(arc, t2)
    out[-1] = replace(out[-1], geom=fixed)
    rest = Line(*fixed.end, seg.geom.end_lat_deg, seg.geom.end_lon_deg)
    if rest.length_m() >= 0.01:
        out.append(replace(seg, geom=rest))


def planned_conditions(tas_mps: float, tailwind_mps: float, isa_dev_c: float,
                       alt_m: float) -> tuple[str, float] | None:
    """The planned conditions of a class-1 finding in words, and the TAS the same CAS has in
    calm ISA air (m/s): e.g. ("245 kt TAS + 30 kt tailwind, ISA+20", 238.1 kt in m/s); None in
    calm ISA air.

    Parameters
    ----------
    tas_mps : planned TAS, m/s; tailwind_mps : planned wind along the turn, m/s
    isa_dev_c : planned ISA deviation, K; alt_m : the leg's planned altitude, m
    """
    if tailwind_mps <= 0.05 and abs(isa_dev_c) < 0.05:
        return None
    cond = f"{tas_mps / KT_MPS:.0f} kt TAS"
    if tailwind_mps > 0.05:
        cond += f" + {tailwind_mps / KT_MPS:.0f} kt tailwind"
    if abs(isa_dev_c) >= 0.05:
        cond += f", ISA{isa_dev_c:+.0f}"
    v_isa = tas_mps
    if isa_dev_c:
        v_isa = float(cas_to_tas(tas_to_cas(tas_mps, alt_m, isa_dev_c), alt_m))
    return cond, v_isa


def conditions_text(tas_mps: float, tailwind_mps: float, isa_dev_c: float, alt_m: float,
                    radius_m: float, radius_fit_m: float, bank_deg: float, g_mps2: float) -> str:
    """What the planned conditions do to a turn that does not fit, for a class-1 finding
    (Danilin 2017: the current conditions change the plan parameters): '' in calm ISA air,
    else e.g. "; turn radius 3120 m at 245 kt TAS + 30 kt tailwind, ISA+20 (2480 m in calm ISA
    air) exceeds the 2800 m the legs leave: forced by the conditions" — the radius
    R = (V + W)² / (g tan γ) against the calm-ISA one for the same CAS.

    Parameters
    ----------
    tas_mps : planned TAS, m/s; tailwind_mps : planned wind along the turn, m/s
    isa_dev_c : planned ISA deviation, K; alt_m : the leg's planned altitude, m
    radius_m : radius planned in these conditions, m
    radius_fit_m : largest radius the legs leave room for, m; bank_deg : planned bank, deg
    g_mps2 : gravity, m/s²
    """
    planned = planned_conditions(tas_mps, tailwind_mps, isa_dev_c, alt_m)
    if planned is None:
        return ""
    cond, v_isa = planned
    r_calm = turn_radius_m(v_isa, bank_deg, g_mps2)
    forced = ": forced by the conditions" if r_calm <= radius_fit_m else ""
    return (f"; turn radius {radius_m:.0f} m at {cond} ({r_calm:.0f} m in calm ISA air) "
            f"exceeds the "
            f"{radius_fit_m:.0f} m the legs leave{forced}")


def _line_arc_fillet(b: LegBuilder, out: list[PathSegment], seg: PathSegment,
                     perf: Performance, params: BuildParams, bank_deg: float
                     ) -> list[PathSegment]:
    """Fly-by from a line onto a coded arc (CI/VI onto a DME arc, a non-tangent RF entry)
    (:func:`~.fillets.line_arc_fillet`); γ is raised to the monitor's limit when the planned
    radius does not fit. Returns the segments that replace ``seg`` (``out[-1]`` is trimmed in
    place); when no fillet fits the sharp corner is kept (the monitor then reports the track
    jump)."""
    a = out[-1]
    v = min(a.speed_mps, seg.speed_mps)
    b.use_leg_params(seg.leg_index)
    w = b.wind_mps
    gmax = min(params.bank_limit_deg, perf.bank_max_deg)
    for bank in (bank_deg, gmax):
        r = turn_radius_m(v + w, bank, b.g)
        f = line_arc_fillet(a.geom, seg.geom, r)
        if f is None:
            continue
        if f.line is None:
            out.pop()
        else:
            out[-1] = replace(a, geom=f.line)
        g_used = math.degrees(math.atan((v + w) ** 2 / (r * b.g)))
        res = [PathSegment(f.fillet, a.leg_index, a.path_term, a.fix_ident, "flyby", v, g_used,
                           f.lead_m)]
        if f.gap is not None:
            res.append(replace(seg, geom=f.gap, role="connector"))
        res.append(replace(seg, geom=f.arc))
        if bank > bank_deg:
            b.finding("correction", f"fly-by onto the {seg.path_term} arc: bank "
                      f"{bank_deg:.0f} -> {g_used:.1f}°, radius {r:.0f} m", "γ",
                      leg_index=seg.leg_index)
        return res
    return [seg]


def _arc_line_fillet(b: LegBuilder, out: list[PathSegment], seg: PathSegment,
                     perf: Performance, params: BuildParams, bank_deg: float,
                     avail_m: float) -> list[PathSegment]:
    """Fly-by from the end of a coded arc (RF/AF end fix) onto the line that leaves it (the
    CF, TF or DF after it) (:func:`~.fillets.arc_line_fillet`); γ is raised to the monitor's
    limit when the planned radius does not fit in ``avail_m`` of the line. ``out[-1]`` (the
    arc) is trimmed in place; returns what replaces ``seg``. When no fillet fits the corner is
    flown over the fix: the line's leg rejoins its course (branch V,γ,φ,λ)."""
    a = out[-1]
    v = max(a.speed_mps, seg.speed_mps)
    b.use_leg_params(seg.leg_index)
    w = b.wind_mps
    gmax = min(params.bank_limit_deg, perf.bank_max_deg)
    for bank in (bank_deg, gmax):
        r = turn_radius_m(v + w, bank, b.g)
        f = arc_line_fillet(a.geom, seg.geom, r, avail_m)
        if f is None:
            continue
        out[-1] = replace(a, geom=f.arc)
        if f.gap is not None:
            out.append(replace(a, geom=f.gap, role="connector"))
        g_used = math.degrees(math.atan((v + w) ** 2 / (r * b.g)))
        res = [PathSegment(f.fillet, a.leg_index, a.path_term, a.fix_ident, "flyby", v, g_used,
                           f.lead_m)]
        if f.line is not None:
            res.append(replace(seg, geom=f.line))
        if bank > bank_deg:
            b.finding("correction", f"fly-by off the {a.path_term} arc at {a.fix_ident}: bank "
                      f"{bank_deg:.0f} -> {g_used:.1f}°, radius {r:.0f} m", "γ",
                      leg_index=a.leg_index)
        return res
    omega = wrap180(seg.geom.start_course_deg - a.geom.end_course_deg)
    return _flyover(b, a, seg, omega, turn_radius_m(v + w, gmax, b.g))


def _flyover(b: LegBuilder, a: PathSegment, seg: PathSegment, omega: float, r: float,
             depth: int = 0) -> list[PathSegment]:
    """Branch V,γ,φ,λ: the turn cannot be cut inside the fixes; fly over the corner, turn at
    the bank limit (radius ``r``, planned for the speed flown there: there is no room to slow
    down) and rejoin the next line's course before its end. A departure leg's turn is
    planned :data:`~fms_testbed.core.planning.ARC_BANK_MARGIN_DEG` below the bank limit (its
    speed is the lowest flown clean, and its TAS grows in the climb through the turn)."""
    gmax = min(b.params.bank_limit_deg, b.perf.bank_max_deg)
    if seg.leg_index in b.dep_legs and gmax > ARC_BANK_MARGIN_DEG:
        r *= math.tan(math.radians(gmax)) / math.tan(math.radians(gmax - ARC_BANK_MARGIN_DEG))
    at = a.fix_ident or f"the intercept of {seg.path_term} {seg.fix_ident}"
    b.finding("correction", f"fly-by at {at} (turn {omega:+.0f}°) "
              f"does not fit even at minimum speed: flown over the fix, radius {r:.0f} m",
              "V,γ,φ,λ", leg_index=a.leg_index)
    lat, lon = a.geom.end
    end = seg.geom.end
    # rejoin the next line's own course before its end, so that the legs built after it (which
    # assumed that course) still start tangent to the path
    tmp = LegBuilder(b.legs, b.perf, b.params, b.g, b.prev_fixes)
    # the turn is flown at the speed that gives radius r at the bank limit
    v_turn = min(seg.speed_mps,
                 math.sqrt(r * b.g * math.tan(math.radians(gmax))) - b.wind_mps)
    tmp.i, tmp.speed_mps, tmp.radius_m = seg.leg_index, v_turn, r
    tmp.climbing = False
    tmp.flown_before_m = b.flown_before_m + sum(
        x.geom.length_m() for x in b.segments if x.leg_index < seg.leg_index)
    target = Fix(ident=seg.fix_ident, region="", section="", lat_deg=end[0], lon_deg=end[1])
    state = FlightState(lat, lon, a.geom.end_course_deg, 0.0, flyby=False)
    join_course(tmp, state, target, seg.geom.end_course_deg, "R" if omega > 0 else "L", False,
                course_leg=LEG_TYPES[seg.path_term].course_to_fix)
    if depth == 0:
        segs = round_corners(tmp, b.perf, b.params, math.degrees(math.atan(
            (v_turn + b.wind_mps) ** 2 / (r * b.g))), depth=1)
    else:
        segs = tmp.segments
    out = [replace(x, role="turn" if x.role == "leg" else x.role) for x in segs[:-1]]
    out.append(replace(segs[-1], role=seg.role) if segs else replace(
        seg, geom=Line(lat, lon, *end)))
    b.findings.extend(f for f in tmp.findings if f.category != "info")
    return out  # 'a' is already in the caller's output list
