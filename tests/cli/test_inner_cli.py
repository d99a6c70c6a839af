"""`fms-testbed inner`: a table with units in its column names, one plot per loop and a short
human table instead of JSON lines with radians and `Infinity`; exit 1 when a spec is missed."""

from __future__ import annotations

import math

import pandas as pd
import yaml

from fms_testbed.cli import main
from fms_testbed.cli.inner import step_rows
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.data import aircraft_dir
from fms_testbed.sim.inner_steps import StepResult, check_aircraft, specs_for

COLUMNS = ["alt_m", "tas_mps", "loop", "bank_step_deg", "load_step_g", "settle_s",
           "settle_max_s", "overshoot_pct", "overshoot_max_pct", "ok"]


def test_inner_writes_the_table_the_plots_and_a_human_summary(tmp_path, capsys):
    out = tmp_path / "inner"
    rc = main(["inner", "--aircraft", "737", "--out", str(out)])
    text = capsys.readouterr().out
    cfg = load_aircraft("737")
    ref = check_aircraft(cfg)                               # the same JSBSim steps, again
    assert rc == (0 if all(r.ok for r in ref) else 1)
    df = pd.read_csv(out / "inner_steps.csv")
    assert list(df.columns) == COLUMNS and len(df) == len(ref)
    assert df.loc[df["loop"] == "bank", "bank_step_deg"].iloc[0] == cfg.inner_spec.bank_step_deg
    for (_, row), r in zip(df.iterrows(), ref):
        assert row["loop"] == r.spec.loop and row["settle_s"] == round(r.settle_s, 3)
        assert row["ok"] == r.ok
    assert "| settle_s |" in (out / "inner_steps.md").read_text()
    for loop in ("bank", "ny", "nx"):
        assert (out / f"inner_{loop}.png").stat().st_size > 10_000
    assert "PASS" in text and "settle, s" in text
    assert "Infinity" not in text and "rad" not in text and "{" not in text


def test_a_missed_spec_exits_1_and_says_fail(tmp_path, capsys):
    raw = yaml.safe_load((aircraft_dir() / "737.yaml").read_text())
    raw.setdefault("inner_spec", {})["bank_settle_max_s"] = 0.2     # no airliner banks 25° so
    f = tmp_path / "737-strict.yaml"
    f.write_text(yaml.safe_dump(raw))
    assert main(["inner", "--aircraft", str(f), "--out", str(tmp_path / "o")]) == 1
    text = capsys.readouterr().out
    bank = next(ln for ln in text.splitlines() if " bank " in ln)
    assert bank.rstrip().endswith("FAIL") and "≤ 0.2" in bank
    df = pd.read_csv(tmp_path / "o" / "inner_steps.csv")
    assert not df.loc[df["loop"] == "bank", "ok"].iloc[0]


def test_a_response_that_never_settles_is_an_empty_cell_not_infinity(tmp_path):
    cfg = load_aircraft("737")
    spec = specs_for(cfg)[1]
    r = StepResult(spec, [0.1, 0.2], [1.0, 1.0], 1.0 + spec.amplitude, math.inf, 0.0)
    df = step_rows([(cfg.default_condition, r)])
    assert math.isnan(df["settle_s"].iloc[0]) and not df["ok"].iloc[0]
    df.to_csv(tmp_path / "t.csv", index=False)
    assert "inf" not in (tmp_path / "t.csv").read_text().lower()
