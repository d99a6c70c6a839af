"""CF legs are flown along their coded course or the transition is impossible with the reason;
PDE is signed along a coded course; a path with a discontinuity or a loop is never ok or
corrected — on the records of the shipped cycle where the builder once flew them otherwise."""

import math

import pytest

from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.geodesy import direct, inverse, wrap180
from fms_testbed.core.segments import Line
from fms_testbed.evaluation.check import check_airport, perf_for
from fms_testbed.legs.coded import course_into, path_definition_error_m, track_between
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.monitor import CF_OFF_COURSE_DEG, check_path
from fms_testbed.path.segmentation import build_sequence

PERF = perf_for("737")

# missed approaches whose VI meets the CF's course a few hundred metres before its fix: the
# builder once flew them direct and arrived against the course (coded 247.6°, built 70.0°)
NO_ROOM = [("KMCO", "I36R", "", "DNMOR"), ("KATL", "I28", "", "PAJVO"),
           ("KOXC", "I36", "", "ZATMI")]
# CFs once flown direct to the fix 44-46° off the course for want of room at the planned
# radius, in missed approaches with the approach behind to slow down in: joined at the
# minimum speed
MIN_SPEED = [("KBJC", "D30L", "", "BIZEN"), ("KBJC", "D30R", "", "BIZEN")]
# SIDs whose CF is to be joined within a few NM of the runway (the demo SID's SKORR among
# them): once flown direct 34-60° off the course at the 230 kt climb speed; planned at the
# departure's climb-out speed they are flown along it
DEPARTURE_CF = [("KJFK", "SKORR5", "RW31L", "SKORR"), ("KSFO", "MOLEN9", "RW19B", "SIPLY"),
                ("KRDD", "KENDL4", "RW12", "KENDL")]
G_MPS2 = 9.80665


def _path(cifp, airport, proc, trans):
    seq = cifp.select(airport, proc, trans)[0]
    return check_path(build_sequence(cifp, seq, PERF, BuildParams()), PERF, BuildParams())


def _coded_true_deg(lg):
    return lg.record.course_deg + (0.0 if lg.record.course_true else lg.resolved.magvar_deg)


def _min_speed_radius_m(alt_m):
    """R = V²/(g tan 25°) at the 737's minimum CAS as TAS at ``alt_m`` (independent of the
    builder: the ISA conversion and the bank limit of the paper)."""
    v = cas_to_tas_scalar(PERF.tas_min_mps, alt_m)
    return v * v / (G_MPS2 * math.tan(math.radians(25.0)))


@pytest.mark.parametrize("airport, proc, trans, fix", NO_ROOM)
def test_a_cf_with_no_room_for_its_course_makes_the_transition_impossible(cifp, airport, proc,
                                                                         trans, fix):
    """Impossible, with the reason; and the reason holds in independent geometry: the leg
    starts on the course line, nearer the fix than the turn anticipation R tan(Ω/2) of the
    turn onto the course at the minimum speed and 25° bank."""
    p = _path(cifp, airport, proc, trans)
    assert p.status == "impossible"
    why = [f for f in p.findings if f.category == "impossible"]
    assert any(f"into {fix} before the fix" in f.message and "cannot be flown" in f.message
               for f in why), [f.message for f in why]
    lg = p.legs[next(f.leg_index for f in why if fix in f.message)]
    crs = _coded_true_deg(lg)
    s, _, az2 = inverse(lg.start.lat_deg, lg.start.lon_deg, lg.resolved.fix.lat_deg,
                        lg.resolved.fix.lon_deg)
    off = math.radians(wrap180(az2 - crs))
    assert abs(s * math.sin(off)) < 50.0
    omega = abs(wrap180(crs - lg.start.track_deg))
    lead = _min_speed_radius_m(lg.start.alt_m) * math.tan(math.radians(omega) / 2.0)
    assert 0.0 < s * math.cos(off) < lead, (s, lead)


