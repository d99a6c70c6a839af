"""Issue 12, classes A-I flown closed loop (737, truth navigation): real procedures of the FAA
cycle 2301 that failed before, and synthetic records where the cycle has no example.

The CIFP is loaded once for the module and each procedure flown once (module cache); the
module is skipped, with the reason, when the CIFP is not beside the repository. Goals are the
issue's: FTE95 ≤ 150 m and max FTE ≤ 185 m, coded constraints within 50 ft / 5 kt.
"""

from __future__ import annotations


import numpy as np
import pytest

from fms_testbed.core.units import FT_M as FT
from fms_testbed.core.units import NM_M as NM
from fms_testbed.loop.procedure import prepare
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.procedures.synth import offset, waypoint_record, write_file
from fms_testbed.run import fly_procedure
from tests.path.test_world import base_records, world

FTE95_GOAL_M = 150.0
FTE_MAX_GOAL_M = 0.1 * NM



_CACHE: dict = {}


def fly(db, airport, procedure, transition=None, runway=None, wind_kt=None, aircraft="737"):
    key = (id(db), airport, procedure, transition, runway, wind_kt, aircraft)
    if key not in _CACHE:
        proc = {"airport": airport, "procedure": procedure}
        if transition:
            proc["transition"] = transition
        if runway:
            proc["runway"] = runway
        raw = {"aircraft": aircraft, "procedure": proc}
        if wind_kt:
            raw["wind"] = {"from_deg": 270.0, "speed_kt": wind_kt}
        scn, spec, fp, d = prepare(raw, db=db)
        _CACHE[key] = (fly_procedure(scn, spec, fp, d, progress=False, plots=False), fp)
    return _CACHE[key]


def within_goals(res):
    s = res.summary
    assert s["sequencing"]["completed"], s["reason"]
    e = s["errors"]["fte"]["all"]
    assert e["p95_m"] <= FTE95_GOAL_M and e["max_m"] <= FTE_MAX_GOAL_M, e
    return e


def test_A_if_af_approach_flies_the_arc_not_90_deg_off_it(cifp):
    """12J VOR/DME 30 via ITNEW (IF → AF): FTE95 3.0 km before (start 90° off the arc)."""
    res, fp = fly(cifp, "12J", "D30", "ITNEW")
    within_goals(res)
    af = res.df[res.df["leg_code"] == "AF"]
    assert len(af) > 100 and af["nav_xtk_m"].abs().max() < 30.0
    assert res.summary["status"] == "ok", res.summary["reason"]


def test_B_procedure_turn_ends_on_the_final_course(cifp):
    """PAFA VOR 20R via CUN: the PI flown as coded joins the inbound CF on its course (before:
    refused as impossible, and the PI ~11 km beside the final)."""
    res, fp = fly(cifp, "PAFA", "S20R", "CUN")
    within_goals(res)
    assert res.summary["status"] == "ok", res.summary["reason"]
    cf = res.df[(res.df["leg_code"] == "CF") & (res.df["seg_role"] == "leg")]
    assert np.nanmax(cf["pde_m"].to_numpy()) < 50.0


def test_C_rf_71_m_off_the_previous_fix_is_flown_without_a_direct_to(tmp_path):
    """Synthetic: a 3 NM RF whose end fix is 71 m farther from the centre than the previous
    fix (the cycle has none this large): closed in the geometry, the aircraft stays on the arc
    (a connector ≥ 50 m used to be flown as a direct-to: 1.8 km outside the RF)."""
    w = world()
    centre = offset(*w["WB"], 0.0, 3.0)
    c = offset(*centre, 90.0, 3.0 + 71.0 / NM)
    d = offset(*c, 0.0, 8.0)

    def app(pt, seq, **kw):
        return L("XTST", "R09", pt, seq, proc_type="F", transition="", route_type="R", **kw)

    legs = [app("IF", 10, fix="WA", alt_desc="+", alt1_ft=4000), app("TF", 20, fix="WB"),
            app("RF", 30, fix="WC", turn="L", centre="CTR", arc_radius_nm=3.0),
            app("TF", 40, fix="WD")]
    f = write_file(tmp_path / "c.dat", base_records() + [
        waypoint_record("WC", *c), waypoint_record("CTR", *centre), waypoint_record("WD", *d)]
        + legs)
    db = load_database(f)
    res, fp = fly(db, "XTST", "R09")
    e = within_goals(res)
    rf = res.df[res.df["leg_code"] == "RF"]
    assert len(rf) > 50 and rf["nav_xtk_m"].abs().max() < 30.0
    assert not [s for s in fp.path.segments if s.role == "connector"]
    assert e["max_m"] < 50.0


