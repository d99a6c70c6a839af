"""The flight-test attitude-reference scenarios fly in JSBSim and their runs carry the mode's
columns, the summary block and the Fig. 2 plot (short flights: 70 s of each profile)."""

from __future__ import annotations

import pytest

from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario

COLUMNS = [f"att_ref_{k}_{a}_deg" for k in ("err", "est", "sigma")
           for a in ("roll", "pitch", "heading")]


@pytest.mark.parametrize("name", ["flight-test-attitude", "flight-test-attitude-level",
                                  "flight-test-attitude-climb", "flight-test-attitude-speed"])
def test_profile_flies_and_reports(name):
    res = run_scenario(scenarios_dir() / f"{name}.yaml", seed=0, progress=False,
                       overrides={"duration_s": 70})
    assert res.summary["status"] == "ok"
    assert set(COLUMNS) <= set(res.df.columns)
    block = res.summary["attitude_reference"]
    assert block["at_s"] == 60.0 and set(block["angles"]) == {"roll", "pitch", "heading"}
    assert block["angles"]["roll"]["inside_3sigma"]
    h = block["angles"]["heading"]
    if name == "flight-test-attitude-level":
        assert h["sigma_at_s_deg"] > 0.45          # no manoeuvre: heading unobservable
    elif name == "flight-test-attitude-speed":
        assert 0.02 < h["sigma_at_s_deg"] < 0.1    # accelerations alone: partly resolved
    else:
        assert h["sigma_at_s_deg"] < 0.03          # turns: heading resolved by 60 s
    assert "attitude_reference" in res.plot()
