"""Issue 12, classes A-I and the builder defects the PDE measurement exposed: the built path
(no flight), each on real records of the FAA cycle 2301 and on a synthetic record.

The CIFP is loaded once for the module (skipped, with the reason, when it is not beside the
repository); the synthetic records come from :mod:`fms_testbed.procedures.synth`.
"""

from __future__ import annotations

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.procedure import parse_procedure
from fms_testbed.core.geodesy import gravity_mps2, inverse, wrap180
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import FT_M as FT
from fms_testbed.core.units import KT_MPS
from fms_testbed.core.units import NM_M as NM
from fms_testbed.guidance.active_path import smooth_connectors
from fms_testbed.guidance.pde import path_pde_m, segment_pde_m
from fms_testbed.legs.construct import centre_through
from fms_testbed.legs.model import BuildParams, max_tailwind_mps, turn_radius_m
from fms_testbed.path.monitor import check_path
from fms_testbed.path.plan import _perf_params, build_procedure, merge_parts, select_parts
from fms_testbed.path.profile import plan_profile
from fms_testbed.path.segmentation import build_sequence, runway_part
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.procedures.synth import offset, waypoint_record
from tests.path.test_world import APT, PARAMS, PERF, build, world




@pytest.fixture(scope="module")
def b737():
    return load_aircraft("737")


def flyable(db, cfg, airport, procedure, transition=None, runway=None, wind=None):
    """The procedure built and checked as a flight would fly it (select, merge, build)."""
    spec = parse_procedure({"airport": airport, "procedure": procedure,
                            "transition": transition, "runway": runway}, "test")
    return build_procedure(db, spec, cfg, wind=wind)


def fp_seq(db, cfg, airport, procedure, transition=None, runway=None):
    """The merged sequence a flight of the procedure flies."""
    return merge_parts(select_parts(db, airport, procedure, transition, runway))


def transition(db, airport, name):
    seq = next(s for s in db.sequences(airport) if s.name == name)
    return seq


def dist(a, b):
    return inverse(a[0], a[1], b[0], b[1])[0]


def app(pt, seq, **kw):
    return L("XTST", "T09", pt, seq, proc_type="F", transition="", route_type="R", **kw)


def sid(pt, seq, **kw):
    return L("XTST", "TSID1", pt, seq, proc_type="D", transition="RW09", route_type="1", **kw)


def continuity(path, tol_m=0.02, tol_deg=1.0, skip_roles=()):
    """Largest (gap m, track jump deg) between consecutive segments."""
    gap = jump = 0.0
    for a, b in zip(path.segments, path.segments[1:]):
        gap = max(gap, dist(a.geom.end, b.geom.start))
        if a.geom.length_m() > 1.0 and b.geom.length_m() > 1.0 and \
                a.role not in skip_roles and b.role not in skip_roles:
            jump = max(jump, abs(wrap180(b.geom.start_course_deg - a.geom.end_course_deg)))
    return gap, jump


# --------------------------------------------------------------------------- A: IF -> AF
def test_A_if_to_af_starts_on_the_arc_tangent_without_a_radial_connector(cifp, b737):
    """12J VOR/DME 30 via ITNEW: IF at a range 0.2 m off the end fix's: the arc is closed in the
    geometry (circle through both points) — no connector, the path starts tangent to it."""
    fp = flyable(cifp, b737, "12J", "D30", "ITNEW")
    p = fp.path
    first = p.segments[0]
    assert first.path_term == "AF" and isinstance(first.geom, Arc) and first.role == "leg"
    assert not [s for s in p.segments if s.role == "connector"]
    itnew = p.legs[0].termination
    assert dist(first.geom.start, (itnew.lat_deg, itnew.lon_deg)) < 0.05
    from fms_testbed.loop.procedure import initial_from_path
    hdg = initial_from_path(fp, b737)["heading_deg"]
    assert abs(wrap180(hdg - first.geom.start_course_deg)) < 0.01


