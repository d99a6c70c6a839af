"""Seed 001's decision functions on arrays and the fault-tolerant estimator: channel test,
adaptive R with its divergence check, baro-channel exclusion, vertical-channel freezing."""

import math

import numpy as np
import pytest

from fms_testbed.navigation import make_source
from fms_testbed.navigation.fdi import (FdiTuning, channel_mask, declared_sensor_noise,
                                        frozen_states, majority, residual_ok, switch_components)
from fms_testbed.navigation.identification.rules import pair_flags as _pair_flags


def pair_flags(y, sig, k, mask=None):
    """Stage 1 of one realisation as ints."""
    return _pair_flags(y[None], sig[None], k, mask=mask)[0].astype(int)
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.presets import load_imu


def test_pair_flags_and_the_majority_table_name_the_odd_unit_out():
    y = np.zeros((3, 9))
    sig = np.ones((3, 9))
    assert list(pair_flags(y, sig, 6.0)) == [0, 0, 0] and majority((0, 0, 0)) is None
    y[1, 4] = 9.0                                              # unit 2, velocity N: 9 > 6√2
    nu = pair_flags(y, sig, 6.0)
    assert list(nu) == [1, 0, 1] and majority(nu) == 1
    y[1, 4] = 8.0                                              # 8 < 6√2 = 8.49
    assert list(pair_flags(y, sig, 6.0)) == [0, 0, 0]


def test_a_frozen_vertical_channel_is_left_out_of_the_comparison():
    y = np.zeros((3, 9))
    y[2, 2] = 100.0                                            # unit 3, position U
    sig = np.ones((3, 9))
    assert majority(pair_flags(y, sig, 6.0)) == 2
    assert list(pair_flags(y, sig, 6.0, channel_mask(True))) == [0, 0, 0]
    assert channel_mask(False).all() and list(np.flatnonzero(~channel_mask(True))) == [2, 5]


def test_frozen_states_are_the_vertical_ones_that_exist():
    assert list(np.flatnonzero(frozen_states(22, True))) == [2, 5, 21]
    assert list(np.flatnonzero(frozen_states(21, True))) == [2, 5]
    assert not frozen_states(22, False).any()


def test_residual_ok_is_the_channel_test_per_component():
    S = np.diag([4.0, 1.0, 9.0])
    assert list(residual_ok(np.array([9.9, -5.1, 14.0]), S, 5.0)) == [True, False, True]


def test_component_switching_turns_off_the_failed_component_and_flags_divergence():
    """Seed 001 eq. 7: a_i = 0 for |ν_i| > ε_i — that component's R becomes the artificial
    noise ζ (switch_noise × R) —, back to 1 when it passes; νᵀν > γ tr(S) is divergence."""
    tune = FdiTuning()
    S = np.diag([1.0, 1.0, 4.0])
    R = np.diag([0.5, 0.5, 0.5])
    nu = np.array([0.3, 10.0, -1.0])                          # component 2: 10 > 5√1
    scale, div = switch_components(nu, S, np.ones(3), R, tune)
    np.testing.assert_array_equal(scale, [1.0, tune.switch_noise, 1.0])
    assert not div                                             # two components pass
    S_off = S + np.diag((scale - 1.0) * 0.5)                  # the filter's S with ζ
    scale2, _ = switch_components(nu, S_off, scale, R, tune)  # tested at the nominal S
    np.testing.assert_array_equal(scale2, scale)              # still off while it fails
    scale, div = switch_components(np.zeros(3), S_off, scale, R, tune)
    np.testing.assert_array_equal(scale, [1.0, 1.0, 1.0])
    assert not div
    big = np.full(3, 20.0)                                     # 1200 > 25 × 6
    assert switch_components(big, S, np.ones(3), R, tune)[1]


