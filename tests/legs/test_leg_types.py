"""One test per path terminator, on synthetic records (FD and CR included: absent from FAA data)."""

import math

import pytest

from fms_testbed.legs.construct import _foot
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.procedures.legrecord import PATH_TERMINATORS
from fms_testbed.legs.model import isa_tas_mps, turn_radius_m
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.procedures.synth import offset, waypoint_record
from fms_testbed.core.segments import Arc
from fms_testbed.core.geodesy import gravity_mps2, inverse
from fms_testbed.core.units import FT_M as FT
from fms_testbed.core.units import KT_MPS
from fms_testbed.core.units import NM_M as NM
from tests.path.test_world import APT, PARAMS, PERF, build, world

G = gravity_mps2(APT[0])
R_PLAN = turn_radius_m(PERF.tas_plan_mps, PARAMS.bank_plan_deg, G)


def sid(pt, seq, **kw):
    return L("XTST", "TSID1", pt, seq, proc_type="D", transition="RW09", route_type="1", **kw)


def app(pt, seq, **kw):
    return L("XTST", "T09", pt, seq, proc_type="F", transition="", route_type="R", **kw)


def end_of(path):
    return path.segments[-1].geom.end


def dist(a, b):
    return inverse(a[0], a[1], b[0], b[1])[0]


def arcs(path, role=None):
    return [s for s in path.segments if isinstance(s.geom, Arc) and (role is None or s.role == role)]


def test_table_has_all_23_path_terminators():
    assert sorted(LEG_TYPES) == sorted(PATH_TERMINATORS) and len(LEG_TYPES) == 23


def test_if_tf_ends_at_fix_with_geodesic_length(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB")])
    w = world()
    assert p.status == "ok"
    assert dist(end_of(p), w["WB"]) < 0.5
    assert p.length_m() == pytest.approx(dist(w["WA"], w["WB"]), abs=1.0)
    assert p.legs[1].termination.kind == "fix"


def test_tf_fly_by_turn_uses_radius_and_lead_from_speed_and_bank(tmp_path):
    w = world()
    c = offset(*w["WB"], 150.0, 15.0)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("TF", 30, fix="WC")], extra=[waypoint_record("WC", *c)])
    fb = arcs(p, "flyby")
    assert len(fb) == 1
    arc = fb[0].geom
    # the planned speed is flown as a CAS — an approach's at most 210 kt (issue 12) — : its
    # TAS at the leg's planned altitude
    from fms_testbed.legs.model import APPROACH_CAS_MPS
    v = isa_tas_mps(min(PERF.tas_plan_mps, APPROACH_CAS_MPS), p.legs[1].end.alt_m)
    assert fb[0].speed_mps == pytest.approx(v, rel=1e-6)
    r_plan = turn_radius_m(v, PARAMS.bank_plan_deg, G)
    assert arc.radius_m == pytest.approx(r_plan, rel=1e-6)
    assert arc.sweep_deg == pytest.approx(60.0, abs=0.3)
    lead = r_plan * math.tan(math.radians(abs(arc.sweep_deg)) / 2)
    assert dist(arc.start, w["WB"]) == pytest.approx(lead, abs=1.0)
    assert dist(arc.end, w["WB"]) == pytest.approx(lead, abs=1.0)
    assert fb[0].bank_deg == pytest.approx(PARAMS.bank_plan_deg, abs=1e-6)


def test_fly_over_fix_is_passed_then_rejoined(tmp_path):
    w = world()
    c = offset(*w["WB"], 150.0, 15.0)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB", desc="EY  "),
                         app("TF", 30, fix="WC")], extra=[waypoint_record("WC", *c)])
    assert not [a for a in arcs(p, "flyby") if a.leg_index == 1]   # no fly-by at WB
    assert min(dist(s.geom.end, w["WB"]) for s in p.segments) < 0.5   # over the fix
    turn = arcs(p, "turn")[0]
    assert dist(turn.geom.start, w["WB"]) < 0.5 and turn.geom.sweep_deg > 0
    assert dist(end_of(p), c) < 0.5
    # the track WB-WC is rejoined: the leg's own straight lies on it
    last = p.segments[-1]
    mid = last.geom.point_at(0.5 * last.geom.length_m())
    _, az, _ = inverse(*w["WB"], *c)
    assert last.role == "leg" and abs(_foot(*w["WB"], az, *mid)[1]) < 1.0


