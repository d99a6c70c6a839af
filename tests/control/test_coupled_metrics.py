"""Step metrics on synthetic responses with known answers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from fms_testbed.control.metrics import settling_time, step_metrics
from fms_testbed.control.pointmass import second_order_step


def _run(T, xi, step_m=100.0, t_step=10.0):
    t = np.arange(0.0, 200.0, 0.025)
    y = 3000.0 + step_m * np.where(t >= t_step, second_order_step(np.maximum(t - t_step, 0), T, xi), 0)
    n = len(t)
    return pd.DataFrame({"t_s": t, "alt_m": y, "tas_mps": 111.0 + 0.3 * np.sin(t / 5),
                         "cmd_alt_m": np.where(t >= t_step, 3000.0 + step_m, 3000.0),
                         "cmd_tas_mps": np.full(n, 111.0),
                         "throttle": np.clip(0.5 + 0.1 * np.sin(t), 0, 1), "ny": np.ones(n)})


def test_settling_time_of_a_critically_damped_second_order_is_5_83_T():
    m = step_metrics(_run(8.0, 1.0), "alt")
    assert m.settling_s == pytest.approx(5.834 * 8.0, abs=0.05)
    assert m.overshoot_pct == pytest.approx(0.0, abs=1e-9)
    assert m.step == pytest.approx(100.0)


def test_overshoot_matches_the_damping_ratio():
    xi = 0.5
    m = step_metrics(_run(8.0, xi), "alt")
    assert m.overshoot_pct == pytest.approx(100 * math.exp(-math.pi * xi / math.sqrt(1 - xi ** 2)),
                                            rel=1e-3)


def test_cross_deviation_and_throttle_activity():
    m = step_metrics(_run(8.0, 1.0), "alt")
    assert m.max_cross_dev == pytest.approx(0.3, abs=1e-3)
    # |d/dt (0.1 sin t)| averages 0.2/pi
    assert m.throttle_activity_ps == pytest.approx(0.2 / math.pi, rel=0.02)
    assert m.throttle_sat_frac == 0.0


def test_never_settling_is_nan_and_no_step_is_an_error():
    t = np.linspace(0, 10, 11)
    assert math.isnan(settling_time(t, np.linspace(0, 1, 11), 2.0, 0.1))
    df = _run(8.0, 1.0)
    df["cmd_alt_m"] = 3000.0
    with pytest.raises(ValueError, match="no alt command change"):
        step_metrics(df, "alt")


def test_a_command_appearing_on_engagement_counts_as_a_step_from_the_measurement():
    df = _run(8.0, 1.0)
    df.loc[df["t_s"] < 10.0, "cmd_alt_m"] = np.nan
    m = step_metrics(df, "alt")
    assert m.t_step_s == pytest.approx(10.0)
    assert m.step == pytest.approx(100.0)