def test_declared_sensor_noise_is_the_presets_vrw_arw_and_scale_factor_misalignment():
    imu = load_imu("STIM300")
    q, sf = declared_sensor_noise([imu, imu], 0.1)
    assert q.shape == (2, 6) and sf.shape == (2, 2)
    assert math.isclose(math.sqrt(q[0, 3]), math.radians(0.15) / 60.0, rel_tol=1e-6)
    assert math.isclose(math.sqrt(q[0, 0]), 0.06 / 60.0, rel_tol=1e-6)
    assert math.isclose(sf[0, 1], (500e-6) ** 2 + 2 * 1e-3 ** 2, rel_tol=1e-6)


@pytest.fixture(scope="module")
def climb():
    segs = [Segment(100.0), Segment(150.0, 0.0, 3.0), Segment(100.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))


def test_a_stuck_baro_in_a_climb_is_excluded_and_the_vertical_stays_on_gnss(climb):
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=0)
    up = []
    for s in climb:
        up.append(nav.update(s).errors["nse_up_m"])
        if abs(s.t_s - 120.0) < 1e-6:
            nav.inject({"unit": "baro", "kind": "baro_failure"}, s.t_s)
    exc = [e for e in nav.events if e["kind"] == "excluded" and e["unit"].startswith("baro")]
    assert {e["unit"] for e in exc} == {"baro@ins1", "baro@ins2", "baro@ins3"}
    assert all(120.0 < e["t_s"] < 150.0 for e in exc)
    assert not [e for e in nav.events if e["kind"] == "excluded" and e["unit"].startswith("ins")]
    assert np.max(np.abs(up[2000:])) < 10.0                   # GNSS keeps the vertical


def test_no_altitude_measurement_freezes_the_vertical_channel_and_gnss_releases_it(climb):
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3, "baro": None,
                       "gnss": {"outages": [{"start_s": 150.0, "end_s": 250.0}]}}, seed=1)
    frozen_at = {}
    for s in climb:
        nav.update(s)
        if abs(s.t_s - 200.0) < 1e-6:
            frozen_at = {i: f.frozen.copy() for i, f in enumerate(nav.filters)}
    ev = [e for e in nav.events if e["kind"] == "reconfigured" and e["stage"] == "estimator"]
    frz = [e for e in ev if "frozen" in e["reason"]]
    rel = [e for e in ev if "released" in e["reason"]]
    assert len(frz) == 3 and all(150.0 < e["t_s"] < 153.0 for e in frz)
    assert len(rel) == 3 and all(250.0 <= e["t_s"] < 252.0 for e in rel)
    assert all(list(np.flatnonzero(m)) == [2, 5] for m in frozen_at.values())
    assert not any(f.frozen.any() for f in nav.filters)
    assert not [e for e in nav.events if e["kind"] == "excluded"]


EVENT_KINDS = {"fault_injected", "detected", "isolated", "excluded", "reconfigured", "alert"}


@pytest.mark.slow
def test_ins_fault_step_logs_every_step_as_an_event_and_the_columns_follow_it(tmp_path):
    from fms_testbed.data import scenarios_dir
    from fms_testbed.run import run_scenario
    res = run_scenario(scenarios_dir() / "ins-fault-step.yaml", progress=False)
    ev = res.summary["navigation"]["events"]
    assert ev and all(set(e) == {"t_s", "unit", "kind", "stage", "reason"} for e in ev)
    assert {e["kind"] for e in ev} <= EVENT_KINDS
    assert [e["t_s"] for e in ev] == sorted(e["t_s"] for e in ev)
    first = {k: next(e for e in ev if e["kind"] == k) for k in
             ("fault_injected", "detected", "isolated", "excluded", "reconfigured")}
    assert first["fault_injected"]["unit"] == "ins2" and first["excluded"]["unit"] == "ins2"
    assert (first["fault_injected"]["t_s"] <= first["detected"]["t_s"]
            <= first["isolated"]["t_s"] <= first["excluded"]["t_s"])
    df = res.df
    assert {"nav_mode", "ins_used", "anp_m", "rnp_alert", "ins_used_ref", "ins_used_vote",
            "refdesc_d_ins1"} <= set(df.columns)
    t_exc = first["excluded"]["t_s"]
    before, after = df[df.t_s < t_exc - 0.05], df[df.t_s >= t_exc + 0.05]
    assert set(before.ins_used) == {7.0} and set(after.ins_used) == {5.0}
    assert set(df.nav_mode[df.t_s > 5]) == {0.0} and (df.anp_m[df.t_s > 5] > 0).all()
    assert set(df.rnp_alert) == {0.0}
    assert res.summary["navigation"]["nse95_m"]["output"] < 5.0


