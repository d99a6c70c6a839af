"""The identification rules over arrays (navigation/identification): table 1, the estimate,
the three-way stage 2 on (Z_i, Ẑ, Ẑ_p), the two-stage state machine, the different-type
rules for the GNSS and the baro, and majority voting."""

import numpy as np
import pytest

from fms_testbed.navigation.identification.rules import (ESTIMATE_FAILED, PREDICTION_FAILED,
                                                         UNIT_FAILED, fuse, named_unit,
                                                         pair_flags, three_way, vote)
from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.identification.two_stage import BY_TABLE, TwoStage


def test_table_1_names_the_odd_source_out_per_realisation():
    nu = np.array([[0, 0, 0], [1, 1, 0], [1, 0, 1], [0, 1, 1], [1, 1, 1]])
    assert list(named_unit(nu)) == [-1, 0, 1, 2, -1]
    assert list(named_unit(nu, np.array([3, 3, 2, 3, 3]))) == [-1, 0, -1, 2, -1]


def test_pair_flags_wrap_the_heading_and_skip_units_out_of_use():
    y = np.zeros((2, 3, 9))
    y[:, 0, 8] = np.pi - 1e-3                     # heading +179.94° against −179.94°: 0.11°
    y[:, 1, 8] = -np.pi + 1e-3
    y[:, 2, 8] = np.pi
    sig = np.full((2, 3, 9), 1e-3)
    assert not pair_flags(y, sig, 6.0).any()
    y[:, 2, 0] = 1.0                              # unit 3 position E: 1000σ
    live = np.array([[True, True, True], [True, True, False]])
    assert pair_flags(y, sig, 6.0, live).astype(int).tolist() == [[0, 1, 1], [0, 0, 0]]


def test_fuse_is_the_inverse_variance_mean():
    y = np.array([[[1.0], [4.0], [100.0]]])
    sig = np.array([[[1.0], [2.0], [1.0]]])
    z, s = fuse(y, sig, np.array([[True, True, False]]))
    assert z[0, 0] == pytest.approx((1.0 + 4.0 / 4) / 1.25)
    assert s[0, 0] == pytest.approx(1.0 / np.sqrt(1.25))


def test_three_way_table_names_the_unit_the_estimate_or_the_prediction():
    """(Z_i, Ẑ, Ẑ_p): a unit off from two agreeing references is the unit; a heavy unit that
    drags Ẑ away from Ẑ_p makes the others read 'estimate failed' and itself 'prediction
    failed' (its own value is the estimate)."""
    sz = np.ones((1, 3, 1))
    z = np.array([[[10.0], [0.0], [0.0]]])
    v = three_way(z, sz, np.zeros((1, 1)), np.full((1, 1), 0.5), np.zeros((1, 1)),
                  np.full((1, 1), 0.5), 5.0)
    assert v.tolist() == [[UNIT_FAILED, -1, -1]]
    zhat = np.array([[10.0]])                      # the estimate sits on unit 1
    v = three_way(z, sz, zhat, np.full((1, 1), 0.1), np.zeros((1, 1)), np.full((1, 1), 0.1),
                  5.0)
    assert v.tolist() == [[PREDICTION_FAILED, ESTIMATE_FAILED, ESTIMATE_FAILED]]


def _steps(core, y_of_t, sig, t_end, dt=0.1):
    for k in range(int(round(t_end / dt)) + 1):
        core.update(k * dt, y_of_t(k * dt), sig)


def test_stage_2_excludes_a_survivor_stage_1_does_not_name():
    """A 12σ step on unit 1 below the coarse stage-1 threshold (20 √2 σ): stage 2 (k_est 5)
    sees it against the estimate and the prediction, (1 1 0) for 2 s → excluded; the healthy
    units read 4σ / 1.15σ from Ẑ and stay."""
    tun = FdiTuning(k_pair=20.0, k_est=5.0, stage2_persist_s=2.0, predict_s=2.0)
    core = TwoStage(1, 3, tun)
    sig = np.ones((1, 3, 9))

    def y(t):
        out = np.zeros((1, 3, 9))
        out[0, 0, 3] = 12.0 if t >= 10.0 else 0.0
        return out

    _steps(core, y, sig, 20.0)
    assert not core.isolated.any() and not core.nu.any()       # stage 1 never named it
    assert core.used.tolist() == [[False, True, True]]
    assert core.t_detect_s[0] == core.t_exclude_s[0, 0]       # stage 2 detected it
    assert core.excluded_by[0, 0] == BY_TABLE
    assert 12.0 - 1e-9 <= core.t_exclude_s[0, 0] <= 12.5


def test_stage_1_isolates_at_once_and_a_common_motion_is_no_fault():
    """All units moving together (the aircraft's motion, the median increment of the
    prediction) trigger nothing; a large step on unit 3 is named by table 1 after persist_s
    and leaves the output at once; stage 2 then excludes it."""
    core = TwoStage(1, 3, FdiTuning())
    sig = np.ones((1, 3, 9))

    def y(t):
        out = np.full((1, 3, 9), 150.0 * t)       # common motion, m
        out[0, :, 8] = 0.0
        if t >= 10.0:
            out[0, 2, 1] += 50.0
        return out

    _steps(core, y, sig, 9.9)
    assert core.used.all() and not core.isolated.any() and (core.verdict == -1).all()
    _steps(core, y, sig, 20.0)
    assert core.t_isolate_s[0, 2] == pytest.approx(11.0)
    assert core.output_units.tolist() == [[True, True, False]]
    assert core.used.tolist() == [[True, True, False]]          # stage 2 confirmed


