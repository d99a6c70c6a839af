"""Heading legs (V*) hold the coded heading and let the wind drift the track; track legs fly
the ground track (the aircraft crabs). Checked on the guidance alone with a synthetic
navigation solution (no JSBSim), since a heading leg differs from a course leg only in wind."""

from __future__ import annotations

import math
import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.loop.procedure import prepare
from fms_testbed.guidance.fms import ProcedureGuidance
from fms_testbed.core.geodesy import direct


def _nav(lat, lon, alt, heading_deg, track_deg, gs=118.0, t=1.0):
    tr = math.radians(track_deg)
    return NavSolution(t, math.radians(lat), math.radians(lon), alt,
                       np.array([gs * math.sin(tr), gs * math.cos(tr), 0.0]), 0.0, 0.05,
                       math.radians(heading_deg) % (2 * math.pi))


def _air(nav, tas=118.0):
    """Air data of an aircraft flying ``tas`` (m/s) in still air at the navigation altitude."""
    return AirData(nav.t_s, tas, tas, 0.36, nav.alt_m, nav.alt_m, 0.0, 95000.0, 280.0, 0.05, 0.0)


@pytest.fixture(scope="module")
def guidance_on_first_leg():
    """DEEZZ5 RW04B: the first leg is VA (heading to an altitude) from the DER."""
    scn, spec, fp, db = prepare({"aircraft": "737", "procedure": {
        "airport": "KJFK", "procedure": "DEEZZ5", "runway": "04B"}})
    assert fp.path.legs[0].path_term == "VA"
    seg0 = fp.path.segments[0]
    assert seg0.role == "leg" and seg0.geom.kind == "line"
    return fp, db, spec, seg0


def _bank_deg(fp, db, spec, seg, heading_deg, track_deg):
    g = ProcedureGuidance(fp, load_aircraft("737"), db=db, spec=spec)
    lat, lon, _ = direct(*seg.geom.start, seg.geom.start_course_deg, 300.0)
    nav = _nav(lat, lon, fp.path.legs[0].start.alt_m + 10.0, heading_deg, track_deg)
    out = g.update(0.1, nav, _air(nav))
    return math.degrees(out.bank_rad)


def test_on_a_heading_leg_a_crab_from_wind_commands_no_correction(guidance_on_first_leg):
    fp, db, spec, seg = guidance_on_first_leg
    crs = seg.geom.start_course_deg
    # heading on the coded heading, track drifted 8° by wind: keep the heading
    assert abs(_bank_deg(fp, db, spec, seg, crs, crs + 8.0)) < 0.5
    # heading 5° off the coded heading: turn back toward it
    assert _bank_deg(fp, db, spec, seg, crs + 5.0, crs + 5.0) < -2.0


def test_on_a_track_leg_the_same_drift_is_corrected(guidance_on_first_leg):
    """The same situation on the TF leg of the path (course legs fly the ground track)."""
    fp, db, spec, _ = guidance_on_first_leg
    tf = next(s for s in fp.path.segments if s.path_term == "TF" and s.role == "leg")
    g = ProcedureGuidance(fp, load_aircraft("737"), db=db, spec=spec)
    g.seq.i = next(i for i, p in enumerate(g.act.pieces) if g.act.segs[p.seg_index] is tf)
    g.seq.leg = tf.leg_index  # sequenced up to that leg
    lat, lon, _ = direct(*tf.geom.start, tf.geom.start_course_deg, 300.0)
    crs = tf.geom.course_at(300.0)
    nav = _nav(lat, lon, 3000.0, crs, crs + 8.0)
    bank = math.degrees(g.update(0.1, nav, _air(nav)).bank_rad)
    assert bank < -5.0  # track 8° right of the course: bank left to correct it
