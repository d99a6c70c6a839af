"""The navigation error seen from truth decides the outcome when every monitor stays silent: a
procedure flight whose solution is stuck (every INS frozen, ANP small, no RNP alert) while the
aircraft flies on is not ``ok``, and the missed alert is recorded."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from geographiclib.geodesic import Geodesic

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.units import NM_M
from fms_testbed.evaluation.navigation_truth import (horizontal_distance_m, missed_alert,
                                                     navigation_containment)
from fms_testbed.evaluation.outcome import decide

N = 600                      # 60 s at 10 Hz
V_MPS = 130.0                # ground speed of the aircraft, m/s (due north)


def _flight(stuck_at_s: float | None, alert_at_s: float | None = None, rnp_nm: float = 0.3):
    """A procedure flight's timeseries: truth flies north at V_MPS; the solution follows it,
    or freezes from ``stuck_at_s``; ANP stays at 10 m; the RNP alert is raised at
    ``alert_at_s`` (None: never)."""
    t = np.arange(N) * 0.1
    lat = 47.0 + V_MPS * t / 111_200.0
    nav = lat.copy()
    if stuck_at_s is not None:
        nav[t >= stuck_at_s] = lat[np.argmax(t >= stuck_at_s)]
    alert = np.zeros(N) if alert_at_s is None else (t >= alert_at_s).astype(float)
    return pd.DataFrame({"t_s": t, "alt_m": 1000.0, "cas_mps": 120.0, "mach": 0.3, "ny": 1.0,
                         "lat_deg": lat, "lon_deg": -122.0, "nav_lat_deg": nav,
                         "nav_lon_deg": -122.0, "anp_m": 10.0, "rnp_m": rnp_nm * NM_M,
                         "rnp_alert": alert})


def _record(nav="ins_gnss"):
    # the path-side verdict a stuck solution gives: guidance holds the path it believes it is
    # on, so FTE and the TSE derived from it look contained
    return {"status": "ok", "reason": "procedure flown to its end",
            "rnp": {"contained": True, "legs_not_contained": [], "tse95_m": 20.0,
                    "min_rnp_nm": 0.3},
            "constraints": [], "procedure": {"degraded": [], "navigation": nav}}


@pytest.fixture(scope="module")
def cfg():
    return load_aircraft("737")


def test_nse_matches_the_wgs84_geodesic():
    d = horizontal_distance_m(np.array([47.0]), np.array([-122.0]), np.array([47.1]),
                              np.array([-121.9]))
    ref = Geodesic.WGS84.Inverse(47.0, -122.0, 47.1, -121.9)["s12"]
    assert d[0] == pytest.approx(ref, rel=5e-3)


def test_stuck_solution_with_silent_monitors_is_not_ok(cfg):
    df = _flight(stuck_at_s=10.0)
    d = decide(_record(), df, cfg)
    assert d["status"] == "not_contained"
    assert "seen from truth" in d["reason"] and "missed alert" in d["reason"]
    checks = d["outcome"]["checks"]
    assert checks["navigation"]["contained"] is False
    # 50 s stuck at 130 m/s: 6.5 km of navigation error at the end
    assert checks["navigation"]["nse_max_m"] == pytest.approx(50 * V_MPS, rel=0.02)
    miss = checks["missed_alert"]
    assert miss["alert_t_s"] is None
    # the error passes RNP 0.3 NM (556 m) 556 / 130 = 4.3 s after the freeze
    assert miss["t_s"] == pytest.approx(10.0 + 0.3 * NM_M / V_MPS, abs=0.2)


def test_a_raised_alert_is_not_a_missed_one(cfg):
    df = _flight(stuck_at_s=10.0, alert_at_s=12.0)
    d = decide(_record(), df, cfg)
    assert d["status"] == "not_contained"
    assert "missed_alert" not in d["outcome"]["checks"]
    assert missed_alert(df, None) is None


def test_a_healthy_solution_stays_ok(cfg):
    d = decide(_record(), _flight(stuck_at_s=None), cfg)
    assert d["status"] == "ok" and d["outcome"]["checks"]["navigation"]["contained"] is True
    assert "missed_alert" not in d["outcome"]["checks"]


def test_truth_navigation_is_not_checked_again(cfg):
    d = decide(_record(nav="truth"), _flight(stuck_at_s=10.0), cfg)
    assert "navigation" not in d["outcome"]["checks"]


def test_containment_uses_the_rnp_in_force_at_each_sample():
    df = _flight(stuck_at_s=55.0)                 # 5 s stuck: 650 m at the end
    assert navigation_containment(df, None)["contained"] is True          # 5 % beyond RNP 0.3
    df.loc[df["t_s"] >= 50.0, "rnp_m"] = 0.1 * NM_M                      # RNP 0.1 from 50 s
    nc = navigation_containment(df, None)
    assert nc["rnp_nm"] == pytest.approx(0.1) and nc["contained"] is False
