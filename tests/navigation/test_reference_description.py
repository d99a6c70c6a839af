"""Zaitseva's reference-description monitor: its decision rule on arrays, its per-channel filter,
the envelope's honesty on fault-free units, a large drift change identified (and seen by majority
voting on the raw outputs), and the output weighted by the ranking."""

import numpy as np
import pytest

from fms_testbed.navigation import make_source
from fms_testbed.navigation.reference_description import (ReferenceTuning, channel_filter_step,
                                                           envelope_start, normalised_distance,
                                                           reference_decision)
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.presets import load_imu

TUNE = ReferenceTuning(k_sigma=4.0, persist_s=10.0)


def _decide(d, excluded, since, t):
    return reference_decision(np.array(d, float), np.array(excluded), np.array(since, float), t,
                              TUNE)


def test_a_unit_outside_is_excluded_only_after_the_persistence():
    used, exc, since, rank = _decide([1.0, 5.0, 2.0], [False] * 3, [np.nan] * 3, 100.0)
    assert used.all() and not exc.any() and since[1] == 100.0 and np.isnan(since[0])
    assert list(rank) == [0, 2, 1]
    used, exc, since, _ = _decide([1.0, 5.0, 2.0], exc, since, 109.0)
    assert used.all()
    used, exc, since, _ = _decide([1.0, 5.0, 2.0], exc, since, 110.0)
    assert list(used) == [True, False, True] and list(exc) == [False, True, False]


def test_an_excursion_that_returns_inside_restarts_the_timer_and_exclusion_latches():
    _, exc, since, _ = _decide([1.0, 5.0, 2.0], [False] * 3, [np.nan] * 3, 0.0)
    _, exc, since, _ = _decide([1.0, 3.0, 2.0], exc, since, 5.0)
    assert np.isnan(since[1])
    used, exc, since, _ = _decide([1.0, 5.0, 2.0], exc, since, 12.0)
    assert used.all()                                          # 0 s into the new excursion
    _, exc, since, _ = _decide([1.0, 5.0, 2.0], exc, since, 22.0)
    used, exc, _, _ = _decide([1.0, 0.5, 2.0], exc, since, 30.0)    # back inside: stays out
    assert list(used) == [True, False, True]


def test_when_every_unit_is_outside_the_closest_to_its_reference_description_is_used():
    since = [0.0, 0.0, 0.0]
    used, exc, _, rank = _decide([6.0, 9.0, 4.5], [False] * 3, since, 20.0)
    assert list(used) == [False, False, True] and not exc.any() and rank[0] == 2
    used, exc, _, _ = _decide([6.0, 9.0, 4.5], [False, True, False], since, 20.0)
    assert list(used) == [False, False, True] and list(exc) == [False, True, False]


def test_normalised_distance_is_the_worst_channel_in_sigma():
    d = normalised_distance(np.array([[3.0, -8.0, 0.1, 0.0], [1.0, 1.0, 1.0, 1.0]]),
                            np.array([[1.0, 4.0, 1.0, 1.0], [4.0, 4.0, 4.0, 4.0]]))
    np.testing.assert_allclose(d, [4.0, 0.5])


def test_the_per_channel_filter_tracks_a_ramp_with_an_honest_covariance():
    rng = np.random.default_rng(3)
    u, n, dt = 400, 120, 1.0
    var0 = np.array([25.0, 0.01])                                   # δp m², δV (m/s)²
    r = np.broadcast_to(var0, (u, 2, 2))
    x = np.zeros((u, 2, 2))
    P = np.broadcast_to(np.diag(var0), (u, 2, 2, 2)).copy()
    p0 = np.sqrt(var0[0]) * rng.standard_normal((u, 2))           # drawn from P0: consistent
    v = np.sqrt(var0[1]) * rng.standard_normal((u, 2)) + np.array([2.0, -0.5])
    x[..., 1] = np.array([2.0, -0.5])
    for k in range(1, n):
        true = np.stack([p0 + v * k * dt, v], axis=-1)
        z = true + np.sqrt(r) * rng.standard_normal((u, 2, 2))
        x, P = channel_filter_step(x, P, z, r, np.full((u, 2), 1e-12), dt)
    nees = np.mean((x - true) ** 2 / np.diagonal(P, axis1=-2, axis2=-1), axis=0)
    assert np.all(np.abs(nees - 1.0) < 0.25), nees            # 400 runs: σ of the mean ≈ 0.07
    np.testing.assert_allclose(P, np.swapaxes(P, -1, -2))


def test_envelope_start_keeps_the_filter_block_and_declares_the_unmodelled_errors():
    imu = load_imu("STIM300")
    Pf = np.diag(np.arange(1.0, 23.0))
    P = envelope_start(Pf, imu)
    np.testing.assert_array_equal(P[:15, :15], Pf[:15, :15])
    assert P[16, 16] == imu.p0_var[16] and P[27, 27] == imu.p0_var[27]
    assert P[17, 17] == P[22, 22] == P[24, 24] == 0.0         # carried by the filter's b_a


@pytest.fixture(scope="module")
def states():
    segs = [Segment(120.0), Segment(30.0, 3.0), Segment(450.0), Segment(30.0, -3.0),
            Segment(570.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=200.0))


