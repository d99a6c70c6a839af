"""The database check with corrupted records: degraded rows with their lines, rejected records
listed in rejected_records.csv, internal errors counted apart from 'impossible', an honest
'ok or corrected' share, and the real FAA CIFP with a corrupted copy of a slice."""

import json
from pathlib import Path

import pandas as pd
import pytest

from fms_testbed.cli import main
from fms_testbed.data import procedures_dir
from fms_testbed.evaluation import check as checkmod
from fms_testbed.evaluation.check import ROW_COLUMNS, check_airport, perf_for, run_check
from fms_testbed.procedures.database import load_text

CIFP = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "cifp" / "FAACIFP18_230126"
EXCERPT = procedures_dir() / "cifp_excerpt.dat"
LINES = EXCERPT.read_text(encoding="latin-1").split("\n")[:-1]
PERF = perf_for("737")


def put(rec: str, col: int, text: str) -> str:
    """``rec`` with ``text`` written from 1-based column ``col``."""
    return rec[:col - 1] + text + rec[col - 1 + len(text):]


def is_leg(rec: str) -> bool:
    return rec[4:6] in ("P ", "H ") and rec[12:13] in ("D", "E", "F") and rec[38:39] in "01"


def write(tmp_path, lines, name="db.dat") -> Path:
    p = tmp_path / name
    p.write_text("".join(r + "\n" for r in lines), encoding="latin-1")
    return p


def test_a_corrupted_record_makes_its_row_degraded_with_the_line(tmp_path):
    k = next(i for i, r in enumerate(LINES) if is_leg(r) and r[6:10] == "KDLS")
    lines = list(LINES)
    lines[k] = put(lines[k], 100, "000")            # speed limit 0
    res = run_check(str(write(tmp_path, lines)), PERF, ["KDLS"], progress=False)
    rows = {(r["procedure"], r["transition"]): r for r in res.rows}
    key = (LINES[k][13:19].strip(), LINES[k][20:25].strip())
    bad = rows[key]
    assert bad["status"] == "degraded" and bad["defects"] == "rejected"
    assert f"line {k + 1}: speed limit" in bad["findings"]
    assert bad["monitor_status"] in ("ok", "corrected", "impossible")  # what the monitor said
    assert [e.line for e in res.rejected] == [k + 1]
    clean = {(r["procedure"], r["transition"]): r["status"]
             for r in check_airport(load_text("".join(x + "\n" for x in LINES), "c"), "KDLS",
                                    PERF)}
    for kk, r in rows.items():
        if kk != key:
            assert r["status"] == clean[kk]
    n = len(res.rows)
    good = sum(r["status"] in ("ok", "corrected") for r in res.rows)
    assert res.summary["ok_or_corrected_pct"] == pytest.approx(100.0 * good / n)
    assert res.summary["by_status"]["degraded"] == 1
    assert res.summary["degraded_by_defect"] == {"rejected": 1}


def test_an_internal_error_is_degraded_and_counted_apart(monkeypatch):
    def broken(*a, **k):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(checkmod, "build_sequence", broken)
    res = run_check(None, PERF, ["KDLS"], progress=False)
    assert {r["status"] for r in res.rows} == {"degraded"}
    assert {r["monitor_status"] for r in res.rows} == {"internal-error"}
    assert all("internal error: ZeroDivisionError: float division by zero (records at lines "
               in r["findings"] for r in res.rows)
    assert res.summary["internal_errors"] == len(res.rows)
    assert "impossible" not in res.summary["by_status"]
    assert res.summary["ok_or_corrected_pct"] == 0.0


def test_cli_check_lists_rejected_records_and_keeps_all_rejected_transitions(tmp_path, capsys):
    lines = [put(r, 71, "1²34") if is_leg(r) else r for r in LINES]
    db = write(tmp_path, lines)
    out = tmp_path / "out"
    rc = main(["procedures", "check", "--db", str(db), "--no-progress", "--out", str(out)])
    assert rc == 0
    n_legs = sum(map(is_leg, LINES))
    text = capsys.readouterr().out
    assert f"{n_legs} rejected records" in text
    rej = pd.read_csv(out / "rejected_records.csv")
    assert list(rej.columns) == ["file", "line", "columns", "field", "reason", "record"]
    assert len(rej) == n_legs and set(rej.field) == {"course"}
    assert rej.reason.str.contains("U+00B2", regex=False).all()
    assert sorted(rej.line) == [i + 1 for i, r in enumerate(LINES) if is_leg(r)]
    assert (rej.record.str.len() == 132).all()
    df = pd.read_parquet(out / "procedures_check.parquet")
    assert len(df) == 306 and set(df.status) == {"degraded"} and (df.n_legs == 0).all()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ok_or_corrected_pct"] == 0.0 and summary["rejected_records"] == n_legs