def test_D_sid_with_runway_and_en_route_transition_starts_on_the_runway(cifp):
    """KCLT KILNS4 RW18C + AUDII: the merged name 'RW18C+AUDII' found its runway: the flight
    starts 35 ft above the threshold (before: at the VA's altitude)."""
    res, fp = fly(cifp, "KCLT", "KILNS4", "AUDII", "18C")
    within_goals(res)
    rwy = cifp.terminal[("KCLT", "RW18C")][0]
    assert res.df["alt_m"].iloc[0] == pytest.approx(rwy.elev_m + 35 * FT, abs=15.0)
    assert res.summary["procedure"]["start"] == "runway"


def test_E_direct_to_after_vectors_has_its_fly_by(cifp):
    """KBCT MYZNR2 RW05: VM, then the direct-to JAVAA 17.7 NM away, then TF CONAS: no
    overshoot at JAVAA (83-253 m before)."""
    res, fp = fly(cifp, "KBCT", "MYZNR2", runway="05")
    within_goals(res)
    near = res.df[res.df["leg_index"].isin([2, 3])]
    assert near["nav_xtk_m"].abs().max() < 30.0


def test_F_at_or_below_cap_holds_until_its_fix_is_passed(cifp):
    """KDEN BAYLR6 RW17L: BRKEM at or below 10,000 ft, then higher climbs: crossed 82 ft above
    before (the climb command was lifted up to ~20 s before the fix)."""
    res, fp = fly(cifp, "KDEN", "BAYLR6", runway="17L")
    within_goals(res)
    brkem = next(c for c in res.summary["constraints"] if c["fix"] == "BRKEM")
    assert brkem["ok"] and brkem["alt_ft"] <= 10000 + 50


def test_G_descent_meets_the_coded_final_path(cifp):
    """PAFA VOR 20R via CUN: refused before (the planner stayed high: 16.2 %); now every coded
    constraint is met, the MAP ILTAF within 50 ft on the coded 3.26° path."""
    res, fp = fly(cifp, "PAFA", "S20R", "CUN")
    assert res.summary["constraints_met"], [c for c in res.summary["constraints"]
                                            if c.get("ok") is False]
    iltaf = next(c for c in res.summary["constraints"] if c["fix"] == "ILTAF")
    assert abs(iltaf["alt_ft"] - 748) <= 50


def test_H_sid_joined_at_a_fix_flies_its_climb_constraints(cifp):
    """3R9 AEROZ2 via SJT without a runway: the common route starts at AMUSE (+5,000 ft); the
    flight starts there at a climb altitude, meets every constraint and reports ok."""
    res, fp = fly(cifp, "3R9", "AEROZ2", "SJT")
    within_goals(res)
    assert res.summary["status"] == "ok", res.summary["reason"]
    assert res.df["alt_m"].iloc[0] >= 5000 * FT - 50 * FT


@pytest.mark.parametrize("wind_kt", [0, 30])
def test_I_hold_to_altitude_stays_within_the_goal_in_wind(cifp, wind_kt):
    """KENV ENV1 RW08 ends in an HA at BVL: its turns are planned for the ground speed and the
    heading legs for their drift, so in a 30 kt wind the hold's max FTE stays within the goal
    (293 m at the 25° bank limit before)."""
    res, fp = fly(cifp, "KENV", "ENV1", runway="08", wind_kt=wind_kt or None)
    e = within_goals(res)
    ha = res.df[res.df["leg_code"] == "HA"]
    assert ha["nav_xtk_m"].abs().max() < 50.0
    assert res.df["bank_deg"].abs().max() < 25.5 if "bank_deg" in res.df else e


def test_I_heading_legs_drift_is_predicted_in_wind(cifp):
    """KBCT MYZNR2 RW05 in a 30 kt wind: the VA/VM headings drift; planned for the drift, the
    direct-to after them starts where the aircraft is (FTE95 608 m before)."""
    res, fp = fly(cifp, "KBCT", "MYZNR2", runway="05", wind_kt=30)
    within_goals(res)


def test_rebuild_in_a_turn_starts_after_the_roll_out(cifp):
    """KHLN DIVD1 RW09 (CA VI FA DF): the FA's altitude is met while the aircraft still banks
    left on the VI, and the DF is rebuilt from there. Rebuilt from the present track with a
    wings-level roll-in, the aircraft rolled through the reversal 205 m outside the DF turn
    (FTE95 150 m); started where the roll-out ends (guidance/replan.roll_out_state), the
    turn is flown on its path."""
    res, fp = fly(cifp, "KHLN", "DIVD1", runway="09")
    e = within_goals(res)
    assert e["max_m"] < 100.0, e
    assert res.summary["status"] == "ok", res.summary["reason"]


