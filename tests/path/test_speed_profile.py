"""The approach's planned speeds (path/speed_profile.py) and its runway (path/runway.py), on a
synthetic approach written as ARINC-424 records."""

import math

import numpy as np
import pytest
from approach_helpers import ELEV_FT, TCH_FT, VPA_DEG, write_synthetic_approach

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.procedure import ProcedureSpec
from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.path.plan import build_procedure, load_db
from fms_testbed.path.runway import approach_runway, runway_of_ident, terrain_elevation_m


@pytest.fixture(scope="module")
def db(tmp_path_factory):
    return load_db(write_synthetic_approach(tmp_path_factory.mktemp("syn") / "syn.dat"))


def _fp(db, **kw):
    return build_procedure(db, ProcedureSpec(airport="KSYN", procedure="R09", **kw),
                           load_aircraft("737"))


def test_runway_record_gives_threshold_tch_vpa_and_terrain(db):
    fp = _fp(db)
    rw = approach_runway(db, fp.seq)
    assert rw.ident == "RW09" and rw.map_is_threshold
    assert rw.elev_m == pytest.approx(ELEV_FT * FT_M)
    assert rw.tch_m == pytest.approx(TCH_FT * FT_M)
    assert rw.vpa_deg == pytest.approx(VPA_DEG)
    # the threshold, not the (higher) airport reference elevation
    assert terrain_elevation_m(db, fp.seq) == pytest.approx(ELEV_FT * FT_M)
    assert db.terminal[("KSYN", "RW09")][0].tch_m == pytest.approx(TCH_FT * FT_M)
    assert runway_of_ident("I16R") == "RW16R" and runway_of_ident("R16RY") == "RW16R"
    assert runway_of_ident("VOR-A") is None


def test_speed_profile_decelerates_to_vapp_at_the_faf_honouring_the_limit(db):
    fp = _fp(db)
    sp = fp.path.profile.speed
    ap = load_aircraft("737").approach
    assert sp.vapp_cas_mps == pytest.approx(ap.vapp_cas_mps)
    # FAF 5 NM before the threshold, which is the MAP, 20 NM from the IAF
    assert sp.faf_m == pytest.approx(15 * NM_M, abs=200.0)
    assert sp.map_m == pytest.approx(20 * NM_M, abs=200.0)
    assert sp.cas_at(sp.faf_m) == pytest.approx(ap.vapp_cas_mps, abs=0.01)
    assert sp.cas_at(sp.map_m) == pytest.approx(ap.vapp_cas_mps, abs=0.01)
    # the 200 kt 'at or below' of the leg to the IF (as guidance flies it: over its leg) holds
    # from there on
    assert sp.cas_at(0.0) == pytest.approx(200 * KT_MPS)
    assert sp.cas_at(10 * NM_M) <= 200 * KT_MPS + 1e-6
    # never rising along the approach; decelerations planned at the aircraft's rate
    v = np.array([sp.cas_at(s) for s in np.linspace(0, sp.map_m, 400)])
    assert np.all(np.diff(v) <= 1e-6)
    assert sp.decelerations
    for d in sp.decelerations:
        alt = float(fp.path.profile.alt_at(0.5 * (d.start_m + d.end_m)))
        a = (cas_to_tas_scalar(d.cas_from_mps, alt) ** 2 - cas_to_tas_scalar(d.cas_to_mps, alt)
             ** 2) / (2 * (d.end_m - d.start_m))
        assert a == pytest.approx(ap.decel_mps2, rel=0.15)
    # a heavier aircraft flies a higher Vapp from the FAF on
    assert sp.cas_at(sp.faf_m + 100.0, 1.1 * ap.vapp_cas_mps) == pytest.approx(
        1.1 * ap.vapp_cas_mps)


def test_profile_is_on_the_coded_path_through_the_tch(db):
    prof = _fp(db).path.profile
    thr_alt = (ELEV_FT + TCH_FT) * FT_M
    assert prof.alt_m[-1] == pytest.approx(thr_alt)
    s0 = prof.along_m[-1] - 2 * NM_M
    ang = math.degrees(math.atan((prof.alt_at(s0) - thr_alt) / (2 * NM_M)))
    assert ang == pytest.approx(VPA_DEG, abs=0.01)


def test_missed_keeps_the_missed_legs_and_is_refused_off_approaches(db):
    assert [lg.path_term for lg in _fp(db).seq.legs] == ["IF", "TF", "TF", "TF"]
    fp = _fp(db, missed=True)
    assert [lg.path_term for lg in fp.seq.legs] == ["IF", "TF", "TF", "TF", "CA", "DF", "HM"]
    prof = fp.path.profile
    assert prof.climb[-1] and not prof.climb[4]
    # the missed approach climbs to its own coded altitude, not to the SID climb top
    assert prof.alt_m[prof.climb].max() == pytest.approx(3000 * FT_M)
    emb = load_db("embedded")
    with pytest.raises(UserError, match="only an approach"):
        build_procedure(emb, ProcedureSpec(airport="KBFI", procedure="CBAIN1", runway="RW32L",
                                           missed=True), load_aircraft("737"))
