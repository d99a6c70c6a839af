"""Danilin's (2017) three classes on monitor findings, each on a real CIFP record and on a
synthetic one: (1) the current conditions — a correction forced by the wind or the temperature
names the condition; (2) a leg combination the geometry has to bridge; (3) the coding itself."""

from __future__ import annotations


import pytest

from fms_testbed.core.units import KT_MPS
from fms_testbed.legs.model import BuildParams
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.synth import leg_record as L
from fms_testbed.procedures.synth import offset, waypoint_record
from tests.path.test_world import APT, PERF, build

WINDY_HOT = BuildParams(wind_speed_mps=40 * KT_MPS, wind_from_deg=270.0, isa_dev_c=20.0)



def _seq(db, airport, name):
    return next(s for s in db.sequences(airport) if s.name == name)


def _checked(db, seq, params):
    return check_path(build_sequence(db, seq, PERF, params), PERF, params)


def test_class1_real_fly_by_forced_by_wind_and_temperature(cifp):
    """KDFW ZACHH4 RW36R: the fly-by at CUZEN fits at 20° in calm ISA air; at 40 kt and
    ISA+20 its radius does not, and the correction says so — class 1, naming the condition."""
    seq = _seq(cifp, "KDFW", "KDFW SID ZACHH4 RW36R")
    calm = _checked(cifp, seq, BuildParams())
    assert not any("CUZEN" in f.message and f.category == "correction" for f in calm.findings)
    hot = _checked(cifp, seq, WINDY_HOT)
    f = next(f for f in hot.findings if "fly-by at CUZEN" in f.message)
    assert f.danilin_class == 1 and f.branch == "R"
    assert "40 kt tailwind, ISA+20" in f.message and "forced by the conditions" in f.message


def test_class1_real_rf_bank_forced_by_wind_and_temperature(cifp):
    """KSEA RNAV (RNP) Z 16C via PPAUL: an RF of 2.8 NM flown at 20° needs more bank at 40 kt
    and ISA+20 (14° in calm ISA air): a γ correction naming the condition, class 1."""
    seq = _seq(cifp, "KSEA", "KSEA APPROACH H16CZ PPAUL")
    assert not any(f.category == "correction" and "RF radius" in f.message
                   for f in _checked(cifp, seq, BuildParams()).findings)
    f = next(f for f in _checked(cifp, seq, WINDY_HOT).findings if "RF radius" in f.message)
    assert f.danilin_class == 1 and f.branch == "γ"
    assert "ISA+20" in f.message and "in calm ISA air): forced by the conditions" in f.message


@pytest.mark.parametrize("name, text, cls", [
    ("KSMX SID BUELT4 RW12", "IF GLJ away", 2),         # a discontinuity the geometry bridges
    ("3AU APPROACH VDM-A", "doubles back", 3),          # the coding: the path drawn twice
])
def test_classes_2_and_3_real(cifp, name, text, cls):
    p = _checked(cifp, _seq(cifp, name.split()[0], name), BuildParams())
    f = next(f for f in p.findings if text in f.message)
    assert f.danilin_class == cls


def _short_dogleg(tmp_path, params):
    """IF P0, TF P1, TF P2: 3 NM legs with a 90° turn at P1. At the planned 118 m/s CAS (≈ 265
    kt TAS at the STAR's 10,000 ft) a 20° fly-by needs a 5.2 km radius: the 5.56 km the legs
    leave fit it in calm ISA air, not with a 40 kt tailwind nor on an ISA+40 day."""
    p1 = offset(*APT, 0.0, 30.0)
    p0 = offset(*p1, 180.0, 3.0)
    p2 = offset(*p1, 90.0, 3.0)
    extra = [waypoint_record("P0", *p0), waypoint_record("P1", *p1), waypoint_record("P2", *p2)]
    legs = [L("XTST", "SYN1", "IF", 10, fix="P0", proc_type="E"),
            L("XTST", "SYN1", "TF", 20, fix="P1", proc_type="E"),
            L("XTST", "SYN1", "TF", 30, fix="P2", proc_type="E")]
    return build(tmp_path, legs, extra, params=params)


def test_class1_synthetic_tailwind_forces_the_correction(tmp_path):
    calm = _short_dogleg(tmp_path, BuildParams())
    assert not [f for f in calm.findings if f.category == "correction"]
    windy = _short_dogleg(tmp_path, BuildParams(wind_speed_mps=40 * KT_MPS, wind_from_deg=180.0))
    f = next(f for f in windy.findings if "fly-by at P1" in f.message)
    assert f.danilin_class == 1
    assert "TAS + 40 kt tailwind (" in f.message and "forced by the conditions" in f.message


def test_class1_synthetic_temperature_alone_forces_the_correction(tmp_path):
    """The same dogleg in calm air on an ISA+40 day: the TAS for the planned CAS is ~7 % higher,
    the radius ~14 %: the fly-by no longer fits, and the finding names the temperature only;
    on an ISA−40 day it fits."""
    cool = _short_dogleg(tmp_path, BuildParams(isa_dev_c=-40.0))
    assert not [f for f in cool.findings if f.category == "correction"]
    hot = _short_dogleg(tmp_path, BuildParams(isa_dev_c=40.0))
    f = next(f for f in hot.findings if "fly-by at P1" in f.message)
    assert f.danilin_class == 1
    assert "kt TAS, ISA+40 (" in f.message and "forced by the conditions" in f.message


def test_class2_synthetic_discontinuity(tmp_path):
    """A second IF away from where the path is (a leg combination the coding leaves open):
    bridged, class 2."""
    legs = [L("XTST", "SYN2", "IF", 10, fix="WA", proc_type="E"),
            L("XTST", "SYN2", "TF", 20, fix="WB", proc_type="E"),
            L("XTST", "SYN2", "IF", 30, fix="WE", proc_type="E"),
            L("XTST", "SYN2", "TF", 40, fix="WS", proc_type="E")]
    p = build(tmp_path, legs)
    f = next(f for f in p.findings if "IF WE away" in f.message)
    assert f.danilin_class == 2


def test_class3_synthetic_path_flown_twice(tmp_path):
    """WA → WB → WA → WB: the same track coded twice (the paper's Fig. 4): class 3."""
    legs = [L("XTST", "SYN3", "IF", 10, fix="WA", proc_type="E"),
            L("XTST", "SYN3", "TF", 20, fix="WB", proc_type="E"),
            L("XTST", "SYN3", "TF", 30, fix="WA", proc_type="E"),
            L("XTST", "SYN3", "TF", 40, fix="WB", proc_type="E")]
    p = build(tmp_path, legs)
    f = next(f for f in p.findings if f.category == "loop")
    assert f.danilin_class == 3 and "flown twice" in f.message