def test_A_synthetic_if_37_m_off_the_dme_arc_is_closed_in_the_geometry(tmp_path):
    w = world()
    start = offset(*offset(*w["TVR"], 200.0, 10.0), 200.0, 37.0 / NM)   # 37 m outside
    p = build(tmp_path, [app("IF", 10, fix="WQ"),
                         app("AF", 20, fix="ARC2", turn="L", navaid="TVR", theta_deg=100.0,
                             rho_nm=10.0, course_deg=200.0)],
              extra=[waypoint_record("WQ", *start)])
    assert [s.role for s in p.segments] == ["leg"]
    arc = p.segments[0].geom
    wq, arc2 = p.legs[0].termination, p.legs[1].termination   # the records' positions
    assert dist(arc.start, (wq.lat_deg, wq.lon_deg)) < 0.05
    assert dist(arc.end, (arc2.lat_deg, arc2.lon_deg)) < 0.05
    assert dist(arc.centre, w["TVR"]) < 40.0   # the centre moves by about the gap
    assert p.status == "ok"


def test_centre_through_puts_both_points_on_the_circle():
    c0 = (50.0, 10.0)
    p = offset(*c0, 30.0, 5.0)
    f = offset(*c0, 120.0, 5.0 + 71.0 / NM)
    lat, lon, r = centre_through(p, f, c0)
    assert dist((lat, lon), p) == pytest.approx(r, abs=1e-3)
    assert dist((lat, lon), f) == pytest.approx(r, abs=1e-3)
    assert dist((lat, lon), c0) < 71.0


# --------------------------------------------------------------------------- B: PI
def test_B_pi_45_leg_lies_opposite_the_coded_turn_on_real_procedure_turns(cifp, b737):
    """PAFA VOR 20R via CUN: PI at CENTS, course 092 (45° right of the outbound 047), coded
    turn L. Built: outbound, a right 45° turn, the 45° leg, a left 180°, then the CF into DISTN
    joined on its coded course (before: the mirror image, 12 km beside the final course)."""
    p = flyable(cifp, b737, "PAFA", "S20R", "CUN").path
    k = next(lg.index for lg in p.legs if lg.path_term == "PI")
    own = [s.geom for s in p.segments if s.leg_index == k and s.role in ("leg", "flyby")]
    # the 180° turn is the coded left turn, after the 45° leg on 092 mag (113 true), which
    # lies right of the outbound 047 mag: the side away from the coded turn
    assert isinstance(own[-1], Arc) and round(own[-1].sweep_deg) == -180
    leg45 = own[-2]
    assert isinstance(leg45, Line)
    from fms_testbed.path.segmentation import resolve_legs
    pi = resolve_legs(cifp, fp_seq(cifp, b737, "PAFA", "S20R", "CUN"))[0][k]
    assert abs(wrap180(leg45.start_course_deg - pi.course_true_deg)) < 0.5
    # (here the intercept of the outbound course heads 113° true, the 45° leg's own course:
    # the two merge, no turn between them)
    cf = next(lg for lg in p.legs if lg.index == k + 1)
    assert cf.path_term == "CF"
    segs = smooth_connectors(list(p.segments))
    pde = [v for s, v in zip(segs, path_pde_m(segs, p.legs)) if s.leg_index == k + 1
           and math.isfinite(v)]
    assert pde and max(pde) < 50.0


def test_B_every_pi_of_the_cycle_codes_its_turn_opposite_its_45_degree_side(cifp):
    """The data behind the PI semantics: wherever a PI is followed by a CF, the coded course is
    ±45° off the outbound course and the coded turn direction is the other side (291 PIs)."""
    from fms_testbed.path.segmentation import resolve_legs
    n = 0
    for apt in cifp.airport_idents():
        for s in cifp.sequences(apt):
            if not any(lg.path_term == "PI" for lg in s.legs):
                continue
            legs, _ = resolve_legs(cifp, s)
            for a, b in zip(legs, legs[1:]):
                if a.pt != "PI" or b.pt != "CF" or a.course_true_deg is None:
                    continue
                side = wrap180(a.course_true_deg - b.course_true_deg - 180.0)
                assert 40.0 <= abs(side) <= 57.5, (s.name, side)
                assert a.rec.turn_dir == ("L" if side > 0 else "R"), s.name
                n += 1
    assert n > 250


