"""Path definition error per leg type, on built paths: real records from the embedded CIFP
excerpt where the type occurs there, synthetic records (procedures.synth) otherwise.

PDE = the largest distance of a segment's points from the path its record codes
(guidance/pde.py). Each expected value is computed here from the record's fields and the
database's fix positions, not from the PDE code.
"""

from __future__ import annotations

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import NM_M
from fms_testbed.guidance.pde import SCORED_ROLES, segment_pde_m
from fms_testbed.legs.model import Performance
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.procedures.synth import offset, waypoint_record
from tests.path.test_world import build, world


@pytest.fixture(scope="module")
def db():
    return load_database()


@pytest.fixture(scope="module")
def perf():
    return Performance.from_aircraft(load_aircraft("737"))


def real(db, perf, name):
    airport = name.split()[0]
    seq = next(s for s in db.sequences(airport) if s.name == name)
    return build_sequence(db, seq, perf)


def app(pt, seq, **kw):
    return L("XTST", "T09", pt, seq, proc_type="F", **kw)


def sid(pt, seq, **kw):
    return L("XTST", "TSID1", pt, seq, proc_type="D", transition="RW09", route_type="1", **kw)


def pde_of(path, code):
    """(PDE of every segment of the legs of type ``code``, their roles), m."""
    segs = [s for s in path.segments if s.path_term == code]
    assert segs, f"no {code} segment"
    return [segment_pde_m(s, path.legs[s.leg_index]) for s in segs], [s.role for s in segs]


def scored(path, code):
    vals, roles = pde_of(path, code)
    out = [v for v, r in zip(vals, roles) if r in SCORED_ROLES]
    assert out and all(math.isfinite(v) for v in out), (code, vals, roles)
    return out


# --------------------------------------------------------------------------- TF, CF
def test_tf_pde_is_zero_on_the_track_between_the_fixes(db, perf):
    p = real(db, perf, "KJFK APPROACH R04RY")
    assert max(scored(p, "TF")) < 0.01


def test_cf_whose_course_is_3_deg_off_the_fixes_bearing_is_intercepted_not_flown_direct(tmp_path):
    """A CF whose coded course is 3° off the bearing from the previous fix (d·sin 3° ≈ 1.4 km
    off at WA) is intercepted: the CF's own straight lies on the coded course (PDE below a
    metre) and the way onto it is a transition (role 'turn'), instead of a direct line as far
    off the coded course as the old "within 5°, fly direct" rule built."""
    w = world()
    d, az1, az2 = inverse(*w["WA"], *w["WB"])
    p = build(tmp_path, [app("IF", 10, fix="WA"),
                         app("CF", 20, fix="WB", course_deg=az2 + 3.0)],  # no variation here
              checked=False)
    assert max(scored(p, "CF")) < 1.0
    assert any(s.role == "turn" for s in p.segments if s.path_term == "CF")
    assert d * math.sin(math.radians(3.0)) > 1000.0


def test_cf_pde_on_a_real_intercepted_course_is_small(db, perf):
    """KBFI KENT8 RW14L: VI intercepts the CF course, which is then flown into the fix."""
    p = real(db, perf, "KBFI SID KENT8 RW14L")
    assert max(scored(p, "CF")) < 1.0


# --------------------------------------------------------------------------- RF, AF
def test_rf_pde_is_the_difference_between_the_fixes_radius_and_the_coded_one(tmp_path):
    w = world()
    centre = offset(*w["WB"], 0.0, 2.0)
    c = offset(*centre, 90.0, 2.0)
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("RF", 30, fix="WC", turn="L", centre="CTR", arc_radius_nm=2.2)],
              extra=[waypoint_record("WC", *c), waypoint_record("CTR", *centre)])
    assert max(scored(p, "RF")) == pytest.approx(0.2 * NM_M, abs=1.0)


def test_rf_pde_on_real_arcs_is_within_the_monitor_tolerance(db, perf):
    p = real(db, perf, "KBFI APPROACH H14RZ")
    assert max(scored(p, "RF")) < LEG_TYPES["RF"].radius_tol_m


@pytest.mark.parametrize("name", ["KFXY APPROACH VOR-A", "PABE APPROACH I19RZ ROLLR"])
def test_af_pde_is_the_fix_range_minus_rho(db, perf, name):
    """The DME arc is flown at the fix's range from the DME; the coded arc is at rho."""
    p = real(db, perf, name)
    lg = next(lg for lg in p.legs if lg.path_term == "AF")
    n = db.find_fix(lg.record.navaid, p.airport)
    dme = (n.dme_lat_deg, n.dme_lon_deg) if n.dme_lat_deg is not None else (n.lat_deg, n.lon_deg)
    r_fix = inverse(*dme, lg.termination.lat_deg, lg.termination.lon_deg)[0]
    assert max(scored(p, "AF")) == pytest.approx(abs(r_fix - lg.record.rho_m), abs=0.01)


# --------------------------------------------------------------------------- F* courses
@pytest.mark.parametrize("name, code", [("KJFK APPROACH I22L DPK", "FC"),
                                        ("2R6 APPROACH VDM-A", "FA"),
                                        ("KBFI SID CBAIN1 RW32L", "FM")])
