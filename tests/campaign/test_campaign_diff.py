"""``regress diff``: a run against itself is clean (exit 0); a status change, a value beyond its
tolerance, a value that appears, and a case in one run only are each reported (exit 1); a
change within tolerance is not; a tolerance file is checked field by field."""

from __future__ import annotations

import shutil

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from fms_testbed.campaign.diff import KEY, beyond, diff_frames, read_tolerances
from fms_testbed.campaign.rows import SCHEMA
from fms_testbed.campaign.store import FLIGHTS, part_files, read_flights
from fms_testbed.core.errors import ConfigError, UserError

from campaign_helpers import regress


def test_a_run_against_itself_is_clean(small_run, capsys, tmp_path):
    md = tmp_path / "diff.md"
    assert regress("diff", str(small_run), str(small_run), "--markdown", str(md)) == 0
    out = capsys.readouterr().out
    assert "20 cases matched: 0 changed beyond tolerance" in out
    assert "verdict: no change" in md.read_text()


def _edited(df):
    b = df.copy()
    ok = b.index[b["status"] == "ok"]
    b.loc[ok[0], "status"] = "not_contained"
    b.loc[ok[1], "tse_max_m"] += 5.0           # beyond the 1 m default
    b.loc[ok[2], "fte_p95_m"] += 0.5           # within it
    b.loc[ok[3], "constraints_missed"] += 1
    return b.drop(index=b.index[-1]), ok


def test_changes_beyond_tolerance_are_reported(small_run, tmp_path):
    a = read_flights(small_run)
    b, ok = _edited(a)
    res = diff_frames(a, b)
    assert not res.clean and res.matched == len(a) - 1
    assert len(res.status_changes) == 1
    assert res.status_changes.iloc[0][["status_a", "status_b"]].tolist() == ["ok",
                                                                            "not_contained"]
    assert sorted(res.value_changes["column"]) == ["constraints_missed", "tse_max_m"]
    assert res.value_changes.set_index("column").loc["tse_max_m", "delta"] == pytest.approx(5.0)
    assert len(res.only_a) == 1 and len(res.only_b) == 0
    assert tuple(res.only_a.iloc[0][list(KEY)]) == tuple(a.iloc[-1][list(KEY)])
    assert res.changed_cases == 3
    md = res.markdown()
    assert "| ok | not_contained | 1 |" in md and "CHANGED" in md
    tol = tmp_path / "tol.yaml"
    tol.write_text("tse_max_m: 10.0\nconstraints_missed: {abs: 1}\n")
    assert diff_frames(a, b, read_tolerances(tol)).value_changes.empty


def test_cli_exits_1_on_a_change(small_run, tmp_path, capsys):
    other = tmp_path / "b"
    shutil.copytree(small_run, other)
    a = read_flights(small_run)
    b, _ = _edited(a)
    for p in part_files(other):
        p.unlink()
    pq.write_table(pa.Table.from_pandas(b, schema=SCHEMA, preserve_index=False),
                   other / FLIGHTS / "part-edited.parquet")
    assert regress("diff", str(small_run), str(other)) == 1
    out = capsys.readouterr().out
    assert "status changes (1)" in out and "only in A (1)" in out


def test_beyond_treats_nulls_as_values():
    a = np.array([1.0, np.nan, np.nan, 10.0, 10.0])
    b = np.array([1.4, np.nan, 3.0, 11.4, 11.6])     # tolerance at 10: 0.5 + 0.1 × 10
    assert beyond(a, b, 0.5, 0.1).tolist() == [False, False, True, False, True]


@pytest.mark.parametrize("text, msg", [
    ("wind_m: 1\n", "not a compared column"),
    ("tse_max_m: {abs: -1}\n", "expected a number ≥ 0"),
    ("tse_max_m: {absolute: 1}\n", "expected a number or"),
    ("tse_max_m: .nan\n", "expected a number ≥ 0"),
])
def test_tolerance_file_is_checked(text, msg, tmp_path):
    f = tmp_path / "tol.yaml"
    f.write_text(text)
    with pytest.raises(ConfigError, match=msg):
        read_tolerances(f)


def test_across_conditions_matches_calm_against_wind(small_run):
    df = read_flights(small_run)
    calm, wind = df[df["conditions"] == "calm"], df[df["conditions"] != "calm"]
    plain = diff_frames(calm, wind)
    assert plain.matched == 0 and len(plain.only_a) == len(calm)
    res = diff_frames(calm, wind, key=KEY[:-1])
    assert res.matched == len(calm) == len(wind) and not len(res.only_a)
    with pytest.raises(UserError, match="several condition sets"):
        diff_frames(df, df, key=KEY[:-1])