# --------------------------------------------------------------------------- C: RF gap
def test_C_rf_71_m_off_the_previous_fix_is_closed_without_a_connector(tmp_path):
    """The RF's end fix lies 71 m farther from the centre than the previous fix: the arc
    starts at the previous fix (no radial connector flown as a direct-to)."""
    w = world()
    centre = offset(*w["WB"], 0.0, 2.0)
    c = offset(*centre, 90.0, 2.0 + 71.0 / NM)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("RF", 30, fix="WC", turn="L", centre="CTR", arc_radius_nm=2.0)],
              extra=[waypoint_record("WC", *c), waypoint_record("CTR", *centre)])
    assert not [s for s in p.segments if s.role == "connector"]
    rf = [s for s in p.segments if s.path_term == "RF" and s.role == "leg"]
    wb, wc = p.legs[1].termination, p.legs[2].termination
    # the arc through WB and WC (its start tangent 1° off the TF: a short fillet cuts it)
    assert len(rf) == 1 and dist(rf[0].geom.start, (wb.lat_deg, wb.lon_deg)) < 30.0
    assert dist(rf[0].geom.end, (wc.lat_deg, wc.lon_deg)) < 0.05
    gap, jump = continuity(p)
    assert gap < 0.05 and jump < 0.5


def test_C_real_rf_entries_have_no_connector(cifp):
    """KABQ RNAV (RNP) 03 via CMSTR: the TF-RF junctions had 0.1 m radial connectors."""
    p = build_sequence(cifp, transition(cifp, "KABQ", "KABQ APPROACH H03-Z CMSTR"), PERF)
    assert any(s.path_term == "RF" for s in p.segments)
    assert not [s for s in p.segments if s.role == "connector"]


# --------------------------------------------------------------------------- D: runway part
def test_D_merged_sid_name_starts_at_the_runway(cifp, b737):
    """KCLT KILNS4 RW18C + AUDII: merged name 'RW18C+AUDII'; the runway part is RW18C, so the
    SID starts at its departure end 35 ft above the threshold, not at the VA's altitude."""
    fp = flyable(cifp, b737, "KCLT", "KILNS4", "AUDII", "18C")
    p = fp.path
    assert p.transition == "RW18C+AUDII" and p.start_kind == "runway"
    rwy = cifp.terminal[("KCLT", "RW18C")][0]
    assert p.legs[0].start.alt_m == pytest.approx(rwy.elev_m + 35 * FT, abs=0.01)
    assert runway_part("RW18C+AUDII") == "RW18C" and runway_part("ALL+AUDII") == ""


# --------------------------------------------------------------------------- E: direct-to
def test_E_direct_to_after_vectors_is_built_with_its_fly_by(cifp):
    """KBCT MYZNR2 RW05: VM vectors, then IF JAVAA 17.7 NM away, then TF: the bridge is built
    as a direct-to (turn + line, role 'connector') and the corner at JAVAA is a tangent fly-by
    — guidance flies the built path, so no kink overshoots at the next corner."""
    p = build_sequence(cifp, transition(cifp, "KBCT", "KBCT SID MYZNR2 RW05"), PERF)
    conn = [s for s in p.segments if s.role == "connector"]
    assert [type(s.geom) for s in conn] == [Arc, Line]
    k = p.segments.index(conn[-1])
    assert p.segments[k + 1].role == "flyby"
    gap, jump = continuity(p)
    assert gap < 0.05 and jump < 1.0
    assert smooth_connectors(list(p.segments)) == list(p.segments)   # flown as built


def test_E_synthetic_vectors_then_if_far_away(tmp_path):
    w = world()
    p = build(tmp_path, [sid("VM", 10, course_deg=90.0), sid("IF", 20, fix="WS"),
                         sid("TF", 30, fix="WA")])
    conn = [s for s in p.segments if s.role == "connector"]
    assert conn and isinstance(conn[0].geom, Arc)
    assert any(s.role == "flyby" and s.leg_index == 1 for s in p.segments)
    gap, jump = continuity(p)
    assert gap < 0.05 and jump < 1.0
    assert dist(p.segments[-1].geom.end, w["WA"]) < 0.5


