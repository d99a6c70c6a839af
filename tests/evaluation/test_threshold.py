"""Threshold-crossing evaluation (evaluation/threshold.py) on constructed tracks."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.earth import MEAN_RADIUS_M
from fms_testbed.core.segments import Line
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.evaluation.threshold import threshold_crossing

THR = (40.0, -100.0)


def _track(angle_deg, cas_kt, flap, gear, end_m=500.0, tch_ft=50.0, start_m=-12000.0):
    s = np.arange(start_m, end_m, 70.0)                # along the 090 course, 70 m / 0.5 s
    lat = np.full_like(s, THR[0])
    lon = THR[1] + np.degrees(s / (MEAN_RADIUS_M * math.cos(math.radians(THR[0]))))
    alt = 300.0 + tch_ft * FT_M - s * math.tan(math.radians(angle_deg))
    n = len(s)
    return pd.DataFrame({"t_s": np.arange(n) * 0.5, "lat_deg": lat, "lon_deg": lon,
                         "alt_m": alt, "cas_mps": np.full(n, cas_kt * KT_MPS),
                         "gamma_deg": np.full(n, -angle_deg), "flap_pos_norm": np.full(n, flap),
                         "gear_pos_norm": np.full(n, gear)})


def _path():
    start = (THR[0], THR[1] - 0.3)
    seg = SimpleNamespace(leg_index=3, geom=Line(start[0], start[1], THR[0], THR[1]))
    return SimpleNamespace(segments=[seg])


RW = SimpleNamespace(ident="RW09", lat_deg=THR[0], lon_deg=THR[1], elev_m=300.0,
                     tch_m=50 * FT_M, vpa_deg=3.0, map_is_threshold=True, map_leg=3)


def test_on_the_path_at_vapp_configured_is_ok():
    ap = load_aircraft("737").approach
    t = threshold_crossing(_track(3.0, 140.0, 0.875, 1.0), _path(), RW, 140 * KT_MPS, ap)
    assert t["crossed"] and t["ok"]
    assert t["cas_minus_vapp_kt"] == pytest.approx(0.0, abs=0.01)
    assert t["height_minus_tch_ft"] == pytest.approx(0.0, abs=0.5)
    assert t["path_angle_minus_vpa_deg"] == pytest.approx(0.0, abs=0.01)
    assert t["configured"] is True


def test_each_miss_is_named():
    ap = load_aircraft("737").approach
    t = threshold_crossing(_track(3.5, 150.0, 0.625, 0.0, tch_ft=90.0), _path(), RW,
                           140 * KT_MPS, ap)
    assert not t["ok"]
    assert t["checks"] == {"cas": False, "path_angle": False, "height": False,
                           "configured": False}
    assert t["path_angle_minus_vpa_deg"] == pytest.approx(0.5, abs=0.01)
    assert t["height_minus_tch_ft"] == pytest.approx(40.0, abs=0.5)


def test_short_of_the_threshold_extrapolates_or_says_so():
    ap = load_aircraft("737").approach
    t = threshold_crossing(_track(3.0, 140.0, 0.875, 1.0, end_m=-100.0), _path(), RW,
                           140 * KT_MPS, ap)
    assert t["crossed"] and t["extrapolated_m"] > 0 and t["ok"]
    t = threshold_crossing(_track(3.0, 140.0, 0.875, 1.0, end_m=-1500.0), _path(), RW,
                           140 * KT_MPS, ap)
    assert t["crossed"] is False and "not reached" in t["reason"]
