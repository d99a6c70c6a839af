"""ISA standard atmosphere (ICAO Doc 7488) with a temperature deviation, and CAS/TAS conversion;
SI units, vectorised.

**Non-standard day** (``isa_dev_c`` = ΔT, K or °C): the temperature is the ISA's plus ΔT at every
altitude, T(h) = T_ISA(h) + ΔT, and the pressure is the hydrostatic integral of that warmer or
colder air from the standard sea-level pressure P0 (dp/dh = −ρ g0, ρ = p / (R T)):

    troposphere:  p = P0 ((T0 + ΔT − L h) / (T0 + ΔT)) ** (g0 / (L R))
    above 11 km:  p = p_11 exp(−g0 (h − 11 km) / (R (T_11 + ΔT)))

This is the model JSBSim 1.3's ``FGStandardAtmosphere`` uses with ``atmosphere/delta-T`` (the
temperature bias over the whole profile, sea-level pressure kept): at a given *altitude* a warm
day has a higher pressure and a lower density than the ISA, so the TAS for a CAS is higher.

**Which altitude.** ``alt_m`` is the altitude the flight flies: JSBSim's ``position/h-sl-ft``,
geometric height above mean sea level (no altimeter setting is modelled, so the aircraft flies
true altitude, not pressure altitude; on a warm day it is at a lower pressure altitude than its
true altitude, :func:`pressure_altitude_m`). The formulas take it as geopotential altitude;
JSBSim converts geometric to geopotential (h_gp = h R / (R + h), R = 6,356,766 m), which is
1.4 m lower at 3 km, 13 m at 9 km and 23 m at 12 km: the TAS for a CAS differs by 0.006 %,
0.06 % and 0.14 % (at the geopotential altitude a test finds JSBSim's T, p and ρ within 1e-4).
"""

from __future__ import annotations

import math

import numpy as np

from fms_testbed.core.units import G0_MPS2

T0_K = 288.15
P0_PA = 101325.0
RHO0_KGPM3 = 1.225
LAPSE_KPM = 0.0065
R_JPKGK = 287.05287
GAMMA = 1.4
H_TROP_M = 11000.0
A0_MPS = float(np.sqrt(GAMMA * R_JPKGK * T0_K))
_N = G0_MPS2 / (LAPSE_KPM * R_JPKGK)   # the pressure exponent g0 / (L R), 5.2559


def isa(alt_m, isa_dev_c=0.0):
    """Temperature (K), pressure (Pa) and density (kg/m³) at altitude ``alt_m`` (m,
    geopotential; module docstring) on a day ``isa_dev_c`` (K) warmer than the ISA: T = T_ISA +
    ΔT, p hydrostatic from P0 through that temperature, ρ = p / (R T) (module docstring)."""
    h = np.asarray(alt_m, dtype=float)
    dt = np.asarray(isa_dev_c, dtype=float)
    hc = np.minimum(h, H_TROP_M)
    t0 = T0_K + dt
    t_trop = t0 - LAPSE_KPM * hc
    p_trop = P0_PA * (t_trop / t0) ** _N
    p = np.where(h <= H_TROP_M, p_trop,
                 p_trop * np.exp(-G0_MPS2 * (h - H_TROP_M) / (R_JPKGK * t_trop)))
    return t_trop, p, p / (R_JPKGK * t_trop)


def pressure_altitude_m(alt_m, isa_dev_c=0.0):
    """Pressure altitude (m): the ISA altitude of the pressure at ``alt_m`` (m) on a day
    ``isa_dev_c`` (K) off the ISA (troposphere), the altitude a standard-set altimeter shows."""
    _, p, _ = isa(alt_m, isa_dev_c)
    return T0_K / LAPSE_KPM * (1.0 - (np.asarray(p) / P0_PA) ** (1.0 / _N))


