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


def test_isa_deviation_is_hydrostatic_from_standard_sea_level_pressure():
    """T = T_ISA + ΔT at every altitude; p integrates dp/dh = −ρ g0 from P0 (checked against a
    numerical integral); ΔT = 0 is the ISA."""
    import numpy as np
    from fms_testbed.core.units import G0_MPS2

    for dev in (-20.0, 0.0, 15.0, 30.0):
        h = np.linspace(0.0, 14000.0, 14001)
        t, p, rho = isa(h, dev)
        assert t[0] == pytest.approx(288.15 + dev) and p[0] == pytest.approx(101325.0)
        assert t[5000] == pytest.approx(288.15 - 32.5 + dev)
        p_num = 101325.0 * np.exp(-np.concatenate(([0.0], np.cumsum(
            G0_MPS2 * 0.5 * (rho[1:] / p[1:] + rho[:-1] / p[:-1]) * np.diff(h)))))
        assert np.max(np.abs(p_num / p - 1.0)) < 1e-6
    assert isa(3000.0, 0.0)[1] == pytest.approx(isa(3000.0)[1], rel=1e-12)


def test_warm_day_flies_a_higher_tas_for_the_same_cas():
    """250 kt CAS at 3000 m: TAS rises ~1.2 %/10 °C (√T at nearly equal pressure ratio); the
    scalar and the array versions agree; TAS → CAS round-trips on the same day."""
    from fms_testbed.core.atmosphere import cas_to_tas_scalar, pressure_altitude_m

    cas = 250 * 0.514444
    v = {d: float(cas_to_tas(cas, 3000.0, d)) for d in (-20.0, 0.0, 20.0)}
    assert v[-20.0] < v[0.0] < v[20.0]
    assert v[20.0] / v[0.0] == pytest.approx(1.0245, abs=0.002)
    for d, tas in v.items():
        assert cas_to_tas_scalar(cas, 3000.0, d) == pytest.approx(tas, rel=1e-12)
        assert float(tas_to_cas(tas, 3000.0, d)) == pytest.approx(cas, rel=1e-9)
    # a warm day: the pressure at 3000 m is that of a lower altitude
    assert pressure_altitude_m(3000.0, 20.0) < 3000.0 < pressure_altitude_m(3000.0, -20.0)
    assert float(pressure_altitude_m(3000.0, 0.0)) == pytest.approx(3000.0, abs=0.01)


def test_air_data_temperature_deviation():
    from fms_testbed.core.atmosphere import GAMMA, R_JPKGK, isa_dev_from_air_data_c

    t = isa(2000.0, 12.0)[0]
    a = (GAMMA * R_JPKGK * t) ** 0.5
    assert isa_dev_from_air_data_c(0.6 * a, 0.6, 2000.0) == pytest.approx(12.0, abs=1e-9)
