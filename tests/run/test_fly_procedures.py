"""Closed-loop procedure flights on the embedded CIFP excerpt (737, calm air, truth navigation).

Each procedure is flown once per test session (module-scoped cache, ~1-7 s wall each) and
several behaviours are checked on it. Tolerances are the issue-6 goals unless a test says why.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.core.units import FT_M
from fms_testbed.core.units import NM_M as NM
from fms_testbed.procedures.database import load_database
from fms_testbed.loop.procedure import prepare
from fms_testbed.run import fly_procedure



@pytest.fixture(scope="module")
def db():
    return load_database()


_CACHE: dict = {}


def flown(db, airport, procedure, runway=None, transition=None, **extra):
    key = (airport, procedure, runway, transition, tuple(sorted(extra.items())))
    if key not in _CACHE:
        proc = {"airport": airport, "procedure": procedure}
        if runway:
            proc["runway"] = runway
        if transition:
            proc["transition"] = transition
        raw = {"aircraft": extra.pop("aircraft", "737"), "procedure": proc, **extra}
        scn, spec, fp, d = prepare(raw, db=db)
        _CACHE[key] = (fly_procedure(scn, spec, fp, d, progress=False), fp)
    return _CACHE[key]


def _completed(res):
    s = res.summary
    assert s["status"] == "ok", s["reason"]
    q = s["sequencing"]
    assert q["completed"] and q["in_order"] and not q["skipped"] and not q["repeated"]
    assert q["legs_entered"] == q["legs"]


def test_straight_tf_legs_are_tracked_within_a_few_metres(db):
    """KJFK RNAV 04R final: IF-TF-TF, straight in to the runway."""
    res, fp = flown(db, "KJFK", "R04RY")
    _completed(res)
    e = res.summary["errors"]["fte"]
    assert e["straight"]["p95_m"] <= 30.0
    assert e["all"]["max_m"] <= 30.0


def test_rf_legs_are_flown_within_the_goal(db):
    """KBFI RNAV (RNP) 14R via ZUVEN: TF then RF, RF again in the final."""
    res, fp = flown(db, "KBFI", "H14RZ", transition="ZUVEN")
    _completed(res)
    assert "RF" in res.summary["procedure"]["legs"]
    df = res.df
    on_rf = df[df["leg_code"] == "RF"]
    assert len(on_rf) > 100 and (on_rf["curvature_1pm"] != 0).any()
    assert on_rf["nav_xtk_m"].abs().max() <= 0.1 * NM
    assert res.summary["errors"]["fte"]["all"]["p95_m"] <= 150.0
    assert res.summary["rnp"]["contained"]


def test_fly_by_turns_keep_fte_inside_the_goal(db):
    """The demo SID (DEEZZ5 RW31L + CANDR): fly-by corners up to ~90°, VM vectors, DF."""
    res, fp = flown(db, "KJFK", "DEEZZ5", runway="31L", transition="CANDR")
    _completed(res)
    roles = set(res.df["seg_role"])
    assert "flyby" in roles
    e = res.summary["errors"]["fte"]
    assert e["straight"]["p95_m"] <= 30.0 and e["all"]["p95_m"] <= 150.0
    assert e["all"]["max_m"] <= 0.1 * NM


def test_vi_to_cf_intercept_sequences_onto_the_course(db):
    """KBFI KENT8 RW14L: heading to intercept, then course to fix."""
    res, fp = flown(db, "KBFI", "KENT8", runway="14L")
    _completed(res)
    df = res.df
    assert list(dict.fromkeys(df["leg_code"])) == ["VI", "CF"]
    cf = df[df["leg_code"] == "CF"]
    assert cf["nav_xtk_m"].abs().iloc[-200:].max() < 30.0  # established on the course


def test_ca_leg_ends_when_the_altitude_is_reached_then_df_turns_from_there(db):
    """KDLS DALLS1 RW13: VR (radial) → CA → DF. The CA ends in flight at its altitude (a
    fly-over point), the rest is rebuilt from the aircraft state and the DF turns from it."""
    res, fp = flown(db, "KDLS", "DALLS1", runway="13")
    _completed(res)
    ev = res.summary["guidance_events"]
    cond = [e for e in ev if e["kind"] == "condition" and "altitude" in e.get("detail", "")]
    assert cond, ev
    k = cond[0]["leg"]
    ca_alt = fp.seq.legs[k].alt1_m
    df = res.df
    end_of_ca = df[df["leg_index"] == k].iloc[-1]
    assert end_of_ca["alt_m"] == pytest.approx(ca_alt, abs=50 * FT_M)
    assert any(e["kind"] == "rebuild" and e["leg"] == k + 1 for e in ev)
    after = df[df["leg_index"] == k + 1]
    assert after["leg_code"].iloc[0] == "DF" and "turn" in set(after["seg_role"])
    assert after["nav_xtk_m"].abs().max() < 0.1 * NM


def test_hold_entry_and_one_circuit_for_hf(db):
    """KENV RNAV 26 via BVL: the approach transition ends in an HF course reversal. ARINC-424
    HF ends at the first crossing of the fix after the entry, so the entry (role 'turn') is the
    course reversal; it ends over BVL on the inbound course, and the flight continues."""
    res, fp = flown(db, "KENV", "R26", transition="BVL")
    _completed(res)
    df = res.df
    assert "HF" in set(df["leg_code"])
    hf = df[df["leg_code"] == "HF"]
    # a course reversal: the track turns through at least 180° in the HF
    trk = np.unwrap(np.radians(hf["track_deg"].to_numpy()))
    assert math.degrees(trk.max() - trk.min()) >= 180.0
    k = next(lg.index for lg in fp.path.legs if lg.path_term == "HF")
    last = [sg for sg in fp.path.segments if sg.leg_index == k][-1]
    from fms_testbed.path.segmentation import resolve_legs
    inbound = resolve_legs(db, fp.seq)[0][k].course_true_deg
    assert abs((last.geom.end_course_deg - inbound + 180.0) % 360.0 - 180.0) < 1.0
    assert hf["nav_xtk_m"].abs().max() <= 0.1 * NM


def test_altitude_and_speed_constraints_are_met_at_each_fix(db):
    """Every coded constraint of these flights is met within 50 ft / 5 kt."""
    for args in (("KBFI", "H14RZ", None, "ZUVEN"), ("KENV", "R26", None, "BVL"),
                 ("KJFK", "R04RY", None, None)):
        res, _ = flown(db, *args)
        cons = res.summary["constraints"]
        assert cons, args
        assert res.summary["constraints_met"], [c for c in cons if c.get("ok") is False]


def test_approach_ends_at_the_runway_threshold_at_the_coded_height(db):
    res, fp = flown(db, "KJFK", "R04RY")
    last = fp.seq.legs[-1]
    assert last.fix.ident.startswith("RW")
    end = res.df.iloc[-1]
    assert end["alt_m"] == pytest.approx(last.alt1_m, abs=50 * FT_M)
    assert res.summary["reason"] == "guidance complete"


def test_timeseries_has_the_contract_columns(db):
    res, _ = flown(db, "KJFK", "R04RY")
    for c in ("xtk_m", "nav_xtk_m", "leg_index", "leg_code", "along_m"):
        assert c in res.df
    assert res.df["along_m"].is_monotonic_increasing
    assert res.summary["errors"]["per_leg"][1]["fte95_m"] is not None


def test_an_impossible_speed_ends_the_flight_with_a_clear_status(db, tmp_path):
    """A 737 whose planned speed is 60 m/s TAS (far below its stall speed) starts trimmed at a
    normal 118 m/s, then guidance asks for 60 m/s, clean (its approach block with the flap
    schedule removed): it stalls and the run ends 'diverged' with
    the reason — no hang, no exception."""
    import yaml

    from fms_testbed.data import aircraft_dir

    raw = yaml.safe_load((aircraft_dir() / "737.yaml").read_text())
    raw["name"] = "737-slow"
    raw["limits"]["climb_cas_mps"] = 60.0
    raw["limits"]["cas_min_mps"] = 40.0
    raw.pop("approach", None)   # clean throughout: no flaps to slow down with
    p = tmp_path / "737-slow.yaml"
    p.write_text(yaml.safe_dump(raw))
    scn, spec, fp, d = prepare({"aircraft": str(p), "procedure": {
        "airport": "KJFK", "procedure": "R04RY"}}, db=db)
    scn = scn.model_copy(update={"initial": scn.initial.model_copy(update={"tas_mps": 118.0})})
    res = fly_procedure(scn, spec, fp, d, progress=False)
    s = res.summary
    assert s["status"] == "diverged"
    assert "stall" in s["reason"], s["reason"]
    assert not s["sequencing"]["completed"]


def test_fly_over_fix_is_overflown_not_cut(db):
    """DEEZZ5 RW31L: YNKEE is a fly-over fix (waypoint description 'Y'): the aircraft passes
    over it, unlike a fly-by fix whose corner is cut by the turn anticipation."""
    from fms_testbed.evaluation.flight_errors import _dist_m

    res, fp = flown(db, "KJFK", "DEEZZ5", runway="31L", transition="CANDR")
    df = res.df
    legs = {lg.termination.fix_ident: lg for lg in fp.path.legs if lg.termination.kind == "fix"}
    yn, ce = legs["YNKEE"], legs["DEEZZ"]
    assert yn.record.fly_over and not ce.record.fly_over

    def closest(t):
        return float(np.min(_dist_m(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(),
                                    t.lat_deg, t.lon_deg)))
    assert closest(yn.termination) < 30.0
    # the fly-by fix DEEZZ (a turn of about 90°) is cut by the turn: passed well inside it
    assert closest(ce.termination) > 300.0


def test_df_after_the_end_of_vectors_turns_from_that_point_to_the_fix(db):
    """DEEZZ5 RW31L: after the VM vectors end (a point, not a fix to cut), the DF leg is a turn
    from there and then the line to DEEZZ, tracked within the goal."""
    res, fp = flown(db, "KJFK", "DEEZZ5", runway="31L", transition="CANDR")
    df = res.df
    k = next(i for i, lg in enumerate(fp.seq.legs) if lg.path_term == "DF")
    assert fp.seq.legs[k - 1].path_term == "VM"
    dfl = df[df["leg_index"] == k]
    roles = list(dict.fromkeys(dfl["seg_role"]))
    assert roles[0] == "turn" and "leg" in roles
    assert dfl["nav_xtk_m"].abs().max() < 0.1 * NM


def test_vr_leg_ends_when_the_radial_is_crossed(db):
    """KDLS DALLS1 RW13 starts with VR (heading to a radial): the leg ends in flight when the
    aircraft's bearing from the navaid crosses the coded radial."""
    from fms_testbed.core.geodesy import inverse

    res, fp = flown(db, "KDLS", "DALLS1", runway="13")
    t = fp.path.legs[0].termination
    assert fp.path.legs[0].path_term == "VR" and t.kind == "radial"
    ev = [e for e in res.summary["guidance_events"] if e["kind"] == "condition" and e["leg"] == 0]
    assert ev and "radial" in ev[0]["detail"]
    row = res.df[res.df["t_s"] >= ev[0]["t_s"] - 1e-6].iloc[0]
    _, az, _ = inverse(t.navaid_lat_deg, t.navaid_lon_deg, row["lat_deg"], row["lon_deg"])
    assert abs((az - t.radial_deg + 180.0) % 360.0 - 180.0) < 0.5


