"""Scenario values that must be refused (issue 11): booleans as numbers, infinities and NaN,
inconsistent rates, unknown keys of any navigation source, non-UTF-8 files, non-regular files.
Each gives one ConfigError naming the file and the field."""

from __future__ import annotations

import os

import pytest

from fms_testbed.config.scenario import load_scenario
from fms_testbed.core.errors import ConfigError

BASE = """aircraft: "737"
initial: {lat_deg: 47.0, lon_deg: 8.0, alt_m: 3000, tas_kmh: 400, heading_deg: 90}
duration_s: 30
"""


@pytest.mark.parametrize("extra, field", [
    ("", None),
    ("navigation: {source: truth}\n", None),
    ("navigation: {source: sins, imu: STIM300, seed: 4}\n", None),
    ("navigation: {imu: STIM300}\n", "navigation.imu"),            # no source: truth, no imu key
    ("navigation: {source: truth, imu: STIM300}\n", "navigation.imu"),
    ("navigation: {source: sins, imu: STIM300, dt_s: .inf}\n", "navigation.dt_s"),
    ("navigation: {source: sins, imu: STIM300, dt_s: true}\n", "navigation.dt_s"),
    ("navigation: {source: kalman}\n", "navigation"),
    ("log_rate_hz: 50\nouter_rate_hz: 10\n", "<root>"),
    ("events:\n  - {t_s: .inf, bank_deg: 10}\n", "events.0.t_s"),
    ("events:\n  - {when: {alt_m_above: .nan}, bank_deg: 10}\n", "events.0.when.alt_m_above"),
    ("events:\n  - {t_s: true, bank_deg: 10}\n", "events.0.t_s"),
])
def test_strict_values(tmp_path, extra, field):
    p = tmp_path / "s.yaml"
    p.write_text(BASE + extra)
    if field is None:
        load_scenario(p)
        return
    with pytest.raises(ConfigError) as exc:
        load_scenario(p)
    msg = str(exc.value)
    assert str(p) in msg and f"'{field}'" in msg, msg


def test_boolean_altitude_is_not_one_metre(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text(BASE.replace("alt_m: 3000", "alt_m: true"))
    with pytest.raises(ConfigError, match="initial"):
        load_scenario(p)


def test_unquoted_aircraft_number_is_its_name(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text(BASE.replace('aircraft: "737"', "aircraft: 737"))
    assert load_scenario(p).aircraft == "737"


def test_non_utf8_file_is_one_line(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_bytes(BASE.encode() + b"description: caf\xe9\n")
    with pytest.raises(ConfigError, match="not UTF-8"):
        load_scenario(p)


def test_fifo_is_refused_without_blocking(tmp_path):
    p = tmp_path / "fifo.yaml"
    os.mkfifo(p)
    with pytest.raises(ConfigError, match="not a regular file"):
        load_scenario(p)