def test_cf_intercepts_the_course_and_ends_on_it(tmp_path):
    w = world()
    p = build(tmp_path, [app("IF", 10, fix="WN"), app("CF", 20, fix="WB", course_deg=90.0)])
    assert dist(end_of(p), w["WB"]) < 0.5
    assert p.segments[-1].geom.end_course_deg == pytest.approx(90.0 + 0.0, abs=0.5) or \
        abs(((p.segments[-1].geom.end_course_deg - 90.0) + 180) % 360 - 180) < 0.5
    # the last straight lies on the coded course line
    mid = p.segments[-1].geom.point_at(p.segments[-1].geom.length_m() / 2)
    assert abs(_foot(*w["WB"], 90.0, *mid)[1]) < 1.0


def test_df_turns_the_coded_way_even_beyond_180(tmp_path):
    p = build(tmp_path, [sid("CA", 10, course_deg=90.0, alt_desc="+", alt1_ft=1000),
                         sid("DF", 20, fix="WS", turn="L")])
    w = world()
    turn = [s for s in arcs(p, "turn") if s.leg_index == 1][0].geom
    assert turn.sweep_deg < -180.0   # WS bears ~153° right of the runway heading; coded left
    assert dist(end_of(p), w["WS"]) < 0.5


def test_fa_ends_where_the_climb_reaches_the_altitude(tmp_path):
    p = build(tmp_path, [sid("IF", 10, fix="WB"),
                         sid("FA", 20, fix="WB", course_deg=90.0, alt_desc="+", alt1_ft=6000)])
    grad = PERF.climb_gradient_at(p.legs[1].speed_mps)
    assert p.legs[1].termination.kind == "altitude"
    start_alt = p.legs[0].start.alt_m   # joined at WB: climbed from the field at the gradient
    assert start_alt == pytest.approx(
        35 * FT + PERF.climb_gradient_at(PERF.tas_plan_mps) * dist(APT, world()["WB"]), abs=0.5)
    assert p.length_m() == pytest.approx((6000 * FT - start_alt) / grad, abs=1.0)


def test_fc_flies_the_coded_distance(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WB"), app("FC", 20, fix="WB", course_deg=90.0,
                                                      distance_nm=7.0)])
    assert p.length_m() == pytest.approx(7.0 * NM, abs=0.01)
    assert p.legs[1].termination.kind == "distance"


def test_fd_ends_at_the_dme_distance(tmp_path):
    w = world()
    p = build(tmp_path, [app("IF", 10, fix="WB"),
                         app("FD", 20, fix="WB", course_deg=90.0, navaid="TVR",
                             distance_nm=12.0)])
    t = p.legs[1].termination
    assert t.kind == "dme"
    assert dist(end_of(p), w["TVR"]) == pytest.approx(12.0 * NM, abs=0.5)


