"""The parameter monitor (Danilin 2017, Fig. 5): one case per correction branch, the
'impossible' outcomes, and the flags (loop, discontinuity, intercept that never happens)."""

import dataclasses

import pytest

from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.core.units import NM_M as NM
from fms_testbed.procedures.synth import offset, waypoint_record
from tests.path.test_world import PERF, build, world



def app(pt, seq, **kw):
    return L("XTST", "T09", pt, seq, proc_type="F", **kw)


def sid(pt, seq, **kw):
    return L("XTST", "TSID1", pt, seq, proc_type="D", transition="RW09", route_type="1", **kw)


def branches(p):
    return {f.branch for f in p.findings if f.branch}


def cats(p):
    return {f.category for f in p.findings}


def _square_turn(tmp_path, next_leg_m):
    """IF WA -> TF WB -> TF WC with a 90° right turn at WB and a WB-WC leg of next_leg_m."""
    c = offset(*world()["WB"], 180.0, next_leg_m / NM)
    return build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                            app("TF", 30, fix="WC")], extra=[waypoint_record("WC", *c)])


def test_plain_path_is_ok_without_findings(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB")])
    assert p.status == "ok" and not p.findings


def test_branch_R_tightens_the_fly_by_radius_within_25_deg_bank(tmp_path):
    p = _square_turn(tmp_path, 3500.0)
    assert p.status == "corrected" and branches(p) == {"R"}
    arc = [s for s in p.segments if s.role == "flyby"][0]
    assert arc.geom.radius_m == pytest.approx(3500.0, rel=0.005)  # Ω is not exactly 90° on WGS-84
    assert 20.0 < arc.bank_deg <= 25.0


def test_branch_V_gamma_slows_down_at_25_deg_bank(tmp_path):
    p = _square_turn(tmp_path, 2000.0)
    assert branches(p) == {"V,γ"} and p.status == "corrected"
    arc = [s for s in p.segments if s.role == "flyby"][0]
    assert arc.bank_deg == pytest.approx(25.0)
    assert PERF.tas_min_mps <= arc.speed_mps < PERF.tas_plan_mps


def test_branch_V_gamma_phi_lambda_flies_over_when_nothing_fits(tmp_path):
    p = _square_turn(tmp_path, 500.0)
    assert "V,γ,φ,λ" in branches(p) and p.status == "corrected"
    # no fly-by at WB: the path passes over it (the rejoin of WB-WC may have its own fly-by)
    assert not [s for s in p.segments if s.role == "flyby" and s.leg_index == 1]
    from fms_testbed.core.geodesy import inverse
    assert min(inverse(*s.geom.end, *world()["WB"])[0] for s in p.segments) < 1.0
    assert all(s.bank_deg <= 25.0 + 1e-9 for s in p.segments)


def _rf(tmp_path, radius_nm, coded_nm=None):
    w = world()
    centre = offset(*w["WB"], 0.0, radius_nm)
    c = offset(*centre, 90.0, radius_nm)
    return build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                            app("RF", 30, fix="WC", turn="L", centre="CTR",
                                arc_radius_nm=coded_nm or radius_nm)],
                 extra=[waypoint_record("WC", *c), waypoint_record("CTR", *centre)])


def test_branch_gamma_raises_bank_for_a_tight_rf(tmp_path):
    p = _rf(tmp_path, 1.85)
    assert branches(p) == {"γ"} and p.status == "corrected"


def test_branch_V_gamma_for_an_rf_too_tight_at_planned_speed(tmp_path):
    p = _rf(tmp_path, 1.0)
    assert branches(p) == {"V,γ"}


def test_rf_too_tight_even_at_minimum_speed_is_impossible(tmp_path):
    p = _rf(tmp_path, 0.5)
    assert p.status == "impossible"
    assert any("even at the minimum speed" in f.message for f in p.findings)


def test_branch_R_reports_an_rf_radius_that_disagrees_with_its_fixes(tmp_path):
    p = _rf(tmp_path, 2.0, coded_nm=2.2)
    assert "R" in branches(p)
    assert any("coded 2.200 NM" in f.message for f in p.findings)


def _climb(tmp_path, alt_ft, perf=PERF):
    return build(tmp_path, [sid("VA", 10, course_deg=90.0, alt_desc="+", alt1_ft=400),
                            sid("DF", 20, fix="WE", alt_desc="+", alt1_ft=alt_ft)], perf=perf)


def test_branch_V_theta_slows_down_for_a_steep_climb_constraint(tmp_path):
    p = _climb(tmp_path, 10000)
    assert branches(p) == {"V,Θ"} and p.status == "corrected"


def test_climb_beyond_capability_is_impossible_with_the_reason(tmp_path):
    p = _climb(tmp_path, 14000)
    assert p.status == "impossible"
    assert any("climb" in f.message and "WE" in f.message for f in p.findings)


def test_aircraft_below_the_3_3_percent_minimum_gradient_is_impossible(tmp_path):
    weak = dataclasses.replace(PERF, climb_gradient_max=0.02, tas_min_mps=100.0)
    p = _climb(tmp_path, 1000, perf=weak)
    assert p.status == "impossible"
    assert any("3.3%" in f.message for f in p.findings)


def _descent(tmp_path, a_ft):
    return build(tmp_path, [app("IF", 10, fix="WB", alt1_ft=a_ft, alt_desc=" "),
                            app("TF", 20, fix="WC", alt1_ft=3000, alt_desc=" ")],
                 extra=[waypoint_record("WC", *offset(*world()["WB"], 90.0, 5.0))])


def test_branch_V_theta_for_a_steep_descent(tmp_path):
    p = _descent(tmp_path, 7000)
    assert branches(p) == {"V,Θ"}


def test_descent_beyond_capability_is_impossible(tmp_path):
    p = _descent(tmp_path, 9000)
    assert p.status == "impossible" and any("descent" in f.message for f in p.findings)


def test_path_flown_twice_is_flagged_as_a_loop(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("TF", 30, fix="WS"), app("TF", 40, fix="WA"),
                         app("TF", 50, fix="WB")])
    assert "loop" in cats(p) and p.status == "coding_suspect"   # class 3: never ok


def test_initial_fix_away_from_the_path_is_a_discontinuity(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("IF", 30, fix="WE"), app("TF", 40, fix="WS")])
    # a path with a discontinuity is never ok or corrected: the built path is not the coded one
    assert "discontinuity" in cats(p) and p.status == "impossible"


def test_intercept_that_never_happens_is_flagged_and_bounded(tmp_path):
    p = build(tmp_path, [sid("CA", 10, course_deg=90.0, alt_desc="+", alt1_ft=1000),
                         sid("CI", 20, course_deg=90.0),
                         sid("CF", 30, fix="WS", course_deg=270.0)])
    assert "no-intercept" in cats(p)
    assert p.length_m() < 300 * NM          # bounded: no runaway path
    assert p.status == "corrected"


def test_unknown_fix_is_impossible_with_the_record_line(tmp_path):
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="NOPE")])
    assert p.status == "impossible"
    assert any("NOPE" in f.message and "line" in f.message for f in p.findings)