def test_pde_is_zero_on_tf_and_the_radius_difference_on_rf(db):
    """PDE of TF legs (built geodesic = coded geodesic) is ~0; on RF legs it is the distance of
    the built arc (through the database fixes) from the coded centre/radius, within the
    monitor's RF tolerance (0.05 NM); undefined (None) on the IF."""
    res, _ = flown(db, "KBFI", "H14RZ", transition="ZUVEN")
    rows = {r["leg"]: r for r in res.summary["errors"]["per_leg"]}
    tf = [r for r in rows.values() if r["code"] == "TF" and r["samples"]]
    rf = [r for r in rows.values() if r["code"] == "RF"]
    assert tf and all(r["pde_max_m"] is not None and r["pde_max_m"] < 0.5 for r in tf)
    assert rf and all(r["pde_max_m"] is not None and r["pde_max_m"] < 0.05 * NM for r in rf)
    assert rows[1]["code"] == "IF" and rows[1].get("pde95_m") is None


def test_ha_hold_is_left_over_the_fix_once_the_altitude_is_reached(db):
    """KENV ENV1 RW08 ends with HA at BVL (hold to 9000 ft): the aircraft reaches the altitude
    during the entry, but an HA is left over its fix at the end of a circuit, not of the entry
    (issue 12: it used to leave right after the entry, no circuit flown)."""
    from fms_testbed.evaluation.flight_errors import _dist_m

    res, fp = flown(db, "KENV", "ENV1", runway="08")
    _completed(res)
    ha = fp.path.legs[-1]
    assert ha.path_term == "HA"
    on_ha = res.df[res.df["leg_index"] == ha.index]
    assert "turn" in set(on_ha["seg_role"]) and "hold" in set(on_ha["seg_role"])
    end = res.df.iloc[-1]
    assert end["alt_m"] >= ha.termination.alt_m - 50 * FT_M
    assert _dist_m(end["lat_deg"], end["lon_deg"], ha.termination.lat_deg,
                   ha.termination.lon_deg) < 300.0
    assert on_ha["nav_xtk_m"].abs().max() <= 0.1 * NM