def test_gnss_named_when_every_unit_fails_its_innovations_together():
    core = TwoStage(2, 3, FdiTuning(window_s=5.0))
    y, sig = np.zeros((2, 3, 9)), np.ones((2, 3, 9))
    for k in range(100):
        t = k * 0.1
        if k % 10 == 0:
            nis = np.full((2, 3), 3.0)
            if t >= 5.0:
                nis[0] = 400.0                          # realisation 1: every unit
                nis[1, 1] = 400.0                       # realisation 2: one unit only
            core.add_innovation(t, nis, np.full((2, 3), 3))
        core.update(t, y, sig)
    assert core.gnss_failed.tolist() == [True, False]
    assert core.used.all()                              # no unit removed for the GNSS fault


def test_baro_named_when_every_unit_fails_its_baro_test():
    core = TwoStage(2, 3, FdiTuning(baro_fails=3, baro_window_s=10.0))
    for k in range(6):
        f = np.zeros((2, 3), bool)
        if k >= 3:
            f[0] = True
            f[1, 0] = True
        core.add_baro_test(float(k), f)
    assert core.baro_failed.tolist() == [True, False] and core.t_baro_s[0] == 5.0


def test_vote_leaves_out_the_unit_table_1_names_at_this_instant_only():
    flags = np.array([[1, 0, 1], [0, 0, 0], [1, 1, 1]], bool)
    assert vote(flags, 3).astype(int).tolist() == [[1, 0, 1], [1, 1, 1], [1, 1, 1]]
    assert vote(flags, 2).all()


def _cusum_flight(M2, step_at_s=None, seed=0, tuning=None):
    """Three STIM300 gyro triads (white noise at the declared ARW; unit 2 with the scale-factor
    and misalignment matrix ``M2``) through 100 s straight, a 60 s turn at 3 °/s and 100 s
    straight, on Page's CUSUM; a 22 °/h x step on unit 2 at ``step_at_s``. Returns (first alarm
    time s or None, the largest statistic)."""
    import math
    from fms_testbed.navigation.identification.sensor import SensorPairTest
    from fms_testbed.sensors.sins.presets import load_imu
    from fms_testbed.navigation.fdi import declared_sensor_noise
    dt, dph = 0.1, math.radians(1.0) / 3600.0
    imu = load_imu("STIM300")
    q, sf = declared_sensor_noise([imu] * 3, dt)
    test = SensorPairTest(1, 3, q, dt, sf, tuning or FdiTuning(sensor_test="cusum"))
    rng = np.random.default_rng(seed)
    first, top = None, 0.0
    for k in range(2600):
        t = k * dt
        w = np.array([0.0, 0.0, math.radians(3.0) if 100.0 <= t < 160.0 else 0.0])
        e = rng.standard_normal((1, 3, 6)) * np.sqrt(q / dt)
        e[0, 1, 3:] += M2 @ w
        if step_at_s is not None and t >= step_at_s:
            e[0, 1, 3] += 22.0 * dph
        nu = test.update(e, np.array([0.0, 0.0, -9.81]), w)
        top = max(top, float(test.last_z[0, :, 3:].max()))
        if nu.any() and first is None:
            first = t
    return first, top


M2_2SIGMA = np.array([[0.0, 0.0, 2e-3], [0.0, 0.0, 0.0], [0.0, 0.0, 1e-3]])
"""Unit 2's gyro x misaligned 2 mrad towards z and z scale factor 1,000 ppm (2σ of the declared
1 mrad and 500 ppm): in a 3 °/s turn its difference from the others holds 22 °/h on x."""


def test_the_cusum_rides_through_a_turn_that_holds_a_scale_factor_bias_in_the_difference():
    """A turn's scale-factor/misalignment difference is a bias held for the turn, not white
    noise: the CUSUM against the reference window's regression on the rate (ĉ, bias bound κ
    of its posterior σ) does not alarm, while a 22 °/h step after the turn is detected within
    15 s."""
    first, top = _cusum_flight(M2_2SIGMA)
    assert first is None and top < FdiTuning().cusum_h
    first, _ = _cusum_flight(np.zeros((3, 3)), step_at_s=200.0)
    assert first is not None and 200.0 < first <= 215.0       # the step after the turn


def test_the_cusum_holds_its_reference_so_a_step_in_a_turn_is_not_absorbed():
    """A 22 °/h step 25 s into the turn, on the misaligned unit: the reference regression
    (which lags the statistic by the short window) would take the step in as part of ĉ · u
    and the statistic would fall back; held while the CUSUM is above the freeze level, the
    step is detected in every seed and the statistic keeps growing (the step stays in the
    difference)."""
    tuning = FdiTuning(sensor_test="cusum", cusum_freeze=0.25)
    h = tuning.cusum_h
    for seed in range(3):
        first, top = _cusum_flight(M2_2SIGMA, step_at_s=125.0, seed=seed, tuning=tuning)
        assert first is not None and 125.0 < first <= 170.0, (seed, first)
        assert top > 4.0 * h, (seed, top)
