"""The builder's moves build a rejected candidate on a trial copy and leave nothing of it
behind: no segment, corner or finding; a kept one becomes the builder's whole."""

import math

from fms_testbed.core.geodesy import direct
from fms_testbed.legs.builder import LegBuilder, ResolvedLeg
from fms_testbed.legs.model import BuildParams, FlightState
from fms_testbed.legs.moves import commit, join_from_fix, trial
from fms_testbed.procedures.legrecord import parse_leg
from fms_testbed.procedures.records import Fix
from fms_testbed.procedures.synth import leg_record
from tests.path.test_world import PERF

FIX = Fix(ident="F", region="", section="", lat_deg=45.0, lon_deg=7.0)


def _builder() -> LegBuilder:
    rec = parse_leg(leg_record("XTST", "T09", "TF", 10, fix="F"), 1)
    b = LegBuilder([ResolvedLeg(rec, FIX, None, None, None, 0.0)], PERF, BuildParams(), 9.81,
                   [None])
    b.radius_m = 3000.0
    # something built already: one straight into the fix, a corner pending
    st = FlightState(*direct(FIX.lat_deg, FIX.lon_deg, 270.0, 5000.0)[:2], 90.0, 1000.0)
    b.line_to(st, FIX.lat_deg, FIX.lon_deg, "F")
    b.corners.add(0)
    return b


def test_a_rejected_candidate_leaves_the_builder_untouched():
    """Over the fix heading 090, the course out of it is 180: the rejoin's intercept needs far
    more than the 100 m allowed — join_from_fix builds nothing and says so (None)."""
    b = _builder()
    segs, corners, pending = list(b.segments), set(b.corners), b._corner_pending
    over = FlightState(FIX.lat_deg, FIX.lon_deg, 90.0, 1000.0, flyby=False, fix_ident="F")
    assert join_from_fix(b, over, FIX, 180.0, "R", max_along_m=100.0) is None
    assert b.segments == segs and b.corners == corners and b._corner_pending == pending
    assert b.findings == []


def test_the_same_join_with_room_is_kept_whole():
    b = _builder()
    n0 = len(b.segments)
    over = FlightState(FIX.lat_deg, FIX.lon_deg, 90.0, 1000.0, flyby=False, fix_ident="F")
    st = join_from_fix(b, over, FIX, 180.0, "R")
    assert st is not None and math.isclose(st.track_deg, 180.0)
    assert len(b.segments) > n0 and b.segments[:n0] == _builder().segments
    assert b._corner_pending       # the fly-by onto the course is the next corner


def test_commit_takes_the_candidates_segments_corners_and_findings():
    b = _builder()
    t = trial(b)
    t.finding("info", "candidate")
    t.straight(FlightState(FIX.lat_deg, FIX.lon_deg, 180.0, 1000.0), 180.0, 2000.0)
    assert len(b.segments) == 1 and not b.findings      # the trial is a copy
    commit(b, t)
    assert len(b.segments) == 2 and [f.message for f in b.findings] == ["candidate"]
