"""Units: the one place aviation units meet SI. SI inside the package; ft, kt, NM, FL and degrees
only at the edges (ARINC-424 records, scenario keys that say so, CLI options, plot labels).

Exact conversion factors by definition: the international foot (0.3048 m) and nautical mile
(1852 m), 1959/1929; standard gravity g0 = 9.80665 m/s² (CGPM 1901), the unit of load factors and
of accelerometer specifications (mg, µg) — not the local gravity, which is
:func:`fms_testbed.core.earth.normal_gravity_mps2`. Each constant is "one <unit> in SI"; the
converters take a float or a numpy array (or a pandas Series).
"""

from __future__ import annotations

import math

FT_M = 0.3048
"""One foot in metres (exact)."""
NM_M = 1852.0
"""One nautical mile in metres (exact)."""
KT_MPS = NM_M / 3600.0
"""One knot in m/s."""
KMH_MPS = 1000.0 / 3600.0
"""One km/h in m/s."""
FPM_MPS = FT_M / 60.0
"""One foot per minute in m/s."""
G0_MPS2 = 9.80665
"""Standard gravity, m/s² (the g of load factors, the 'g' of accelerometer specs)."""
DEG_RAD = math.pi / 180.0
"""One degree in radians."""
DPH_RPS = DEG_RAD / 3600.0
"""One degree per hour in rad/s."""
LB_KG = 0.45359237
"""One (avoirdupois) pound in kilograms (exact)."""
LBF_N = LB_KG * G0_MPS2
"""One pound-force in newtons (exact: lb × g0, 4.4482216152605)."""
SLUG_KG = LBF_N / FT_M
"""One slug (lbf·s²/ft) in kilograms (exact, 14.5939029372)."""
PSF_PA = LBF_N / FT_M ** 2
"""One pound-force per square foot in pascals (exact, 47.880259)."""
RANKINE_K = 5.0 / 9.0
"""One degree Rankine in kelvin (a temperature in °R times this is the temperature in K)."""


def ft_to_m(x_ft):
    """Feet → metres."""
    return x_ft * FT_M


def m_to_ft(x_m):
    """Metres → feet."""
    return x_m / FT_M


def kt_to_mps(x_kt):
    """Knots → m/s."""
    return x_kt * KT_MPS


def mps_to_kt(x_mps):
    """m/s → knots."""
    return x_mps / KT_MPS


def nm_to_m(x_nm):
    """Nautical miles → metres."""
    return x_nm * NM_M


def m_to_nm(x_m):
    """Metres → nautical miles."""
    return x_m / NM_M


def kmh_to_mps(x_kmh):
    """km/h → m/s."""
    return x_kmh * KMH_MPS


def mps_to_kmh(x_mps):
    """m/s → km/h."""
    return x_mps * 3.6


def fpm_to_mps(x_fpm):
    """Feet per minute → m/s."""
    return x_fpm * FPM_MPS


def mps_to_fpm(x_mps):
    """m/s → feet per minute."""
    return x_mps / FPM_MPS


def dph_to_rps(x_dph):
    """Degrees per hour → rad/s."""
    return x_dph * DPH_RPS


def rps_to_dph(x_rps):
    """rad/s → degrees per hour."""
    return x_rps / DPH_RPS
