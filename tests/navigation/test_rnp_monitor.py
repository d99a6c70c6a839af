"""RNP on-board monitoring: the alert when ANP exceeds RNP, its time to alert, its events, and
the flight outcome that reflects it (issue 14, item 5)."""

import numpy as np
import pandas as pd
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import NM_M
from fms_testbed.evaluation.outcome import decide
from fms_testbed.navigation.monitor import monitor_flight, rnp_alerts, time_to_alert_limit_s
from fms_testbed.run import run_scenario


def _ramp(anp_from_m, anp_to_m, n=300, dt=0.1):
    t = np.arange(n) * dt
    return t, np.linspace(anp_from_m, anp_to_m, n)


def test_alert_rises_after_the_delay_and_clears_when_anp_is_back_below():
    t = np.arange(0, 60, 0.1)
    anp = np.where((t >= 20) & (t < 40), 700.0, 100.0)
    tr = rnp_alerts(t, anp, np.full(t.size, 0.3 * NM_M), delay_s=2.0)
    on = t[tr.alert]
    assert on[0] == pytest.approx(22.0, abs=1e-6) and on[-1] == pytest.approx(39.9, abs=1e-6)
    assert tr.time_to_alert_s == [pytest.approx(2.0, abs=1e-6)]
    assert [e["kind"] for e in tr.events] == ["alert", "alert"]
    assert tr.events[1]["reason"].startswith("cleared")


def test_single_sample_excursions_shorter_than_the_delay_never_alert():
    t = np.arange(0, 30, 0.1)
    anp = np.full(t.size, 100.0)
    anp[::37] = 1e4                                  # isolated spikes
    assert not rnp_alerts(t, anp, np.full(t.size, 556.0), delay_s=1.0).alert.any()


def test_monitor_is_causal_future_samples_do_not_change_past_verdicts():
    t, anp = _ramp(400.0, 800.0)
    rnp = np.full(t.size, 556.0)
    full = rnp_alerts(t, anp, rnp, 2.0).alert
    for k in (50, 150, 250):
        assert np.array_equal(rnp_alerts(t[:k], anp[:k], rnp[:k], 2.0).alert, full[:k])


def test_time_to_alert_limits_and_a_delay_beyond_them_is_refused():
    assert time_to_alert_limit_s(0.3 * NM_M) == 10.0
    assert time_to_alert_limit_s(2.0 * NM_M) == 30.0
    t, anp = _ramp(0.0, 1.0)
    with pytest.raises(ConfigError, match="alert_delay_s"):
        rnp_alerts(t, anp, np.full(t.size, 0.3 * NM_M), delay_s=10.0)
    rnp_alerts(t, anp, np.full(t.size, 2.0 * NM_M), delay_s=10.0)      # en route: 30 s


def test_monitor_flight_adds_the_column_and_sorts_the_events():
    class Source:
        events = [{"t_s": 5.0, "unit": "gnss", "kind": "detected", "stage": "innovation_gate",
                   "reason": "x"}]
        alert_delay_s = 1.0

    t = np.arange(0, 20, 0.1)
    df = pd.DataFrame({"t_s": t, "anp_m": np.where(t > 3, 900.0, 10.0),
                       "rnp_m": np.full(t.size, 556.0)})
    df2, block = monitor_flight(df, Source(), None)
    assert "rnp_alert" in df2 and df2["rnp_alert"].iloc[-1] == 1.0
    assert block["rnp_alert"]["raised"] and block["rnp_alert"]["first_t_s"] == pytest.approx(4.1)
    assert [e["t_s"] for e in block["events"]] == sorted(e["t_s"] for e in block["events"])
    plain = pd.DataFrame({"t_s": t})              # a source without ANP or events
    out, none = monitor_flight(plain, object(), None)
    assert none is None and "rnp_alert" not in out


def test_an_rnp_alert_makes_the_flight_not_contained():
    cfg = load_aircraft("737")
    n = 100
    df = pd.DataFrame({"t_s": np.arange(n) * 0.1, "alt_m": np.full(n, 3000.0),
                       "cas_mps": np.full(n, 120.0), "mach": np.full(n, 0.4), "ny": np.ones(n),
                       "rnp_alert": np.r_[np.zeros(60), np.ones(40)]})
    s = decide({"status": "ok", "reason": "duration flown"}, df, cfg)
    assert s["status"] == "not_contained" and "RNP alert" in s["reason"] and "t=6.0 s" in s["reason"]
    df["rnp_alert"] = 0.0
    assert decide({"status": "ok", "reason": "duration flown"}, df, cfg)["status"] == "ok"


def test_a_gnss_outage_on_a_consumer_imu_raises_the_alert_in_flight():
    # RNP 0.02 NM (37 m): ANP from the filter grows past it within the outage, the flight's
    # outcome is not_contained, and the alert is in summary.json's navigation events
    scn = {"name": "outage", "aircraft": "737", "duration_s": 150, "hold": True,
           "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400},
           "rnp_nm": 0.02,
           "navigation": {"source": "ins_gnss", "imu": "consumer_MEMS",
                          "gnss": {"outages": [{"start_s": 60}]}}}
    res = run_scenario(scn, seed=3, progress=False)
    df, s = res.df, res.summary
    assert {"anp_m", "rnp_alert", "nav_mode", "ins_used"} <= set(df.columns)
    assert s["status"] == "not_contained" and "RNP alert" in s["reason"]
    nav = s["navigation"]
    assert nav["rnp_alert"]["raised"]
    first = nav["rnp_alert"]["first_t_s"]
    # from the time ANP crossed RNP (timeseries) to the alert: within ICAO's time to alert
    crossed = float(df["t_s"][df["anp_m"] > 0.02 * NM_M].iloc[0])
    assert 60 < crossed and 0 <= first - crossed <= 10.0     # RNP 0.02 NM: terminal, 10 s
    assert any(e["kind"] == "alert" for e in nav["events"])
    assert (df["nav_mode"][df["t_s"] > 65] == 1).all() and (df["nav_mode"][
        (df["t_s"] > 10) & (df["t_s"] < 59)] == 0).all()
