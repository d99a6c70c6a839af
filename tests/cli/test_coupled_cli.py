"""`fms-testbed compare / analyse / tune`: outputs, goal checks, gains writing, user errors."""

from __future__ import annotations

import json
import shutil

import pandas as pd
import pytest
import yaml

from fms_testbed.config.aircraft import AircraftConfig, CoupledLawGains, load_aircraft_file
from fms_testbed.cli import main
from fms_testbed.control.coupled_law import CoupledLawParams
from fms_testbed.evaluation.law_tuning import gains_yaml, write_gains_to_config
from fms_testbed.data import aircraft_dir, scenarios_dir


def test_compare_prints_the_table_checks_goals_and_writes_plots(tmp_path, capsys):
    out = tmp_path / "cmp"
    rc = main(["compare", "coupled-altitude-step", "--laws", "coupled,pi", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    table = pd.read_csv(out / "comparison.csv")
    assert set(table["law"]) == {"coupled", "pi"}
    c = table[table["law"] == "coupled"].iloc[0]
    b = table[table["law"] == "pi"].iloc[0]
    assert c["max_dV_kmh"] <= 1.0
    assert b["max_dV_kmh"] >= 5 * c["max_dV_kmh"]
    assert abs(c["settle_vs_ideal_pct"]) <= 10.0
    goals = json.loads((out / "goals.json").read_text())
    assert goals and all(g["ok"] for g in goals)
    assert (out / "coupled-altitude-step-comparison.png").stat().st_size > 10_000
    assert "PASS" in text and "| coupled |" in text


def test_paper_fig2_scenario_gives_the_paper_plot(tmp_path):
    out = tmp_path / "fig2"
    assert main(["compare", str(scenarios_dir() / "paper-fig2.yaml"), "--laws", "coupled",
                 "--out", str(out)]) == 0
    assert (out / "paper-fig2-paper-fig2.png").exists()
    table = pd.read_csv(out / "comparison.csv")
    speed = table[table["step"].str.startswith("speed")].iloc[0]
    assert speed["cross_ref"] == "ideal" and speed["max_dH_m"] <= 1.5


def test_compare_rejects_an_unknown_law_in_one_line(capsys):
    assert main(["compare", "--laws", "coupled,lqr"]) == 2
    err = capsys.readouterr().err
    assert "lqr" in err and err.count("\n") == 1


def test_compare_rejects_a_missing_scenario(capsys):
    assert main(["compare", "no-such-scenario"]) == 2
    assert "no-such-scenario" in capsys.readouterr().err


def test_analyse_reports_zero_cross_terms_without_lags(tmp_path, capsys):
    out = tmp_path / "an"
    assert main(["analyse", "--aircraft", "737", "--out", str(out)]) == 0
    rep = json.loads((out / "analysis.json").read_text())
    ideal = rep["no lags (paper)"]
    assert ideal["max|W_V,Hcmd|/max|W_V,Vcmd|"] <= 1e-9
    assert ideal["pole_error_rps"] <= 1e-6
    lagged = [v for k, v in rep.items() if k != "no lags (paper)"]
    assert all(v["max|W_V,Hcmd|/max|W_V,Vcmd|"] > 1e-5 for v in lagged)
    assert (out / "bode.png").exists() and (out / "steps.png").exists()


def test_tune_quick_writes_gains_in_the_aircraft_config_format(tmp_path, capsys):
    out = tmp_path / "tune"
    assert main(["tune", "--aircraft", "737", "--quick", "--plant", "pointmass",
                 "--out", str(out)]) == 0
    block = yaml.safe_load((out / "gains.yaml").read_text())["coupled_law"]
    g = CoupledLawGains.model_validate(block)
    assert g.T_V_s >= 5.0 and g.T_H_s >= 6.0
    hist = pd.read_csv(out / "history.csv")
    assert 1 <= len(hist) <= 8
    assert "tuned" in (out / "report.md").read_text()
    assert (out / "tuned-vs-linear.png").exists()


def test_tune_caps_the_budget(capsys):
    assert main(["tune", "--aircraft", "737", "--max-evals", "500"]) == 2
    assert "60" in capsys.readouterr().err


def test_writing_gains_changes_only_the_coupled_law_block(tmp_path):
    src = aircraft_dir() / "737.yaml"
    dst = tmp_path / "737.yaml"
    shutil.copy(src, dst)
    before = dst.read_text().splitlines()
    p = CoupledLawParams(T_V_s=7.25, xi_V=0.9, T_H_s=9.5, xi_H=0.85)
    write_gains_to_config(dst, p)
    after = dst.read_text().splitlines()
    changed = [(a, b) for a, b in zip(before, after) if a != b]
    assert len(before) == len(after) and len(changed) == 1
    assert changed[0][1] == gains_yaml(p)
    cfg = load_aircraft_file(dst)
    assert isinstance(cfg, AircraftConfig)
    assert (cfg.coupled_law.T_V_s, cfg.coupled_law.xi_H) == (7.25, 0.85)


def test_writing_gains_replaces_a_block_style_section(tmp_path):
    f = tmp_path / "x.yaml"
    f.write_text("name: x\ncoupled_law:\n  T_V_s: 6\n  xi_V: 1\n\nother: 1\n")
    write_gains_to_config(f, CoupledLawParams(T_V_s=8.0, xi_V=1.0, T_H_s=9.0, xi_H=1.0))
    d = yaml.safe_load(f.read_text())
    assert d["coupled_law"]["T_V_s"] == 8.0 and d["other"] == 1 and d["name"] == "x"


def test_compare_envelope_covers_every_envelope_point(tmp_path):
    out = tmp_path / "env"
    assert main(["compare", "--envelope", "--aircraft", "c172p", "--laws", "coupled",
                 "--out", str(out)]) == 0
    table = pd.read_csv(out / "envelope.csv")
    assert len(table) == len(load_aircraft_file(aircraft_dir() / "c172p.yaml").envelope)
    assert (table["speed_step_max_dH_m"] <= 1.5).all()


def test_tune_quick_on_jsbsim_does_not_worsen_the_cost_and_writes_the_file(tmp_path):
    cfg_file = tmp_path / "737.yaml"
    shutil.copy(aircraft_dir() / "737.yaml", cfg_file)
    out = tmp_path / "tune"
    assert main(["tune", "--aircraft", str(cfg_file), "--quick", "--write", "--out", str(out)]) == 0
    hist = pd.read_csv(out / "history.csv")
    assert len(hist) <= 8
    assert hist["cost"].min() <= hist["cost"].iloc[0]
    best = hist.loc[hist["cost"].idxmin()]
    written = load_aircraft_file(cfg_file).coupled_law
    assert written.T_V_s == pytest.approx(best["T_V_s"], abs=0.006)
    assert written.xi_H == pytest.approx(best["xi_H"], abs=0.006)
    assert "identified inner-loop lags" in (out / "report.md").read_text().lower()


def test_compare_rejects_a_malformed_wind(capsys):
    assert main(["compare", "--wind", "270"]) == 2
    assert "FROM_DEG/SPEED_KT" in capsys.readouterr().err


def test_compare_set_overrides_a_law_parameter_and_rejects_unknown_keys(tmp_path, capsys):
    out = tmp_path / "abl"
    assert main(["compare", "coupled-speed-step", "--laws", "coupled", "--set", "ny_trim_tau_s=0",
                 "--out", str(out)]) == 1                  # without the integrator ΔH > 1.5 m
    row = pd.read_csv(out / "comparison.csv").iloc[0]
    assert row["max_dH_m"] > 1.5
    capsys.readouterr()
    assert main(["compare", "--set", "T_V=6"]) == 2
    assert "T_V_s" in capsys.readouterr().err


def test_compare_refuses_a_scenario_without_an_altitude_or_speed_step(tmp_path, capsys):
    scn = tmp_path / "turn.yaml"
    scn.write_text('name: turn\naircraft: "737"\n'
                   'initial: {lat_deg: 47.45, lon_deg: 8.55, alt_m: 3000, tas_kmh: 400, '
                   'heading_deg: 90}\nduration_s: 20\nhold: true\n'
                   'events:\n  - {t_s: 5, heading_deg: 120}\n')
    from fms_testbed.cli import main
    assert main(["compare", str(scn), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "turn.yaml" in err and "no event steps the altitude or the speed" in err
    assert not (tmp_path / "out").exists()


def test_check_goals_on_a_table_without_any_step_row_checks_nothing():
    import pandas as pd
    from fms_testbed.evaluation.law_comparison import check_goals
    table = pd.DataFrame([{"scenario": "s", "law": "coupled", "status": "diverged"}])
    assert check_goals(table) == []