def test_fm_flies_the_manual_distance(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WB"), app("FM", 20, fix="WB", course_deg=45.0)])
    assert p.length_m() == pytest.approx(PARAMS.manual_leg_m, abs=0.01)
    assert p.legs[1].termination.kind == "manual"


@pytest.mark.parametrize("pt", ["CA", "VA"])
def test_course_or_heading_to_altitude_from_the_runway(tmp_path, pt):
    p = build(tmp_path, [sid(pt, 10, course_deg=90.0, alt_desc="+", alt1_ft=2000)])
    grad = PERF.climb_gradient_at(p.legs[0].speed_mps)
    assert p.length_m() == pytest.approx((2000 - 35) * FT / grad, abs=1.0)
    assert p.legs[0].termination.alt_m == pytest.approx(2000 * FT)


@pytest.mark.parametrize("pt", ["CD", "VD"])
def test_course_or_heading_to_dme(tmp_path, pt):
    w = world()
    p = build(tmp_path, [sid(pt, 10, course_deg=90.0, navaid="TVR", distance_nm=15.0)])
    assert dist(end_of(p), w["TVR"]) == pytest.approx(15.0 * NM, abs=0.5)


@pytest.mark.parametrize("pt", ["CR", "VR"])
def test_course_or_heading_to_radial(tmp_path, pt):
    w = world()
    p = build(tmp_path, [sid(pt, 10, course_deg=90.0, navaid="TVR", theta_deg=120.0)])
    _, az, _ = inverse(*w["TVR"], *end_of(p))
    assert az % 360 == pytest.approx(120.0, abs=0.01)
    assert p.legs[0].termination.kind == "radial"


@pytest.mark.parametrize("pt", ["CI", "VI"])
def test_intercept_ends_on_the_next_course(tmp_path, pt):
    w = world()
    p = build(tmp_path, [sid("CA", 10, course_deg=90.0, alt_desc="+", alt1_ft=1000),
                         sid(pt, 20, course_deg=200.0, turn="R"),
                         sid("CF", 30, fix="WS", course_deg=270.0)])
    t = p.legs[1].termination
    assert t.kind == "intercept" and t.next_leg == 2
    assert abs(_foot(*w["WS"], 270.0, t.lat_deg, t.lon_deg)[1]) < 1.0
    assert not [f for f in p.findings if f.category == "no-intercept"]
    assert dist(end_of(p), w["WS"]) < 0.5


def test_vm_flies_the_manual_distance(tmp_path):
    p = build(tmp_path, [sid("VM", 10, course_deg=90.0)])
    assert p.length_m() == pytest.approx(PARAMS.manual_leg_m, abs=0.01)


def test_rf_follows_the_coded_centre_radius_and_direction_beyond_180(tmp_path):
    w = world()
    centre = offset(*w["WB"], 0.0, 2.0)   # WB is on a 2 NM circle about the centre
    c = offset(*centre, 340.0, 2.0)       # 200 deg clockwise from radial 180 -> 20 (340 ccw)
    # arriving westbound: the clockwise arc starts tangent at WB (radial 180, track 270)
    p = build(tmp_path, [app("IF", 10, fix="WE"), app("TF", 20, fix="WB"),
                         app("RF", 30, fix="WC", turn="R", arc_radius_nm=2.0, centre="CTR")],
              extra=[waypoint_record("WC", *c), waypoint_record("CTR", *centre)])
    rf = [s.geom for s in arcs(p) if s.path_term == "RF"][0]
    assert rf.radius_m == pytest.approx(2.0 * NM, abs=0.05 * NM)
    assert rf.sweep_deg == pytest.approx(160.0, abs=0.1)   # clockwise from 180 to 340
    assert dist(end_of(p), c) < 0.5


def test_rf_coded_left_goes_the_long_way(tmp_path):
    w = world()
    centre = offset(*w["WB"], 0.0, 2.0)
    c = offset(*centre, 200.0, 2.0)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("RF", 30, fix="WC", turn="L", arc_radius_nm=2.0, centre="CTR")],
              extra=[waypoint_record("WC", *c), waypoint_record("CTR", *centre)])
    rf = [s.geom for s in arcs(p) if s.path_term == "RF"][0]
    assert rf.sweep_deg == pytest.approx(-340.0, abs=0.1) and rf.turn == "L"


