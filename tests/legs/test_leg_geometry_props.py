"""Property tests (hypothesis) of the geometric invariants on random synthetic procedures:
consecutive segments meet, fix legs end at their fix (fly-over: over it; fly-by: within the turn
anticipation), RF radius and turn direction as coded, fly-by turns turn the short way."""

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fms_testbed.evaluation.check import invariants
from fms_testbed.procedures.database import load_database
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.synth import (airport_record, leg_record, offset, waypoint_record,
                                        write_file)
from fms_testbed.core.segments import Arc
from fms_testbed.core.geodesy import inverse, wrap180
from fms_testbed.core.units import NM_M
from tests.path.test_world import PARAMS, PERF

SETTINGS = settings(max_examples=40, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def _build(tmp, recs):
    db = load_database(write_file(tmp / "p.dat", recs))
    seq = db.sequences("XPRP")[0]
    return check_path(build_sequence(db, seq, PERF, PARAMS), PERF, PARAMS)


legs_st = st.lists(st.tuples(st.floats(-150.0, 150.0), st.floats(3.0, 30.0), st.booleans()),
                   min_size=2, max_size=6)


@SETTINGS
@given(lat=st.floats(-60.0, 60.0), lon=st.floats(-170.0, 170.0), crs=st.floats(0.0, 360.0),
       legs=legs_st)
def test_tf_chains_meet_and_end_at_their_fixes(tmp_path_factory, lat, lon, crs, legs):
    tmp = tmp_path_factory.mktemp("tf")
    recs = [airport_record("XPRP", lat, lon)]
    pts = [(lat, lon)]
    course = crs
    for turn, dist_nm, _ in legs:
        course = (course + turn) % 360.0
        pts.append(offset(*pts[-1], course, dist_nm))
    for k, p in enumerate(pts):
        recs.append(waypoint_record(f"P{k:03d}", *p))
    recs.append(leg_record("XPRP", "R01", "IF", 10, fix="P000"))
    for k, (_, _, over) in enumerate(legs, 1):
        recs.append(leg_record("XPRP", "R01", "TF", 10 * (k + 1), fix=f"P{k:03d}",
                               desc="EY  " if over else "E   "))
    path = _build(tmp, recs)
    inv = invariants(path)
    assert inv.max_gap_m <= 1.0
    assert inv.fix_excess_m <= 0.0
    segs = path.segments
    for k, seg in enumerate(segs):
        if seg.role == "flyby" and 0 < k < len(segs) - 1:
            # the fly-by arc turns the short way, by the track change between its neighbours
            change = wrap180(segs[k + 1].geom.start_course_deg - segs[k - 1].geom.end_course_deg)
            assert abs(seg.geom.sweep_deg - change) < 0.5
            assert abs(seg.geom.sweep_deg) <= PARAMS.flyby_max_deg + 1.0


@SETTINGS
@given(lat=st.floats(-60.0, 60.0), lon=st.floats(-170.0, 170.0), r_nm=st.floats(1.0, 6.0),
       start=st.floats(0.0, 360.0), sweep=st.floats(10.0, 300.0), right=st.booleans())
def test_rf_arcs_keep_the_coded_radius_direction_and_end_fix(tmp_path_factory, lat, lon, r_nm,
                                                             start, sweep, right):
    tmp = tmp_path_factory.mktemp("rf")
    centre = (lat, lon)
    a = offset(*centre, start, r_nm)
    b = offset(*centre, start + (sweep if right else -sweep), r_nm)
    tangent = start + (90.0 if right else -90.0)
    before = offset(*a, tangent + 180.0, 5.0)
    recs = [airport_record("XPRP", lat, lon), waypoint_record("P000", *before),
            waypoint_record("P001", *a), waypoint_record("P002", *b),
            waypoint_record("CTR", *centre),
            leg_record("XPRP", "R01", "IF", 10, fix="P000"),
            leg_record("XPRP", "R01", "TF", 20, fix="P001"),
            leg_record("XPRP", "R01", "RF", 30, fix="P002", turn="R" if right else "L",
                       centre="CTR", arc_radius_nm=r_nm)]
    path = _build(tmp, recs)
    inv = invariants(path)
    assert inv.max_gap_m <= 1.0 and inv.fix_excess_m <= 0.0
    assert inv.rf_radius_err_m <= 0.05 * NM_M and inv.turn_mismatch == 0
    rf = [s.geom for s in path.segments if s.path_term == "RF" and isinstance(s.geom, Arc)]
    assert len(rf) == 1
    assert abs(abs(rf[0].sweep_deg) - sweep) < 0.05
    assert inverse(*rf[0].end, *b)[0] < 0.5
