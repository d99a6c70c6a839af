"""MEMS gyro presets: the STIM210 file loads, names a source for every value, converts to SI, and
bad files are refused with the file and field named."""

import math
import re

import numpy as np
import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.sensors.mems.preset import gyro_model, list_mems_presets, load_mems, mems_dir


def test_stim210_preset_loads_and_converts_to_si():
    spec = load_mems("stim210")                      # names are case-insensitive
    assert spec.name == "STIM210" and "STIM210" in list_mems_presets()
    m = gyro_model(spec)
    deg = math.pi / 180
    assert m.arw_rps_per_sqrt_hz == pytest.approx(spec.gyro.arw_deg_per_sqrt_h * deg / 60)
    assert m.bias_instability_rps == pytest.approx(spec.gyro.bias_instability_deg_per_h * deg / 3600)
    assert m.poly_rps_per_degC_k.shape == (3, 4)
    assert m.poly_rps_per_degC_k[1, 0] == pytest.approx(spec.gyro.zero_signal_poly_deg_per_s.y[0] * deg)
    np.testing.assert_allclose(m.hysteresis_rps, np.array(spec.gyro.hysteresis_deg_per_s) * deg)


def test_every_value_in_the_stim210_file_names_its_source():
    lines = (mems_dir() / "STIM210.yaml").read_text().splitlines()
    values = [ln for ln in lines if re.match(r"^\s+[a-z_A-Z]+:\s*[-\d\[]", ln)]
    assert len(values) > 30
    missing = [ln for ln in values if "#" not in ln]
    assert not missing, missing
    # the seed's published figures are the reference block, as published
    ref = load_mems("STIM210").reference
    assert (ref.temperature_residual_deg_per_s, ref.run_to_run_error_deg_per_s,
            ref.run_to_run_residual_deg_per_s, ref.angle_uncompensated_deg,
            ref.angle_compensated_deg) == (0.00713, 0.017, 0.00684, 108.0, 1.7)


def test_unknown_preset_lists_the_shipped_ones():
    with pytest.raises(ConfigError, match="unknown MEMS gyro preset 'STIM999'.*STIM210"):
        load_mems("STIM999")


def test_a_bad_value_names_the_file_and_field(tmp_path):
    text = (mems_dir() / "STIM210.yaml").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("cutoff_hz: 0.1 ", "cutoff_hz: 0.5 "))
    with pytest.raises(ConfigError, match=r"bad.yaml: field 'slow_drift.cutoff_hz'"):
        load_mems(bad)
    bad.write_text(text.replace("sample_rate_hz: 100", "sample_rate_hz: 100\nsampel: 1"))
    with pytest.raises(ConfigError, match="field 'sampel': unknown field"):
        load_mems(bad)
    bad.write_text(text.replace("operating_range_degC: [-40.0, 85.0]",
                                "operating_range_degC: [85.0, -40.0]"))
    with pytest.raises(ConfigError, match="operating_range_degC"):
        load_mems(bad)
