"""Consistency of the INS/GNSS filter on the strapdown truth, judged by the goal's four checks:
mean NEES of the nine navigation states inside its 95 % χ² band at ≥ 95 % of the epochs, NIS
mean within ±10 % of the dimension, and pyins' per-run checks (RMS(error/σ) < 1.5 per state,
innovation RMS < 3).

The per-run check RMS(e/σ) < 1.5 is a statement about one run's time average. Where an error
stays correlated for minutes (the position errors under a GNSS Markov error of τ = 300 s) a
600-s run holds a few independent samples and an honest filter fails it in a few per cent of
runs; the slow test therefore asks, per state, no more failing runs than the 99.9 % binomial
bound of a consistent filter's failure probability
(:func:`~fms_testbed.navigation.kalman.rms_check_failure_probability`), and — on a white-noise
receiver, pyins' own test setup — the same.

The IMU is the consistency test's (no scale-factor or misalignment errors: the filter's 15 INS
states are then the truth's model).
"""

import numpy as np
import pytest
from scipy.stats import binom, chi2

from fms_testbed.navigation import make_source
from fms_testbed.navigation.kalman import rms_check_failure_probability
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile

IMU = {"name": "matched-tactical",
       "gyro": {"arw_deg_per_sqrt_h": 0.05, "bias_instability_deg_per_h": 0.05,
                "bias_correlation_time_s": 3600},
       "accelerometer": {"vrw_mps_per_sqrt_h": 0.06, "bias_turn_on_ug": 750,
                         "bias_instability_ug": 50, "bias_correlation_time_s": 3600}}
WHITE_GNSS = {"pos_markov_sigma_m": [0.001, 0.001, 0.001],
              "vel_markov_sigma_mps": [0.0001, 0.0001, 0.0001]}


def ten_minutes():
    """600 s at 150 m/s: level, turns of ±3 °/s, a 3° climb and descent, 1 °/s turns."""
    segs = [Segment(60.0), Segment(60.0, 3.0), Segment(60.0, 0.0, 3.0), Segment(60.0, -3.0),
            Segment(120.0, 1.0), Segment(60.0, 0.0, -3.0), Segment(180.0, -1.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))


def two_minutes():
    segs = [Segment(30.0), Segment(40.0, 3.0), Segment(20.0), Segment(30.0, -2.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=120.0, heading_deg=20.0))


def runs(states, n_runs, seed0, gnss=None, q_scale=1.0):
    """Per run: NEES of the 9 navigation states and their e/σ at every whole second, and the
    innovation RMS of each GNSS group; NIS / dimension of every update pooled."""
    spec = {"source": "ins_gnss", "imu": IMU, "truth_model": "strapdown", "gnss": gnss or {}}
    nees, z, innov, nis = [], [], [], {}
    for r in range(n_runs):
        nav = make_source(spec, seed=seed0 + r)
        for f in nav.filters:
            f.q = f.q * q_scale
        row, zr = [], []
        for s in states:
            nav.update(s)
            if s.t_s > 0.5 and abs(s.t_s - round(s.t_s)) < 1e-6:
                f = nav.filters[0]
                e = nav.bank.errors(0)[:9] - f.x[:9]
                P = f.P[:9, :9]
                row.append(float(e @ np.linalg.solve(P, e)))
                zr.append(e / np.sqrt(np.diag(P)))
        nees.append(row)
        z.append(zr)
        by_group = {}
        for _, g, v, m in nav.nis_log:
            by_group.setdefault(g, []).append(v / m)
            nis.setdefault(g, []).append(v / m)
        innov.append([np.sqrt(np.mean(by_group[g])) for g in ("gnss_pos", "gnss_vel")])
    return (np.array(nees), np.array(z), np.array(innov),
            {g: float(np.mean(v)) for g, v in nis.items()})


def test_failure_probability_of_the_per_run_check_matches_a_brute_force_count():
    # AR(1) with a 150-s time constant sampled at 1 s, 300 samples: few independent samples
    rng = np.random.default_rng(7)
    a, n = np.exp(-1.0 / 150.0), 300
    x = np.empty((4000, n))
    x[:, 0] = rng.standard_normal(4000)
    for k in range(1, n):
        x[:, k] = a * x[:, k - 1] + np.sqrt(1 - a * a) * rng.standard_normal(4000)
    brute = np.mean(np.sqrt((x ** 2).mean(axis=1)) >= 1.5)
    p = rms_check_failure_probability(x[:200])
    assert brute > 0.05                       # the check fails often on such a process
    assert abs(p - brute) < 0.3 * brute
    assert rms_check_failure_probability(rng.standard_normal((100, n))) < 1e-3


@pytest.mark.parametrize("q_scale, consistent", [(1.0, True), (0.1, False)])
def test_quick_nees_and_nis_on_the_strapdown_and_a_filter_with_too_little_process_noise(
        q_scale, consistent):
    nees, _, innov, nis = runs(two_minutes(), 10, 500, q_scale=q_scale)
    # 10 runs × 120 epochs, correlated: the pooled mean within -20/+25 % of the dimension
    ok = 0.8 * 9 < nees.mean() < 1.25 * 9
    assert ok == consistent, nees.mean()
    if consistent:
        for g, v in nis.items():
            assert abs(v - 1) <= 0.10, (g, v)
        assert (innov < 3).all()


@pytest.mark.slow
@pytest.mark.parametrize("gnss", [None, WHITE_GNSS], ids=["default-receiver", "white-receiver"])
def test_consistency_over_100_ten_minute_strapdown_flights(gnss):
    n_runs = 100
    nees, z, innov, nis = runs(ten_minutes(), n_runs, 4000, gnss)
    lo, hi = chi2.ppf([0.025, 0.975], 9 * n_runs) / n_runs
    mean = nees.mean(axis=0)
    assert ((mean > lo) & (mean < hi)).mean() >= 0.95, (lo, hi, mean.mean())
    for g, v in nis.items():
        assert abs(v - 1) <= 0.10, (g, v)
    assert (innov < 3).all(), innov.max()
    rms = np.sqrt((z ** 2).mean(axis=1))                       # (runs, 9)
    for k in range(9):
        assert abs((z[:, :, k] ** 2).mean() - 1) <= 0.15, (k, (z[:, :, k] ** 2).mean())
        p = rms_check_failure_probability(z[:, :, k])
        bound = binom.ppf(0.999, n_runs, p)
        assert (rms[:, k] >= 1.5).sum() <= bound, (k, (rms[:, k] >= 1.5).sum(), p)
