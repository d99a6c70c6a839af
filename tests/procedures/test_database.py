"""The embedded excerpt and the whole FAA CIFP (slow): every transition built, the goals and
the geometric invariants hold, the CLI writes its outputs, results do not depend on workers."""

import json
from pathlib import Path

import pandas as pd
import pytest

from fms_testbed.evaluation.check import check_database, invariants, perf_for, schedule
from fms_testbed.procedures.database import load_database
from fms_testbed.viz.geojson import to_feature_collection
from fms_testbed.procedures.legrecord import PATH_TERMINATORS
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.cli import main

CIFP = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "cifp" / "FAACIFP18_230126"
FAA_ABSENT = {"FD", "CR"}


def _assert_goals(rows, summary):
    assert summary["ok_or_corrected_pct"] >= 99.0
    for r in rows:
        if r["status"] == "impossible":
            assert r["findings"], f"{r['airport']} {r['procedure']}: impossible without a reason"
        assert "internal error" not in r["findings"], r
    # a leg type coded but never built: only where every transition coding it is impossible
    # with its reason (the excerpt's one VD transition, KFXY VOR-A, joins its AF 138° off the
    # arc's tangent: a discontinuity, never ok or corrected)
    for pt in summary["leg_types_present_not_built"]:
        with_pt = [r for r in rows if pt in r["legs"].split()]
        assert with_pt and all(r["status"] in ("impossible", "degraded") and r["findings"]
                               for r in with_pt), pt
    assert len(summary["leg_types_present_not_built"]) <= 1
    assert summary["max_gap_m"] <= 1.0
    assert summary["max_fix_excess_m"] <= 0.0
    assert summary["turn_mismatches"] == 0
    for r in rows:  # RF radius as coded, unless the monitor reported the database's mismatch
        if r["rf_radius_err_nm"] > 0.05:
            assert "[R]: RF radius coded" in r["findings"], r


def test_embedded_excerpt_meets_the_goals_and_covers_every_faa_leg_type():
    rows, summary = check_database(None, perf_for("737"), progress=False)
    _assert_goals(rows, summary)
    coded = {pt for pt, v in summary["by_leg_type"].items() if v["coded"]}
    assert coded == set(PATH_TERMINATORS) - FAA_ABSENT
    assert summary["parse_issues"] == 0


def test_results_do_not_depend_on_the_number_of_workers():
    perf = perf_for("737")
    one, _ = check_database(None, perf, ["KJFK", "PAFA", "KDLS"], workers=1, progress=False)
    two, _ = check_database(None, perf, ["KJFK", "PAFA", "KDLS"], workers=2, progress=False)
    assert pd.DataFrame(one).equals(pd.DataFrame(two))


def test_workers_get_the_largest_airports_first_and_every_airport_once():
    db = load_database()
    airports = db.airport_idents()
    for a in airports:        # counted unparsed: the parsed transitions' legs
        assert db.record_count(a) == sum(len(s.legs) for s in db.sequences(a)), a
    order, chunk = schedule(db, airports, 2)
    assert sorted(order) == airports and chunk >= 1
    counts = [db.record_count(a) for a in order]
    assert counts == sorted(counts, reverse=True) and counts[0] > counts[-1]


def test_geojson_has_one_feature_per_segment_with_the_issue_fields():
    db = load_database()
    perf = perf_for("737")
    seq = db.select("PAFA", "H02LZ", "GLDHL")[0]
    path = check_path(build_sequence(db, seq, perf), perf)
    fc = to_feature_collection(path)
    assert len(fc["features"]) == len(path.segments)
    arcs = [f["properties"] for f in fc["features"] if f["properties"]["segment_type"] == "arc"]
    assert arcs and {"centre_lat_deg", "radius_m", "turn_direction", "subtended_angle_deg",
                     "planned_alt_start_ft", "along_end_nm",
                     "planned_speed_kt", "bank_deg", "altitude_descriptor", "leg_index",
                     "path_terminator", "fix_ident"} <= set(arcs[0])
    json.dumps(fc, allow_nan=False)
    assert invariants(path).max_gap_m <= 1.0


def test_cli_build_writes_geojson_and_png(tmp_path, capsys):
    rc = main(["procedures", "build", "--airport", "KJFK", "--procedure", "DEEZZ5",
               "--out", str(tmp_path)])
    assert rc == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert "KJFK_SID_DEEZZ5_RW04B.geojson" in names and "KJFK_SID_DEEZZ5_RW04B.png" in names
    assert "KJFK SID DEEZZ5 RW04B:" in capsys.readouterr().out


def test_cli_check_writes_table_and_summary(tmp_path):
    rc = main(["procedures", "check", "--airports", "KDLS", "PABE", "--no-progress",
               "--out", str(tmp_path)])
    assert rc == 0
    df = pd.read_parquet(tmp_path / "procedures_check.parquet")
    assert {"airport", "procedure", "transition", "type", "legs", "status",
            "findings"} <= set(df.columns)
    assert set(df.airport) == {"KDLS", "PABE"}
    assert (tmp_path / "procedures_check.csv").exists()
    assert json.loads((tmp_path / "summary.json").read_text())["transitions"] == len(df)


def test_cli_unknown_airport_is_a_one_line_error(tmp_path, capsys):
    rc = main(["procedures", "build", "--airport", "ZZZZ", "--out", str(tmp_path)])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "ZZZZ" in err[0]


@pytest.mark.slow
def test_whole_faa_cifp_meets_the_goals_and_invariants():
    if not CIFP.exists():
        pytest.skip(f"FAA CIFP not found at {CIFP}")
    rows, summary = check_database(str(CIFP), perf_for("737"), progress=False)
    _assert_goals(rows, summary)
    assert summary["transitions"] == 51706
    coded = {pt for pt, v in summary["by_leg_type"].items() if v["coded"]}
    assert coded == set(PATH_TERMINATORS) - FAA_ABSENT