def test_adaptive_r_rides_out_a_gnss_noise_burst_and_returns_to_nominal():
    segs = [Segment(100.0), Segment(40.0, 3.0), Segment(160.0)]
    states = aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))
    out = {}
    for adaptive in (False, True):
        nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 1,
                           "gnss": {"outliers": [{"start_s": 150.0, "end_s": 210.0,
                                                  "sigma_m": 8.0}]}}, seed=4)
        nav.ft.adaptive = adaptive
        nav.ft.set_component_channels(False)       # against the all-or-nothing group gate
        peak, nse = 1.0, []
        for s in states:
            e = nav.update(s).errors
            peak = max(peak, float(nav.filters[0].r_scale["gnss_pos"].max()))
            if 150.0 <= s.t_s < 215.0:
                nse.append(math.hypot(e["nse_east_m"], e["nse_north_m"]))
        out[adaptive] = (peak, float(np.percentile(nse, 95)),
                         nav.filters[0].r_scale["gnss_pos"].copy(), nav.events)
    assert out[False][0] == 1.0 and out[True][0] > 5.0
    np.testing.assert_allclose(out[True][2], 1.0, atol=1e-3)   # back to nominal after the burst
    assert out[True][1] < out[False][1]                        # the burst pulls it less
    assert not [e for e in out[True][3] if e["kind"] == "reset"]


def test_navigation_adaptive_key_selects_the_adaptive_variant():
    base = {"source": "ins_gnss", "imu": "STIM300", "n_ins": 1}
    assert not make_source(base, seed=0).ft.adaptive
    assert make_source({**base, "adaptive": True}, seed=0).ft.adaptive


def _filter_with_a_vertical_coupling(baro=None):
    """A filter whose position covariance couples δh to E and N (as a climbing turn does)."""
    from fms_testbed.core.state import NavSolution
    from fms_testbed.navigation.ins_filter import InsGnssFilter
    from fms_testbed.sensors.gnss import GnssSpec
    f = InsGnssFilter(load_imu("STIM300"), GnssSpec(), baro)
    f.initialise(NavSolution(0.0, 0.8, 0.1, 3000.0, np.array([150.0, 0.0, 0.0]), 0.0, 0.0, 0.5))
    f.P[:3, :3] += np.array([[4.0, 0.0, 2.0], [0.0, 4.0, 1.0], [2.0, 1.0, 9.0]])
    f.P[5, 0] = f.P[0, 5] = 0.5
    return f, NavSolution(0.0, 0.8, 0.1, 3000.0, np.array([150.0, 0.0, 0.0]), 0.0, 0.0, 0.5)


def _gnss_pos(sol, de_m, dn_m, du_m):
    from fms_testbed.navigation.measurements import GnssPosition
    from fms_testbed.core.earth import radii_m
    rm, rn = radii_m(sol.lat_rad)
    return GnssPosition(0.0, sol.lat_rad - dn_m / (rm + sol.alt_m),
                        sol.lon_rad - de_m / ((rn + sol.alt_m) * math.cos(sol.lat_rad)),
                        sol.alt_m - du_m, np.array([1.0, 1.0, 2.0]), np.zeros(3))