def altitude_of_pressure_m(p_pa):
    """ISA (pressure) altitude, m, of a static pressure ``p_pa`` (Pa): the inverse of the
    standard day's p(h), troposphere and the isothermal layer above 11 km. A Python float gives
    a float (the same formula in ``math``: the air-data computer calls it every outer step)."""
    if type(p_pa) is float:
        if p_pa >= _P_TROP_PA:
            return T0_K / LAPSE_KPM * (1.0 - (p_pa / P0_PA) ** (1.0 / _N))
        return H_TROP_M - R_JPKGK * _T_TROP_K / G0_MPS2 * math.log(p_pa / _P_TROP_PA)
    p = np.asarray(p_pa, dtype=float)
    h_trop = T0_K / LAPSE_KPM * (1.0 - (p / P0_PA) ** (1.0 / _N))
    h_strat = H_TROP_M - R_JPKGK * _T_TROP_K / G0_MPS2 * np.log(p / _P_TROP_PA)
    return np.where(p >= _P_TROP_PA, h_trop, h_strat)


_T_TROP_K = T0_K - LAPSE_KPM * H_TROP_M
_P_TROP_PA = P0_PA * (_T_TROP_K / T0_K) ** _N


def _qc_pa(cas_mps):
    """Impact pressure of a calibrated airspeed (m/s), Pa (subsonic St-Venant at sea level)."""
    return P0_PA * ((1 + (GAMMA - 1) / 2 * (cas_mps / A0_MPS) ** 2) ** (GAMMA / (GAMMA - 1)) - 1)


def cas_to_tas(cas_mps, alt_m, isa_dev_c=0.0):
    """True airspeed (m/s) for a calibrated airspeed (m/s) at altitude ``alt_m`` (m) on a day
    ``isa_dev_c`` (K) off the ISA, subsonic: q_c from CAS at sea level, M from q_c / p, TAS =
    M √(γ R T)."""
    t, p, _ = isa(alt_m, isa_dev_c)
    qc = _qc_pa(np.asarray(cas_mps, dtype=float))
    mach = np.sqrt(2 / (GAMMA - 1) * ((qc / p + 1) ** ((GAMMA - 1) / GAMMA) - 1))
    return mach * np.sqrt(GAMMA * R_JPKGK * t)


def cas_to_tas_scalar(cas_mps: float, alt_m: float, isa_dev_c: float = 0.0) -> float:
    """:func:`cas_to_tas` for one float (m/s at altitude m, ΔT K): the same formula in ``math``,
    ~20x faster than the numpy version on a scalar (the guidance calls it every outer step)."""
    h = float(alt_m)
    t0 = T0_K + isa_dev_c
    t = t0 - LAPSE_KPM * min(h, H_TROP_M)
    p = P0_PA * (t / t0) ** _N
    if h > H_TROP_M:
        p *= math.exp(-G0_MPS2 * (h - H_TROP_M) / (R_JPKGK * t))
    k = (GAMMA - 1) / GAMMA
    qc = P0_PA * ((1 + (GAMMA - 1) / 2 * (cas_mps / A0_MPS) ** 2) ** (1 / k) - 1)
    mach = math.sqrt(2 / (GAMMA - 1) * ((qc / p + 1) ** k - 1))
    return mach * math.sqrt(GAMMA * R_JPKGK * t)


def tas_to_cas(tas_mps, alt_m, isa_dev_c=0.0):
    """Calibrated airspeed (m/s) for a true airspeed (m/s) at altitude ``alt_m`` (m) on a day
    ``isa_dev_c`` (K) off the ISA, subsonic."""
    t, p, _ = isa(alt_m, isa_dev_c)
    mach = np.asarray(tas_mps, dtype=float) / np.sqrt(GAMMA * R_JPKGK * t)
    qc = p * ((1 + (GAMMA - 1) / 2 * mach**2) ** (GAMMA / (GAMMA - 1)) - 1)
    return A0_MPS * np.sqrt(2 / (GAMMA - 1) * ((qc / P0_PA + 1) ** ((GAMMA - 1) / GAMMA) - 1))


def isa_dev_from_air_data_c(tas_mps: float, mach: float, alt_m: float) -> float:
    """Temperature deviation (K) an air-data computer measures: the static temperature from
    TAS and Mach, T = (TAS / M)² / (γ R), minus the ISA temperature at ``alt_m`` (m)."""
    t = (tas_mps / mach) ** 2 / (GAMMA * R_JPKGK)
    return t - (T0_K - LAPSE_KPM * min(float(alt_m), H_TROP_M))