def _fly(states, fault=None, at_s=300.0, seed=0):
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=seed)
    rows = []
    for s in states:
        rows.append(nav.update(s).errors)
        if fault is not None and abs(s.t_s - at_s) < 1e-6:
            nav.inject(fault, s.t_s)
    return nav, rows


@pytest.mark.slow
def test_fault_free_units_stay_inside_their_reference_description(states):
    for seed in (0, 1):
        nav, rows = _fly(states, seed=seed)
        d = np.array([[r[f"refdesc_d_ins{i}"] for i in (1, 2, 3)] for r in rows])
        assert np.nanmax(d) < TUNE.k_sigma
        assert not [e for e in nav.events if e["stage"] == "reference"]
        assert {r["ins_used_ref"] for r in rows} == {7.0}


@pytest.mark.slow
def test_a_large_drift_change_is_excluded_by_the_reference_description_and_seen_by_raw_voting(
        states):
    nav, rows = _fly(states, {"unit": "ins2", "kind": "drift_scale", "factor": 20.0})
    exc = [e for e in nav.events if e["kind"] == "excluded" and e["stage"] == "reference"]
    assert exc and exc[0]["unit"] == "ins2" and exc[0]["t_s"] - 300.0 <= 700.0   # 665 s at k 5
    after = [r for r in rows[int(exc[0]["t_s"] * 10) + 1:]]
    assert {r["ins_used_ref"] for r in after} == {5.0}
    # voting on the raw (free) outputs sees a ×20 drift (9.5 °/h excess) too: it votes it out
    assert any(not int(r["ins_used_vote"]) & 2 for r in after)


def test_the_channel_filter_follows_an_error_that_turns_while_the_envelope_shrinks():
    """In a turn the free copy's velocity error turns with the heading (here a component falls
    from 28 to 18 m/s in 16 s) while the envelope's variance of that component shrinks
    (36 → 25 (m/s)²): with q from the variance growth alone the filter froze and lagged the
    measurement by metres per second; with channel_process_noise it follows within the
    measurement noise."""
    from fms_testbed.navigation.reference_description import channel_process_noise

    def run(rule):
        x = np.array([[[1000.0, 28.0], [0.0, 0.0]]])              # one unit, axes E, N
        Pc = np.tile(np.diag([1.0, 0.01]), (1, 2, 1, 1))
        r = np.array([[[1.0, 0.0025], [1.0, 0.0025]]])
        var_v, p = 36.0, 1000.0
        for k in range(16):
            v_true = 28.0 - 10.0 * (k + 1) / 16
            p += v_true
            new_var = 36.0 - 11.0 * (k + 1) / 16
            q = np.array([[rule(new_var, var_v), rule(new_var, var_v)]])
            var_v = new_var
            x, Pc = channel_filter_step(x, Pc, np.array([[[p, v_true], [0.0, 0.0]]]), r, q, 1.0)
        return abs(x[0, 0, 1] - v_true)

    assert run(lambda now, before: channel_process_noise(now, before, 1.0, 10.0)) < 0.1
    assert run(lambda now, before: max(now - before, 1e-10)) > 2.0      # the old rule lags


def test_rank_weights_follow_the_ranking():
    from fms_testbed.navigation.reference_description import rank_weights
    w = rank_weights(np.array([0.0, 3.0, 1.0]))
    np.testing.assert_allclose(w.sum(), 1.0)
    assert list(np.argsort(-w)) == [0, 2, 1]                   # the ranking's order
    np.testing.assert_allclose(w[1] / w[0], 1.0 / 10.0)        # (1 + 0²) / (1 + 3²)
    np.testing.assert_allclose(rank_weights(np.full(3, 2.0)), 1.0 / 3.0)


@pytest.mark.slow
def test_the_output_is_weighted_by_the_reference_ranking_and_changes_with_it():
    """Fault-free three units past the reference epoch: the output is Σ w_i C_i with the rank
    weights of the monitor's distances, not the plain mean, and reversing the ranking moves it."""
    import math
    from fms_testbed.navigation.ins_gnss import _corrected_many, weighted_solution
    from fms_testbed.navigation.reference_description import rank_weights
    segs = [Segment(100.0), Segment(40.0, 3.0), Segment(60.0)]
    states = aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=0)
    for s in states:
        out = nav.update(s)
    d = nav.refdesc.d.copy()
    assert np.isfinite(d).all() and np.ptp(d) > 0.1 and out.errors["ins_used"] == 7.0
    O = np.array([(u.lat_rad, u.lon_rad, u.alt_m, *u.v_enu_mps, u.roll_rad, u.pitch_rad,
                   u.heading_rad) for u in nav._prev_ins])
    C, _ = _corrected_many(O, np.array([f.x[:9] for f in nav.filters]))
    w = rank_weights(d)
    ref = weighted_solution(C, [0, 1, 2], w)
    assert math.isclose(out.lat_rad, ref[0], rel_tol=0, abs_tol=1e-13)
    assert math.isclose(out.lon_rad, ref[1], rel_tol=0, abs_tol=1e-13)
    rev = weighted_solution(C, [0, 1, 2], rank_weights(d[::-1]))
    plain = weighted_solution(C, [0, 1, 2], np.full(3, 1.0 / 3.0))
    r_m = 6.37e6
    for other in (rev, plain):
        moved_m = r_m * math.hypot(other[0] - ref[0], (other[1] - ref[1]) * math.cos(ref[0]))
        assert moved_m > 1e-3
