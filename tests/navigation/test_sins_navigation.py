"""SinsNavigation: scenario spec, truth ⊕ errors, seeding, agreement between methods."""

import math

import numpy as np
import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.navigation import make_source
from fms_testbed.core.earth import radii_m
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.sins.trajectory import straight_level
from fms_testbed.core.state import AircraftState


def _states(duration_s=20.0):
    tr = straight_level(duration_s, 0.1, lat_deg=47.0, speed_mps=200.0, heading_deg=30.0)
    out = []
    for k in range(len(tr)):
        out.append(AircraftState(
            t_s=tr.t_s[k], lat_rad=tr.lat_rad[k], lon_rad=tr.lon_rad[k], alt_m=tr.alt_m[k],
            tas_mps=200.0, cas_mps=170.0, gs_mps=200.0, vs_mps=0.0, v_enu_mps=tr.v_enu_mps[k],
            roll_rad=tr.rpy_rad[k, 0], pitch_rad=tr.rpy_rad[k, 1], heading_rad=tr.rpy_rad[k, 2],
            track_rad=tr.rpy_rad[k, 2], alpha_rad=0.03, beta_rad=0.0, gamma_rad=0.0,
            p_rps=tr.w_eb_b_rps[k, 0], q_rps=tr.w_eb_b_rps[k, 1], r_rps=tr.w_eb_b_rps[k, 2],
            nx=0.0, ny=1.0, f_body_mps2=tr.f_b_mps2[k], mach=0.6, agl_m=3000.0, throttle=0.6,
            mass_kg=60000.0))
    return out


def _fly(spec, seed=None, states=None):
    nav = make_source(spec, seed=seed)
    return [nav.update(s) for s in (states or _states())]


def test_make_source_builds_a_sins_source_from_the_scenario_block():
    nav = make_source({"source": "sins", "imu": "STIM300", "seed": 7, "method": "picard",
                       "dt_s": 0.1}, seed=1)
    assert isinstance(nav, SinsNavigation) and nav.seed == 7


def test_solution_is_truth_plus_the_error_state():
    states = _states()
    nav = SinsNavigation.from_spec({"source": "sins", "imu": "STIM300", "seed": 2})
    for s in states:
        sol = nav.update(s)
    x, t = nav.x, states[-1]
    rm, rn = radii_m(t.lat_rad)
    # lat/lon differences of ~1e-8 rad keep ~8 significant digits
    assert (sol.lat_rad - t.lat_rad) * (rm + t.alt_m) == pytest.approx(x[1], rel=1e-6)
    assert (sol.lon_rad - t.lon_rad) * (rn + t.alt_m) * math.cos(t.lat_rad) == pytest.approx(
        x[0], rel=1e-6)
    assert sol.alt_m - t.alt_m == pytest.approx(x[2])
    assert np.allclose(sol.v_enu_mps - t.v_enu_mps, x[3:6])
    assert sol.errors["nse_north_m"] == pytest.approx(x[1])
    assert len(sol.errors) <= 12
    assert all(("_m" in k or "_mps" in k or "_deg" in k or "_dph" in k or "_ug" in k)
               for k in sol.errors)
    assert abs(x[1]) > 0.01                                  # errors did grow in 20 s


def test_same_seed_same_errors_other_seed_other_errors():
    a = _fly({"source": "sins", "imu": "STIM300", "seed": 5})[-1]
    b = _fly({"source": "sins", "imu": "STIM300", "seed": 5})[-1]
    c = _fly({"source": "sins", "imu": "STIM300", "seed": 6})[-1]
    assert a.errors == b.errors and a.errors != c.errors


def test_run_seed_is_used_when_the_block_has_none():
    a = _fly({"source": "sins", "imu": "HG1700"}, seed=9)[-1]
    b = _fly({"source": "sins", "imu": "HG1700", "seed": 9})[-1]
    assert a.errors == b.errors


def test_picard_and_van_loan_give_the_same_realisation():
    states = _states(10.0)
    a = _fly({"source": "sins", "imu": "STIM300", "seed": 1}, states=states)[-1]
    b = _fly({"source": "sins", "imu": "STIM300", "seed": 1, "method": "vanloan"},
             states=states)[-1]
    for k in a.errors:
        assert a.errors[k] == pytest.approx(b.errors[k], rel=1e-9, abs=1e-12), k