def test_heading_legs_are_left_out_of_the_path_error_statistics(db):
    """VM (vectors) in DEEZZ5 RW31L is a heading with no defined ground track: its straight
    samples are flagged and excluded from FTE/TSE and RNP containment."""
    res, _ = flown(db, "KJFK", "DEEZZ5", runway="31L", transition="CANDR")
    e = res.summary["errors"]
    vm = next(r for r in e["per_leg"] if r["code"] == "VM")
    assert e["heading_leg_samples"] >= vm["samples"] > 0
    assert vm["fte95_m"] is None and vm["rnp_contained"] is None
    assert (res.df.loc[res.df["leg_code"] == "VM", "heading_leg"] == 1).all()


def test_demo_sid_flies_with_a_finite_pde_on_its_cf_leg():
    """Issue 10: PDE on CF legs raised UnboundLocalError, hidden as NaN by a broad except.
    DEEZZ5 RW31L (demo-sid.yaml), from the departure end of the runway: planned at the
    climb-out speed, the CF to SKORR is joined on its coded course and its own line (the
    part between the turns) is flown with a finite PDE equal to that line's offset from the
    coded course (nil: it is built on it); the turns and the fly-by arcs are transitions (NaN)."""
    import fms_testbed
    from pathlib import Path
    from fms_testbed.legs.construct import _foot

    scn = Path(__file__).resolve().parents[2] / "scenarios" / "demo-sid.yaml"
    res = fms_testbed.run_scenario(scn, out_dir=None, plots=False)
    df = res.df
    cf = df[df["leg_code"] == "CF"]
    own = cf.loc[cf["seg_role"] == "leg", "pde_m"].to_numpy()
    assert own.size > 10 and np.isfinite(own).all()
    fp = res.procedure.path
    line = next(s.geom for s in fp.path.segments if s.path_term == "CF" and s.role == "leg")
    rec = next(lg for lg in fp.path.legs if lg.path_term == "CF")
    from fms_testbed.path.segmentation import resolve_legs
    crs = resolve_legs(res.procedure.db, fp.seq)[0][rec.index].course_true_deg
    t = rec.termination
    offset = max(abs(_foot(t.lat_deg, t.lon_deg, crs, *line.point_at(line.length_m() * k / 4))[1])
                 for k in range(5))
    assert own.max() == pytest.approx(offset, rel=1e-3, abs=0.5)
    assert own.max() < 1.0                  # on the coded course, not flown direct off it
    assert cf.loc[cf["seg_role"].isin(["flyby", "turn"]), "pde_m"].isna().all()


def test_pde_is_logged_on_a_flown_hold_circuit(db):
    """2R6 R18 JEBTA starts with an HF at JEBTA, entered over the fix on its inbound course:
    the circuit flown is the coded racetrack (PDE finite, millimetres)."""
    res, _ = flown(db, "2R6", "R18", transition="JEBTA")
    _completed(res)
    hf = res.df[res.df["leg_code"] == "HF"]
    circuit = hf.loc[hf["seg_role"].isin(["leg", "hold"]), "pde_m"].to_numpy()
    assert circuit.size > 1000 and np.isfinite(circuit).all()
    assert circuit.max() < 0.01