# --------------------------------------------------------------------------- G: descent
def test_G_final_approach_keeps_its_coded_path_angle(cifp, b737):
    """PAFA VOR 20R via CUN: the start (4,000 ft) lies above the geometric path; the planner
    used to stay high and was then refused (16.2 %). Now the final HERIL-ILTAF is planned on
    the coded 3.26°, and the earlier descent is within the aircraft's gradient."""
    fp = flyable(cifp, b737, "PAFA", "S20R", "CUN")
    prof = fp.path.profile
    g = prof.gradients()
    assert -g[-1] == pytest.approx(math.tan(math.radians(3.26)), rel=0.02)
    perf, _ = _perf_params(b737, parse_procedure({"airport": "PAFA", "procedure": "S20R"}, "t"))
    assert all(-x <= perf.descent_rate_max_mps / perf.tas_plan_mps * 1.001
               for x in g if math.isfinite(x))


def test_G_synthetic_high_start_descends_early_not_steep_at_the_end(tmp_path):
    w = world()
    faf = offset(*w["WB"], 270.0, 5.0)
    recs = [app("IF", 10, fix="WA", alt_desc="+", alt1_ft=6000),
            app("TF", 20, fix="WF", alt_desc="+", alt1_ft=1500),
            app("TF", 30, fix="WB", alt_desc=" ", alt1_ft=300)]
    recs[2] = recs[2][:102] + "-300" + recs[2][106:]   # VPA -3.00° (cols 103-106)
    p = build(tmp_path, recs, extra=[waypoint_record("WF", *faf)])
    g_max = PERF.descent_rate_max_mps / PERF.tas_plan_mps
    prof = plan_profile(p, 0.05, 6000 * FT, descent_gradient_max=g_max)
    g = prof.gradients()
    assert -g[-1] == pytest.approx(math.tan(math.radians(3.0)), rel=0.01)   # the coded VPA
    assert max(-x for x in g if math.isfinite(x)) <= g_max * 1.001
    # the old forward pass stayed on 3° from the start and dived into the final
    assert -g[-2] > math.tan(math.radians(3.0)) * 1.2


# --------------------------------------------------------------------------- H: SID join
def test_H_sid_joined_at_a_fix_starts_at_its_climb_altitude_not_the_field(cifp, b737):
    """3R9 AEROZ2 via SJT (no runway): the transition starts at a VOR with no altitude; it is
    planned there at the altitude of a climb from the field, not near field elevation."""
    fp = flyable(cifp, b737, "3R9", "AEROZ2", "SJT")
    apt = cifp.airports["3R9"]
    start = fp.path.legs[0].start
    d = dist((apt.lat_deg, apt.lon_deg), (start.lat_deg, start.lon_deg))
    assert d > 10 * NM
    assert start.alt_m > apt.elev_m + 0.5 * 0.05 * d


def test_H_monitor_flags_a_sid_start_too_low_for_its_climb_windows(tmp_path):
    p = build(tmp_path, [sid("IF", 10, fix="WB"),
                         sid("TF", 20, fix="WA", alt_desc="+", alt1_ft=12000)], checked=False)
    low = p.legs[0].start
    from dataclasses import replace as _r
    p_low = build_sequence_from(tmp_path, p, _r(low, alt_m=35 * FT))
    flags = [f for f in p_low.findings if "cannot make its climb constraints" in f.message]
    assert flags and p_low.status == "corrected"


def build_sequence_from(tmp_path, p, start):
    db = load_database(tmp_path / "synthetic.dat")
    seq = db.sequences("XTST")[0]
    return check_path(build_sequence(db, seq, PERF, PARAMS, start=start), PERF, PARAMS)


# --------------------------------------------------------------------------- I: wind
def test_I_turns_are_planned_for_the_ground_speed_in_wind(tmp_path):
    """A 30 kt wind: the hold's 180° turns and the leg turns are planned for TAS + wind at the
    planned bank, so the bank flown stays at it (R = V_g²/(g tan γ))."""
    wind = BuildParams(wind_speed_mps=30 * KT_MPS, wind_from_deg=270.0)
    legs = [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
            app("HM", 30, fix="WB", turn="R", course_deg=90.0, time_min=1.0)]
    calm = build(tmp_path, legs)
    windy = build(tmp_path, legs, params=wind)
    g = gravity_mps2(APT[0])
    r_calm = next(s.geom.radius_m for s in calm.segments if s.role == "hold")
    hold = next(s for s in windy.segments if s.role == "hold")
    assert hold.geom.radius_m == pytest.approx(
        turn_radius_m(hold.speed_mps + 30 * KT_MPS, PARAMS.bank_plan_deg, g), rel=1e-6)
    assert hold.geom.radius_m > 1.2 * r_calm
    assert hold.bank_deg == pytest.approx(PARAMS.bank_plan_deg, abs=1e-6)


