"""The Earth model: WGS-84 constants, radii of curvature, normal gravity, Earth and transport rates.

One definition for the whole package (path geodesy, guidance, coupled law, SINS error model).
Reference: NIMA TR8350.2, "Department of Defense World Geodetic System 1984", 3rd ed., Amendment 1
(2000): defining parameters (Table 3.1), derived geometric constants (Table 3.3), derived physical
constants (Table 3.4), normal gravity on the ellipsoid (eq. 4-1, Somigliana) and above it (eq. 4-3,
the second-order Taylor series in height). The same formulas are in Groves, "Principles of GNSS,
Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., eqs. 2.105-2.106 (radii) and
2.134/2.139 (gravity).

Conventions: SI units, geodetic latitude in rad, ellipsoidal height in m, local frame ENU.

The radius and gravity functions are numba-compiled (``@njit(cache=True)``) so that the SINS
kernels (:mod:`fms_testbed.sensors.sins.model`, :mod:`fms_testbed.navigation.sins`) call them
inside their compiled code; called from Python they take a float or a numpy array (any shape,
element-wise) and cost about a microsecond a call on a float. Their cached machine code is
inlined into the SINS kernels' caches: the guard :mod:`fms_testbed.core._numba_cache` hashes this
file for them, so an edit here invalidates the stale kernels.

Which gravity where. *Normal gravity* γ(φ, h) (this module) is the magnitude of gravity of the
level ellipsoid (gravitation plus centrifugal) at a point: physics. The SINS error model applies
it, the coupled law's apparent gravity starts from it, and, since a coordinated turn balances
lift against it, the path builder's turn radii R = V² / (γ tan φ) use γ at the procedure's
reference latitude on the ellipsoid (:func:`fms_testbed.core.geodesy.gravity_mps2`;
9.7803-9.8322 m/s², -0.27 % to +0.26 % about g0). *Standard gravity* g0 = 9.80665 m/s²
(:data:`fms_testbed.core.units.G0_MPS2`) is a unit: load factors (n = force / (m g0)),
accelerometer specifications in mg and µg, and the ISA's geopotential altitude. The guidance's
bank-curvature relation tan φ = V² κ / g takes g0.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# --- defining parameters (TR8350.2 Table 3.1) ---------------------------------------------------
A_M = 6378137.0
"""Semi-major axis a, m."""
FLATTENING = 1.0 / 298.257223563
"""Flattening f = (a - b) / a, dimensionless."""
OMEGA_IE_RPS = 7.292115e-5
"""Earth rotation rate ω, rad/s."""
GM_M3PS2 = 3.986004418e14
"""Earth's gravitational constant GM (atmosphere included), m³/s²."""

# --- derived geometric constants (Table 3.3) -------------------------------------------------------
B_M = A_M * (1.0 - FLATTENING)
"""Semi-minor axis b = a (1 - f), m (6356752.3142)."""
E2 = FLATTENING * (2.0 - FLATTENING)
"""First eccentricity squared e² = f (2 - f), dimensionless (6.69437999014e-3)."""
MEAN_RADIUS_M = (2.0 * A_M + B_M) / 3.0
"""Mean radius of the semi-axes R1 = (2a + b)/3, m (6371008.7714; Table 3.5)."""

# --- derived physical constants (Table 3.4) --------------------------------------------------------
GAMMA_E_MPS2 = 9.7803253359
"""Normal gravity at the equator γ_e, m/s²."""
GAMMA_P_MPS2 = 9.8321849378
"""Normal gravity at the poles γ_p, m/s²."""
K_SOMIGLIANA = 0.00193185265241
"""Somigliana's constant k = b γ_p / (a γ_e) - 1, dimensionless."""
M_RATIO = 0.00344978650684
"""m = ω² a² b / GM, dimensionless."""


