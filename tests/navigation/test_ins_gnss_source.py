"""The ins_gnss navigation source: scenario block, seeding, covariance/ANP, feedback, gating."""

import math

import numpy as np
import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.navigation import SOURCES, make_source
from fms_testbed.navigation.ins_bank import derive_seeds
from fms_testbed.navigation.ins_gnss import InsGnssNavigation
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.profiles import PROFILES, Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.analysis import horizontal_radius


@pytest.fixture(scope="module")
def states():
    return aircraft_states(fly_profile([Segment(30.0), Segment(60.0, 3.0), Segment(30.0)],
                                       dt_s=0.1))


def _fly(spec, states, seed=0):
    nav = make_source(spec, seed=seed)
    return nav, [nav.update(s) for s in states]


def test_registry_has_one_ins_gnss_entry():
    assert SOURCES["ins_gnss"] is InsGnssNavigation


@pytest.mark.parametrize("spec, field", [
    ({"imu": "STIM300", "gnss": {"rate_hz": 0}}, "navigation.gnss.rate_hz"),
    ({"imu": "STIM300", "gnss": {"rate_hz": 1, "latency_s": 1.5}}, "navigation.gnss"),
    ({"imu": "STIM300", "gnss": {"pos_markov_sigma_m": [1, 2]}}, "navigation.gnss.pos_markov"),
    ({"imu": "STIM300", "bogus": 1}, "navigation.bogus"),
    ({"imu": "STIM300", "gnss": {"outages": [{"start_s": 20, "end_s": 10}]}}, "outages"),
    ({}, "navigation.imu"),
    ({"imu": "STIM300", "filter": {"predict_interval_s": -1}}, "navigation.filter.predict_interval_s"),
    ({"imu": "STIM300", "filter": {"predict_rotation_deg": 0}}, "navigation.filter.predict_rotation_deg"),
    ({"imu": "STIM300", "matrices_dt_s": 11}, "navigation.matrices_dt_s"),
    ({"imu": "STIM300", "matrices_rotation_deg": 0}, "navigation.matrices_rotation_deg"),
])
def test_bad_blocks_are_config_errors_naming_the_field(spec, field):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        make_source({"source": "ins_gnss", **spec}, seed=0)


def test_same_seed_same_flight_and_navigation_seed_wins(states):
    a = _fly({"source": "ins_gnss", "imu": "STIM300"}, states[:200], seed=5)[1][-1]
    b = _fly({"source": "ins_gnss", "imu": "STIM300"}, states[:200], seed=5)[1][-1]
    c = _fly({"source": "ins_gnss", "imu": "STIM300", "seed": 5}, states[:200], seed=99)[1][-1]
    d = _fly({"source": "ins_gnss", "imu": "STIM300"}, states[:200], seed=6)[1][-1]
    assert a.lat_rad == b.lat_rad == c.lat_rad and a.lat_rad != d.lat_rad


def test_derived_seeds_are_distinct_and_a_new_unit_changes_no_other():
    s3, s4 = derive_seeds(7, 3), derive_seeds(7, 4)
    assert len(set(s4)) == 4 and s4[:3] == s3
    n1 = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 1}, seed=7)
    n3 = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=7)
    assert n1.bank.seeds[0] == n3.bank.seeds[0]
    assert len(set(n3.bank.seeds)) == 3
    lin = {"source": "ins_gnss", "imu": "STIM300", "truth_model": "linear"}
    l1, l3 = make_source({**lin, "n_ins": 1}, seed=7), make_source({**lin, "n_ins": 3}, seed=7)
    assert l1.bank.units[0].seed == l3.bank.units[0].seed == n1.bank.seeds[0]
    assert len({u.seed for u in l3.bank.units}) == 3


def test_solution_carries_the_covariance_and_anp_is_its_95_percent_radius(states):
    nav, sols = _fly({"source": "ins_gnss", "imu": "STIM300"}, states, seed=2)
    s = sols[-1]
    P = nav.filters[0].P
    assert np.array_equal(s.pos_cov_enu_m2, P[:3, :3])
    assert s.errors["anp_m"] == pytest.approx(horizontal_radius(P[0, 0], P[1, 1], P[0, 1]))
    assert {"anp_m", "nav_mode", "ins_used", "nse_east_m"} <= set(s.errors)
    # GNSS-aided: metres, not the kilometres of the free INS
    nse = [math.hypot(x.errors["nse_east_m"], x.errors["nse_north_m"]) for x in sols]
    assert max(nse[100:]) < 10.0


def test_feedback_keeps_the_ins_error_bounded_where_the_free_ins_drifts(states):
    nav, _ = _fly({"source": "ins_gnss", "imu": "consumer_MEMS"}, states, seed=1)
    free = SinsNavigation.from_spec({"source": "sins", "imu": "consumer_MEMS", "vertical": "free"},
                                    seed=1)
    for s in states:
        free.update(s)
    aided = float(np.hypot(*nav.bank.errors(0)[:2]))
    drift = float(np.hypot(*free.x[:2]))
    assert aided < 10.0 and drift > 20 * aided


def test_outlier_burst_is_rejected_by_the_gate_and_logged(states):
    spec = {"source": "ins_gnss", "imu": "STIM300",
            "gnss": {"outliers": [{"start_s": 60, "end_s": 70, "sigma_m": 200}]}}
    nav, sols = _fly(spec, states, seed=3)
    kinds = [(e["kind"], e["unit"]) for e in nav.events]
    assert ("detected", "gnss") in kinds and ("reconfigured", "gnss") in kinds
    t_det = min(e["t_s"] for e in nav.events if e["kind"] == "detected")
    assert 60.0 <= t_det <= 61.5
    nse = [math.hypot(x.errors["nse_east_m"], x.errors["nse_north_m"]) for x in sols
           if 60 <= x.t_s <= 75]
    assert max(nse) < 10.0                # 200 m outliers do not reach the solution


def test_profile_is_kinematically_consistent():
    tr = fly_profile(PROFILES["climb_turns"], dt_s=0.1)
    k = np.searchsorted(tr.t_s, 90.0)              # steady part of the climbing right turn
    V = np.linalg.norm(tr.v_enu_mps[k])
    roll = tr.rpy_rad[k, 0]
    assert roll == pytest.approx(math.atan(V * math.radians(2.0) / 9.80665), rel=0.02)
    # body z specific force ≈ -g / cos(roll) in a coordinated turn
    assert tr.f_b_mps2[k, 2] == pytest.approx(-9.80665 / math.cos(roll), rel=0.01)
    assert abs(tr.f_b_mps2[k, 1]) < 0.05