def test_cli_check_merges_repeated_airports(tmp_path):
    rc = main(["procedures", "check", "--airports", "KDLS", "KDLS", "kdls", "--no-progress",
               "--out", str(tmp_path)])
    assert rc == 0
    df = pd.read_parquet(tmp_path / "procedures_check.parquet")
    assert len(df) == len(check_airport(load_text("".join(x + "\n" for x in LINES), "c"),
                                        "KDLS", PERF))
    assert list(df.columns) == [c for c in ROW_COLUMNS if c != "order"]


@pytest.mark.parametrize("args, what", [
    (["--manual-nm", "nan"], "--manual-nm"),
    (["--manual-nm", "inf"], "--manual-nm"),
    (["--manual-nm", "0"], "--manual-nm"),
    (["--db", "/dev/zero"], "character device"),
])
def test_cli_check_refuses_bad_numbers_and_files_in_one_line(tmp_path, capsys, args, what):
    rc = main(["procedures", "check", "--no-progress", "--out", str(tmp_path / "o")] + args)
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and what in err[0]
    assert not (tmp_path / "o").exists()


SLICE_AIRPORTS = ("KASE", "KBFI", "KEGE")


def _cifp_slice() -> list[str]:
    """The FAA CIFP's enroute waypoints and navaids, and every record of SLICE_AIRPORTS, in
    file order."""
    out = []
    for rec in CIFP.read_text(encoding="latin-1").split("\n"):
        if rec[4:6] in ("EA", "D ", "DB") or (rec[4:5] in ("P", "H")
                                              and rec[6:10].strip() in SLICE_AIRPORTS):
            out.append(rec)
    return out


def test_check_of_a_corrupted_copy_of_a_real_cifp_slice(tmp_path, capsys):
    if not CIFP.exists():
        pytest.skip(f"FAA CIFP not found at {CIFP}")
    clean = _cifp_slice()
    legs = [i for i, r in enumerate(clean) if is_leg(r)]
    bad = list(clean)
    edits = {
        legs[3]: (71, "04\xb2"),     # a Latin-1 superscript two in a course
        legs[40]: (100, "000"),      # speed limit 0
        legs[77]: (103, "0300"),     # a positive vertical angle
    }
    for i, (col, text) in edits.items():
        bad[i] = put(bad[i], col, text)
    dup = legs[120]
    bad.insert(dup + 1, clean[dup])  # a record repeated
    ref, cor = tmp_path / "ref", tmp_path / "cor"
    for lines, out in ((clean, ref), (bad, cor)):
        rc = main(["procedures", "check", "--db", str(write(tmp_path, lines, out.name + ".dat")),
                   "--airports", *SLICE_AIRPORTS, "--no-progress", "--out", str(out)])
        assert rc == 0
    assert "3 rejected records" in capsys.readouterr().out
    rej = pd.read_csv(cor / "rejected_records.csv")
    shift = {i: i + 1 + (i > dup) for i in edits}     # 1-based lines in the corrupted copy
    assert sorted(rej.line) == sorted(shift.values())
    assert set(rej.field) == {"course", "speed limit", "vertical angle"}
    a = pd.read_parquet(ref / "procedures_check.parquet")
    b = pd.read_parquet(cor / "procedures_check.parquet")
    assert len(a) == len(b) and (a.procedure.values == b.procedure.values).all()
    hit = set()
    for i in list(edits) + [dup]:
        rec = clean[i]
        hit.add((rec[6:10].strip(), rec[13:19].strip(), rec[19], rec[20:25].strip()))
    keys = list(zip(b.airport, b.procedure, b.route_type, b.transition))
    for k, sa, sb, d in zip(keys, a.status, b.status, b.defects):
        if k in hit:
            assert sb == "degraded" and d, k
        else:
            assert sb == sa, k
    assert (a.status != "degraded").all()
