"""The compiled two-stage step (:class:`~fms_testbed.navigation.identification.two_stage.TwoStage`)
against the straightforward numpy expressions of the same rules (``two_stage_reference.py``):
every state array equal after every step, on seeded inputs where units drift, step and jump,
the GNSS innovations fail for one unit or for all, the sensor level flags pairs and channels are
masked — and each branch (isolation, both exclusion reasons, estimate failure, GNSS failure) is
taken in some realisation, so a broken rule cannot pass unseen."""

from __future__ import annotations

import numpy as np

from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.identification.two_stage import BY_INNOVATION, BY_TABLE, TwoStage
from tests.navigation.two_stage_reference import TwoStageNumpy

_ARRAYS = ("used", "isolated", "nu", "flags", "verdict", "gnss_failed", "baro_failed",
           "t_gnss_s", "t_baro_s", "stat_max", "t_detect_s", "t_isolate_s", "t_exclude_s",
           "t_estimate_failed_s", "excluded_by", "new_detect", "new_isolate", "new_exclude",
           "new_estimate_failed")


def _inputs(R: int, U: int, n: int, seed: int):
    """Seeded (t, y, sig, nu_sensor, mask, nis, dof, baro) per step at 10 Hz: units with noise
    at their σ, one unit per realisation given a step, a ramp or a heading jump at a random
    time, some realisations with every unit's innovations failing (a GNSS fault)."""
    rng = np.random.default_rng(seed)
    C = 9
    sig = np.abs(rng.normal(1.0, 0.2, (R, U, C))) + 0.1
    base = np.cumsum(rng.normal(0.0, 0.3, (n, R, 1, C)), axis=0)
    bad = rng.integers(0, U, R)
    kind = rng.integers(0, 4, R)                  # 0 none, 1 step, 2 ramp, 3 heading jump
    t0 = rng.uniform(2.0, 0.8 * n / 10.0, R)
    gnss = rng.random(R) < 0.15
    for k in range(n):
        t = 0.1 * k
        y = base[k] + rng.normal(0.0, 1.0, (R, U, C)) * sig
        y[:, :, 8] = np.remainder(y[:, :, 8] * 0.01 + 3.1, 2 * np.pi) - np.pi   # near ±π
        on = t >= t0
        r = np.nonzero(on & (kind == 1))[0]
        y[r, bad[r], rng.integers(0, C)] += 12.0 * sig[r, bad[r], 0]
        r = np.nonzero(on & (kind == 2))[0]
        y[r, bad[r], 3] += 3.0 * (t - t0[r]) * sig[r, bad[r], 3]
        r = np.nonzero(on & (kind == 3))[0]
        y[r, bad[r], 8] += 0.5
        nus = (rng.random((R, 3)) < 0.002) | ((kind == 1) & on & (rng.random(R) < 0.3))[:, None]
        mask = np.ones(C, bool) if k % 50 < 40 else np.r_[[True] * 2, False, True, True,
                                                          False, [True] * 3]
        nis = rng.chisquare(3, (R, U)) * np.where(on[:, None] & gnss[:, None], 30.0, 1.0)
        one = on & (kind == 2)
        nis[one, bad[one]] *= 40.0
        dof = np.full((R, U), 3, np.int64)
        dof[rng.random((R, U)) < 0.1] = 0
        nis[dof == 0] = 0.0
        yield t, y, sig, nus, mask, (nis, dof) if k % 10 == 0 else None, rng.random((R, U)) < 0.05


def _run_both(R, U, n, seed, track):
    tu = FdiTuning()
    a, b = TwoStage(R, U, tu, track_stats=track), TwoStageNumpy(R, U, tu, track_stats=track)
    seen = {k: np.zeros(R, bool) for k in ("isolate", "table", "innov", "est", "gnss")}
    for t, y, sig, nus, mask, innov, baro in _inputs(R, U, n, seed):
        for o in (a, b):
            if innov is not None:
                o.add_innovation(t, *innov)
            o.add_baro_test(t, baro)
            o.update(t, y, sig, nus, mask)
        for name in _ARRAYS:
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name),
                                          err_msg=f"{name} at t = {t:.1f} s")
        seen["isolate"] |= a.new_isolate.any(axis=1)
        seen["table"] |= (a.new_exclude & (a.excluded_by == BY_TABLE)).any(axis=1)
        seen["innov"] |= (a.new_exclude & (a.excluded_by == BY_INNOVATION)).any(axis=1)
        seen["est"] |= a.new_estimate_failed
        seen["gnss"] |= a.gnss_failed
    return seen


def test_compiled_step_equals_the_numpy_rules_on_three_units():
    seen = _run_both(200, 3, 300, 7, track=True)
    assert all(v.sum() >= 3 for v in seen.values()), {k: int(v.sum()) for k, v in seen.items()}


def test_compiled_step_equals_the_numpy_rules_on_two_units_and_one_realisation():
    _run_both(40, 2, 200, 11, track=False)
    _run_both(1, 3, 300, 12, track=False)


def test_compiled_pair_flags_equal_the_numpy_pairs():
    from fms_testbed.navigation.identification.rules import pair_flags
    from tests.navigation.two_stage_reference import pair_flags as pair_flags_np
    hits = 0
    for t, y, sig, nus, mask, _, live in _inputs(300, 3, 40, 5):
        live = ~live
        np.testing.assert_array_equal(pair_flags(y, sig, 4.3, live, mask),
                                      pair_flags_np(y, sig, 4.3, live, mask))
        np.testing.assert_array_equal(pair_flags(y[:, :2], sig[:, :2], 2.0),
                                      pair_flags_np(y[:, :2], sig[:, :2], 2.0))
        hits += pair_flags(y, sig, 4.3, live, mask).sum()
    assert hits > 100
