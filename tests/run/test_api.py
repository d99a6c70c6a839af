"""One run path: run_scenario flies a file, a mapping or a Scenario, with or without a
procedure block; stepping a Flight gives the same flight; overrides apply the same way."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

import fms_testbed
from fms_testbed.cli import main
from fms_testbed.loop.flight import Flight
from fms_testbed.run import Results, load, results_of, run_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.fixture(scope="module")
def demo_sid():
    return fms_testbed.run_scenario(str(SCEN / "demo-sid.yaml"), out_dir=None)


def test_procedure_scenario_file_flies_from_the_package_entry_point(demo_sid):
    res = demo_sid
    assert isinstance(res, Results) and res.procedure is not None
    assert res.summary.status == "ok", res.summary.reason
    assert res.summary["procedure"]["procedure"] == "DEEZZ5"
    assert {"fte_m", "tse_m", "nse_m", "xtk_m"} <= set(res.df.columns)
    assert res.summary["outcome"]["failed"] == []


def test_stepping_a_procedure_flight_equals_one_run(demo_sid):
    scn, proc = load(str(SCEN / "demo-sid.yaml"))
    f = Flight(scn, procedure=proc, progress=False)
    assert f.step(400)                                 # 40 s, still flying
    assert f.step(1 << 30) is False
    res = results_of(f)
    pd.testing.assert_frame_equal(res.df, demo_sid.df)
    assert res.summary["errors"] == demo_sid.summary["errors"]


def test_mapping_and_scenario_objects_fly_like_the_file():
    raw = {"name": "m", "aircraft": "737", "duration_s": 5, "hold": True,
           "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400}}
    a = run_scenario(raw, seed=1)
    scn, _ = load(raw)
    b = run_scenario(scn, seed=1)
    pd.testing.assert_frame_equal(a.df, b.df)
    assert a.summary.seed == 1 and a.summary.ok


def test_results_plot_returns_figures_and_save_writes_them(tmp_path, demo_sid):
    figs = demo_sid.plot()
    assert {"ground_track", "time_histories", "procedure_track", "procedure_vertical",
            "procedure_errors"} <= set(figs)
    assert all(isinstance(f, Figure) for f in figs.values())
    out = demo_sid.save(tmp_path / "out")
    names = {p.name for p in out.iterdir()}
    assert {"timeseries.parquet", "summary.json", "run.json", "procedure_track.png"} <= names
    back = pd.read_parquet(out / "timeseries.parquet")
    assert np.allclose(back["alt_m"], demo_sid.df["alt_m"])


def test_cli_overrides_apply_to_scenario_files_in_run_and_fly(tmp_path):
    # --wind on a plain scenario with run, and on a procedure scenario with fly
    assert main(["run", str(SCEN / "demo.yaml"), "--wind", "270/20", "--no-plots",
                 "--out", str(tmp_path / "a")]) in (0, 1)
    import json
    s = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert s["scenario"] == "demo"
    scn, _ = load(str(SCEN / "demo.yaml"), {"wind": {"from_deg": 270, "speed_kt": 20}})
    assert scn.wind.from_deg == 270
    scn, proc = load(str(SCEN / "demo-sid.yaml"), {"procedure": {"rnp_nm": 0.3},
                                                   "aircraft": "global5000"})
    assert scn.aircraft == "global5000" and proc.spec.rnp_nm == 0.3


def test_cli_refuses_contradicting_options(capsys):
    assert main(["fly", "--scenario", str(SCEN / "demo-sid.yaml"), "--airport", "KSEA"]) == 2
    assert "not used with it" in capsys.readouterr().err
    assert main(["run", str(SCEN / "demo.yaml"), "--imu", "STIM300"]) == 2
    assert "--imu is only used with a --nav source other than truth" in capsys.readouterr().err
    assert main(["run", str(SCEN / "demo.yaml"), "--nav", "gps"]) == 2
    err = capsys.readouterr().err
    assert "unknown navigation source" in err and "attitude_reference" in err
    assert main(["run", str(SCEN / "demo.yaml"), "--nav", "attitude_reference"]) == 2
    assert "--nav attitude_reference needs --imu PRESET" in capsys.readouterr().err


def test_relative_paths_in_a_scenario_resolve_against_its_folder(tmp_path, monkeypatch):
    import shutil

    from fms_testbed.data import aircraft_dir
    sub = tmp_path / "cases"
    sub.mkdir()
    shutil.copy(aircraft_dir() / "737.yaml", sub / "my737.yaml")
    (sub / "s.yaml").write_text(
        'aircraft: my737.yaml\nduration_s: 2\n'
        "initial: {lat_deg: 47, lon_deg: 8, alt_m: 3000, tas_kmh: 400}\n")
    monkeypatch.chdir(tmp_path)                      # not the scenario's folder
    scn, _ = load(str(sub / "s.yaml"))
    assert scn.aircraft == str(sub / "my737.yaml")


def test_a_flight_stopped_from_outside_is_a_timeout_with_its_checks():
    """Flight.stop (a wall-time limit): status timeout, the reason says where, the checks of
    what was flown are kept (evaluation.outcome.decide is the one place of the status)."""
    from fms_testbed.evaluation.outcome import EXIT_CODES
    from fms_testbed.loop.procedure import prepare_procedure
    from fms_testbed.run import results_of

    scn, proc = prepare_procedure({"aircraft": "737", "procedure": {
        "airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L", "transition": "CANDR"}})
    f = Flight(scn, procedure=proc, progress=False)
    f.step(300)
    f.stop("--case-timeout 5 s reached")
    assert not f.step(1)
    s = results_of(f).summary
    assert s.status == "timeout" and EXIT_CODES["timeout"] == 1
    assert s.reason.startswith("--case-timeout 5 s reached after 30 s simulated, on leg ")
    assert s.outcome.checks.envelope.ok and s.sequencing.legs_entered >= 1