@pytest.mark.parametrize("airport, proc, trans, fix", MIN_SPEED)
def test_a_cf_with_no_room_at_the_planned_radius_is_joined_at_the_minimum_speed(
        cifp, airport, proc, trans, fix):
    """A correction of branch V,γ; the CF's own straight ends at the database fix on the
    record's course (course + variation, within 1°), and no turn of the leg needs more than
    the 25° bank at the speed it is planned for (atan(V²/(R g)))."""
    p = _path(cifp, airport, proc, trans)
    assert p.status in ("corrected", "coding_suspect")
    assert any(f.branch == "V,γ" and f"course into {fix} joined at the minimum speed"
               in f.message for f in p.findings)
    lg = next(lg for lg in p.legs if lg.path_term == "CF" and lg.record.fix.ident == fix)
    own = [s for s in p.segments if s.leg_index == lg.index]
    last = [s for s in own if s.role == "leg" and s.geom.kind == "line"][-1]
    assert abs(wrap180(last.geom.end_course_deg - _coded_true_deg(lg))) < 1.0
    f = lg.resolved.fix
    assert inverse(*last.geom.end, f.lat_deg, f.lon_deg)[0] < 1.0 or \
        lg.index + 1 < len(p.legs)   # or the fly-by into the next leg starts before it
    for s in own:
        if s.geom.kind == "arc":
            bank = math.degrees(math.atan(s.speed_mps ** 2 / (s.geom.radius_m * G_MPS2)))
            assert bank <= 25.0 + 0.05, (s.role, s.geom.radius_m, s.speed_mps)


@pytest.mark.parametrize("airport, proc, trans, fix", DEPARTURE_CF)
def test_a_cf_just_after_the_runway_is_flown_along_its_course_at_the_climb_out_speed(
        cifp, airport, proc, trans, fix):
    """The CF's own straights lie within 20° of the record's course (course + variation) and
    end at the database fix; a leg that starts below the acceleration height (1,000 ft above
    the runway record's elevation) is planned at the 737 file's climb-out speed, V2 + 10 kt
    (150 + 10 kt) raised to 1.15 × its 150 kt minimum clean CAS (172.5 kt, the lowest clean
    CAS guidance flies) as TAS at the leg's start altitude, a later one between that and the
    230 kt climb speed; no turn of the path needs more
    than the 25° bank at the speed it is planned for."""
    from fms_testbed.config.aircraft import load_aircraft
    from fms_testbed.core.units import FT_M, KT_MPS
    from fms_testbed.path.segmentation import runway_record

    p = _path(cifp, airport, proc, trans)
    assert p.status in ("ok", "corrected", "coding_suspect")
    assert not any(f"CF {fix} built" in f.message for f in p.findings)
    lg = next(lg for lg in p.legs if lg.path_term == "CF" and lg.record.fix.ident == fix)
    crs = _coded_true_deg(lg)
    lines = [s for s in p.segments if s.leg_index == lg.index and s.role == "leg"
             and isinstance(s.geom, Line) and s.geom.length_m() >= 1.0]
    assert lines
    for s in lines:
        assert abs(wrap180(s.geom.end_course_deg - crs)) <= 20.0, (s.geom.end_course_deg, crs)
    end = lines[-1].geom.end
    assert inverse(*end, lg.resolved.fix.lat_deg, lg.resolved.fix.lon_deg)[0] < 1.0
    rwy = runway_record(cifp, airport, trans)
    ac = load_aircraft("737")
    cas = max(ac.takeoff.v2_cas_mps + 10 * KT_MPS, 1.15 * ac.limits.cas_min_mps)
    assert cas - 0.01 <= lg.departure_cas_mps <= ac.limits.climb_cas_mps + 0.01
    if lg.start.alt_m - rwy.elev_m < 1000 * FT_M:
        assert lg.departure_cas_mps == pytest.approx(cas, abs=0.01)
        assert lg.speed_mps == pytest.approx(cas_to_tas_scalar(cas, lg.start.alt_m), abs=0.05)
    for s in p.segments:
        if s.geom.kind == "arc":
            bank = math.degrees(math.atan(s.speed_mps ** 2 / (s.geom.radius_m * G_MPS2)))
            assert bank <= 25.0 + 0.05, (s.role, s.geom.radius_m, s.speed_mps)


@pytest.mark.parametrize("airport", ["KBJC", "KJFK", "KMCO", "KSFO", "KDFW", "KATL"])
def test_no_cf_straight_of_a_buildable_transition_is_off_its_course(cifp, airport):
    """Every CF of every transition that is not impossible flies its own straights within
    20° of its coded course (the course from the record, not from the builder), but where a
    correction says the coded course is not flown (no distance to slow down): within 90°."""
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
            crs = _coded_true_deg(lg)
            tol = 90.0 if any("without flying the coded course" in f.message and
                              f.leg_index == lg.index for f in p.findings) else CF_OFF_COURSE_DEG
            for s in p.segments:
                if s.leg_index == lg.index and s.role == "leg" and s.geom.kind == "line":
                    n += 1
                    assert abs(wrap180(s.geom.end_course_deg - crs)) <= tol, \
                        (p.name, lg.index)
    assert n >= 10


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
