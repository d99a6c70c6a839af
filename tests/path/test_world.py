"""Shared synthetic world for the ARINC-424 tests (records written with arinc424.synth)."""

from __future__ import annotations

from fms_testbed.procedures.database import load_database
from fms_testbed.legs.model import BuildParams, Performance
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.synth import (airport_record, offset, runway_record, vor_record,
                                        waypoint_record, write_file)

APT = (50.0, 10.0)
PERF = Performance(tas_plan_mps=118.0, tas_min_mps=77.0, climb_gradient_max=0.10,
                   climb_rate_max_mps=12.0, descent_rate_max_mps=12.0, bank_max_deg=25.0)
PARAMS = BuildParams()


def world() -> dict[str, tuple[float, float]]:
    """Named points: the airport, a VOR 10 NM north, waypoints around."""
    pts = {"TVR": offset(*APT, 0.0, 10.0)}
    pts.update({
        "WA": offset(*APT, 270.0, 20.0), "WB": offset(*APT, 270.0, 5.0),
        "WN": offset(*offset(*APT, 270.0, 20.0), 0.0, 2.0),
        "WS": offset(*offset(*APT, 180.0, 10.0), 270.0, 20.0),
        "WE": offset(*APT, 90.0, 15.0),
        "ARC1": offset(*pts["TVR"], 200.0, 10.0),   # on the 10 NM DME arc of TVR
        "ARC2": offset(*pts["TVR"], 100.0, 10.0),
    })
    return pts


def base_records() -> list[str]:
    pts = world()
    recs = [airport_record("XTST", *APT), runway_record("XTST", "RW09", *APT, 90.0),
            vor_record("TVR", *pts["TVR"])]
    for name, p in pts.items():
        if name != "TVR":
            recs.append(waypoint_record(name, *p))
    return recs


def build(tmp_path, legs: list[str], extra: list[str] | None = None, perf=PERF, params=PARAMS,
          checked: bool = True):
    """Write world + extra fix records + legs, load, build (and monitor) the first sequence."""
    f = write_file(tmp_path / "synthetic.dat", base_records() + (extra or []) + legs)
    db = load_database(f)
    assert not db.issues, db.issues
    seq = db.sequences("XTST")[0]
    path = build_sequence(db, seq, perf, params)
    return check_path(path, perf, params) if checked else path
