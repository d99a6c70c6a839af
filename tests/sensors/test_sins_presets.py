"""IMU presets: shipped files load, units convert, bad files are named with field and reason."""

import math

import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import G0_MPS2
from fms_testbed.sensors.sins.presets import list_presets, load_imu, load_imu_spec

DEG_H = math.pi / 180 / 3600


def test_every_shipped_preset_loads_and_cites_a_source():
    names = list_presets()
    assert {"STIM300", "ADIS16488", "HG1700", "HG9900", "consumer_MEMS"} <= set(names)
    for n in names:
        spec = load_imu_spec(n)
        assert len(spec.source) > 40, n
        imu = load_imu(n)
        assert imu.q_psd.shape == (33,) and imu.p0_var.shape == (33,) and imu.decay_rps.shape == (24,)
        assert (imu.q_psd >= 0).all() and (imu.p0_var >= 0).all()


def test_stim300_units_convert_to_si():
    imu = load_imu("stim300")                                 # case-insensitive
    assert math.sqrt(imu.q_psd[6]) == pytest.approx(0.15 * math.pi / 180 / 60)   # rad/√s
    assert math.sqrt(imu.q_psd[3]) == pytest.approx(0.06 / 60)                   # m/s/√s
    # gyro bias (no turn-on): stationary Gauss-Markov, variance σ², q = 2σ²/τ, decay 1/τ
    assert imu.decay_rps[3] == pytest.approx(1 / 3600)
    assert imu.p0_var[12] == pytest.approx((0.5 * DEG_H) ** 2)
    assert imu.q_psd[12] == pytest.approx(2 * (0.5 * DEG_H) ** 2 / 3600)
    # accel bias: turn-on 750 µg kept constant (no decay) + in-run 50 µg as a random walk
    assert imu.decay_rps[0] == 0.0
    assert imu.p0_var[9] == pytest.approx((750e-6 * G0_MPS2) ** 2)
    assert imu.q_psd[9] == pytest.approx(2 * (50e-6 * G0_MPS2) ** 2 / 3600)
    assert imu.p0_var[18] == pytest.approx(500e-6 ** 2)                          # gyro SF
    assert imu.p0_var[27] == pytest.approx(1e-3 ** 2) and imu.q_psd[27] == 0     # constant


def test_random_walk_bias_when_no_correlation_time():
    imu = load_imu({"gyro": {"bias_rate_random_walk_deg_per_h_per_sqrt_h": 0.6}})
    assert imu.decay_rps[3] == 0
    assert math.sqrt(imu.q_psd[12]) == pytest.approx(0.6 * DEG_H / 60)


def test_user_yaml_file(tmp_path):
    p = tmp_path / "my_imu.yaml"
    p.write_text("gyro: {arw_deg_per_sqrt_h: 0.1}\naccelerometer: {bias_turn_on_ug: 100}\n")
    imu = load_imu(p)
    assert imu.name == "my_imu" and imu.p0_var[9] == pytest.approx((100e-6 * G0_MPS2) ** 2)


@pytest.mark.parametrize("text, match", [
    ("gyro: {arw_dph: 0.1}\n", "gyro.arw_dph"),
    ("gyro: {arw_deg_per_sqrt_h: -1}\n", "gyro.arw_deg_per_sqrt_h"),
    ("noise_model: discrete\n", "noise_model"),
    ("gyro: [1, 2\n", "not valid YAML"),
    ("- 1\n", "must be a mapping"),
])
def test_bad_files_name_the_file_and_field(tmp_path, text, match):
    p = tmp_path / "bad.yaml"
    p.write_text(text)
    with pytest.raises(ConfigError, match=match) as e:
        load_imu(p)
    assert "bad.yaml" in str(e.value)


def test_unknown_preset_lists_the_known_ones():
    with pytest.raises(ConfigError, match="STIM300"):
        load_imu("LN-200X")
