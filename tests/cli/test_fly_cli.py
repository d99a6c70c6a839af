"""`fms-testbed fly`: arguments, scenario files, clear errors, outputs; SINS errors reach TSE."""

from __future__ import annotations

import json

import pytest

from fms_testbed.cli import main
from fms_testbed.cli.common import parse_wind
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.loop.procedure import prepare
from fms_testbed.path.plan import parse_procedure


def test_fly_command_writes_summary_timeseries_and_plots(tmp_path, capsys):
    out = tmp_path / "run"
    rc = main(["fly", "--airport", "KJFK", "--procedure", "R04RY", "--aircraft", "737",
               "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "FTE95" in text and "RNP" in text and "sequencing: 3/3" in text
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "ok" and s["procedure"]["type"] == "APPROACH"
    for name in ("procedure_track.png", "procedure_vertical.png", "procedure_errors.png"):
        assert (out / name).stat().st_size > 10_000
    assert s["tracks"] == ["track.geojson", "track.kml"]              # for Google Earth / QGIS
    assert "track.kml" in text
    import pandas as pd
    df = pd.read_parquet(out / "timeseries.parquet")
    assert {"xtk_m", "nav_xtk_m", "leg_index", "leg_code"} <= set(df.columns)


def test_unknown_procedure_is_one_clear_line_and_exit_2(capsys):
    rc = main(["fly", "--airport", "KJFK", "--procedure", "NOPE1", "--no-plots"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "NOPE1" in err and "procedures:" in err and err.count("\n") == 1


def test_missing_runway_and_transition_for_a_sid_names_the_choices(capsys):
    rc = main(["fly", "--airport", "KJFK", "--procedure", "DEEZZ5", "--runway", "99X"])
    err = capsys.readouterr().err
    assert rc == 2 and "RW31L" in err


@pytest.mark.parametrize("text", ["270", "270/", "abc/20", "400/20", "270/300"])
def test_bad_wind_is_rejected(text):
    with pytest.raises(UserError, match="--wind"):
        parse_wind(text)


def test_wind_parses_direction_and_knots():
    assert parse_wind("270/20") == {"from_deg": 270.0, "speed_kt": 20.0}


def test_procedure_block_errors_name_the_file_and_field():
    with pytest.raises(ConfigError, match=r"s\.yaml: field 'procedure\.airprot': unknown field"):
        parse_procedure({"airport": "KJFK", "procedure": "R04RY", "airprot": "x"}, "s.yaml")
    with pytest.raises(ConfigError, match=r"procedure\.manual_leg_nm"):
        parse_procedure({"airport": "KJFK", "procedure": "R04RY", "manual_leg_nm": -1}, "s.yaml")


def test_scenario_file_with_wind_flies_the_ground_track(tmp_path):
    """A crosswind scenario file: the aircraft crabs, the ground track stays on the path."""
    scn_file = tmp_path / "xwind.yaml"
    scn_file.write_text("aircraft: '737'\nwind: {from_deg: 130, speed_kt: 30}\n"
                        "procedure: {airport: KJFK, procedure: R04RY}\n")
    out = tmp_path / "o"
    assert main(["fly", "--scenario", str(scn_file), "--out", str(out), "--no-plots"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["errors"]["fte"]["straight"]["p95_m"] <= 30.0
    import pandas as pd
    df = pd.read_parquet(out / "timeseries.parquet")
    crab = ((df["heading_deg"] - df["track_deg"] + 180) % 360 - 180).abs()
    assert crab.median() > 3.0  # 30 kt at ~90° to a 118 m/s aircraft: ~7° of crab


def test_sins_navigation_errors_show_in_tse_and_break_rnp_containment(tmp_path):
    """Guidance flies the navigation solution: FTE stays small while TSE follows NSE, and a
    consumer-grade IMU breaks RNP 0.3 containment on this 7-minute approach."""
    from fms_testbed.run import fly_procedure

    raw = {"aircraft": "737", "procedure": {"airport": "KBFI", "procedure": "H14RZ",
                                            "transition": "ZUVEN"},
           "navigation": {"source": "sins", "imu": "consumer_MEMS"}}
    scn, spec, fp, db = prepare(raw)
    res = fly_procedure(scn, spec, fp, db, seed=0, progress=False)
    e = res.summary["errors"]
    assert e["fte"]["all"]["p95_m"] < 150.0
    assert e["tse"]["all"]["p95_m"] > 10 * e["fte"]["all"]["p95_m"]
    assert e["nse"]["all"]["p95_m"] >= e["tse"]["all"]["p95_m"] * 0.5
    assert not res.summary["rnp"]["contained"]
    df = res.df
    # TSE = FTE minus the navigation error's cross-track component (same piece, same time)
    assert (df["xtk_m"] - df["nav_xtk_m"]).abs().max() <= df["nse_m"].max() + 1.0 \
        if "nse_m" in df else True


def test_every_shipped_procedure_scenario_validates_and_builds():
    import yaml

    from fms_testbed.loop.procedure import load_procedure_scenario
    from fms_testbed.data import scenarios_dir

    files = [p for p in sorted(scenarios_dir().glob("*.yaml"))
             if "procedure" in (yaml.safe_load(p.read_text()) or {})]
    assert any(p.name == "demo-sid.yaml" for p in files)
    for p in files:
        scn, spec, fp, db = load_procedure_scenario(p)
        assert fp.path.segments and scn.initial.tas_mps > 0, p


@pytest.mark.parametrize("text, want", [
    ("270/20", {"from_deg": 270.0, "speed_kt": 20.0}),
    ("270/20kt", {"from_deg": 270.0, "speed_kt": 20.0}),
    ("90/10mps", {"from_deg": 90.0, "speed_mps": 10.0}),
    ("90/36kmh", {"from_deg": 90.0, "speed_mps": 10.0}),
])
def test_wind_unit_suffixes(text, want):
    got = parse_wind(text)
    assert got.keys() == want.keys()
    assert all(got[k] == pytest.approx(v) for k, v in want.items())


def test_every_command_taking_a_wind_parses_it_the_same_way():
    """compare, run and fly: the same --wind help (FROM_DEG/SPEED_KT) and the same parser."""
    import argparse

    from fms_testbed.cli import build_parser
    from fms_testbed.cli.common import WIND_HELP

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    with_wind = {name: p for name, p in sub.choices.items()
                 if any("--wind" in a.option_strings for a in p._actions)}
    assert {"run", "fly", "compare"} <= set(with_wind)
    for name, p in with_wind.items():
        act = next(a for a in p._actions if "--wind" in a.option_strings)
        assert act.help == WIND_HELP, name
