"""ISA and CAS/TAS conversions against tabulated values."""

import pytest

from fms_testbed.core.atmosphere import cas_to_tas, isa, tas_to_cas
from fms_testbed.core.units import mps_to_kt


def test_isa_table_values():
    t, p, rho = isa(11000.0)
    assert t == pytest.approx(216.65, abs=0.01)
    assert p == pytest.approx(22632.0, rel=1e-3)
    assert isa(0.0)[2] == pytest.approx(1.225, rel=1e-4)


def test_cas_equals_tas_at_sea_level_and_roundtrips():
    assert cas_to_tas(100.0, 0.0) == pytest.approx(100.0, rel=1e-9)
    tas = cas_to_tas(128.6, 3048.0)  # 250 kt CAS at 10,000 ft ≈ 289 kt TAS
    assert mps_to_kt(tas) == pytest.approx(289, abs=2)
    assert tas_to_cas(tas, 3048.0) == pytest.approx(128.6, rel=1e-9)