def test_max_tailwind_over_a_turn():
    w = 15.0
    assert max_tailwind_mps(w, 270.0, 80.0, 20.0) == pytest.approx(w)      # passes 090
    assert max_tailwind_mps(w, 270.0, 0.0, 30.0) == pytest.approx(w * math.cos(math.radians(60)))
    assert max_tailwind_mps(w, 90.0, 0.0, 30.0) == 0.0                     # all headwind
    assert max_tailwind_mps(w, 270.0) == w and max_tailwind_mps(0.0, 270.0) == 0.0


# --------------------------------------------------------------------------- holds
@pytest.mark.parametrize("name", ["KENV SID ENV1 RW08", "KBFI APPROACH I14R SEA"])
def test_hold_entries_end_over_the_fix_on_the_inbound_course(cifp, name):
    """KENV ENV1 HA (teardrop, PDE 928 m before) and KBFI I14R SEA HF (1,628 m before): the
    entry (role 'turn') ends over the fix on the coded inbound course, so the circuit flown
    after it lies on the coded racetrack."""
    p = build_sequence(cifp, transition(cifp, name.split()[0], name), PERF)
    hold = next(lg for lg in p.legs if lg.path_term in ("HA", "HF", "HM"))
    segs = [s for s in p.segments if s.leg_index == hold.index]
    entry = [s for s in segs if s.role == "turn"]
    assert entry
    inbound = hold.record.course_deg
    from fms_testbed.path.segmentation import resolve_legs
    crs = resolve_legs(cifp, transition(cifp, name.split()[0], name))[0][hold.index]
    assert abs(wrap180(entry[-1].geom.end_course_deg - crs.course_true_deg)) < 1.0
    assert dist(entry[-1].geom.end, (hold.termination.lat_deg, hold.termination.lon_deg)) < 1.0
    scored = [segment_pde_m(s, hold) for s in segs if s.role in ("hold", "leg")]
    assert inbound is not None and (not scored or max(scored) < 5.0)


@pytest.mark.parametrize("inbound, kind", [(45.0, "direct"), (300.0, "teardrop"),
                                           (200.0, "parallel")])
def test_synthetic_hold_entries_of_every_sector_end_on_the_inbound_course(tmp_path, inbound,
                                                                          kind):
    """Arriving eastbound at WH, a right-hand hold on three inbound courses: one entry of each
    ICAO sector, each ending over the fix on the inbound course, so the circuit is exact."""
    from fms_testbed.legs.holds import entry_kind
    w = world()
    fixp = offset(*w["WB"], 90.0, 3.0)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WH"),
                         app("HM", 30, fix="WH", turn="R", course_deg=inbound, time_min=1.0)],
              extra=[waypoint_record("WH", *fixp)])
    arrival = [s for s in p.segments if s.leg_index == 1][-1].geom.end_course_deg
    assert entry_kind(arrival, inbound, "R") == kind
    segs = [s for s in p.segments if s.leg_index == 2]
    entry = [s for s in segs if s.role == "turn"]
    assert entry and abs(wrap180(entry[-1].geom.end_course_deg - inbound)) < 1.0
    assert dist(entry[-1].geom.end, fixp) < 1.0
    circuit = [segment_pde_m(s, p.legs[2]) for s in segs if s.role in ("hold", "leg")]
    assert len(circuit) == 4 and max(circuit) < 1.0


# --------------------------------------------------------------------------- TF, CF
def test_tf_after_an_af_leaves_the_arc_with_a_fly_by_on_its_track(cifp):
    """KTWF SNAKO3 via SAMAN: AF then TF turning 77° at YIRUR (13.4 km PDE before)."""
    p = build_sequence(cifp, transition(cifp, "KTWF", "KTWF SID SNAKO3 SAMAN"), PERF)
    segs = smooth_connectors(list(p.segments))
    pde = path_pde_m(segs, p.legs)
    tf = [v for s, v in zip(segs, pde) if s.path_term == "TF" and math.isfinite(v)]
    assert tf and max(tf) < 1.0
    k = next(i for i, s in enumerate(p.segments) if s.path_term == "AF" and s.role == "flyby")
    assert isinstance(p.segments[k - 1].geom, Arc)
    gap, jump = continuity(p)
    assert gap < 0.05 and jump < 1.0