def test_af_flies_the_dme_arc_the_coded_way(tmp_path):
    w = world()
    p = build(tmp_path, [app("IF", 10, fix="ARC1"),
                         app("AF", 20, fix="ARC2", turn="L", navaid="TVR", theta_deg=100.0,
                             rho_nm=10.0, course_deg=200.0)])
    af = [s.geom for s in arcs(p) if s.path_term == "AF"][0]
    assert dist(af.centre, w["TVR"]) < 0.5
    assert af.radius_m == pytest.approx(10.0 * NM, abs=1.0)
    assert af.sweep_deg == pytest.approx(-100.0, abs=0.01)
    assert dist(end_of(p), w["ARC2"]) < 0.5


def _hold_arcs(p):
    return [s.geom for s in p.segments if s.role == "hold"]


def test_hf_flies_one_circuit_in_the_coded_direction_and_leaves_over_the_fix(tmp_path):
    w = world()
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("HF", 30, fix="WB", turn="L", course_deg=90.0, time_min=1.0)])
    holds = _hold_arcs(p)
    assert len(holds) == 2 and all(a.sweep_deg < 0 for a in holds)
    assert sum(abs(a.sweep_deg) for a in holds) == pytest.approx(360.0, abs=1.0)
    assert dist(end_of(p), w["WB"]) < 0.5
    assert p.legs[2].termination.kind == "circuit"
    # a one-minute outbound leg at the timed-leg speed of 210 kt is 3.5 NM
    outbound = [s.geom.length_m() for s in p.segments if s.leg_index == 2 and s.role == "leg"]
    assert any(abs(x - 3.5 * NM) < 1.0 for x in outbound)


def test_hm_is_a_manual_termination_at_the_fix(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("HM", 30, fix="WB", turn="R", course_deg=90.0, distance_nm=4.0)])
    assert p.legs[2].termination.kind == "manual"
    assert all(a.sweep_deg > 0 for a in _hold_arcs(p))
    straight = [s.geom.length_m() for s in p.segments if s.leg_index == 2 and s.role == "leg"]
    assert max(straight) == pytest.approx(4.0 * NM, abs=1.0)   # outbound leg length


def test_ha_holds_until_the_altitude_is_reached(tmp_path):
    p = build(tmp_path, [sid("IF", 10, fix="WB"),
                         sid("HA", 20, fix="WB", turn="R", course_deg=90.0, time_min=1.0,
                             alt_desc="+", alt1_ft=25000)])
    holds = _hold_arcs(p)
    circuits = sum(abs(a.sweep_deg) for a in holds) / 360.0
    grad = PERF.climb_gradient_at(PERF.tas_plan_mps)
    assert circuits >= 2 - 1e-6
    assert circuits * 0 + p.length_m() * grad >= (25000 - 35) * FT - 1.0
    assert p.legs[1].termination.kind == "altitude"


def test_pi_flies_outbound_then_45_to_the_coded_course_then_180_the_coded_way(tmp_path):
    """ARINC-424 PI (issue 12, class B): col. 71 is the 45° leg's course, col. 44 the 180°
    turn's direction. Inbound course 090 into WB, outbound 270, coded course 315 and turn L:
    outbound on 270, a 45° right turn onto 315 (the 45° leg north of the inbound course, away
    from the coded left turn: the chart's protected side), a 180° left turn onto 135, the 45°
    intercept of the inbound course, the CF to WB — within the coded 10 NM."""
    w = world()
    p = build(tmp_path, [app("IF", 10, fix="WE"), app("TF", 20, fix="WB"),
                         app("PI", 30, fix="WB", turn="L", course_deg=315.0, distance_nm=10.0),
                         app("CF", 40, fix="WB", course_deg=90.0)])
    pi = [s for s in p.segments if s.leg_index == 2]
    sweeps = [round(s.geom.sweep_deg) for s in pi if isinstance(s.geom, Arc)]
    assert sweeps == [45, -180]
    leg45 = [s.geom for s in pi if s.geom.kind == "line"
             and abs(s.geom.start_course_deg - 315.0) < 1.0]
    assert leg45 and all(_foot(*w["WB"], 90.0, *g.end)[1] < -1000.0 for g in leg45)  # north
    assert max(dist(s.geom.point_at(s.geom.length_m() * k / 4), w["WB"])
               for s in pi for k in range(5)) < 10.0 * NM
    assert p.legs[2].termination.kind == "intercept"
    assert dist(end_of(p), w["WB"]) < 0.5
    cf = [s.geom for s in p.segments if s.leg_index == 3 and s.role == "leg"][-1]
    assert abs(_foot(*w["WB"], 90.0, *cf.point_at(0.5 * cf.length_m()))[1]) < 1.0