def test_inline_imu_parameters_are_accepted():
    sol = _fly({"source": "sins", "seed": 1,
                "imu": {"gyro": {"arw_deg_per_sqrt_h": 0.1}, "accelerometer": {}}})[-1]
    assert sol.errors["bias_gyro_x_dph"] == 0.0 and sol.errors["ve_err_mps"] != 0.0


@pytest.mark.parametrize("spec, match", [
    ({"source": "sins"}, "navigation.imu"),
    ({"source": "sins", "imu": "STIM300", "gain": 3}, "navigation.gain"),
    ({"source": "sins", "imu": "STIM300", "method": "euler"}, "navigation.method"),
    ({"source": "sins", "imu": "STIM300", "vertical": "gps"}, "navigation.vertical"),
    ({"source": "sins", "imu": "STIM300", "dt_s": 0}, "navigation.dt_s"),
    ({"source": "sins", "imu": {"gyro": {"arw": 1}}}, "gyro.arw"),
])
def test_bad_navigation_blocks_raise_config_errors(spec, match):
    with pytest.raises(Exception, match=match) as e:
        SinsNavigation.from_spec(spec)
    from fms_testbed.core.errors import UserError
    assert isinstance(e.value, UserError)


def test_config_error_type_for_unknown_key():
    with pytest.raises(ConfigError):
        SinsNavigation.from_spec({"source": "sins", "imu": "STIM300", "foo": 1})


def test_euler_errors_in_the_solution_follow_eq_6_10():
    from fms_testbed.sensors.sins.euler import eps_to_euler_errors
    states = _states(5.0)
    nav = SinsNavigation.from_spec({"source": "sins", "imu": "STIM300", "seed": 4})
    for s in states:
        sol = nav.update(s)
    d = eps_to_euler_errors(*nav.x[6:9], s.pitch_rad, s.heading_rad)
    assert sol.roll_rad - s.roll_rad == pytest.approx(d[0], rel=1e-9)
    assert sol.pitch_rad - s.pitch_rad == pytest.approx(d[1], rel=1e-9)
    assert sol.errors["att_err_heading_deg"] == pytest.approx(math.degrees(d[2]), rel=1e-9)


def test_held_matrices_match_per_step_matrices_on_steady_flight():
    states = _states(20.0)
    a = _fly({"source": "sins", "imu": "STIM300", "seed": 8}, states=states)[-1]
    b = _fly({"source": "sins", "imu": "STIM300", "seed": 8, "matrices_dt_s": 1.0},
             states=states)[-1]
    # steady straight flight: F barely changes over 1 s, so the realisations nearly coincide
    assert b.errors["nse_east_m"] == pytest.approx(a.errors["nse_east_m"], rel=1e-3)
    assert b.errors["att_err_heading_deg"] == pytest.approx(a.errors["att_err_heading_deg"],
                                                             rel=1e-3)


def test_navigation_realisations_have_the_covariance_of_the_analysis():
    from fms_testbed.sensors.sins.analysis import SinsOptions, covariance_run
    from fms_testbed.sensors.sins.presets import load_imu

    duration, n_seeds = 10.0, 300
    states = _states(duration)
    tr = straight_level(duration, 0.1, lat_deg=47.0, speed_mps=200.0, heading_deg=30.0)
    cov = covariance_run(tr, load_imu("STIM300"), SinsOptions())
    finals = []
    for seed in range(n_seeds):
        nav = SinsNavigation.from_spec({"source": "sins", "imu": "STIM300", "seed": seed})
        for s in states:
            nav.update(s)
        finals.append(nav.x.copy())
    X = np.array(finals)
    var = X.var(axis=0, ddof=1)
    sig2 = cov.sigma[-1] ** 2
    live = sig2 > 0
    z = (var[live] / sig2[live] - 1) / np.sqrt(2 / n_seeds)
    assert np.all(np.abs(z) < 4), z
