"""Whole-cycle sweeps of the shipped FAA cycle (slow; their quick counterparts are the
per-record tests of test_cf_course.py and test_plan_envelope.py): every CF of every
transition that is not impossible flies its own straights within 20° of the record's course
(90° where a correction says its course is not flown),
every timed hold is as long as its time at the planned speed, the check's planned profile
stays below the ceiling and inside VMO/MMO, and no path with a discontinuity or a loop is
'ok' or 'corrected'."""

import math

import numpy as np
import pytest

from fms_testbed.core.geodesy import wrap180
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.evaluation.check import perf_for, run_check
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.monitor import CF_OFF_COURSE_DEG, check_path
from fms_testbed.path.segmentation import build_sequence

PERF = perf_for("737")
HOLDS = ("HA", "HF", "HM")


def _outbound_m(path, leg_index):
    """The hold leg's outbound straight: the line after its first racetrack turn, m."""
    segs = [s for s in path.segments if s.leg_index == leg_index]
    for a, b in zip(segs, segs[1:]):
        if a.role == "hold" and a.geom.kind == "arc" and b.geom.kind == "line":
            return b.geom.length_m()
    return math.nan


@pytest.mark.slow
def test_every_cf_on_its_course_and_every_timed_hold_its_length(cifp):
    params = BuildParams()
    n_cf = n_hold = 0
    for apt in cifp.airport_idents():
        for seq in cifp.sequences(apt):
            pts = {r.path_term for r in seq.legs}
            if "CF" not in pts and not pts & set(HOLDS):
                continue
            p = check_path(build_sequence(cifp, seq, PERF, params), PERF, params)
            if p.status == "impossible":
                continue
            for lg in p.legs:
                r = lg.record
                if lg.path_term == "CF":
                    crs = r.course_deg + (0.0 if r.course_true else lg.resolved.magvar_deg)
                    tol = 90.0 if any("without flying the coded course" in f.message and
                                      f.leg_index == lg.index for f in p.findings) \
                        else CF_OFF_COURSE_DEG
                    for s in p.segments:
                        if s.leg_index == lg.index and s.role == "leg" and \
                                s.geom.kind == "line" and s.geom.length_m() >= 1.0:
                            n_cf += 1
                            assert abs(wrap180(s.geom.end_course_deg - crs)) \
                                <= tol, (p.name, lg.index)
                elif lg.path_term in HOLDS and r.time_s is not None:
                    out = _outbound_m(p, lg.index)
                    if math.isnan(out):
                        continue
                    v = lg.speed_mps if r.speed_limit_mps else params.timed_speed_mps
                    n_hold += 1
                    assert abs(out - r.time_s * v) <= 0.1 * NM_M, (p.name, lg.index)
    assert n_cf > 10000 and n_hold > 1000


@pytest.mark.slow
def test_whole_cycle_check_inside_the_envelope_and_honest_statuses(cifp):
    res = run_check(str(cifp.path), PERF, workers=2, progress=False)
    rows = res.rows
    assert len(rows) > 50000
    for r in rows:
        if "discontinuity" in r["flags"] or "loop" in r["flags"]:
            assert r["status"] not in ("ok", "corrected"), (r["airport"], r["procedure"])
    alt = np.array([r["max_plan_alt_ft"] for r in rows], dtype=float)
    tas = np.array([r["max_plan_tas_kt"] for r in rows], dtype=float)
    ok = np.isfinite(alt)
    assert np.all(alt[ok] <= PERF.alt_max_m / FT_M)
    # VMO/MMO as TAS: no more than the largest TAS the envelope allows at any altitude up to
    # the transition's highest planned one (its legs' own altitudes are not in the row)
    grid = np.linspace(0.0, float(alt[ok].max()) * FT_M + 1.0, 400)
    cap = np.maximum.accumulate([PERF.tas_max_mps(h) for h in grid]) / KT_MPS
    k = np.minimum(np.searchsorted(grid, alt[ok] * FT_M), len(grid) - 1)
    assert np.all(tas[ok] <= cap[k] + 0.5)
