"""Regression runs on the local pool: one row per case with the schema's columns, identical
results for one and two workers, resume without flying again, a refused resume of other cases,
and every failure a row — a timeout, an exception, a worker process that dies."""

from __future__ import annotations

import json
import os
import shutil

import pandas as pd
import pytest

from fms_testbed.campaign.cases import aircraft_files, enumerate_cases
from fms_testbed.campaign.conditions import command_line_sets
from fms_testbed.campaign.executors import run_local
from fms_testbed.campaign.rows import COLUMNS, WALL_COLUMNS, failed_row
from fms_testbed.campaign.store import finished_ids, part_files, read_flights
from fms_testbed.campaign.worker import FlyOptions
from fms_testbed.procedures.index import load_index

from campaign_helpers import SMALL, regress


def comparable(df: pd.DataFrame) -> pd.DataFrame:
    """A flights table without the wall times, in case-id order."""
    return df.drop(columns=list(WALL_COLUMNS)).sort_values("case_id").reset_index(drop=True)


def test_small_run_has_one_row_per_case(small_run):
    df = read_flights(small_run)
    info = json.loads((small_run / "run.json").read_text())
    assert list(df.columns) == list(COLUMNS)
    assert len(df) == info["cases"]["count"] == 20 and df["case_id"].is_unique
    assert info["status"] == "complete" and info["counts"] == df["status"].value_counts().to_dict()
    assert info["database"]["sha256"] == load_index(None).sha256
    flown = df[df["status"] != "impossible"]
    assert (flown["loop_wall_s"] > 0).all() and (flown["wall_s"] >= flown["loop_wall_s"]).all()
    assert (flown["sim_time_s"] > 0).all()
    # the approach misses a constraint in calm air (class 2) and in wind (class 1)
    miss = df[df["status"] == "constraints_missed"]
    assert set(miss["error_class"]) <= {1, 2} and len(miss)
    assert (miss.loc[miss["conditions"] == "calm", "error_class"] == 2).all()
    assert df.loc[df["status"] == "ok", "error_class"].isna().all()


def test_one_and_two_workers_give_identical_rows(small_run, tmp_path):
    out = tmp_path / "one"
    assert regress("run", *SMALL, "--workers", "1", "--no-progress", "--out", str(out)) == 0
    pd.testing.assert_frame_equal(comparable(read_flights(out)),
                                  comparable(read_flights(small_run)))


def test_same_command_resumes_without_flying(small_run, tmp_path, capsys):
    out = tmp_path / "again"
    shutil.copytree(small_run, out)
    parts = part_files(out)
    assert regress("run", *SMALL, "--workers", "2", "--no-progress", "--out", str(out)) == 0
    assert "0 flown now, 20 already done" in capsys.readouterr().out
    assert part_files(out) == parts
    info = json.loads((out / "run.json").read_text())
    assert len(info["sessions"]) == 2 and info["status"] == "complete"


def test_resume_of_other_cases_is_refused(small_run, tmp_path, capsys):
    out = tmp_path / "other"
    shutil.copytree(small_run, out)
    assert regress("run", *SMALL, "--limit", "3", "--no-progress", "--out", str(out)) == 2
    assert "holds a run of other cases" in capsys.readouterr().err


def test_a_folder_with_other_files_is_refused(tmp_path, capsys):
    out = tmp_path / "busy"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert regress("run", *SMALL, "--no-progress", "--out", str(out)) == 2
    assert "holds other files" in capsys.readouterr().err


def test_timeout_is_a_row_with_what_was_flown(tmp_path):
    out = tmp_path / "slow"
    assert regress("run", "--airports", "KDLS", "--types", "SID", "--case-timeout", "0.02",
                   "--workers", "2", "--no-progress", "--out", str(out)) == 0
    df = read_flights(out)
    assert len(df) == 3 and (df["status"] == "timeout").all()
    assert df["reason"].str.contains("--case-timeout 0.02 s reached").all()
    assert df["error_class"].isna().all()


def _cases(n: int):
    ix = load_index(None)
    cases = enumerate_cases(ix, ["KBFI"], ["D"], aircraft_files(["737"]),
                            command_line_sets([None], [{"source": "truth"}]))
    return ix, cases[:n]


def die_on(case, opts):
    """A worker function that kills its process on the case named by ``opts.db_sha256``."""
    if case.case_id == opts.db_sha256:
        os._exit(3)
    return failed_row(case, "ok", f"fine in {os.getpid()}")


def test_a_dying_worker_costs_only_its_case():
    _, cases = _cases(5)
    victim = cases[1].case_id
    rows = []
    run_local(cases, FlyOptions("", victim), 2, rows.append, fly=die_on)
    by_id = {r["case_id"]: r for r in rows}
    assert sorted(by_id) == sorted(c.case_id for c in cases) and len(rows) == len(cases)
    assert by_id[victim]["status"] == "error" and by_id[victim]["error_type"] == "WorkerDied"
    assert "worker process died" in by_id[victim]["reason"]
    assert all(r["status"] == "ok" for k, r in by_id.items() if k != victim)


def test_an_exception_is_an_error_row():
    ix, cases = _cases(2)
    rows = []
    run_local(cases, FlyOptions(str(ix.path), "0" * 64), 1, rows.append)
    assert [r["status"] for r in rows] == ["error", "error"]
    assert all("changed since the campaign started" in r["reason"] for r in rows)


@pytest.mark.slow
def test_every_case_of_the_excerpt_flies_to_a_row(tmp_path):
    out = tmp_path / "all"
    assert regress("run", "--workers", "2", "--no-progress", "--out", str(out)) == 0
    df = read_flights(out)
    assert df["case_id"].is_unique and set(df["case_id"]) == finished_ids(out)
    assert not (df["status"] == "error").any(), df.loc[df["status"] == "error", "reason"]


def test_a_degraded_procedure_is_a_class_3_row_not_a_flight(tmp_path):
    src = load_index(None).path
    lines = src.read_text(encoding="latin-1").split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.startswith("SUSAP KBFIK1DCBAIN1"))
    lines.insert(k + 1, lines[k])           # a record coded twice: the transition is degraded
    db = tmp_path / "dup.dat"
    db.write_text("\n".join(lines), encoding="latin-1")
    out = tmp_path / "deg"
    assert regress("run", "--db", str(db), "--airports", "KBFI", "--types", "SID",
                   "--workers", "1", "--no-progress", "--out", str(out)) == 0
    df = read_flights(out).set_index("procedure")
    bad = df.loc["CBAIN1"]
    assert bad["status"] == "degraded" and bad["error_class"] == 3
    assert "is degraded, not built" in bad["reason"] and "duplicate" in bad["defects"]
    assert pd.isna(bad["loop_wall_s"])
    assert (df.drop(index="CBAIN1")["status"] == "ok").all()


def test_keep_writes_each_cases_outputs(tmp_path):
    out = tmp_path / "keep"
    assert regress("run", "--airports", "KDLS", "--types", "SID", "--limit", "2", "--keep",
                   "timeseries,plots", "--workers", "2", "--no-progress", "--out", str(out)) == 0
    ids = sorted(read_flights(out)["case_id"])
    assert sorted(p.name for p in (out / "cases").iterdir()) == ids
    for cid in ids:
        case_dir = out / "cases" / cid
        ts = pd.read_parquet(case_dir / "timeseries.parquet")
        assert len(ts) > 100 and (case_dir / "summary.json").exists()
        assert list(case_dir.glob("*.png"))
