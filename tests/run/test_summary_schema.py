"""The run record's published schemas: the shipped files are the ones the types generate, and
what the package writes validates against them — ``summary.json`` of ``run``, ``fly`` and
``demo`` and of procedure flights of every kind (SID airborne and from the runway, an approach
with its threshold crossing and missed approach, a STAR, INS/GNSS with its navigation block, the
flight-test attitude reference), and the rows of a regression run. A schema that did not forbid
undeclared keys, or a record type it did not describe, would fail here."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pandas as pd
import pytest

from fms_testbed.cli import main
from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario
from fms_testbed.run.schemas import ROW_SCHEMA, SUMMARY_SCHEMA, dumps_schema, validator
from fms_testbed.run.summary import Summary

REPO = Path(__file__).resolve().parents[2]


def _write_schemas():
    spec = importlib.util.spec_from_file_location("write_schemas",
                                                  REPO / "scripts" / "write_schemas.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def check():
    v = validator(SUMMARY_SCHEMA)

    def check(path: Path) -> dict:
        data = json.loads(Path(path).read_text())
        errors = sorted(v.iter_errors(data), key=lambda e: list(e.path))
        assert not errors, "; ".join(f"{list(e.path)}: {e.message}" for e in errors[:5])
        return data
    return check


def test_the_shipped_schemas_are_the_generated_ones():
    mod = _write_schemas()
    for name, schema in mod.schemas().items():
        shipped = (REPO / "fms_testbed" / "data" / "schemas" / name).read_text()
        assert shipped == dumps_schema(schema), f"{name}: run python scripts/write_schemas.py"


def test_the_schema_refuses_an_undeclared_key_and_a_wrong_type(check, tmp_path):
    res = run_scenario(scenarios_dir() / "demo.yaml", overrides={"duration_s": 20},
                       progress=False)
    good = json.loads(res.summary.to_json())
    v = validator(SUMMARY_SCHEMA)
    assert v.is_valid(good)
    assert not v.is_valid({**good, "surprise_m": 1.0})
    assert not v.is_valid({**good, "metrics": {**good["metrics"], "alt_max_ft": 1.0}})
    assert not v.is_valid({**good, "duration_s": "long"})
    bad = dict(good)
    del bad["status"]
    assert not v.is_valid(bad)


def test_run_fly_and_demo_write_valid_summaries(check, tmp_path):
    assert main(["run", str(scenarios_dir() / "demo.yaml"), "--out", str(tmp_path / "run"),
                 "--no-plots"]) == 0
    check(tmp_path / "run" / "summary.json")
    assert main(["fly", "--airport", "KJFK", "--procedure", "DEEZZ5", "--runway", "31L",
                 "--transition", "CANDR", "--takeoff", "--out", str(tmp_path / "fly"),
                 "--no-plots"]) == 0
    s = check(tmp_path / "fly" / "summary.json")
    assert s["takeoff"]["start"] == "takeoff"
    assert main(["demo", "--out", str(tmp_path / "demo")]) == 0
    s = check(tmp_path / "demo" / "summary.json")
    assert s["plots"] and s["tracks"] == ["track.geojson", "track.kml"]


@pytest.mark.parametrize("scenario, overrides", [
    ("approach-kbfi-h14rz-rf.yaml", {}),
    ("star-kjfk-parch3.yaml", {}),
    ("ins-fault-step.yaml", {"duration_s": 120}),
    ("flight-test-attitude.yaml", {"duration_s": 70}),
])
def test_shipped_scenarios_write_valid_summaries(check, tmp_path, scenario, overrides):
    res = run_scenario(scenarios_dir() / scenario, overrides=overrides, progress=False)
    res.save(tmp_path / "out", plots=False)
    s = check(tmp_path / "out" / "summary.json")
    assert Summary.__name__ and s["outcome"]["status"] == s["status"]


def test_an_approach_with_its_missed_approach_writes_a_valid_summary(check, tmp_path):
    res = run_scenario({"aircraft": "737", "procedure": {
        "airport": "KJFK", "procedure": "I13L", "transition": "KMCHI", "missed": True}},
        progress=False)
    res.save(tmp_path / "out", plots=False)
    s = check(tmp_path / "out" / "summary.json")
    assert s["threshold"]["runway"] and s["constraints"]


def test_regress_rows_are_valid(tmp_path):
    out = tmp_path / "regress"
    assert main(["regress", "run", "--airports", "KENV", "--wind", "calm", "--workers", "1",
                 "--no-progress", "--out", str(out)]) in (0, 1)
    from fms_testbed.campaign.store import read_flights

    df = read_flights(out)
    assert len(df) >= 10 and set(df["status"]) > {"ok"}
    v = validator(ROW_SCHEMA)
    for row in df.astype(object).where(pd.notna(df), None).to_dict("records"):
        errors = list(v.iter_errors(row))
        assert not errors, f"{row['case_id']}: {errors[0].message}"
    assert not v.is_valid({**row, "extra": 1})
