"""Unit conversions: exact definitions, round trips, and no raw unit or WGS-84 literal elsewhere."""

from __future__ import annotations

import io
import math
import tokenize
from fractions import Fraction
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fms_testbed.core import units as u

ROOT = Path(__file__).resolve().parents[2]


def test_definitions_are_exact():
    # international foot and nautical mile, standard gravity, avoirdupois pound: exact by definition
    assert Fraction(u.FT_M) == Fraction(0.3048) and u.NM_M == 1852.0 and u.G0_MPS2 == 9.80665
    assert u.LB_KG == 0.45359237
    # derived factors to the last bit of a double
    assert u.KT_MPS == 1852.0 / 3600.0 and u.KMH_MPS == 1000.0 / 3600.0
    assert u.FPM_MPS == pytest.approx(0.00508, rel=1e-15)
    assert u.DEG_RAD == math.radians(1.0) and u.DPH_RPS == pytest.approx(math.pi / 648000.0, rel=1e-15)
    assert u.LBF_N == pytest.approx(4.4482216152605, rel=1e-15)
    assert u.SLUG_KG == pytest.approx(14.593902937206, rel=1e-12)        # NIST SP 811: 1.459390 E+01


def test_familiar_aviation_figures():
    assert u.m_to_ft(u.nm_to_m(1.0)) == pytest.approx(6076.115486, abs=1e-6)   # ft in a NM
    assert u.kt_to_mps(100.0) == pytest.approx(51.444444, abs=1e-6)
    assert u.mps_to_fpm(u.fpm_to_mps(1000.0)) == pytest.approx(1000.0, rel=1e-15)
    assert u.fpm_to_mps(1000.0) == pytest.approx(5.08, rel=1e-15)
    assert u.kmh_to_mps(360.0) == pytest.approx(100.0, rel=1e-15)
    assert u.mps_to_kmh(100.0) == pytest.approx(360.0, rel=1e-15)
    assert u.rps_to_dph(u.dph_to_rps(0.01)) == pytest.approx(0.01, rel=1e-15)
    assert u.dph_to_rps(1.0) == pytest.approx(4.8481368e-6, rel=1e-7)          # 1 °/h in rad/s


PAIRS = [(u.ft_to_m, u.m_to_ft), (u.kt_to_mps, u.mps_to_kt), (u.nm_to_m, u.m_to_nm),
         (u.kmh_to_mps, u.mps_to_kmh), (u.fpm_to_mps, u.mps_to_fpm), (u.dph_to_rps, u.rps_to_dph)]


@given(st.floats(min_value=-1e7, max_value=1e7, allow_nan=False))
def test_converters_round_trip(x):
    for to_si, from_si in PAIRS:
        assert from_si(to_si(x)) == pytest.approx(x, rel=1e-15, abs=1e-300)


def test_converters_take_arrays_and_series():
    x = np.array([0.0, 1.0, 250.0])
    assert np.array_equal(u.kt_to_mps(x), x * u.KT_MPS)
    s = u.m_to_ft(pd.Series([0.0, 3048.0]))
    assert isinstance(s, pd.Series) and s.iloc[1] == pytest.approx(10000.0, rel=1e-15)


#: values that must come from core/units.py or core/earth.py, never be written again elsewhere
BANNED = {1852.0: "units.NM_M", 1.852: "units.NM_M", 0.3048: "units.FT_M", 3.28084: "units.FT_M",
          9.80665: "units.G0_MPS2", 0.514444: "units.KT_MPS", 0.5144444: "units.KT_MPS",
          0.45359237: "units.LB_KG", 4.4482216152605: "units.LBF_N", 14.593902937: "units.SLUG_KG",
          6378137.0: "earth.A_M", 298.257223563: "earth.FLATTENING", 6356752.3142: "earth.B_M",
          7.292115e-5: "earth.OMEGA_IE_RPS", 3.986004418e14: "earth.GM_M3PS2",
          9.7803253359: "earth.GAMMA_E_MPS2", 9.8321849378: "earth.GAMMA_P_MPS2",
          0.00193185265241: "earth.K_SOMIGLIANA", 0.00669437999013: "earth.E2",
          6.69437999014e-3: "earth.E2", 0.00344978650684: "earth.M_RATIO",
          6371008.8: "earth.MEAN_RADIUS_M", 6371000.0: "earth.MEAN_RADIUS_M"}
HOMES = {"fms_testbed/core/units.py", "fms_testbed/core/earth.py"}


def _number_tokens(path: Path):
    for tok in tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline):
        if tok.type == tokenize.NUMBER:
            try:
                yield tok.start[0], float(tok.string.replace("_", ""))
            except ValueError:                      # complex literals
                continue


def test_no_raw_unit_or_wgs84_literal_outside_units_and_earth():
    files = [p for d in ("fms_testbed", "bench") for p in sorted((ROOT / d).rglob("*.py"))
             if p.relative_to(ROOT).as_posix() not in HOMES]
    assert len(files) > 50
    hits = [f"{p.relative_to(ROOT)}:{line}: {v!r} -> use {BANNED[v]}"
            for p in files for line, v in _number_tokens(p) if v in BANNED]
    assert not hits, "\n".join(hits)
