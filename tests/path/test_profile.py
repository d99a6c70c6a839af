"""Planned vertical profile: altitude windows from the descriptors, climbs that level off,
descents at the coded angle, never above the start or the highest coded altitude."""

import math

import pytest

from fms_testbed.path.profile import window
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.core.units import FT_M as FT
from fms_testbed.procedures.synth import offset, waypoint_record
from tests.path.test_world import APT, PERF, build, world



@pytest.mark.parametrize("desc, lo, hi", [("+", 1000, None), ("-", None, 1000),
                                          (" ", 1000, 1000), ("B", 500, 1000),
                                          ("C", 500, None), ("G", 1000, 1000)])
def test_windows_from_altitude_descriptors(desc, lo, hi):
    assert window(desc.strip(), 1000.0, 500.0) == (lo, hi)


def test_sid_climbs_at_the_aircraft_gradient_and_levels_off_below_the_ceiling(tmp_path):
    e2 = offset(*APT, 90.0, 40.0)
    p = build(tmp_path, [L("XTST", "TSID1", "VA", 10, proc_type="D", transition="RW09",
                           route_type="1", course_deg=90.0, alt_desc="+", alt1_ft=400),
                         L("XTST", "TSID1", "DF", 20, proc_type="D", transition="RW09",
                           route_type="1", fix="WE", alt_desc="+", alt1_ft=5000),
                         L("XTST", "TSID1", "TF", 30, proc_type="D", transition="RW09",
                           route_type="1", fix="WE2", alt_desc="-", alt1_ft=6000)],
              extra=[waypoint_record("WE2", *e2)])
    prof = p.profile
    g = PERF.climb_gradient_at(PERF.tas_plan_mps)
    grads = prof.gradients()
    assert grads[0] == pytest.approx(g, rel=1e-9)                # climbing at capability
    assert prof.alt_m[2] >= 5000 * FT - 1e-6                    # WE at or above 5000 ft
    assert prof.alt_m[-1] == pytest.approx(6000 * FT)           # levelled at or below 6000 ft
    assert prof.alt_at(prof.along_m[-1] + 1.0) == pytest.approx(6000 * FT)


def test_approach_descends_at_the_coded_angle_and_never_above_the_start(tmp_path):
    w = world()
    c = offset(*w["WB"], 90.0, 10.0)
    p = build(tmp_path, [L("XTST", "T09", "IF", 10, fix="WA", alt_desc="+", alt1_ft=6000),
                         L("XTST", "T09", "TF", 20, fix="WB", alt_desc="+", alt1_ft=3000),
                         L("XTST", "T09", "TF", 30, fix="WC", alt_desc=" ", alt1_ft=1000)],
              extra=[waypoint_record("WC", *c)])
    prof = p.profile
    # last piece: at 3°, from the 'at' constraint back up
    last = prof.alt_m[-2] - prof.alt_m[-1]
    run = prof.along_m[-1] - prof.along_m[-2]
    assert prof.alt_m[-1] == pytest.approx(1000 * FT)
    assert last / run == pytest.approx(math.tan(math.radians(3.0)), rel=1e-6) or \
        prof.alt_m[-2] == pytest.approx(3000 * FT)
    assert max(prof.alt_m) <= 6000 * FT + 1e-6
    for wdw in prof.windows:
        h = prof.alt_m[wdw.leg_index + 1]
        assert wdw.lo_m is None or h >= wdw.lo_m - 1e-6
        assert wdw.hi_m is None or h <= wdw.hi_m + 1e-6


def test_star_descent_never_climbs_after_its_last_constraint(tmp_path):
    """KDCA CAPSS3-like: an 'at' fix followed by unconstrained legs. The backward pass from the
    final node used to plan the later fixes above the 'at' fix (a climb inside a STAR)."""
    w = world()
    c = offset(*w["WB"], 90.0, 15.0)
    d = offset(*c, 90.0, 15.0)
    star = dict(proc_type="E", transition="RW09", route_type="6")
    p = build(tmp_path, [L("XTST", "TSTR1", "IF", 10, fix="WA", alt_desc="B", alt1_ft=13000,
                           alt2_ft=10000, **star),
                         L("XTST", "TSTR1", "TF", 20, fix="WB", alt_desc=" ", alt1_ft=9000, **star),
                         L("XTST", "TSTR1", "TF", 30, fix="WC", **star),
                         L("XTST", "TSTR1", "TF", 40, fix="WD", **star)],
              extra=[waypoint_record("WC", *c), waypoint_record("WD", *d)])
    alt = p.profile.alt_m
    assert all(b <= a + 1e-6 for a, b in zip(alt[:-1], alt[1:])), alt
    assert alt[2] == pytest.approx(9000 * FT) and alt[-1] == pytest.approx(9000 * FT)


def test_a_flight_climb_top_replaces_the_transition_altitude_level_off():
    """plan_profile(climb_top_m=...) levels a SID at the flight's climb top (raised to a higher
    climb constraint), where the database check levels at 18,000 ft; 'at or above' windows
    below the top no longer make the plan level at them."""
    import yaml

    from fms_testbed.path.profile import plan_profile
    from fms_testbed.loop.procedure import prepare
    from fms_testbed.data import scenarios_dir

    raw = yaml.safe_load((scenarios_dir() / "demo-sid.yaml").read_text())
    _, spec, fp, _ = prepare(raw, "demo-sid.yaml")
    path = fp.path
    grad = 0.07
    check = plan_profile(path, grad, path.legs[0].start.alt_m)
    flight = plan_profile(path, grad, path.legs[0].start.alt_m, climb_top_m=4572.0)
    assert max(check.alt_m) == pytest.approx(18000 * FT)
    assert max(flight.alt_m) == pytest.approx(4572.0)
    assert all(b >= a - 1e-9 for a, b in zip(flight.alt_m, flight.alt_m[1:]))   # climbs only
    assert fp.path.profile is not None and max(fp.path.profile.alt_m) == pytest.approx(
        spec.climb_top_ft * FT)
