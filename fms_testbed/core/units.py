"""Units: the one place aviation units meet SI. SI inside the package; ft, kt, NM, FL and degrees
only at the edges (ARINC-424 records, scenario keys that say so, CLI options, plot labels).

Exact conversion factors (international foot and nautical mile, standard gravity).
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
