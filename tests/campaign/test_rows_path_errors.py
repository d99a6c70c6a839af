"""Regress rows: vertical path error and speed error columns (``campaign.rows.add_path_errors``)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from fms_testbed.campaign.rows import COLUMNS, add_path_errors
from fms_testbed.core.units import KT_MPS


def _df(alt_m, along_m, tas=None, cmd=None):
    n = len(alt_m)
    return pd.DataFrame({"alt_m": alt_m, "along_m": along_m,
                         "tas_mps": np.full(n, 100.0) if tas is None else tas,
                         "cmd_tas_mps": np.full(n, 100.0) if cmd is None else cmd})


def test_columns_are_in_the_schema():
    assert {"vpe_p95_m", "vpe_max_m", "spd_err_p95_kt"} <= set(COLUMNS)


def test_vpe_counts_only_where_the_profile_does_not_climb():
    # profile: climb 0→1000 m over 0-10 km, level 1000 m to 20 km, descent to 0 at 30 km
    prof = SimpleNamespace(along_m=[0.0, 10e3, 20e3, 30e3], alt_m=[0.0, 1000.0, 1000.0, 0.0])
    s = np.linspace(0.0, 30e3, 301)
    h = np.interp(s, prof.along_m, prof.alt_m)
    off = np.where(s < 10e3, 300.0, 20.0)         # large off the climb, 20 m elsewhere
    row = {}
    add_path_errors(row, _df(h + off, s), prof)
    assert row["vpe_max_m"] == pytest.approx(20.0)
    assert row["vpe_p95_m"] == pytest.approx(20.0)


def test_speed_error_in_knots_and_nulls_without_data():
    tas = np.full(100, 100.0)
    tas[:10] += 5 * KT_MPS                       # 10 % of samples 5 kt fast
    row = {}
    add_path_errors(row, _df(np.zeros(100), np.full(100, np.nan), tas=tas), None)
    assert row["spd_err_p95_kt"] == pytest.approx(5.0)
    assert "vpe_p95_m" not in row
    empty = {}
    add_path_errors(empty, pd.DataFrame(), None)
    assert empty == {}