def test_fix_leg_reached_from_elsewhere_turns_the_coded_way_to_its_fix(tmp_path):
    # after the runway heading the fix lies to the right; the FA is coded to turn left
    p = build(tmp_path, [sid("VA", 10, course_deg=90.0, alt_desc="+", alt1_ft=400),
                         sid("FA", 20, fix="WS", turn="L", course_deg=270.0, alt_desc="+",
                             alt1_ft=9000)])
    first = [s for s in arcs(p, "turn") if s.leg_index == 1][0].geom
    assert first.turn == "L"
    from fms_testbed.evaluation.check import leg_turn_mismatches
    assert leg_turn_mismatches(p) == 0


def test_coded_speed_limit_caps_the_planned_speed_but_not_the_entry_turn(tmp_path):
    """An 'at or below 180 kt' limit caps the leg's planned speed, but the turn at the start of
    the leg is entered at the previous leg's speed, so its radius is planned for that."""
    legs = [sid("CA", 10, course_deg=90.0, alt_desc="+", alt1_ft=1000),
            sid("DF", 20, fix="WS", speed_kt=180, speed_desc="-")]
    p = build(tmp_path, legs)
    turn = [s for s in arcs(p, "turn") if s.leg_index == 1][0]
    assert turn.speed_mps < 180 * KT_MPS * 1.05          # IAS 180 kt -> TAS at ~1000 ft
    assert turn.geom.radius_m == pytest.approx(
        turn_radius_m(p.legs[0].speed_mps, PARAMS.bank_plan_deg, G), rel=1e-3)
    assert turn.geom.radius_m > R_PLAN


def test_speed_limit_on_both_legs_gives_the_smaller_turn(tmp_path):
    legs = [sid("CA", 10, course_deg=90.0, alt_desc="+", alt1_ft=1000, speed_kt=180,
                speed_desc="-"),
            sid("DF", 20, fix="WS", speed_kt=180, speed_desc="-")]
    p = build(tmp_path, legs)
    turn = [s for s in arcs(p, "turn") if s.leg_index == 1][0]
    assert turn.geom.radius_m < R_PLAN * 0.7
    assert turn.geom.radius_m == pytest.approx(
        turn_radius_m(turn.speed_mps, PARAMS.bank_plan_deg, G), rel=1e-2)


def test_intercept_onto_a_dme_arc_is_flown_with_a_tangent_fillet(tmp_path):
    w = world()
    start = offset(*APT, 225.0, 8.0)
    p = build(tmp_path, [app("IF", 10, fix="WQ"), app("CI", 20, course_deg=45.0),
                         app("AF", 30, fix="ARC2", turn="L", navaid="TVR", theta_deg=100.0,
                             rho_nm=10.0, course_deg=200.0)],
              extra=[waypoint_record("WQ", *start)])
    segs = p.segments
    k = next(i for i, s in enumerate(segs) if s.role == "flyby")
    before, fillet, after = segs[k - 1], segs[k], segs[k + 1]
    assert isinstance(before.geom, type(segs[0].geom)) and after.path_term == "AF"
    assert isinstance(after.geom, Arc) and after.geom.sweep_deg < 0
    for x, y in ((before, fillet), (fillet, after)):
        assert dist(x.geom.end, y.geom.start) < 0.02
        assert abs((y.geom.start_course_deg - x.geom.end_course_deg + 180) % 360 - 180) < 0.5
    assert dist(end_of(p), w["ARC2"]) < 0.5
    assert p.status in ("ok", "corrected")