def test_sid_joined_at_an_at_fix_starts_at_its_altitude(cifp):
    """KAPA ECHOO1 RW35B (runway part 'B' for both runways, first leg IF BAPME 'at 8,000 ft',
    the transition altitude 18,000 ft in the same record): the start was capped only by 'at or
    below' windows and joined BAPME at the 18,000 ft cap, 10,000 ft above its window."""
    res, fp = fly(cifp, "KAPA", "ECHOO1", "SHAYK", runway="35B")
    within_goals(res)
    assert abs(fp.path.legs[0].start.alt_m - 8000 * FT) < 1.0
    assert res.summary["status"] == "ok", res.summary["reason"]


def test_cf_from_a_fix_just_off_its_course_turns_onto_it_as_a_fly_by(cifp):
    """KBIS ILS 31 via YIRNU (AF → IF WIGAG → CF ICONO): WIGAG lies 133 m beside the 311°
    course into ICONO. The CF intercepted it with a 702 m S-turn; the 83° turn off the arc
    found no room for its fly-by on that, was flown over WIGAG and looped back: 747 m max FTE,
    not contained in RNP 0.3. Flown as the line WIGAG → ICONO (legs/builder.CF_FROM_FIX_DEG)
    the turn is a fly-by off the arc."""
    res, fp = fly(cifp, "KBIS", "I31", "YIRNU")
    e = within_goals(res)
    assert e["max_m"] < 50.0, e
    assert not [f for f in fp.path.findings if "does not fit" in f.message]
    assert res.summary["status"] == "ok", res.summary["reason"]


@pytest.mark.parametrize("airport, procedure, transition, runway", [
    ("KTMB", "BNFSH2", "HOAGG", None),     # slows 280 → 230 kt after GELDE: ENRGY was 551 ft high
    ("KDEN", "FLATI3", "MJANE", "RW25"),   # slows to @210 kt for CAPTJ 'at' 11,000: 59 ft high
    ("KDCA", "TRUPS4", "BKW", "RW01"),     # WEEDU 521 ft high; TRUPS 'at' in a steeper descent
    ("KBOI", "KOURT4", "DERSO", "RW10B"),  # KOLKE 'at or below' 60 ft high (the blend)
])
def test_star_constraints_met_when_it_slows_down_and_at_knees(cifp, airport, procedure,
                                                              transition, runway):
    """STAR descents planned within the energy the aircraft can shed while it slows down
    (path/profile.plan_profile) and blended profiles that pass each constrained fix at its
    planned altitude (guidance/vertical.knees_clear_of_windows): every coded constraint met."""
    res, _ = fly(cifp, airport, procedure, transition, runway)
    s = res.summary
    missed = [c for c in s["constraints"] if c.get("ok") is False]
    assert not missed, missed
    assert s["status"] == "ok", s["reason"]


def test_circling_map_coded_at_the_field_elevation_is_checked_at_the_circling_floor(cifp):
    """KBIS VOR-A: the MAP WINFY is coded 'at' 1,661 ft, the field elevation; the flight levels
    at the circling floor (field + 591 ft) and is checked there, not reported 583 ft high."""
    from fms_testbed.evaluation.flight_errors import constraint_checks, error_columns

    res, fp = fly(cifp, "KBIS", "VOR-A", "BIS")
    row = next(c for c in res.summary["constraints"] if c["fix"] == "WINFY")
    elev_ft = cifp.airports["KBIS"].elev_m / FT
    assert row["floor_ft"] == pytest.approx(elev_ft + 591, abs=1)
    assert row["ok"] is True and abs(row["alt_ft"] - row["floor_ft"]) <= 50
    plain = next(c for c in constraint_checks(error_columns(res.df), fp) if c["fix"] == "WINFY")
    assert plain["ok"] is False and "floor_ft" not in plain


def test_fix_followed_by_a_hold_at_it_is_checked_at_its_first_passage(cifp):
    """KRST I31-Z RST: TF MINGO 'at or above' 2,900 ft, then the hold-in-lieu HF at MINGO
    descending to 2,800 ft. The check used to take the sample nearest MINGO among the legs
    around it — the hold's return a circuit later, at 2,799 ft — and report 101 ft below."""
    res, _ = fly(cifp, "KRST", "I31-Z", "RST")
    rows = [c for c in res.summary["constraints"] if c["fix"] == "MINGO"]
    assert [c["code"] for c in rows] == ["TF", "HF"]
    assert rows[0]["ok"] is True and rows[0]["alt_ft"] >= 2900 - 50, rows[0]
    assert rows[1]["ok"] is True, rows[1]


