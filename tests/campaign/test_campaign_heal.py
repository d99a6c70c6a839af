"""Datasets that heal: a truncated, duplicated or foreign part file is found by what it holds
(not by run.json), named with its cases by report and diff, moved into DIR/quarantine/ on resume
and its cases flown again, so the resumed run equals the undamaged one row by row."""

from __future__ import annotations

import json
import shutil

import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from fms_testbed.campaign.audit import QUARANTINE, audit
from fms_testbed.campaign.store import part_files, read_flights

from campaign_helpers import SMALL, regress
from test_campaign_run import comparable


def _split_parts(out, n):
    """Rewrite the run's rows as ``n`` part files (how many parts a run writes depends on its
    timing: rows wait in memory up to a time limit)."""
    t = pa.concat_tables([pq.read_table(p) for p in part_files(out)])
    for p in part_files(out):
        p.unlink()
    k = -(-t.num_rows // n)
    for i in range(n):
        pq.write_table(t.slice(i * k, k), out / "flights" / f"part-{i:020d}-0-split.parquet")


def _damage(src, out):
    """A copy of ``src`` with its first part truncated to 100 bytes, its second duplicated
    under another name and a part of rows of another run (foreign case ids) added."""
    shutil.copytree(src, out)
    _split_parts(out, 4)
    parts = part_files(out)
    lost = set(pq.read_table(parts[0]).column("case_id").to_pylist())
    with open(parts[0], "r+b") as fh:
        fh.truncate(100)
    shutil.copy(parts[1], parts[1].with_name("part-99999999999999999998-copy.parquet"))
    t = pq.read_table(parts[2])
    ids = pc.binary_join_element_wise(pa.scalar("f0"), pc.utf8_slice_codeunits(
        t.column("case_id"), 2), "")
    pq.write_table(t.set_column(0, "case_id", ids),
                   out / "flights" / "part-99999999999999999999-foreign.parquet")
    return lost


def test_report_and_diff_name_the_damage(small_run, tmp_path, capsys):
    out = tmp_path / "damaged"
    lost = _damage(small_run, out)
    found = audit(out)
    assert len(found.damaged) == 3 and set(found.missing) == lost
    assert found.duplicate_rows > 0 and found.foreign_rows > 0
    assert regress("report", str(out), "--no-refly") == 0
    said = capsys.readouterr().out
    assert f"incomplete: {20 - len(lost)} of 20 planned cases written" in said
    assert "3 damaged part file(s)" in said and "unreadable" in said
    assert regress("diff", str(small_run), str(out)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "damaged part file(s)" in err
    assert any(i in err for i in lost) and "part-" in err


def test_resume_quarantines_and_equals_the_undamaged_run(small_run, tmp_path, capsys):
    out = tmp_path / "damaged"
    _damage(small_run, out)
    assert regress("run", *SMALL, "--workers", "2", "--no-progress", "--out", str(out)) == 0
    err = capsys.readouterr().err
    assert err.count("moved to quarantine/") == 3
    assert len(list((out / QUARANTINE).iterdir())) == 3
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "complete" and sum(info["counts"].values()) == 20
    pd.testing.assert_frame_equal(comparable(read_flights(out)),
                                  comparable(read_flights(small_run)))
    assert regress("diff", str(small_run), str(out)) == 0


def test_run_json_that_is_not_json_is_named(small_run, tmp_path, capsys):
    out = tmp_path / "bad"
    shutil.copytree(small_run, out)
    (out / "run.json").write_text("{not json")
    assert regress("report", str(out)) == 2
    err = capsys.readouterr().err.strip()
    assert "run.json is not valid JSON: line 1 col 2" in err and len(err.splitlines()) == 1


def test_a_folder_of_another_kind_is_not_reported(tmp_path, capsys):
    out = tmp_path / "mc"
    out.mkdir()
    (out / "run.json").write_text(json.dumps({"tool": "fms-testbed", "kind": "montecarlo"}))
    assert regress("report", str(out)) == 2
    err = capsys.readouterr().err.strip()
    assert "holds a montecarlo run, not a regress run folder" in err
    assert not (out / "report.html").exists()


def test_regress_run_replaces_another_kind_only_with_overwrite(tmp_path, capsys):
    from fms_testbed.run.outputs import OutputFolder

    out = tmp_path / "was-a-flight"
    with OutputFolder(out, kind="fly") as tmp:
        (tmp / "timeseries.parquet").write_text("x")
    argv = ["run", *SMALL, "--limit", "1", "--workers", "1", "--no-progress", "--out", str(out)]
    assert regress(*argv) == 2
    err = capsys.readouterr().err.strip()
    assert "holds a fly run, not a regress-run run" in err and "--overwrite" in err
    assert (out / "timeseries.parquet").exists()
    assert regress(*argv, "--overwrite") == 0
    assert not (out / "timeseries.parquet").exists()
    info = json.loads((out / "run.json").read_text())
    assert info["kind"] == "regress-run" and info["status"] == "complete"
    assert len(read_flights(out)) == 1