@njit(cache=True)
def radii_m(lat_rad):
    """Meridian and prime-vertical radii of curvature of the WGS-84 ellipsoid.

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.

    Returns
    -------
    (M_m, N_m) : meridian radius M = a (1 - e²) / W³ and prime-vertical (transverse) radius
        N = a / W, W = √(1 - e² sin²φ), m (Groves eq. 2.105-2.106). At height h the radii of the
        parallel-to-ellipsoid surface are M + h and N + h.
    """
    rm, rn, _, _ = radii_and_derivatives(lat_rad)
    return rm, rn


@njit(cache=True)
def radii_and_derivatives(lat_rad):
    """Radii of curvature and their latitude derivatives (for the SINS error model's Jacobian).

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.

    Returns
    -------
    (M_m, N_m, dM_dlat_m, dN_dlat_m) : the radii of :func:`radii_m`, m, and
        dM/dφ = 3 a (1 - e²) e² sin φ cos φ / W⁵, dN/dφ = a e² sin φ cos φ / W³, m/rad.
    """
    s, c = np.sin(lat_rad), np.cos(lat_rad)
    w = 1.0 - E2 * s * s
    rn = A_M / np.sqrt(w)
    rm = A_M * (1.0 - E2) / w ** 1.5
    drn = A_M * E2 * s * c / w ** 1.5
    drm = 3.0 * A_M * (1.0 - E2) * E2 * s * c / w ** 2.5
    return rm, rn, drm, drn


@njit(cache=True)
def normal_gravity_mps2(lat_rad, alt_m):
    """Normal gravity γ(φ, h) of WGS-84, m/s².

    Somigliana's closed formula on the ellipsoid (TR8350.2 eq. 4-1)
    ``γ0 = γ_e (1 + k sin²φ) / √(1 - e² sin²φ)`` times the second-order height correction
    (eq. 4-3) ``1 - 2 (h/a)(1 + f + m - 2 f sin²φ) + 3 (h/a)²``. Against the exact
    closed-form normal gravity of the level ellipsoid (Heiskanen & Moritz eq. 2-151) the series
    is within 3e-7 m/s² at 3 km, 7e-7 at 10 km and 1.5e-6 at 20 km, where the inverse-square
    rule γ0 (a/(a+h))² is off by 6e-5, 2e-4 and 4e-4 m/s² (``tests/core/test_earth.py``).

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.
    alt_m : float or ndarray
        Height above the ellipsoid h, m.

    Returns
    -------
    float or ndarray : γ, m/s² (magnitude; the vector points down the ellipsoid normal).
    """
    return normal_gravity_and_gradient(lat_rad, alt_m)[0]


@njit(cache=True)
def normal_gravity_and_gradient(lat_rad, alt_m):
    """Normal gravity and its partial derivatives (for the SINS error model's Jacobian).

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.
    alt_m : float or ndarray
        Height above the ellipsoid h, m.

    Returns
    -------
    (gamma_mps2, dgamma_dlat_mps2, dgamma_dh_ps2) : γ of :func:`normal_gravity_mps2`, m/s²;
        ∂γ/∂φ, m/s² per rad; ∂γ/∂h, 1/s² (negative: about -2γ/a = -3.1e-6 1/s²).
    """
    s, c = np.sin(lat_rad), np.cos(lat_rad)
    s2 = s * s
    w = 1.0 - E2 * s2
    num = 1.0 + K_SOMIGLIANA * s2
    g0 = GAMMA_E_MPS2 * num / np.sqrt(w)
    dg0 = GAMMA_E_MPS2 * (2.0 * K_SOMIGLIANA * s * c / np.sqrt(w) + num * E2 * s * c / w ** 1.5)
    h = alt_m / A_M
    lin = 1.0 + FLATTENING + M_RATIO - 2.0 * FLATTENING * s2
    corr = 1.0 - 2.0 * h * lin + 3.0 * h * h
    dcorr_dlat = 8.0 * FLATTENING * h * s * c
    dcorr_dh = (-2.0 * lin + 6.0 * h) / A_M
    return g0 * corr, dg0 * corr + g0 * dcorr_dlat, g0 * dcorr_dh


