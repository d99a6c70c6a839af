"""The planned vertical profile stays inside the aircraft's envelope: below its ceiling (less
the planner's margin) and inside VMO/MMO, with the same climb planner in the builder (planned
altitudes, speeds, radii) and in the profile; timed holds are as long as their time at the
planned speed."""

import math

import numpy as np
import pytest

from fms_testbed.core.atmosphere import GAMMA, R_JPKGK, cas_to_tas_scalar, isa
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.evaluation.check import perf_for
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.monitor import check_path
from fms_testbed.path.profile import climb_caps_m, climb_phases
from fms_testbed.path.segmentation import build_sequence

PERF = perf_for("737")

# SIDs of the shipped cycle whose climb the builder planned without a top: KLGU ORNEY1 RW35
# reached 196,590 ft and 890 kt TAS in its HA, KOMA CATTL3 ICT 137,121 ft
HIGH = [("KLGU", "ORNEY1", "RW35"), ("KOMA", "CATTL3", "ICT"), ("KSEA", "SUMMA2", "LKV"),
        ("KAPC", "OZIEE4", "JSICA"), ("KIAH", "LFK3", "LIT")]


def test_tas_max_is_vmo_low_and_mmo_high():
    """min(TAS(VMO), MMO·a): the 737's 340 kt at sea level, 0.82 × the local speed of sound at
    FL370 (independent: the ISA temperature there)."""
    assert PERF.tas_max_mps(0.0) == pytest.approx(PERF.cas_max_mps, rel=1e-6)
    h = 37000 * FT_M
    a = math.sqrt(GAMMA * R_JPKGK * float(isa(h)[0]))
    assert PERF.tas_max_mps(h) == pytest.approx(0.82 * a, rel=1e-9)
    assert PERF.tas_max_mps(h) < cas_to_tas_scalar(PERF.cas_max_mps, h)


@pytest.mark.parametrize("airport, proc, trans", HIGH)
def test_real_sids_are_planned_below_the_ceiling_and_inside_vmo_mmo(cifp, airport, proc, trans):
    seq = cifp.select(airport, proc, trans)[0]
    params = BuildParams()          # the CLI check's: no climb top given
    path = check_path(build_sequence(cifp, seq, PERF, params), PERF, params)
    assert path.legs
    assert path.max_plan_alt_m() <= PERF.alt_max_m
    for lg in path.legs:
        assert lg.end.alt_m <= PERF.alt_plan_max_m + 1e-6
        assert lg.speed_mps <= PERF.tas_max_mps(max(lg.start.alt_m, lg.end.alt_m)) + 1e-6
    # the builder's climb and the profile's level at the same altitudes (one planner)
    caps = climb_caps_m([lg.record for lg in path.legs],
                        climb_phases([lg.record for lg in path.legs], "D"), None,
                        PERF.alt_plan_max_m)
    ends = np.array([lg.end.alt_m for lg in path.legs])
    assert np.all(ends <= caps[1:] + 1e-6)
    assert float(path.profile.alt_m.max()) == pytest.approx(float(ends.max()), abs=1.0)


def test_a_climb_top_above_the_ceiling_is_capped():
    climb = np.array([False, True, True])
    class R:   # a record with no constraint: climb to the given top
        alt_desc, alt1_m, alt2_m, trans_alt_m = "", None, None, None
    caps = climb_caps_m([R, R], climb, 45000 * FT_M, PERF.alt_plan_max_m)
    assert np.all(caps <= PERF.alt_plan_max_m)
    assert caps[-1] == PERF.alt_plan_max_m
    # no top given and nothing coded: 18,000 ft, as the database check always planned
    assert climb_caps_m([R, R], climb)[-1] == pytest.approx(18000 * FT_M)


def _outbound_m(path, leg_index):
    """Length of the outbound straight of a hold leg's circuit (the line after its first
    racetrack turn, role 'hold'), m."""
    segs = [s for s in path.segments if s.leg_index == leg_index]
    for a, b in zip(segs, segs[1:]):
        if a.role == "hold" and a.geom.kind == "arc" and b.geom.kind == "line":
            return b.geom.length_m()
    return math.nan


def test_timed_holds_of_the_cycle_are_built_at_their_time_times_the_planned_speed(cifp):
    """Every timed (1-minute) hold of a sample of airports: the built outbound leg is 60 s at
    the timed-leg speed (the coded limit's planned TAS, else 210 kt) within 0.1 NM, and that
    speed is inside the envelope."""
    params = BuildParams()
    n = 0
    for airport in ("KLGU", "KDFW", "KDEN", "KSEA", "KORD", "KATL", "KBOS", "KSFO"):
        for seq in cifp.sequences(airport):
            if not any(r.path_term in ("HA", "HF", "HM") and r.time_s == 60.0 for r in seq.legs):
                continue
            path = build_sequence(cifp, seq, PERF, params)
            for lg in path.legs:
                if lg.path_term not in ("HA", "HF", "HM") or lg.record.time_s != 60.0:
                    continue
                v = lg.speed_mps if lg.record.speed_limit_mps else params.timed_speed_mps
                out = _outbound_m(path, lg.index)
                if math.isnan(out):
                    continue
                n += 1
                assert abs(out - 60.0 * v) <= 0.1 * NM_M, (seq.name, out / NM_M, v / KT_MPS)
                assert lg.speed_mps <= PERF.tas_max_mps(lg.end.alt_m) + 1e-6
    assert n >= 20
