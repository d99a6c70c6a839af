"""A compensated MEMS gyro as the SINS IMU: request forms, measured residual terms, ``load_imu``."""

import math

import numpy as np
import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.mems.equivalent import equivalent_imu_spec, parse_mems_request
from fms_testbed.sensors.mems.static_test import run_static_test
from fms_testbed.sensors.sins.analysis import covariance_run
from fms_testbed.sensors.sins.presets import load_imu
from fms_testbed.sensors.sins.trajectory import straight_level

ALL = ("temperature", "run-to-run", "slow-drift")
DPH = math.pi / 180 / 3600


def test_request_forms():
    assert parse_mems_request("STIM210") == ("STIM210", ())
    assert parse_mems_request("stim210+compensated") == ("stim210", ALL)
    assert parse_mems_request("STIM210+run-to-run+temperature") == \
        ("STIM210", ("temperature", "run-to-run"))
    assert parse_mems_request({"mems": "STIM210", "stages": ["slow-drift"]}) == \
        ("STIM210", ("slow-drift",))
    assert parse_mems_request("HG1700") is None and parse_mems_request({"gyro": {}}) is None
    with pytest.raises(ConfigError, match="unknown compensation stage 'kalman'"):
        parse_mems_request("STIM210+kalman")
    with pytest.raises(ConfigError, match="navigation.imu.mems: unknown MEMS gyro preset"):
        parse_mems_request({"mems": "STIM999"})
    with pytest.raises(ConfigError, match="navigation.imu.stage: unknown key"):
        parse_mems_request({"mems": "STIM210", "stage": []})


def test_residual_terms_are_measured_from_the_static_runs():
    none = equivalent_imu_spec("STIM210", ())
    comp = equivalent_imu_spec("STIM210", ALL)
    assert none.name == "STIM210" and comp.name == "STIM210+temperature+run-to-run+slow-drift"
    # uncompensated: the turn-on term is the 1-h mean zero signal, ~0.015 °/s (54 °/h)
    r = run_static_test("STIM210", 3600.0, "warmup", ("none",), seed=0)
    rms = float(np.sqrt(np.mean(r.stage["none"].mean_drift_deg_per_s ** 2))) * 3600
    assert none.gyro.bias_turn_on_deg_per_h == pytest.approx(rms, rel=0.35)
    assert 40 < none.gyro.bias_turn_on_deg_per_h < 70
    # all three stages: below 1.7° in 2 h, i.e. < 0.85 °/h
    assert comp.gyro.bias_turn_on_deg_per_h < 0.85
    assert none.gyro.bias_turn_on_deg_per_h / comp.gyro.bias_turn_on_deg_per_h > 50
    assert comp.gyro.arw_deg_per_sqrt_h == 0.10 and comp.accelerometer.vrw_mps_per_sqrt_h == 0.06
    assert "residual measured" in comp.source


def test_load_imu_takes_the_mems_request_and_keeps_the_other_presets():
    m = load_imu("STIM210+compensated")
    spec = equivalent_imu_spec("STIM210", ALL)
    assert math.sqrt(m.p0_var[12]) == pytest.approx(spec.gyro.bias_turn_on_deg_per_h * DPH)
    assert load_imu({"mems": "STIM210", "stages": list(ALL)}).name == m.name
    assert load_imu("HG1700").name == "HG1700"
    nav = SinsNavigation.from_spec({"source": "sins", "imu": "STIM210+compensated"})
    assert nav.imu.name == m.name


def test_compensation_shrinks_the_ins_position_error():
    traj = straight_level(600.0, 1.0, lat_deg=47.5, speed_mps=120.0, heading_deg=90.0)
    h95 = {k: covariance_run(traj, load_imu(k)).h95_m[-1]
           for k in ("STIM210", "STIM210+compensated")}
    assert h95["STIM210+compensated"] * 5 < h95["STIM210"], h95
