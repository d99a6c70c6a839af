"""The path planned for the day's conditions: TAS of the planned CAS on a warm/cold day, and a
wind profile used at each leg's planned altitude (turn radii, hold turns, heading-leg drift)."""

from __future__ import annotations

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.procedure import parse_procedure
from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.segments import Arc
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.core.wind import WindProfile
from fms_testbed.legs.model import BuildParams, drift_track_deg, turn_radius_m
from fms_testbed.path.plan import build_procedure
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.synth import leg_record as L
from tests.path.test_world import build

SPEC = parse_procedure({"airport": "KENV", "procedure": "R26", "transition": "BVL"}, "<test>")


@pytest.fixture(scope="module")
def embedded():
    return load_database()


@pytest.fixture(scope="module")
def b737():
    return load_aircraft("737")


def _hold_arcs(fp):
    k = next(lg.index for lg in fp.path.legs if lg.path_term == "HF")
    return k, [s for s in fp.path.segments if s.leg_index == k and isinstance(s.geom, Arc)
               and abs(s.geom.sweep_deg) > 150.0]


@pytest.mark.parametrize("dev", [-20.0, 20.0])
def test_hold_turns_are_planned_for_the_tas_of_the_day(embedded, b737, dev):
    """KENV RNAV 26 via BVL (HF): the hold's TAS is the planned CAS's TAS at the leg's planned
    altitude on the day, and its radius R = V²/(g tan 20°) — 5 % larger/smaller per ±20 °C."""
    base = build_procedure(embedded, SPEC, b737)
    day = build_procedure(embedded, SPEC, b737, isa_dev_c=dev)
    k, arcs0 = _hold_arcs(base)
    _, arcs = _hold_arcs(day)
    alt = day.path.legs[k].start.alt_m
    cas = min(b737.limits.climb_cas_mps, 210 * KT_MPS)   # the approach's planned CAS cap
    v = cas_to_tas_scalar(max(cas, 1.15 * b737.limits.cas_min_mps), alt, dev)
    assert arcs[0].speed_mps == pytest.approx(v, rel=1e-6)
    g = arcs[0].geom.radius_m * math.tan(math.radians(20.0)) / v ** 2   # the g used
    assert 9.78 < 1.0 / g < 9.83
    ratio = arcs[0].geom.radius_m / arcs0[0].geom.radius_m
    assert ratio == pytest.approx((v / arcs0[0].speed_mps) ** 2, rel=1e-6)
    assert (ratio - 1.0) * dev > 0 and abs(ratio - 1.0) > 0.04


def test_hold_turns_use_the_wind_at_the_holds_altitude(embedded, b737):
    """Two profiles with the same wind at the HF's altitude, different elsewhere, give the
    same hold; one with 40 kt more there gives the ground-speed radius (V + W)²/(g tan γ)."""
    calm = build_procedure(embedded, SPEC, b737)
    k, arcs_calm = _hold_arcs(calm)
    h = calm.path.legs[k].start.alt_m
    low = WindProfile.from_layers([(h - 2000.0, 270.0, 30.0), (h, 270.0, 0.0),
                                   (h + 1500.0, 270.0, 0.0), (h + 4000.0, 90.0, 40.0)])
    same = build_procedure(embedded, SPEC, b737, wind=low)
    assert _hold_arcs(same)[1][0].geom.radius_m == pytest.approx(arcs_calm[0].geom.radius_m,
                                                                  rel=1e-9)
    w = 40 * KT_MPS
    there = WindProfile.from_layers([(0.0, 270.0, 0.0), (h - 1500.0, 270.0, 0.0),
                                     (h, 200.0, w), (h + 3000.0, 200.0, w)])
    windy = build_procedure(embedded, SPEC, b737, wind=there)
    arc = _hold_arcs(windy)[1][0]
    r = turn_radius_m(arc.speed_mps + w, 20.0, 9.80665)
    assert arc.geom.radius_m == pytest.approx(r, rel=3e-3)    # g of the latitude


def test_heading_leg_drift_uses_the_wind_at_its_altitude(tmp_path):
    """A SID's VA off the runway (35 ft) in a profile of 30 kt from the north at the surface
    and calm above 3,000 ft: its ground track is the wind triangle's with the surface wind."""
    legs = [L("XTST", "SID1", "VA", 10, proc_type="D", transition="RW09", course_deg=90.0,
              alt_desc="+", alt1_ft=2000),
            L("XTST", "SID1", "DF", 20, proc_type="D", transition="RW09", fix="WE")]
    prof = WindProfile.from_layers([(0.0, 0.0, 30 * KT_MPS), (3000 * FT_M, 0.0, 0.0)])
    p = build(tmp_path, legs, params=BuildParams(wind_profile=prof,
                                                 wind_speed_mps=30 * KT_MPS, wind_from_deg=0.0))
    va = next(s for s in p.segments if s.path_term == "VA" and s.heading_deg is not None)
    spd, frm = prof.at(p.legs[0].start.alt_m)
    want = drift_track_deg(va.heading_deg, va.speed_mps, spd, frm)
    assert va.geom.start_course_deg == pytest.approx(want, abs=0.05)
    assert want > 90.0 + 5.0          # a 30 kt north wind drifts it ~7° right