def earth_rate_enu(lat_rad):
    """Earth rotation rate in the local ENU frame, ω_IE^N = ω (0, cos φ, sin φ), rad/s.

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.

    Returns
    -------
    ndarray, shape ``np.shape(lat_rad) + (3,)`` : (E, N, U) components, rad/s.
    """
    lat = np.asarray(lat_rad, dtype=float)
    return OMEGA_IE_RPS * np.stack([np.zeros_like(lat), np.cos(lat), np.sin(lat)], axis=-1)


def transport_rate_enu(lat_rad, alt_m, v_enu_mps):
    """Transport rate (rotation of ENU over the ellipsoid) ω_EN^N, rad/s.

    ``ω_EN = (-v_N/(M + h), v_E/(N + h), v_E tan φ/(N + h))`` (Groves eq. 5.44 in ENU; Babich
    2017 eq. 6.2).

    Parameters
    ----------
    lat_rad : float or ndarray
        Geodetic latitude φ, rad.
    alt_m : float or ndarray
        Height above the ellipsoid h, m.
    v_enu_mps : array_like, shape (..., 3)
        Velocity over the Earth, E, N, U, m/s.

    Returns
    -------
    ndarray, shape (..., 3) : (E, N, U) components, rad/s.
    """
    lat = np.asarray(lat_rad, dtype=float)
    v = np.asarray(v_enu_mps, dtype=float)
    rm, rn = radii_m(lat if lat.ndim else float(lat))
    mh, nh = rm + alt_m, rn + alt_m
    return np.stack([-v[..., 1] / mh, v[..., 0] / nh, v[..., 0] * np.tan(lat) / nh], axis=-1)


# --- NED navigation-frame terms and JSBSim's height datum (scalar, compiled) ------------------


@njit(cache=True)
def earth_rate_ned(lat_rad):
    """Earth rotation rate in the local NED frame, ω_IE^n = Ω (cos φ, 0, -sin φ), rad/s.

    Parameters
    ----------
    lat_rad : float
        Geodetic latitude φ, rad.

    Returns
    -------
    tuple of 3 floats : (N, E, D) components, rad/s.
    """
    return (OMEGA_IE_RPS * np.cos(lat_rad), 0.0, -OMEGA_IE_RPS * np.sin(lat_rad))


@njit(cache=True)
def transport_rate_ned(lat_rad, alt_m, v_n_mps, v_e_mps):
    """Transport rate ω_EN^n of the NED frame over the ellipsoid, rad/s.

    ``ω_EN = (v_E/(N + h), -v_N/(M + h), -v_E tan φ/(N + h))`` (Groves eq. 5.44; the ENU form
    is :func:`transport_rate_enu`).

    Parameters
    ----------
    lat_rad : float
        Geodetic latitude φ, rad.
    alt_m : float
        Height above the ellipsoid h, m.
    v_n_mps, v_e_mps : float
        North and east velocity over the Earth, m/s.

    Returns
    -------
    tuple of 3 floats : (N, E, D) components, rad/s.
    """
    rm, rn = radii_m(lat_rad)
    nh = rn + alt_m
    return (v_e_mps / nh, -v_n_mps / (rm + alt_m), -v_e_mps * np.tan(lat_rad) / nh)


