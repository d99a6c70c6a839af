"""Scenario validation: unknown fields, wrong types and out-of-range values name file and field;
the CLI turns them into one line on stderr and exit code 2."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from fms_testbed.core.errors import ConfigError
from fms_testbed.data import scenarios_dir
from fms_testbed.config.scenario import load_scenario
from fms_testbed.core.units import KMH_MPS, KT_MPS

GOOD = """\
aircraft: "737"
initial: {lat_deg: 47.0, lon_deg: 8.0, alt_ft: 10000, tas_kmh: 400, heading_deg: 90}
duration_s: 30
wind: {from_deg: 270, speed_kt: 20}
events:
  - {t_s: 5, bank_deg: 20}
  - {when: {alt_m_above: 3100}, cas_kt: 250}
"""


def _file(tmp_path, text):
    p = tmp_path / "s.yaml"
    p.write_text(textwrap.dedent(text))
    return p


def test_good_scenario_converts_units_to_si(tmp_path):
    s = load_scenario(_file(tmp_path, GOOD))
    assert s.initial.altitude_m == pytest.approx(3048.0)
    assert s.initial.speed == ("tas", pytest.approx(400 * KMH_MPS))
    assert s.wind.speed_ms == pytest.approx(20 * KT_MPS, rel=1e-12)
    assert s.events[1].speed == ("cas", pytest.approx(250 * KT_MPS, rel=1e-12))


@pytest.mark.parametrize("text, field, why", [
    (GOOD.replace("duration_s: 30", "duration_s: 30\nturbulance: {severity: light}"),
     "turbulance", "unknown field"),
    (GOOD.replace("duration_s: 30", "duration_s: thirty"), "duration_s", "number"),
    (GOOD.replace("bank_deg: 20", "bank_deg: 95"), "events.0.bank_deg", "less than or equal"),
    (GOOD.replace("lat_deg: 47.0", "lat_deg: 147.0"), "initial.lat_deg", "less than or equal"),
    (GOOD.replace('aircraft: "737"', "aircraft: b52"), "aircraft", "unknown aircraft"),
    (GOOD.replace(", tas_kmh: 400", ""), "initial", "needs a speed"),
    (GOOD.replace("{t_s: 5, bank_deg: 20}", "{t_s: 5}"), "events.0", "at least one target"),
    (GOOD.replace("speed_kt: 20", "speed_kt: 20, speed_mps: 3"), "wind", "exactly one"),
])
def test_bad_scenario_names_file_and_field(tmp_path, text, field, why):
    p = _file(tmp_path, text)
    with pytest.raises(ConfigError) as exc:
        load_scenario(p)
    msg = str(exc.value)
    assert msg.startswith(str(p)), msg
    assert f"'{field}'" in msg and why in msg and "\n" not in msg, msg


def test_yaml_syntax_error_names_line(tmp_path):
    p = _file(tmp_path, "aircraft: 737\ninitial: {lat_deg: 47\n")
    with pytest.raises(ConfigError, match=r"line \d+"):
        load_scenario(p)


def test_cli_reports_one_line_and_exit_2(tmp_path):
    p = _file(tmp_path, GOOD.replace("duration_s: 30", "duration_s: -1"))
    r = subprocess.run([sys.executable, "-m", "fms_testbed.cli", "run", str(p)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "duration_s" in lines[0] and "Traceback" not in r.stderr


def test_cli_missing_file(tmp_path):
    r = subprocess.run([sys.executable, "-m", "fms_testbed.cli", "run", "nope.yaml"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "no such scenario file" in r.stderr


@pytest.mark.parametrize("path", sorted(scenarios_dir().glob("*.yaml")), ids=lambda p: p.name)
def test_shipped_scenarios_validate(path):
    import yaml

    if "procedure" in yaml.safe_load(path.read_text()):
        from fms_testbed.loop.procedure import load_procedure_scenario

        scn, spec, fp, db = load_procedure_scenario(path)
        assert fp.path.segments
    else:
        load_scenario(path)


def test_bad_navigation_block_names_the_scenario_file(tmp_path):
    p = _file(tmp_path, GOOD + "navigation: {source: sins, imu: STIM300, sead: 3}\n")
    r = subprocess.run([sys.executable, "-m", "fms_testbed.cli", "run", str(p)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert str(p) in r.stderr and "navigation.sead" in r.stderr and "Traceback" not in r.stderr
