"""The campaign check of a tuning: pairing, per-run figures, goal lines; and the same aircraft
flown twice shifts nothing."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from fms_testbed.evaluation.campaign_shift import (NEW, OLD, campaign_shift,
                                                   conditions_yaml, goal_lines)


def _flights(rng, procs, fte, vpe, missed):
    rows = []
    for p, f, v, m in zip(procs, fte, vpe, missed):
        rows.append({"airport": "KAAA", "type": "STAR", "procedure": p, "runway": "RW01",
                     "transition": "ALL", "conditions": "wind", "status": "ok" if m == 0
                     else "missed_constraint", "fte_p95_m": f, "vpe_p95_m": v,
                     "spd_err_p95_kt": rng.uniform(5, 15), "constraints_checked": 2,
                     "constraints_missed": m})
    return pd.DataFrame(rows)


def test_flights_are_paired_by_procedure_not_by_row_order():
    rng = np.random.default_rng(3)
    procs = [f"P{k}" for k in range(7)]
    fte_old, vpe_old = rng.uniform(3, 9, 7), rng.uniform(1, 5, 7)
    d_fte = rng.normal(0, 1, 7)
    old = _flights(rng, procs, fte_old, vpe_old, [1, 0, 0, 1, 0, 0, 0])
    new = _flights(rng, procs, fte_old + d_fte, vpe_old - 0.5, [0, 0, 0, 1, 0, 0, 0])
    new = new.iloc[::-1].reset_index(drop=True)           # another order
    new = pd.concat([new, _flights(rng, ["EXTRA"], [50.0], [50.0], [3])])   # unpaired
    s = campaign_shift(old, new)
    assert s.n_pairs == 7
    # against a pairing written out by hand
    by = {p: (f, v) for p, f, v in zip(procs, fte_old, vpe_old)}
    want = np.median([r.fte_p95_m - by[r.procedure][0] for r in new.itertuples()
                      if r.procedure in by])
    assert s.diffs["fte_p95_m"] == pytest.approx(want, abs=1e-12)
    assert s.diffs["vpe_p95_m"] == pytest.approx(-0.5, abs=1e-12)
    t = s.table
    assert t.loc["cases", NEW] == 8 and t.loc["constraints_missed", NEW] == 4
    assert t.loc["fte_p95_m median", OLD] == pytest.approx(float(np.median(fte_old)))
    assert t.loc["constraints_checked", OLD] == 14


def test_goal_lines_follow_the_medians_and_the_missed_constraints():
    rng = np.random.default_rng(4)
    procs = ["A", "B", "C"]
    old = _flights(rng, procs, [5.0, 6.0, 7.0], [2.0, 3.0, 4.0], [1, 1, 0])
    better = _flights(rng, procs, [4.0, 6.0, 7.0], [2.0, 2.5, 4.0], [1, 0, 0])
    worse = _flights(rng, procs, [5.0, 6.5, 7.0], [2.0, 3.0, 4.0], [1, 1, 0])
    assert [ok for ok, _ in goal_lines(campaign_shift(old, better))] == [True, True, True]
    got = [ok for ok, _ in goal_lines(campaign_shift(old, worse))]
    assert got == [False, True, False]       # FTE median 6.5 > 6.0; missed 2, not fewer
    # a tuned run that flew nothing meets nothing (fewer missed of fewer checked is no gain)
    none = better.assign(fte_p95_m=np.nan, vpe_p95_m=np.nan, spd_err_p95_kt=np.nan,
                         constraints_checked=0, constraints_missed=0, status="error")
    assert [ok for ok, _ in goal_lines(campaign_shift(old, none))] == [False, False, False]


def test_conditions_file_is_one_set_the_regression_reads(tmp_path):
    from fms_testbed.campaign.conditions import read_conditions

    p = tmp_path / "c.yaml"
    p.write_text(conditions_yaml({"from_deg": 270.0, "speed_kt": 30.0}, "moderate"))
    (one,) = read_conditions(p)
    assert one.wind == {"from_deg": 270.0, "speed_kt": 30.0}
    assert one.turbulence == {"severity": "moderate"}
    assert one.navigation == {"source": "truth"}
    p.write_text(conditions_yaml({"from_deg": 90.0, "speed_mps": 12.0}, "light"))
    (two,) = read_conditions(p)
    assert two.wind == {"from_deg": 90.0, "speed_mps": 12.0} and two.name != one.name


@pytest.mark.slow
def test_the_same_aircraft_flown_twice_shifts_nothing(tmp_path):
    from fms_testbed.cli.tune_envelope import campaign_check

    s, md = campaign_check("737", "737", tmp_path, airports=["KBFI"], limit=1, workers=1)
    assert s.n_pairs == 1
    assert all(v == 0.0 for v in s.diffs.values()), s.diffs
    assert "1 paired flights" in md
    assert (tmp_path / "campaign-shift.png").stat().st_size > 10_000