@pytest.mark.parametrize("hold", [True, False])
def test_a_failed_gnss_vertical_zeroes_its_gain_column_and_without_altitude_holds_the_vertical(
        hold):
    """Seed 001 eq. 8 per component: U off by 200 m fails |ν| ≤ 5√S, E and N are used; with no
    other altitude channel the gain rows of δh, δV_U are zeroed too (ẑ_H, Ŵ_Z keep their
    prediction, their variance unchanged) — without the hold the E/N correction moves them
    through the position covariance."""
    from fms_testbed.navigation.fdi import FaultTolerantEstimator
    f, sol = _filter_with_a_vertical_coupling()
    ft = FaultTolerantEstimator([f])
    assert f.channel_test == FdiTuning().k_residual and f.hold_vertical is not None
    if not hold:
        f.hold_vertical = None
    P0 = f.P.copy()
    g = f.use(_gnss_pos(sol, 3.0, -2.0, 200.0), sol)        # z = p_INS - p_GNSS = (3, -2, 200)
    assert g.used and g.components == (True, True, False)
    assert 1.0 < f.x[0] < 3.0 and -2.0 < f.x[1] < -0.6       # E, N used (a share of ν)
    vert = f.x[[2, 5]]
    if hold:
        assert np.all(vert == 0.0) and np.all(f.P[[2, 5], [2, 5]] == P0[[2, 5], [2, 5]])
    else:
        assert np.all(np.abs(vert) > 1e-3)
    assert abs(f.x[2]) < 10.0                                 # never the 200 m of U
    ev = ft.check(0, 1.0, [g])
    assert [e["reason"] for e in ev] == ([
        "vertical channel held and excluded: gnss_pos U failed its channel test"] if hold else [])
    assert list(np.flatnonzero(~ft.mask())) == ([2, 5] if hold else [])


def test_with_a_baro_the_failed_gnss_vertical_is_left_out_but_not_held():
    from fms_testbed.navigation.fdi import FaultTolerantEstimator
    from fms_testbed.sensors.baro import BaroSpec
    f, sol = _filter_with_a_vertical_coupling(BaroSpec())
    FaultTolerantEstimator([f])
    assert f.hold_vertical is None                            # the baro is the altitude channel
    g = f.use(_gnss_pos(sol, 0.0, 0.0, 200.0), sol)
    assert g.components == (True, True, False) and abs(f.x[2]) < 10.0


@pytest.mark.slow
def test_no_baro_an_outage_and_a_vertical_gnss_jump_hold_the_vertical_only_with_zeroing(climb):
    """The three-unit case of seed 001: no baro, GNSS lost 150-250 s while its vertical error
    ramps 0.5 m/s (50 m at re-acquisition). Per component, the vertical stays held and out of
    the comparisons while the horizontal is GNSS-aided; the all-or-nothing gate rejects every
    fix until its reset takes the jump into the vertical."""
    out = {}
    for on in (True, False):
        nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3, "baro": None,
                           "gnss": {"outages": [{"start_s": 150.0, "end_s": 250.0}],
                                    "ramps": [{"start_s": 150.0, "rate_mps": [0, 0, 0.5]}]}},
                          seed=1)
        nav.ft.set_component_channels(on)
        rows = [nav.update(s).errors for s in climb]
        out[on] = (np.array([r["nse_up_m"] for r in rows]),
                   np.array([math.hypot(r["nse_east_m"], r["nse_north_m"]) for r in rows]),
                   [e for e in nav.events if "held" in e["reason"]], nav.filters[0].P.copy())
    up_on, hz_on, held_on, P_on = out[True]
    up_off, _, held_off, P_off = out[False]
    assert len(held_on) == 3 and all(250.0 <= e["t_s"] < 252.0 for e in held_on) and not held_off
    assert np.abs(up_on[2510:]).max() < 20.0 < 40.0 < np.abs(up_off[2510:]).max()
    assert hz_on[2510:].max() < 15.0
    assert not np.allclose(P_on[:6, :6], P_off[:6, :6])
