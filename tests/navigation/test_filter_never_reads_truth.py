"""The INS/GNSS filter never reads the true state: while any of its prediction, correction,
feedback or initialisation code runs, every attribute of every true state raises (the poison of
tests/guidance/test_guidance_never_reads_truth.py), and a whole ``ins_gnss`` flight on the
strapdown passes that way — and a recorded flight, replayed, gives the flight's own solution."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from fms_testbed.cli.nav_replay import replay_files
from fms_testbed.navigation.replay import solution_minus_flight
from fms_testbed.navigation import ins_filter, prediction
from fms_testbed.run.api import run_scenario
from tests.guidance.test_guidance_never_reads_truth import TruthRead, truth_poisoned

SCN = {"aircraft": "737", "duration_s": 150, "hold": True, "vertical_law": "coupled",
       "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400,
                   "heading_deg": 90},
       "events": [{"t_s": 20, "heading_deg": 200}, {"t_s": 90, "alt_m": 3400}]}
_FILTER_METHODS = [(ins_filter.InsGnssFilter, m) for m in
                   ("initialise", "predict", "use", "gnss_update", "baro_update",
                    "take_feedback")] + \
    [(prediction.PredictionInterval, m) for m in ("start", "add", "flush")]


def _poisoned(fn):
    @functools.wraps(fn)
    def wrapped(*a, **k):
        with truth_poisoned():
            return fn(*a, **k)
    return wrapped


def test_an_ins_gnss_flight_on_the_strapdown_runs_with_the_filter_poisoned(monkeypatch):
    for cls, name in _FILTER_METHODS:
        monkeypatch.setattr(cls, name, _poisoned(getattr(cls, name)))
    res = run_scenario({**SCN, "navigation": {"source": "ins_gnss", "imu": "STIM300",
                                              "seed": 4}}, progress=None)
    s = res.summary
    assert s.status == "ok", s.reason
    assert s.navigation.truth_model == "strapdown"
    df = res.to_pandas()
    assert np.hypot(df.nse_east_m, df.nse_north_m).iloc[100:].max() < 10.0


def test_the_poison_reaches_the_filter(monkeypatch):
    # the same wrapping with a filter that does read truth fails: the check has teeth
    from fms_testbed.core.state import AircraftState
    truth = AircraftState(*([0.0] * 8), None, *([0.0] * 12), None, 0.0, 0.0, 0.0, 0.0)

    def reads_truth(self, ins, f_b, w_ib, dt_s):
        return truth.tas_mps
    monkeypatch.setattr(ins_filter.InsGnssFilter, "predict", _poisoned(reads_truth))
    with pytest.raises(TruthRead):
        ins_filter.InsGnssFilter.predict(None, None, None, None, 0.1)


def test_a_recorded_flight_replays_to_its_own_solution(tmp_path):
    nav = {"source": "ins_gnss", "imu": "STIM300", "seed": 5, "record_sensors": True,
           "baro": None, "gnss": {"latency_s": 0.0}, "filter": {"predict_interval_s": 0.0}}
    res = run_scenario({**SCN, "navigation": nav}, progress=None)
    res.save(tmp_path / "flight", plots=False)
    s = tmp_path / "flight" / "sensors"
    rp = replay_files(s / "imu.parquet", s / "gnss.parquet", s / "init.json", s / "truth.parquet")
    assert rp["summary"]["gnss_rejected"] == {"gnss_pos": 0, "gnss_vel": 0}
    d = solution_minus_flight(rp["solution"], res.to_pandas())
    assert len(d) > 1000
    assert d.d_horizontal_m.max() < 0.05 and d.d_alt_m.abs().max() < 0.05
    assert d.d_heading_deg.abs().median() < 0.005 and d.d_heading_deg.abs().max() < 0.3
    # and the flight's own NSE is metres: the agreement is not two copies of a broken filter
    assert math.isfinite(rp["stats"]["horizontal_m"]["p95"]) and \
        rp["stats"]["horizontal_m"]["p95"] < 5.0