@njit(cache=True)
def geodetic_to_ecef_m(lat_rad, lon_rad, alt_m):
    """Earth-centred Earth-fixed position of a geodetic point (Groves eq. 2.112), m.

    Parameters
    ----------
    lat_rad, lon_rad : float
        Geodetic latitude φ and longitude λ, rad.
    alt_m : float
        Height above the ellipsoid h, m.

    Returns
    -------
    tuple of 3 floats : (x, y, z) = ((N + h) cos φ cos λ, (N + h) cos φ sin λ,
        (N (1 - e²) + h) sin φ), m.
    """
    s, c = np.sin(lat_rad), np.cos(lat_rad)
    rn = A_M / np.sqrt(1.0 - E2 * s * s)
    return ((rn + alt_m) * c * np.cos(lon_rad), (rn + alt_m) * c * np.sin(lon_rad),
            (rn * (1.0 - E2) + alt_m) * s)


@njit(cache=True)
def sea_level_height_m(lat_rad, alt_m):
    """JSBSim's ``position/h-sl-ft`` height (in m) of a point at ellipsoidal height ``alt_m``.

    JSBSim measures "sea level" height radially: ``h_sl = |r| - r_e(ψ)``, |r| the geocentric
    distance of the point and r_e(ψ) = a b / √(a² sin²ψ + b² cos²ψ) the radius of the ellipsoid
    at the point's geocentric latitude ψ, while ``position/geod-alt-ft`` is the height along the
    ellipsoid normal. The two differ by about h (φ - ψ)²/2: 1.7 cm at 3 km and 47°, 0 at the
    equator and the poles. This function reproduces JSBSim 1.3.3's value to 1e-8 m.

    Parameters
    ----------
    lat_rad : float
        Geodetic latitude φ, rad.
    alt_m : float
        Height above the ellipsoid h, m.

    Returns
    -------
    float : h_sl, m.
    """
    x, y, z = geodetic_to_ecef_m(lat_rad, 0.0, alt_m)
    rho = np.sqrt(x * x + y * y)
    r = np.sqrt(rho * rho + z * z)
    ss, cs = z / r, rho / r
    return r - A_M * B_M / np.sqrt((A_M * ss) ** 2 + (B_M * cs) ** 2)


@njit(cache=True)
def ellipsoidal_height_m(lat_rad, sea_level_alt_m):
    """Inverse of :func:`sea_level_height_m`: ellipsoidal height h of a point whose JSBSim
    sea-level height is ``sea_level_alt_m`` (fixed-point iteration h ← h + (h_sl - h_sl(h)),
    contraction ≈ (φ - ψ)² < 1.2e-5, three passes reach 1e-12 m).

    Parameters
    ----------
    lat_rad : float
        Geodetic latitude φ, rad.
    sea_level_alt_m : float
        JSBSim's radial height above the ellipsoid (``position/h-sl-ft`` in m), m.

    Returns
    -------
    float : h, m.
    """
    h = sea_level_alt_m
    for _ in range(3):
        h += sea_level_alt_m - sea_level_height_m(lat_rad, h)
    return h


@njit(cache=True)
def local_terms(lat_rad, alt_m):
    """The Earth terms a strapdown step needs at one point, with one square root.

    Parameters
    ----------
    lat_rad : float
        Geodetic latitude φ, rad.
    alt_m : float
        Height above the ellipsoid h, m.

    Returns
    -------
    (sin φ, cos φ, 1/(M + h) 1/m, 1/(N + h) 1/m, γ m/s²) : the radii of :func:`radii_m` and the
        normal gravity of :func:`normal_gravity_mps2` (the same formulas, rearranged).
    """
    s, c = np.sin(lat_rad), np.cos(lat_rad)
    s2 = s * s
    w = 1.0 - E2 * s2
    rw = 1.0 / np.sqrt(w)
    rn = A_M * rw
    rm = A_M * (1.0 - E2) * rw / w
    h = alt_m / A_M
    g = GAMMA_E_MPS2 * (1.0 + K_SOMIGLIANA * s2) * rw * (
        1.0 - 2.0 * h * (1.0 + FLATTENING + M_RATIO - 2.0 * FLATTENING * s2) + 3.0 * h * h)
    return s, c, 1.0 / (rm + alt_m), 1.0 / (rn + alt_m), g
