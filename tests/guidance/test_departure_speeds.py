"""The departure speed plan: one schedule (legs.model.Performance.departure_cas_at_mps) that the
leg builder plans SID turn radii for, that the airborne start takes its speed from and that the
guidance speed target never exceeds on a departure leg."""

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.legs.model import Performance


def test_departure_schedule_from_the_aircraft_file():
    """Climb-out CAS = max(V2 + climb-out increment, 1.15 × minimum clean CAS) from the file;
    from the acceleration height V² grows by 2 a per metre of path (a from the file): the
    time to go from V_c to V at a is (V − V_c)/a and the distance (V² − V_c²)/(2a), so the
    schedule at that distance gives V back; capped by the climb CAS and 250 kt below
    10,000 ft."""
    ac = load_aircraft("737")
    perf = Performance.from_aircraft(ac)
    vc = max(ac.takeoff.v2_cas_mps + ac.takeoff.climb_add_cas_mps, 1.15 * ac.limits.cas_min_mps)
    assert perf.departure_cas_mps == pytest.approx(vc)
    assert perf.accel_height_m == pytest.approx(ac.approach.acceleration_height_m)
    a = ac.takeoff.departure_accel_mps2
    assert perf.departure_cas_at_mps(None, 0.0) == pytest.approx(vc)
    v = 0.5 * (vc + ac.limits.climb_cas_mps)
    t_s = (v - vc) / a
    d_m = vc * t_s + 0.5 * a * t_s ** 2        # distance covered at constant a (kinematics)
    assert perf.departure_cas_at_mps(d_m, 0.0) == pytest.approx(v, rel=1e-9)
    assert perf.departure_cas_at_mps(1e6, 0.0) == pytest.approx(ac.limits.climb_cas_mps)
    fast = Performance(tas_plan_mps=300 * KT_MPS, tas_min_mps=70.0, climb_gradient_max=0.1,
                       climb_rate_max_mps=12.0, descent_rate_max_mps=12.0, bank_max_deg=25.0,
                       departure_cas_mps=80.0)
    assert fast.departure_cas_at_mps(1e6, 9000 * FT_M) == pytest.approx(250 * KT_MPS)
    assert fast.departure_cas_at_mps(1e6, 11000 * FT_M) == pytest.approx(300 * KT_MPS)
    none = Performance(tas_plan_mps=118.0, tas_min_mps=70.0, climb_gradient_max=0.1,
                       climb_rate_max_mps=12.0, descent_rate_max_mps=12.0, bank_max_deg=25.0)
    assert none.departure_cas_at_mps(None, 0.0) == pytest.approx(118.0)


@pytest.fixture(scope="module")
def demo_path():
    from fms_testbed.path.plan import build_procedure, load_db, parse_procedure

    spec = parse_procedure({"db": "embedded", "airport": "KJFK", "procedure": "DEEZZ5",
                            "runway": "31L", "transition": "CANDR", "manual_leg_nm": 5},
                           "<test>")
    db = load_db("embedded")
    return build_procedure(db, spec, load_aircraft("737")), db


def test_demo_sid_is_planned_and_started_at_the_climb_out_speed(demo_path):
    """The demo SID's first legs (below 1,000 ft above the runway) are planned at the climb-out
    CAS, their turn radii at its TAS, R = (V_TAS)² / (g tan γ) with γ ≤ 25°; the later legs
    no faster than the schedule allows; the airborne start flies the first leg's planned
    speed (TAS of the climb-out CAS at 35 ft), not the 230 kt climb speed."""
    from fms_testbed.loop.procedure import initial_from_path

    fp, _ = demo_path
    ac = load_aircraft("737")
    perf = Performance.from_aircraft(ac)
    legs = fp.path.legs
    elev = legs[0].start.alt_m - 35 * FT_M
    low = [lg for lg in legs if lg.start.alt_m - elev < perf.accel_height_m]
    assert len(low) >= 2
    for lg in low:
        assert lg.departure_cas_mps == pytest.approx(perf.departure_cas_mps)
    for lg in legs:
        assert lg.departure_cas_mps is not None
        assert lg.departure_cas_mps <= ac.limits.climb_cas_mps + 1e-9
    # every arc of a leg planned at the climb-out speed fits 25° at that TAS (+ margin for
    # the climb within the leg)
    for s in fp.path.segments:
        if s.geom.kind == "arc" and s.leg_index < len(low):
            bank = math.degrees(math.atan(s.speed_mps ** 2 / (s.geom.radius_m * 9.80665)))
            assert bank <= 25.05
            assert s.speed_mps < cas_to_tas_scalar(ac.limits.climb_cas_mps, 3000 * FT_M)
    ini = initial_from_path(fp, ac)
    assert ini["tas_mps"] == pytest.approx(
        cas_to_tas_scalar(perf.departure_cas_mps, ini["alt_m"]), abs=0.01)


def test_guidance_target_on_a_departure_leg_is_its_planned_speed(demo_path):
    """On the first leg of the demo SID the speed target is the TAS of the leg's planned CAS
    (the climb-out speed), well under the 230 kt climb CAS the speed plan holds."""
    from fms_testbed.guidance.locate import locate
    from fms_testbed.guidance.active_path import activate
    from fms_testbed.guidance.vnav import VerticalGuidance
    from fms_testbed.core.state import NavSolution
    import numpy as np

    fp, db = demo_path
    ac = load_aircraft("737")
    vg = VerticalGuidance(fp, ac, None, db)
    act = activate(fp, 0.0)
    p0 = fp.path.segments[0].geom
    lat, lon = p0.point_at(0.5 * p0.length_m())
    alt = fp.path.legs[0].start.alt_m + 50.0
    nav = NavSolution(t_s=0.0, lat_rad=math.radians(lat), lon_rad=math.radians(lon),
                      alt_m=alt, v_enu_mps=np.array([0.0, 88.0, 0.0]), roll_rad=0.0,
                      pitch_rad=0.0, heading_rad=0.0)
    w = locate(act, 0, nav)
    assert w.built.departure_cas_mps is not None
    tgt = vg.speed.update(0.0, alt, w)
    assert tgt == pytest.approx(cas_to_tas_scalar(w.built.departure_cas_mps, alt), abs=0.5)
    assert tgt < cas_to_tas_scalar(ac.limits.climb_cas_mps, alt) - 20 * KT_MPS