@pytest.mark.parametrize("wind_from_deg", [330.0, 165.0])
def test_final_approach_in_along_track_wind_crosses_at_the_tch(cifp, wind_from_deg):
    """KCHA S33 (VPA 3.43°, TCH 47 ft) in a 30 kt headwind and tailwind: the altitude lead is
    on the TAS (the law's lag is air-relative); with the ground speed the tailwind flight
    crossed 45 ft low and touched down at the threshold (``diverged``)."""
    proc = {"airport": "KCHA", "procedure": "S33"}
    raw = {"aircraft": "737", "procedure": proc,
           "wind": {"from_deg": wind_from_deg, "speed_kt": 30.0}}
    scn, spec, fp, d = prepare(raw, db=cifp)
    res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    s = res.summary
    assert s["status"] == "ok", s["reason"]
    thr = s["procedure"].get("threshold") or s.get("threshold")
    assert thr is not None, list(s)
    assert abs(thr["height_ft"] - thr["tch_ft"]) <= 10, thr


@pytest.mark.parametrize("airport, procedure, transition, runway", [
    ("KMFR", "GNATS7", "HANDY", "RW14"),   # SID: the default 15,000 ft climb top
    ("KAEG", "CURLY3", "GUP", None),       # STAR without altitudes: field + 10,000 ft start
])
def test_planner_choices_stay_below_the_ceiling(cifp, airport, procedure, transition, runway):
    """The C172P (13,500 ft ceiling): a climb top and an uncoded arrival start chosen by the
    planner stay CEILING_MARGIN_M below it (both flights were envelope_exceeded)."""
    from fms_testbed.config.aircraft import load_aircraft
    from fms_testbed.legs.model import CEILING_MARGIN_M

    res, fp = fly(cifp, airport, procedure, transition, runway, aircraft="c172p")
    s = res.summary
    assert s["status"] == "ok", s["reason"]
    ceiling_m = load_aircraft("c172p").limits.alt_max_m
    assert res.df["alt_m"].max() <= ceiling_m - CEILING_MARGIN_M + 30.0


@pytest.mark.parametrize("airport, procedure, transition, wind_from_deg", [
    ("KSBY", "L32", "SWL", 204.0),     # FC → CF FRYER: fly-by planned for 167 kt in the wind
    ("KSUS", "L08R", "FTZ", 308.9),
])
def test_fly_by_slowed_for_in_a_tailwind_is_flown_within_the_goal(cifp, airport, procedure,
                                                                  transition, wind_from_deg):
    """A fly-by the monitor slowed down for its tailwind (speed correction): guidance caps the
    TAS ahead of the arc at its ground-speed limit less the measured wind
    (speed_plan.arc_speed_cap_mps). With the calm-air cap the 737 flew the KSBY arc at the bank
    limit 309 m wide (FTE95 202 m); KSUS L08R 243 m."""
    proc = {"airport": airport, "procedure": procedure, "transition": transition}
    raw = {"aircraft": "737", "procedure": proc,
           "wind": {"from_deg": wind_from_deg, "speed_kt": 30.0}}
    scn, spec, fp, d = prepare(raw, db=cifp)
    res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    within_goals(res)


@pytest.mark.parametrize("airport, procedure, transition, runway, wind_from_deg, rebuilt", [
    # VI: drifted 0.9° off the prediction (2.3 km) under the earlier climb planning; with the
    # one climb planner inside the envelope its drift stays within the threshold (no rebuild)
    ("KPHX", "BALDY3", "CNX", "RW07L", 272.4, False),
    ("KDHN", "I14", "SKIPO", None, 136.4, True),       # initial VI in the wind ramp: 215 m
])
def test_heading_leg_that_drifts_off_its_prediction_is_rebuilt_in_flight(
        cifp, airport, procedure, transition, runway, wind_from_deg, rebuilt):
    """A heading leg more than HEADING_DRIFT_REBUILD_M off the track its planned drift
    predicted is rebuilt from the present position, so its intercept starts where the aircraft
    is (guidance.fms.ProcedureGuidance._heading_drifted): KPHX BALDY3 was not_contained (max FTE
    2,311 m at the VI's intercept), KDHN I14 215 m."""
    proc = {"airport": airport, "procedure": procedure, "transition": transition}
    if runway:
        proc["runway"] = runway
    raw = {"aircraft": "737", "procedure": proc,
           "wind": {"from_deg": wind_from_deg, "speed_kt": 30.0}}
    scn, spec, fp, d = prepare(raw, db=cifp)
    res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
    within_goals(res)
    assert res.summary["status"] == "ok", res.summary["reason"]
    assert rebuilt == any(e["kind"] == "rebuild" and "heading leg" in e.get("detail", "")
                          for e in res.summary["guidance_events"])
