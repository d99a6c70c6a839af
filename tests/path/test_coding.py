"""The coded-numbers check (Danilin's class 3): each record's redundant fields against its own
fixes — on synthetic records either side of the tolerance, on the records of the shipped cycle
that disagree with their fixes, and against an independent reading of the records' text."""

import re
import sys
from pathlib import Path

import pytest
from geographiclib.geodesic import Geodesic

from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import NM_M
from fms_testbed.evaluation.check import check_airport, perf_for
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.coding import TOL, coding_kind, variation_tol_deg
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.synth import leg_record as L
from tests.path.test_world import build, world

PERF = perf_for("737")


def _tf(distance_nm=None, course_deg=None, a="WB", b="WS"):
    return [L("XTST", "T09", "IF", 10, fix=a),
            L("XTST", "T09", "TF", 20, fix=b, distance_nm=distance_nm, course_deg=course_deg)]


def _geo(a="WB", b="WS"):
    pts = world()
    return inverse(*pts[a], *pts[b])


@pytest.mark.parametrize("units", [0, 1, -1, 2, -3])
def test_tf_route_distance_flagged_beyond_one_unit_of_the_field(tmp_path, units):
    """Coded as the fixes' distance rounded to 0.1 NM, then ``units`` tenths off: flagged
    exactly when the coded value is more than 0.1 NM from the geodesic."""
    d_m = _geo()[0]
    coded = round(d_m / NM_M, 1) + 0.1 * units
    p = build(tmp_path, _tf(distance_nm=coded))
    flagged = "distance" in {coding_kind(f) for f in p.findings}
    assert flagged == (abs(coded * NM_M - d_m) > TOL.distance_m)
    assert flagged == (units not in (0, 1))    # the geodesic here is 18.028 NM
    assert (p.status == "coding_suspect") == flagged


def test_tf_course_flagged_beyond_course_and_variation_resolution(tmp_path):
    az1 = _geo()[1]     # the synthetic airport has no variation: magnetic = true
    tol = TOL.course_deg + variation_tol_deg(0.0, False)
    ok = build(tmp_path, _tf(course_deg=round(az1 + 0.5 * tol, 1)))
    assert not [f for f in ok.findings if f.category == "coding"]
    bad = build(tmp_path, _tf(course_deg=round(az1 + tol + 0.3, 1)))
    msg = [f.message for f in bad.findings if f.category == "coding"]
    assert len(msg) == 1 and msg[0].startswith("course: TF WS course (cols 71-74)")
    assert bad.status == "coding_suspect"


# the records of the shipped cycle the issue names: an RF coded with an end tangent 100° off
# its geometry, TFs coded 30.0 NM (fixes 30.41 NM apart) and 2.4 NM (2.05 NM)
REAL = [("KAUS", "H18RZ", "SMRFF", "rf_tangent", 124695, 320.2, 217.6),
        ("KAUS", "H18RZ", "XWING", "rf_tangent", 124706, 320.2, 217.6),
        ("KJAQ", "P01", "HNW", "distance", 223045, 30.00, 30.41),
        ("KTDZ", "R04", "", "distance", 320375, 2.40, 2.05)]


@pytest.mark.parametrize("airport, proc, trans, kind, line, coded, geom", REAL)
def test_real_miscoded_records_are_class_3_with_field_values_and_line(cifp, airport, proc,
                                                                      trans, kind, line,
                                                                      coded, geom):
    seq = cifp.select(airport, proc, trans)[0]
    p = check_path(build_sequence(cifp, seq, PERF, BuildParams()), PERF, BuildParams())
    assert p.status == "coding_suspect"
    f = [x for x in p.findings if coding_kind(x) == kind and f"(line {line})" in x.message]
    assert f and f[0].danilin_class == 3
    nums = [float(x) for x in re.findall(r"(\d+\.\d+)(?:°| NM)", f[0].message)]
    assert coded in nums and geom in nums, f[0].message


def test_the_geometric_value_is_geographiclibs_from_the_fixes(cifp):
    """KJAQ P01 HNW: the distance the finding gives is the WGS-84 geodesic between the two
    database fixes (geographiclib directly, to the finding's 0.01 NM)."""
    seq = cifp.select("KJAQ", "P01", "HNW")[0]
    a, b = cifp.find_fix(seq.legs[0].fix, "KJAQ"), cifp.find_fix(seq.legs[1].fix, "KJAQ")
    s = Geodesic.WGS84.Inverse(a.lat_deg, a.lon_deg, b.lat_deg, b.lon_deg)["s12"]
    assert f"give {s / NM_M:.2f} NM" in next(
        x for x in check_airport(cifp, "KJAQ", PERF)
        if x["procedure"] == "P01" and x["transition"] == "HNW")["findings"]


@pytest.mark.parametrize("airports", [["KAUS", "KSEA", "KJAQ", "KTDZ", "KMCO"]])
def test_monitor_and_independent_reading_agree(cifp, airports):
    """The monitor's verdict per transition equals the one from the records' text read by
    column with Vincenty's geodesic (bench/bench_coding.py): no false positive, no miss."""
    import pandas as pd

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
    import bench_coding

    rows = [r for a in airports for r in check_airport(cifp, a, PERF)]
    df = pd.DataFrame(rows)
    lines = [ln.rstrip("\r") for ln in Path(cifp.path).read_text(encoding="latin-1")
             .split("\n")]
    cmp = bench_coding.compare(df, bench_coding.independent(cifp, lines, airports))
    assert cmp["ind_suspect"].sum() >= 6
    assert (cmp["mon_suspect"] == cmp["ind_suspect"]).all(), \
        cmp[cmp["mon_suspect"] != cmp["ind_suspect"]][["airport", "procedure", "transition"]]