def test_course_from_the_fix_pde_is_zero_when_flown_from_over_the_fix(db, perf, name, code):
    p = real(db, perf, name)
    assert max(scored(p, code)) < 0.01


def test_fd_pde_is_zero_on_the_course_from_the_fix(tmp_path):
    """FD never occurs in FAA data: synthetic, from WB east to 12 NM from the VOR TVR."""
    p = build(tmp_path, [app("IF", 10, fix="WA"), app("TF", 20, fix="WB"),
                         app("FD", 30, fix="WB", course_deg=90.0, navaid="TVR",
                             distance_nm=12.0)])
    assert max(scored(p, "FD")) < 0.01


def test_course_from_the_fix_after_a_turn_at_the_fix_rejoins_the_coded_course(db, perf):
    """PAFA HRDNG3 RW20R (issue 12): the FM turns ~46° over HISKA. Flown on from the end of
    that turn its straight lay R (1 − cos Δ) ≈ 1.4 km beside the coded course out of HISKA; it
    now rejoins the coded course line (intercept + fly-by), so its PDE is that of the course
    line itself."""
    p = real(db, perf, "PAFA STAR HRDNG3 RW20R")
    turn = next(s.geom for s in p.segments if s.path_term == "FM" and s.geom.kind == "arc")
    offset_if_parallel = turn.radius_m * (1.0 - math.cos(math.radians(46.0)))
    assert offset_if_parallel > 1000.0
    assert max(scored(p, "FM")) < 30.0


# --------------------------------------------------------------------------- holds
HOLDS = [("HM", {"distance_nm": 4.0}), ("HF", {"time_min": 1.0}),
         ("HA", {"time_min": 1.0, "alt_desc": "+", "alt1_ft": 9000})]


def _hold(tmp_path, code, extra, to_fix, course_deg):
    maker = sid if code == "HA" else app
    return build(tmp_path, [maker("IF", 10, fix="WA"), maker("TF", 20, fix=to_fix),
                            maker(code, 30, fix=to_fix, turn="R", course_deg=course_deg,
                                  **extra)])


@pytest.mark.parametrize("code, extra", HOLDS)
def test_hold_circuits_entered_on_the_inbound_course_lie_on_the_racetrack(tmp_path, code,
                                                                         extra):
    """TF WA -> WN runs due north along the meridian; the hold at WN has inbound course 000."""
    vals = scored(_hold(tmp_path, code, extra, "WN", 0.0), code)
    assert len(vals) >= 4 and max(vals) < 0.05


@pytest.mark.parametrize("code, extra", HOLDS)
def test_a_hold_entered_off_its_inbound_course_is_rotated_by_that_angle(tmp_path, code, extra):
    """TF WA -> WB arrives at WB on the geodesic's azimuth, Δ ≈ 0.1° off the coded inbound
    090: the circuit flown from that track is the racetrack turned by Δ about the fix, whose
    turn centres lie 2 R sin(Δ/2) from the coded ones — the PDE of the turns."""
    w = world()
    arrive = inverse(*w["WA"], *w["WB"])[2]
    p = _hold(tmp_path, code, extra, "WB", 90.0)
    r = next(s.geom.radius_m for s in p.segments if s.role == "hold")
    delta = math.radians(abs(arrive - 90.0))
    assert 0.05 < math.degrees(delta) < 0.2
    assert max(scored(p, code)) == pytest.approx(2 * r * math.sin(delta / 2), rel=2e-3)


def test_hold_entry_is_a_transition_without_pde(db, perf):
    """KENV ENV1 RW08 ends with an HA at BVL entered by a teardrop: the way to the fix and the
    entry are role 'turn' (PDE NaN), the circuit is scored."""
    p = real(db, perf, "KENV SID ENV1 RW08")
    vals, roles = pde_of(p, "HA")
    assert roles[0] == "turn" and "hold" in roles
    assert all(math.isnan(v) for v, r in zip(vals, roles) if r == "turn")
    assert all(math.isfinite(v) for v, r in zip(vals, roles) if r in SCORED_ROLES)


# --------------------------------------------------------------------------- no coded path
@pytest.mark.parametrize("name", ["KJFK SID DEEZZ5 RW04B", "KDLS SID DALLS1 RW07",
                                  "KENV APPROACH D26 BVL"])
def test_legs_without_a_coded_path_and_transitions_have_no_pde(db, perf, name):
    """IF, DF, PI and the C*/V* legs from the present position code no path (their class says
    so); fly-by arcs, turns and connectors are transitions: PDE NaN, by design."""
    p = real(db, perf, name)
    for s in p.segments:
        v = segment_pde_m(s, p.legs[s.leg_index])
        if LEG_TYPES[s.path_term].pde_reference is None or s.role not in SCORED_ROLES:
            assert math.isnan(v), (s.path_term, s.role)
        else:
            assert math.isfinite(v), (s.path_term, s.role)
    codes = {s.path_term for s in p.segments}
    assert codes & {"DF", "VA", "CA", "VR", "PI"}
