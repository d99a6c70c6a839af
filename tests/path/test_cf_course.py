"""CF legs are flown along their coded course or the transition is impossible with the reason;
PDE is signed along a coded course; a path with a discontinuity or a loop is never ok or
corrected — on the records of the shipped cycle where the builder once flew them otherwise."""

import pytest

from fms_testbed.core.geodesy import direct, wrap180
from fms_testbed.core.segments import Line
from fms_testbed.evaluation.check import check_airport, perf_for
from fms_testbed.legs.coded import course_into, path_definition_error_m, track_between
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.monitor import CF_OFF_COURSE_DEG, check_path
from fms_testbed.path.segmentation import build_sequence

PERF = perf_for("737")

# approaches whose missed-approach CF was built backwards (coded 247.6°, built 70.0° at KMCO)
# after the fly-over rejoin, and SIDs/approaches where the CF was flown direct for want of room
REVERSED = [("KMCO", "I36R", "", "DNMOR"), ("KATL", "I28", "", "PAJVO"),
            ("KORH", "I11", "", "LAWRN")]
NO_ROOM = [("KBJC", "D30L", "", "BIZEN"), ("KSFO", "MOLEN9", "RW19B", "SIPLY"),
           ("KRDD", "KENDL4", "RW12", "KENDL")]


def _path(cifp, airport, proc, trans):
    seq = cifp.select(airport, proc, trans)[0]
    return check_path(build_sequence(cifp, seq, PERF, BuildParams()), PERF, BuildParams())


@pytest.mark.parametrize("airport, proc, trans, fix", REVERSED)
def test_a_cf_flown_against_its_course_makes_the_transition_impossible(cifp, airport, proc,
                                                                       trans, fix):
    p = _path(cifp, airport, proc, trans)
    assert p.status == "impossible"
    why = [f.message for f in p.findings if f.category == "impossible"]
    assert any(f"CF {fix} built" in m and "flown against the course" in m for m in why), why


@pytest.mark.parametrize("airport, proc, trans, fix", NO_ROOM)
def test_a_cf_reached_direct_is_never_ok(cifp, airport, proc, trans, fix):
    """Flown direct to the fix for want of room (class 1): a correction that says the coded
    course is not flown — never 'ok'."""
    p = _path(cifp, airport, proc, trans)
    assert p.status in ("corrected", "coding_suspect", "impossible")
    assert any(f"CF {fix} built" in f.message and "without flying the coded course" in f.message
               for f in p.findings if f.category == "correction")


@pytest.mark.parametrize("airport", ["KMCO", "KATL", "KDEN", "KSFO", "KDFW", "KJFK"])
def test_no_cf_straight_of_an_ok_transition_is_off_its_course(cifp, airport):
    """Every CF of every transition the monitor passes without a correction of its CF flies
    its own straights within 20° of its coded course (the course from the record, not from
    the builder), and no CF straight of a buildable transition is flown against it."""
    n = 0
    for seq in cifp.sequences(airport):
        if not any(r.path_term == "CF" for r in seq.legs):
            continue
        p = check_path(build_sequence(cifp, seq, PERF, BuildParams()), PERF, BuildParams())
        if p.status == "impossible":
            continue
        for lg in p.legs:
            if lg.path_term != "CF":
                continue
            tol = 90.0 if any("without flying the coded course" in f.message and
                              f.leg_index == lg.index for f in p.findings) else CF_OFF_COURSE_DEG
            crs = lg.record.course_deg + (0.0 if lg.record.course_true else lg.resolved.magvar_deg)
            for s in p.segments:
                if s.leg_index == lg.index and s.role == "leg" and s.geom.kind == "line":
                    n += 1
                    assert abs(wrap180(s.geom.end_course_deg - crs)) <= tol, \
                        (p.name, lg.index)
    assert n > 20


@pytest.mark.parametrize("airport", ["KATL", "KMCO", "KLAN", "KSFO"])
def test_paths_with_a_discontinuity_or_loop_are_never_ok_or_corrected(cifp, airport):
    rows = check_airport(cifp, airport, PERF, BuildParams())
    flagged = [r for r in rows if "discontinuity" in r["flags"] or "loop" in r["flags"]]
    assert flagged
    for r in flagged:
        assert r["status"] not in ("ok", "corrected"), (r["procedure"], r["transition"])


def test_route_resumed_after_vectors_is_the_coded_direct_to_not_a_discontinuity(cifp):
    """KBCT MYZNR2 RW05/RW23: VA VM IF TF TF, the route resumes at JAVAA after the vectors of
    the VM (a manual termination): flown direct, an 'info' finding, the transition ok."""
    rows = {r["transition"]: r for r in check_airport(cifp, "KBCT", PERF, BuildParams())
            if r["procedure"] == "MYZNR2"}
    for t in ("RW05", "RW23"):
        assert rows[t]["legs"].startswith("VA VM IF"), rows[t]["legs"]
        assert "discontinuity" not in rows[t]["flags"]
        assert rows[t]["status"] == "ok", rows[t]["findings"]
        assert "after the manual termination of VM" in rows[t]["findings"]


def test_pde_of_a_course_flown_backwards_is_its_length_not_zero():
    """A piece exactly on the coded line but flown against the course: the cross-track is 0,
    the PDE is the distance flown back along the course."""
    lat, lon = 40.0, -75.0
    coded = course_into(lat, lon, 90.0)
    a = direct(lat, lon, 270.0, 3000.0)[:2]
    forward = [a, (lat, lon)]
    backward = [(lat, lon), a]
    assert path_definition_error_m(coded, forward) == pytest.approx(0.0, abs=1e-3)
    assert path_definition_error_m(coded, backward) == pytest.approx(3000.0, rel=1e-6)
    tf = track_between(*a, lat, lon)
    assert path_definition_error_m(tf, backward) == pytest.approx(3000.0, rel=1e-6)
    assert Line(*a, lat, lon).length_m() == pytest.approx(3000.0, rel=1e-9)
