"""Flight-test attitude-reference mode (seed 004): the reference's error model, the computer's
error model against a perturbed DCM, the filter's consistency and observability on synthetic
profiles, the summary block, and the scenario block's errors."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import DEG_RAD, DPH_RPS
from fms_testbed.navigation import make_source
from fms_testbed.navigation.attitude_reference import (GOAL_DEG, AttitudeReferenceNavigation,
                                                       attitude_reference_summary)
from fms_testbed.sensors.attitude_reference import VEL, ANG, system_matrix
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.model import dcm_body_to_enu

ANGLES = ("roll", "pitch", "heading")


def _run(segments, seed, nav=None):
    src = make_source({"source": "attitude_reference", **(nav or {})}, seed=seed)
    rows = []
    for s in aircraft_states(fly_profile(segments, dt_s=0.1, speed_mps=120.0,
                                         heading_deg=30.0)):
        rows.append({"t_s": s.t_s, **src.update(s).errors})
    return src, pd.DataFrame(rows)


def _err(df, a):
    return (df[f"att_ref_est_{a}_deg"] - df[f"att_ref_err_{a}_deg"]).to_numpy()


@pytest.mark.parametrize("rpy", [(0.0, 0.05, 0.5), (0.4, -0.1, 2.5), (-0.44, 0.2, 4.0)])
def test_angle_error_block_matches_a_perturbed_dcm(rpy):
    # δV' from the reference's angle errors is (C(angles + δ) - C(angles)) f_b to first order
    f_b = np.array([0.8, 0.4, -10.5])
    F = system_matrix(0.8, 3000.0, np.array([100.0, 50.0, 2.0]), f_b, rpy, np.zeros(3))
    for j in range(3):
        d = np.zeros(3)
        d[j] = 1e-5
        exact = (dcm_body_to_enu(*(np.array(rpy) + d)) - dcm_body_to_enu(*rpy)) @ f_b
        np.testing.assert_allclose(F[VEL, ANG] @ d, exact, rtol=2e-4, atol=1e-12)


def test_injected_errors_are_constant_plus_drift_whatever_the_feedback():
    nav = {"reference": {"bias_deg": [0.1, -0.2, 0.5], "drift_dph": [1.0, -2.0, 3.0],
                         "arw_deg_rh": [0, 0, 0]}}
    _, df = _run([Segment(30, 3.0)], seed=1, nav=nav)
    t = df["t_s"].to_numpy()
    for i, a in enumerate(ANGLES):
        want = nav["reference"]["bias_deg"][i] + nav["reference"]["drift_dph"][i] / 3600 * t
        np.testing.assert_allclose(df[f"att_ref_err_{a}_deg"], want, atol=1e-9)
    # the filter did correct the computer (its estimate moved away from zero)
    assert abs(df["att_ref_est_roll_deg"].iloc[-1]) > 0.05


def test_same_seed_same_numbers_other_seed_other_errors():
    segs = [Segment(12, 3.0)]
    a, b, c = (_run(segs, s)[1] for s in (4, 4, 5))
    pd.testing.assert_frame_equal(a, b)
    assert not np.isclose(a["att_ref_err_heading_deg"].iloc[0], c["att_ref_err_heading_deg"].iloc[0])


TURNS = [Segment(5), Segment(40, 3.0), Segment(40, -3.0), Segment(40, 3.0), Segment(35)]


@pytest.mark.parametrize("truth_model", ["strapdown", "linear"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_filter_is_consistent_and_resolves_heading_in_turns(seed, truth_model):
    _, df = _run(TURNS, seed, {"truth_model": truth_model})
    late = df["t_s"] >= 60
    for a in ANGLES:
        e, s = _err(df, a), df[f"att_ref_sigma_{a}_deg"].to_numpy()
        z = e[late] / s[late]
        assert np.max(np.abs(z)) < 3.5, a            # 3σ (a little slack over 1500 samples)
        assert np.sqrt(np.mean(z ** 2)) < 1.5, a     # pyins-style RMS(error/σ)
    s_h = df["att_ref_sigma_heading_deg"].to_numpy()
    assert s_h[0] == pytest.approx(0.5, rel=1e-6)     # the declared prior
    assert s_h[late.to_numpy()].max() < 0.05          # turns make heading observable


def test_heading_is_not_observable_straight_and_level():
    _, df = _run([Segment(160)], seed=3)
    s_h = df["att_ref_sigma_heading_deg"].to_numpy()
    assert s_h[-1] > 0.45                              # stays at its 0.5° prior
    assert df["att_ref_sigma_roll_deg"].iloc[-1] < 0.01  # tilt is observable
    assert df["att_ref_sigma_pitch_deg"].iloc[-1] < 0.01
    assert np.max(np.abs(_err(df, "roll")[df["t_s"] >= 60] /
                         df["att_ref_sigma_roll_deg"][df["t_s"] >= 60])) < 3.5


def _frame(err_deg: dict, sigma_deg: dict, n=201):
    t = np.linspace(0, 200, n)
    d = {"t_s": t}
    for a in ANGLES:
        d[f"att_ref_err_{a}_deg"] = np.full(n, 0.3)
        d[f"att_ref_est_{a}_deg"] = 0.3 + err_deg[a](t)
        d[f"att_ref_sigma_{a}_deg"] = np.full(n, sigma_deg[a])
    return pd.DataFrame(d)


def test_summary_judges_goal_and_3sigma_from_60_s():
    df = _frame({"roll": lambda t: np.where(t < 50, 0.5, 0.005),
                 "pitch": lambda t: np.where(t < 120, 0.03, 0.0),
                 "heading": lambda t: 0.05 + 0 * t},
                {"roll": 0.004, "pitch": 0.01, "heading": 0.01})
    s = attitude_reference_summary(df)
    r, p, h = (s["angles"][a] for a in ("roll", "pitch", "heading"))
    assert r["meets_goal"] and r["inside_3sigma"] and r["within_goal_from_s"] == 50.0
    assert not p["meets_goal"] and p["within_goal_from_s"] == 120.0
    assert p["max_abs_err_after_deg"] == pytest.approx(0.03)
    assert h["meets_goal"] and not h["inside_3sigma"]          # 5σ: an inconsistent filter
    assert h["max_err_over_sigma_after"] == pytest.approx(5.0)
    assert not s["meets_goal"] and not s["inside_3sigma"]
    assert s["goal_deg"] == GOAL_DEG
    assert attitude_reference_summary(df.drop(columns="att_ref_err_roll_deg")) is None


def test_summary_of_a_flight_shorter_than_60_s_fails():
    df = _frame({a: (lambda t: 0 * t) for a in ANGLES}, {a: 0.001 for a in ANGLES}, n=11)
    df["t_s"] = np.linspace(0, 30, 11)
    s = attitude_reference_summary(df)
    assert not s["meets_goal"] and "30.0 s" in s["reason"]


@pytest.mark.parametrize("nav, field", [
    ({"reference": {"bias_sigma_deg": [0.1, 0.1]}}, "navigation.reference.bias_sigma_deg"),
    ({"reference": {"bias_deg": [1, 2, 3], "typo": 1}}, "navigation.reference.typo"),
    ({"gate_sigma": 0}, "navigation.gate_sigma"),
    ({"filter": {}}, "navigation.filter"),
])
def test_bad_block_names_the_field(nav, field):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        AttitudeReferenceNavigation.from_spec({"source": "attitude_reference", **nav})


def test_units_of_the_reference_block():
    src = make_source({"source": "attitude_reference",
                       "reference": {"drift_sigma_dph": [3.6, 7.2, 0.0],
                                     "arw_deg_rh": [0.6, 0, 0]}}, seed=0)
    spec = src.errors.spec
    assert spec.drift_sigma_rps[0] == pytest.approx(3.6 * DPH_RPS)
    assert spec.arw_rad_rs[0] == pytest.approx(0.6 * DEG_RAD / 60.0)
    assert math.isclose(spec.bias_sigma_rad[2], 0.5 * DEG_RAD)
