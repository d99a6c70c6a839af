"""`fms-testbed tune --envelope` and `analyse --plant jsbsim`: outputs, goals, user errors."""

from __future__ import annotations

import pandas as pd
import pytest
import yaml

from fms_testbed.cli import main
from fms_testbed.config.aircraft import load_aircraft_file
from fms_testbed.control import procedure_law
from fms_testbed.evaluation.envelope_tuning import POINT_COLUMNS


def _three_point_grid(folder):
    grid = folder / "grid.yaml"
    grid.write_text(yaml.safe_dump({"points": [
        {"alt_m": 1000.0, "tas_mps": 105.0}, {"alt_m": 3000.0, "tas_mps": 111.1},
        {"alt_m": 6000.0, "tas_mps": 150.0}]}))
    return grid


def test_bad_grid_file_is_one_line_naming_the_field(tmp_path, capsys):
    grid = tmp_path / "grid.yaml"
    grid.write_text("points:\n  - {alt_m: 3000, tas_mps: 111, config: landing}\n")
    assert main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid),
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "grid.yaml" in err and "config" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("extra, words", [
    (["--campaign-wind", "west/30"], ("--wind", "west/30")),
    (["--campaign-types", "SID,HOLD"], ("HOLD",)),
])
def test_bad_campaign_option_fails_before_any_tuning(tmp_path, capsys, extra, words):
    assert main(["tune", "--aircraft", "737", "--envelope", "--verify-campaign", *extra,
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert all(w in err for w in words) and "Traceback" not in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_envelope_options_without_envelope_are_a_user_error(tmp_path, capsys):
    assert main(["tune", "--aircraft", "737", "--verify-campaign", "--out",
                 str(tmp_path / "out")]) == 2
    assert "--verify-campaign need --envelope" in capsys.readouterr().err


def test_too_few_trimmed_points_is_a_user_error(tmp_path, capsys):
    grid = tmp_path / "grid.yaml"
    grid.write_text("points:\n  - {alt_m: 3000, tas_mps: 111}\n  - {alt_m: 1000, tas_mps: 105}\n")
    assert main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid), "--workers", "1",
                 "--no-robust", "--out", str(tmp_path / "out")]) == 2
    assert "at least 3" in capsys.readouterr().err


def test_envelope_tuning_writes_points_schedule_and_a_flyable_aircraft(tmp_path, capsys):
    grid = _three_point_grid(tmp_path)
    out = tmp_path / "env"
    rc = main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid), "--workers", "1",
               "--no-robust", "--out", str(out)])
    text = capsys.readouterr().out
    df = pd.read_csv(out / "points.csv")
    assert list(df.columns[:len(POINT_COLUMNS)]) == list(POINT_COLUMNS)
    assert len(df) == 3 and (df.status == "ok").all()
    for b in ("throttle", "elevator", "nx_cmd", "dny_cmd", "aileron", "bank_cmd"):
        assert df[f"pm_{b}_deg"].notna().all()
    assert (df.gm_min_db <= df[[c for c in df if c.startswith("gm_") and c.endswith("_db")
                                and c != "gm_min_db"]].min(axis=1) + 1e-9).all()
    met = (df.gm_min_db >= 6).all() and (df.pm_min_deg >= 45).all() and \
        (df.max_dv_kmh <= 1).all() and (df.max_dh_m <= 1.5).all()
    assert rc == (0 if met else 1), text
    cfg = load_aircraft_file(out / "aircraft.yaml")
    assert cfg.coupled_law_schedule is not None and len(cfg.coupled_law_schedule.points) == 3
    law = procedure_law(cfg)
    for _, r in df.iterrows():
        got = law.schedule.values(r.qbar_pa, r.mass_kg)
        assert got["T_V_s"] == pytest.approx(r.tuned_T_V_s, rel=1e-3)
    sched = yaml.safe_load((out / "schedule.yaml").read_text())["coupled_law_schedule"]
    assert len(sched["points"]) == 3
    assert "PASS" in (out / "report.md").read_text() or "FAIL" in (out / "report.md").read_text()
    for f in ("nichols.png", "bode-worst.png", "steps.png", "schedule.png"):
        assert (out / f).stat().st_size > 10_000, f
    bode = sorted((out / "bode").glob("*.png"))
    assert len(bode) == 3 and all(b.stat().st_size > 10_000 for b in bode)
    assert all(f"bode/{b.name}" in (out / "report.md").read_text() for b in bode)


@pytest.mark.slow
def test_verify_campaign_flies_both_files_and_reports_the_shift(tmp_path, capsys):
    grid = _three_point_grid(tmp_path)
    out = tmp_path / "env"
    rc = main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid), "--workers", "1",
               "--no-robust", "--verify-campaign", "--airports", "KBFI", "--campaign-limit", "2",
               "--out", str(out)])
    assert rc in (0, 1)
    old = pd.read_parquet(out / "campaign" / "old" / "flights")
    new = pd.read_parquet(out / "campaign" / "new" / "flights")
    assert len(old) == len(new) == 2
    assert (new.aircraft.astype(str).str.endswith("aircraft.yaml")).all(), new.aircraft
    rep = (out / "report.md").read_text()
    assert "## Campaign check" in rep and "2 paired flights" in rep
    assert "campaign median FTE95 no worse" in rep
    assert (out / "campaign" / "campaign-shift.png").stat().st_size > 10_000


def test_analyse_jsbsim_prints_modes_checked_against_the_nonlinear_model(tmp_path, capsys):
    out = tmp_path / "an"
    assert main(["analyse", "--aircraft", "737", "--plant", "jsbsim", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "short period" in text and "JSBSim linearisation + inner loops" in text
    assert (out / "linear-vs-jsbsim.png").stat().st_size > 10_000
