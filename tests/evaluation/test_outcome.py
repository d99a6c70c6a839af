"""The outcome vocabulary: ok only when flown to the end, contained, constraints met, inside the
envelope; otherwise the first failing status in ORDER, with every reason named."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.units import NM_M
from fms_testbed.evaluation.outcome import (EXIT_CODES, ORDER, decide, envelope_violations,
                                            horizontal_distance_m, navigation_containment)


def _df(n=100, **cols):
    base = {"t_s": np.arange(n) * 0.1, "alt_m": np.full(n, 3000.0), "cas_mps": np.full(n, 120.0),
            "mach": np.full(n, 0.4), "ny": np.ones(n), "lat_deg": np.full(n, 47.0),
            "lon_deg": np.full(n, 8.0), "nav_lat_deg": np.full(n, 47.0),
            "nav_lon_deg": np.full(n, 8.0)}
    base.update(cols)
    return pd.DataFrame(base)


@pytest.fixture(scope="module")
def cfg():
    return load_aircraft("737")


def test_clean_flight_is_ok(cfg):
    s = decide({"status": "ok", "reason": "duration flown"}, _df(), cfg)
    assert s["status"] == "ok" and s["outcome"]["failed"] == []


def test_ceiling_is_an_envelope_exceedance(cfg):
    alt = np.full(100, 3000.0)
    alt[50:] = 14000.0                       # a 737 at 14,000 m: ceiling 12,500 m
    s = decide({"status": "ok", "reason": "duration flown"}, _df(alt_m=alt), cfg)
    assert s["status"] == "envelope_exceeded"
    assert "ceiling" in s["reason"] and "t=5.0 s" in s["reason"]


def test_overspeed_mach_and_load_factor(cfg):
    v = envelope_violations(_df(cas_mps=np.full(100, cfg.limits.cas_max_mps + 1),
                                mach=np.full(100, 0.9), ny=np.full(100, 2.6)), cfg)
    assert len(v) == 3 and any("VMO" in x for x in v) and any("MMO" in x for x in v)


def test_law_command_limits_are_not_the_envelope(cfg):
    # the laws keep n_y in 0.5..1.6 g; the limit load factors (CS 25.337) are -1..2.5 g
    assert not envelope_violations(_df(ny=np.full(100, 0.45)), cfg)


def test_rnp_and_constraints_of_a_procedure_flight(cfg):
    summary = {"status": "ok", "reason": "guidance complete",
               "rnp": {"contained": False, "legs_not_contained": [3]},
               "constraints": [{"leg": 2, "fix": "ABC", "ok": False}, {"leg": 4, "ok": True}]}
    s = decide(summary, _df(), cfg)
    assert s["status"] == "not_contained"
    assert "legs [3]" in s["reason"] and "leg 2 ABC" in s["reason"]
    assert s["outcome"]["failed"] == ["not_contained", "constraints_missed"]


def test_divergence_comes_first(cfg):
    alt = np.full(100, 14000.0)
    s = decide({"status": "diverged", "reason": "stall"}, _df(alt_m=alt), cfg)
    assert s["status"] == "diverged" and "stall" in s["reason"] and "ceiling" in s["reason"]


def test_navigation_error_of_a_free_ins_is_not_contained(cfg):
    lat_nav = np.linspace(47.0, 66.0, 100)          # ~2,100 km of navigation error
    s = decide({"status": "ok", "reason": "duration flown"}, _df(nav_lat_deg=lat_nav), cfg,
               rnp_nm=2.0)
    assert s["status"] == "not_contained" and s["outcome"]["checks"]["navigation"]["nse_max_m"] > 2e6


def test_haversine_distance():
    d = horizontal_distance_m(np.array([0.0]), np.array([0.0]), np.array([0.0]), np.array([1.0]))
    assert d[0] == pytest.approx(111195.0, rel=1e-4)
    nc = navigation_containment(_df(), 1.0)
    assert nc["contained"] and nc["nse_max_m"] == 0.0
    assert 1.0 * NM_M > 0


def test_exit_codes():
    assert EXIT_CODES["ok"] == 0 and all(EXIT_CODES[s] == 1 for s in ORDER)


def test_a_flight_from_degraded_records_is_not_ok(cfg):
    summary = {"status": "ok", "reason": "guidance complete",
               "procedure": {"degraded": ["f.dat:12: sequence number: coded twice"]}}
    s = decide(summary, _df(), cfg)
    assert s["status"] == "degraded" and "f.dat:12" in s["reason"]
    assert EXIT_CODES["degraded"] == 1
