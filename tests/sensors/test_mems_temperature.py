"""Temperature profiles (warm-up, thermal cycle, CSV files) and the play-operator hysteresis."""

import numpy as np
import pytest

from fms_testbed.core.errors import UserError
from fms_testbed.sensors.mems.preset import load_mems
from fms_testbed.sensors.mems.temperature import (hysteresis_state, profile_for, ramp_profile,
                                                  read_profile, warmup_profile)


def test_warmup_follows_the_first_order_rise():
    p = warmup_profile(3600, 20.0, 12.0, 900.0)
    assert p.t_s[0] == 0 and p.duration_s == 3600 and np.all(np.diff(p.t_s) == 1.0)
    assert p.at(np.array([0.0]))[0] == 20.0
    assert p.at(np.array([900.0]))[0] == pytest.approx(20 + 12 * (1 - np.exp(-1)))


def test_ramp_is_a_soaked_thermal_cycle_over_the_range():
    p = ramp_profile(14400, -40.0, 85.0, 25.0, soak_s=600)
    assert np.all(p.temp_degC[:601] == 25.0)
    assert p.temp_degC.max() == pytest.approx(85.0) and p.temp_degC.min() == pytest.approx(-40.0)
    assert p.temp_degC[-1] == pytest.approx(25.0)
    rate = np.abs(np.diff(p.temp_degC[600:]))             # °C per 1-s step
    assert np.mean(np.abs(rate - 250.0 / 13800.0) < 1e-9) > 0.99  # one rate: 60 + 125 + 65 °C
    with pytest.raises(UserError, match="start 90"):
        ramp_profile(100, -40, 85, 90)


def test_hysteresis_branches_switch_after_twice_the_width():
    w = 3.0
    up = np.arange(20.0, 40.01, 0.5)
    down = np.arange(40.0, 19.99, -0.5)
    h = hysteresis_state(np.concatenate([up, down]), w)
    assert h[0] == 0.0                                   # relaxed at switch-on
    assert np.all(np.abs(h) <= 1 + 1e-12)
    assert h[len(up) - 1] == pytest.approx(1.0)          # heating branch
    k = len(up) + int(round(2 * w / 0.5))                # a reversal of 2 w later...
    assert h[k] == pytest.approx(-1.0)                   # ...the cooling branch
    assert h[len(up) + 1] == pytest.approx(1 - 0.5 / w)  # in between: linear in the dead band


def test_csv_profile_is_read_and_checked(tmp_path):
    f = tmp_path / "p.csv"
    f.write_text("t_s,temperature_degC\n0,20\n100,30\n200,25\n")
    p = read_profile(f, duration_s=200)
    assert p.name == "p" and p.at(np.array([50.0]))[0] == pytest.approx(25.0)
    with pytest.raises(UserError, match="covers 200 s but the test lasts 300 s"):
        read_profile(f, duration_s=300)
    f.write_text("t_s,temp\n0,20\n")
    with pytest.raises(UserError, match="columns t_s, temperature_degC"):
        read_profile(f)
    f.write_text("t_s,temperature_degC\n0,20\n10,hot\n")
    with pytest.raises(UserError, match="line 3"):
        read_profile(f)
    f.write_text("t_s,temperature_degC\n0,20\n10,21\n5,22\n")
    with pytest.raises(UserError, match="increase strictly"):
        read_profile(f)
    with pytest.raises(UserError, match="cannot read"):
        read_profile(tmp_path / "missing.csv")


def test_profile_options():
    spec = load_mems("STIM210")
    assert profile_for("warmup", spec, 60).name == "warmup"
    assert profile_for("constant", spec, 60).temp_degC[0] == spec.temperature.constant_degC
    with pytest.raises(UserError, match="expected warmup, ramp, constant or a .csv"):
        profile_for("sauna", spec, 60)
