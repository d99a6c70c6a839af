"""A SID started airborne is flown clean: the approach configuration schedule (gear down below
2,000 ft above the runway, flaps as the speed drops) never extends anything on a departure
(loop/steps.ConfigStep.departure)."""

import yaml

from fms_testbed.data import scenarios_dir
from fms_testbed.loop.procedure import prepare
from fms_testbed.run import fly_procedure


def test_airborne_sid_start_stays_clean():
    raw = yaml.safe_load((scenarios_dir() / "demo-sid.yaml").read_text())
    raw["duration_s"] = 240.0
    scn, spec, fp, db = prepare(raw, str(scenarios_dir() / "demo-sid.yaml"))
    res = fly_procedure(scn, spec, fp, db, progress=False, plots=False)
    events = [e for e in res.summary["guidance_events"] if e["kind"] == "config"]
    assert events == [], events
    assert res.df["gear_pos_norm"].max() == 0.0 and res.df["flap_pos_norm"].max() == 0.0
    assert res.df["agl_m"].min() < 30.0          # it did start just above the runway
