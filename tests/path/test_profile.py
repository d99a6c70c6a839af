"""Planned vertical profile: altitude windows from the descriptors, climbs that level off,
descents at the coded angle, never above the start or the highest coded altitude."""

import math

import numpy as np

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


def _decel_star(tmp_path):
    """A STAR that slows from 280 to 230 kt CAS on its last leg: FL200 at WA (@280 kt), 15 NM
    to WB (no constraint), 15 NM to WC ('at or below' 14,000 ft, @230 kt)."""
    w = world()
    a = offset(*w["WB"], 270.0, 15.0)
    c = offset(*w["WB"], 90.0, 15.0)
    star = dict(proc_type="E", transition="RW09", route_type="6")
    return build(tmp_path, [L("XTST", "TSTR2", "IF", 10, fix="WA2", alt_desc=" ", alt1_ft=20000,
                              speed_kt=280, **star),
                            L("XTST", "TSTR2", "TF", 20, fix="WB", **star),
                            L("XTST", "TSTR2", "TF", 30, fix="WC2", alt_desc="-",
                              alt1_ft=14000, speed_kt=230, **star)],
                 extra=[waypoint_record("WA2", *a), waypoint_record("WC2", *c)])


def test_a_descent_that_slows_down_is_planned_within_the_energy_the_aircraft_can_shed(tmp_path):
    """Δh ≤ (w_d / V) Δs + (V_k² − V_k-1²) / 2g on each leg without a coded angle (Danilin: the
    path from the aircraft's performance; KTMB BNFSH2 crossed an 'at or below' fix 551 ft high
    after slowing 280 → 230 kt on a 3° path). Without the budget the same path is planned
    steeper than that on the slowing leg; with it the fix before is planned lower."""
    from fms_testbed.core.atmosphere import cas_to_tas_scalar
    from fms_testbed.core.units import G0_MPS2, KT_MPS
    from fms_testbed.path.profile import plan_profile

    p = _decel_star(tmp_path)
    rate = 0.75 * PERF.descent_rate_max_mps
    kw = dict(climb_gradient=0.08, start_alt_m=20000 * FT, descent_gradient_max=0.1,
              descent_rate_mps=rate)
    geo = plan_profile(p, **kw)
    en = plan_profile(p, **kw, cas_plan_mps=280 * KT_MPS)     # a STAR flown at 280 kt

    def budget(prof, k):          # leg k (node k → k+1) at its flown TAS
        cas = [280 * KT_MPS, 280 * KT_MPS, 230 * KT_MPS]
        v = [cas_to_tas_scalar(c, h) for c, h in zip(cas, prof.alt_m[1:])]
        ds = prof.along_m[k + 1] - prof.along_m[k]
        return rate / v[k] * ds + (v[k] ** 2 - v[k - 1] ** 2) / (2 * G0_MPS2)

    drop = lambda prof, k: prof.alt_m[k] - prof.alt_m[k + 1]  # noqa: E731
    assert drop(geo, 2) > budget(geo, 2) + 100 * FT        # 3° regardless: beyond the budget
    assert drop(en, 2) <= budget(en, 2) + 1.0               # within it
    assert en.alt_m[2] < geo.alt_m[2] - 300 * FT            # WB planned lower
    assert en.alt_m[3] == pytest.approx(geo.alt_m[3])       # WC still aimed the same
    assert en.alt_m[3] <= 14000 * FT


def test_speed_of_each_descent_leg_follows_the_coded_limits(tmp_path):
    from fms_testbed.core.atmosphere import cas_to_tas_scalar
    from fms_testbed.core.units import KT_MPS
    from fms_testbed.path.profile import descent_leg_tas_mps

    p = _decel_star(tmp_path)
    alt = np.array([20000, 17000, 14000]) * FT
    v = descent_leg_tas_mps(p, alt, 250 * KT_MPS)
    # @280 raises the first leg above the planned 250 kt, WB keeps the 280 'at' as a cap
    # (250 kt planned, as guidance flies it), the last leg is capped at 230 kt
    assert v[0] == pytest.approx(cas_to_tas_scalar(280 * KT_MPS, alt[0]))
    assert v[1] == pytest.approx(cas_to_tas_scalar(250 * KT_MPS, alt[1]))
    assert v[2] == pytest.approx(cas_to_tas_scalar(230 * KT_MPS, alt[2]))

