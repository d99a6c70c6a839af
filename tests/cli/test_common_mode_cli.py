"""A common-mode navigation failure flown for real: all three INS of an INS/GNSS bank stuck at
once. The bank's monitors compare the units with each other and see nothing; the flight must
still not end ``ok`` — the truth-side NSE check against the RNP decides, and the missed alert
is an event (slow: one 240-s flight on JSBSim)."""

import json

import pytest

from fms_testbed.cli import main

SCENARIO = """name: ins-all-stuck
description: three INS/GNSS units, every INS output frozen at t = 60 s, 737 cruise
aircraft: "737"
initial: {lat_deg: 47.45, lon_deg: -122.3, alt_ft: 11000, cas_kt: 250, heading_deg: 90}
duration_s: 240
hold: true
navigation: {source: ins_gnss, imu: STIM300, n_ins: 3}
events:
  - {t_s: 90, heading_deg: 150}
  - {t_s: 60, fault: {unit: ins1, kind: stuck}}
  - {t_s: 60, fault: {unit: ins2, kind: stuck}}
  - {t_s: 60, fault: {unit: ins3, kind: stuck}}
"""


@pytest.mark.slow
def test_every_ins_stuck_is_not_ok_and_the_missed_alert_is_an_event(tmp_path, capsys):
    scen = tmp_path / "all-stuck.yaml"
    scen.write_text(SCENARIO)
    out = tmp_path / "o"
    rc = main(["fly", "--scenario", str(scen), "--no-plots", "--out", str(out)])
    outcome = json.loads((out / "summary.json").read_text())["outcome"]
    assert outcome["status"] != "ok" and "not_contained" in outcome["failed"], outcome
    nav = outcome["checks"]["navigation"]
    # a frozen solution at 250 kt leaves the aircraft ~130 m/s behind it: far past any RNP
    assert not nav["contained"] and nav["nse_max_m"] > 1852.0 * nav["rnp_nm"], nav
    miss = outcome["checks"]["missed_alert"]
    assert miss["alert_t_s"] is None and 60.0 < miss["t_s"] < 240.0, miss
    assert rc in (0, 1), rc
    assert "not_contained" in capsys.readouterr().out
