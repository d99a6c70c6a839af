"""Flights whose actual conditions differ from the planned (forecast) ones: guidance measures
them and rebuilds the rest of the procedure, logging why (KENV RNAV 26 via BVL, embedded
excerpt, 737, truth navigation)."""

from __future__ import annotations

import pytest

from fms_testbed.loop.procedure import prepare
from fms_testbed.procedures.database import load_database
from fms_testbed.run import fly_procedure

PROC = {"airport": "KENV", "procedure": "R26", "transition": "BVL"}


@pytest.fixture(scope="module")
def db():
    return load_database()


def _fly(db, **extra):
    scn, spec, fp, d = prepare({"aircraft": "737", "procedure": PROC, **extra}, db=db)
    res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    return res, [e for e in res.summary["guidance_events"] if e["kind"] == "rebuild"]


def test_warm_day_forecast_as_isa_is_rebuilt_for_the_measured_temperature(db):
    res, ev = _fly(db, atmosphere={"isa_dev_c": 20}, forecast={"isa_dev_c": 0})
    assert res.summary["status"] == "ok", res.summary["reason"]
    assert len(ev) == 1
    assert "conditions changed: temperature measured ISA+" in ev[0]["detail"]
    assert "vs planned ISA+0.0" in ev[0]["detail"] and "rebuilt from the present position" \
        in ev[0]["detail"]
    e = res.summary["errors"]["fte"]["all"]
    assert e["p95_m"] < 50.0 and e["max_m"] < 185.0, e


def test_conditions_as_planned_need_no_rebuild(db):
    res, ev = _fly(db, atmosphere={"isa_dev_c": 20},
                   wind=[{"alt_ft": 2000, "from_deg": 200, "speed_kt": 5},
                         {"alt_ft": 12000, "from_deg": 290, "speed_kt": 30}])
    assert res.summary["status"] == "ok", res.summary["reason"]
    assert ev == []


def test_wind_forecast_too_weak_is_rebuilt_with_its_reason(db):
    res, ev = _fly(db, wind={"from_deg": 290, "speed_kt": 45},
                   forecast={"wind": {"from_deg": 290, "speed_kt": 10}})
    assert res.summary["sequencing"]["completed"], res.summary["reason"]
    assert ev and "wind measured 29" in ev[0]["detail"] and "vs planned 290/10 kt" in \
        ev[0]["detail"]