def test_cf_heading_away_from_its_fix_is_joined_upstream(cifp):
    """17J VOR-A: a CA climbs away from DEBTS, then CF DEBTS on 224 comes back: the course is
    joined upstream of the fix (the aircraft turns back onto it), so the CF's own path lies
    on it."""
    p = build_sequence(cifp, transition(cifp, "17J", "17J APPROACH VOR-A"), PERF)
    k = max(lg.index for lg in p.legs if lg.path_term == "CF")
    assert any("course into DEBTS joined" in f.message for f in p.findings if f.leg_index == k)
    segs = smooth_connectors(list(p.segments))
    pde = [v for s, v in zip(segs, path_pde_m(segs, p.legs))
           if s.leg_index == k and math.isfinite(v)]
    assert pde and max(pde) < 1.0


def test_cf_abeam_its_fix_after_vectors_is_joined_upstream(cifp):
    """KDAB ROYES7 RW07B: after 5 NM of vectors on 065, BARBS (CF course 358) lies abeam,
    20 km west: a direct-to would arrive across the course (PDE 52 km before); the course is
    joined upstream of the fix instead, so the CF's own path lies on it."""
    p = build_sequence(cifp, transition(cifp, "KDAB", "KDAB SID ROYES7 RW07B"), PERF)
    assert any("course into BARBS joined" in f.message for f in p.findings)
    segs = smooth_connectors(list(p.segments))
    pde = [v for s, v in zip(segs, path_pde_m(segs, p.legs))
           if s.path_term == "CF" and math.isfinite(v)]
    assert pde and max(pde) < 1.0
    assert dist(p.segments[-1].geom.end, (p.legs[-1].termination.lat_deg,
                                          p.legs[-1].termination.lon_deg)) < 0.5


@pytest.mark.parametrize("name, text, cls", [
    ("KDFW SID ARDIA7 RW35C", "fly-by at MECHL", 1),         # speed/bank: the conditions
    ("KSMX SID BUELT4 RW12", "IF GLJ away", 2),               # a discontinuity bridged
    ("3AU APPROACH VDM-A", "doubles back", 3),                # the coding (Fig. 4)
])
def test_findings_say_which_of_danilins_classes_forced_them(cifp, name, text, cls):
    p = check_path(build_sequence(cifp, transition(cifp, name.split()[0], name), PERF), PERF)
    f = next(f for f in p.findings if text in f.message)
    assert f.danilin_class == cls


def test_final_joined_at_the_hold_fix_after_an_hf_course_reversal(cifp):
    """KBRD ILS 23 via HUUTA: the transition ends in an HF at LAREW; the final starts at its IF
    CFCJD, 4 NM outbound of LAREW. The final is joined at LAREW (the aircraft is there on the
    inbound course) instead of flying back out to CFCJD in a 180° loop."""
    seq = fp_seq(cifp, None, "KBRD", "I23", "HUUTA")
    assert [lg.path_term for lg in seq.legs] == ["IF", "TF", "HF", "CF"]
    assert seq.legs[-1].fix.ident.startswith("RW")


def test_final_if_after_a_procedure_turn_is_joined_on_the_inbound_course(cifp, b737):
    """KAIZ VOR 04 via ROACH: PI at SHY, then the final's IF WYLEY (on the inbound course,
    outbound of SHY) and CF SHY: the turn's 45° intercept joins that course through WYLEY
    (no direct-to onto the IF), and the intercept falls outside WYLEY."""
    p = flyable(cifp, b737, "KAIZ", "S04", "ROACH").path
    k = next(lg.index for lg in p.legs if lg.path_term == "IF" and lg.index > 0)
    assert not [s for s in p.segments if s.leg_index == k and s.role == "connector"]
    gap, jump = continuity(p)
    assert gap < 0.05 and jump < 1.0
