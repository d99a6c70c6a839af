"""Continuous 33-state SINS error model: F, G, Q from the true state (Babich 2017, §5-6).

State vector ``x`` (SI units; index slices below)::

    0:3   δp     position error E, N, U, m (δE = (R_N+h) cos φ δλ, δN = (R_M+h) δφ, δU = δh)
    3:6   δV     velocity error E, N, U, m/s
    6:9   ε      attitude error, small rotations about E, N, U, rad: C_B^N* = (I - ε×) C_B^N
    9:12  b_a    accelerometer bias, body FRD, m/s^2
    12:15 b_g    gyro bias, body FRD, rad/s
    15:18 k_a    accelerometer scale-factor errors, dimensionless
    18:21 k_g    gyro scale-factor errors, dimensionless
    21:27 β_a    accelerometer misalignments, rad (Γ rows [y z 0 0 0 0], [0 0 x z 0 0], [0 0 0 0 x y])
    27:33 β_g    gyro misalignments, rad

Errors are *measured minus true*. The error equations (paper eq. 6.7) are the standard ENU ones
(Groves ch. 14) linearised from the mechanisation :func:`mechanisation_rates` (eq. 6.2-6.4); they
are first formed in geodetic coordinates (δφ, δλ, δh) and then carried to metres with
``F = T F_geo T⁻¹ + Ṫ T⁻¹``. Sensor errors (eq. 5.1-5.6)::

    δa^B = b_a + D_a k_a + Γ_a β_a + η_a,   δω^B = b_g + D_g k_g + Γ_g β_g + η_g
    ξ' = -ξ/τ + η  (first-order Gauss-Markov, q = 2σ²/τ), τ = inf: random walk / random constant

Earth: :mod:`fms_testbed.core.earth` — WGS-84 radii, normal gravity γ(φ, h) (Somigliana with the
second-order height term, NIMA TR8350.2 eq. 4-1, 4-3) and its gradient, no deflection of the
vertical. The noise input matrix is G = blockdiag(0, C_B^N, -C_B^N, I_24); because each triad's
channels are alike, Q = G Q1 Gᵀ is diagonal and constant (eq. 6.9).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.earth import (OMEGA_IE_RPS, earth_rate_enu, normal_gravity_and_gradient,
                                   radii_and_derivatives, radii_m, transport_rate_enu)

N_STATES = 33
POS, VEL, ATT = slice(0, 3), slice(3, 6), slice(6, 9)
BA, BG, KA, KG, MA, MG = (slice(9, 12), slice(12, 15), slice(15, 18), slice(18, 21),
                          slice(21, 27), slice(27, 33))
STATE_NAMES = (
    [f"dp_{c}_m" for c in "enu"] + [f"dv_{c}_mps" for c in "enu"]
    + [f"eps_{c}_rad" for c in "enu"] + [f"ba_{c}_mps2" for c in "xyz"]
    + [f"bg_{c}_rps" for c in "xyz"] + [f"ka_{c}" for c in "xyz"] + [f"kg_{c}" for c in "xyz"]
    + [f"ma_{i}_rad" for i in range(1, 7)] + [f"mg_{i}_rad" for i in range(1, 7)])


@njit(cache=True)
def gravity_up(lat_rad, alt_m):
    """Up component of gravity and its derivatives: (g_U, ∂g_U/∂φ, ∂g_U/∂h), m/s², per rad, 1/s².

    g_U = -γ(φ, h), γ the normal gravity of :func:`fms_testbed.core.earth.normal_gravity_mps2`
    (latitude φ in rad, height h in m).
    """
    g, dg_dlat, dg_dh = normal_gravity_and_gradient(lat_rad, alt_m)
    return -g, -dg_dlat, -dg_dh


def dcm_body_to_enu(roll_rad: float, pitch_rad: float, heading_rad: float) -> np.ndarray:
    """C_B^N: body (forward, right, down) to ENU, from Euler angles body→NED (ψ, θ, γ; rad)."""
    cr, sr = math.cos(roll_rad), math.sin(roll_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    ch, sh = math.cos(heading_rad), math.sin(heading_rad)
    c_ned = np.array([
        [cp * ch, sr * sp * ch - cr * sh, cr * sp * ch + sr * sh],
        [cp * sh, sr * sp * sh + cr * ch, cr * sp * sh - sr * ch],
        [-sp, sr * cp, cr * cp]])
    return c_ned[[1, 0, 2]] * np.array([[1.0], [1.0], [-1.0]])


@njit(cache=True)
def _skew_into(out, r0, c0, v, sign):
    """out[r0:r0+3, c0:c0+3] += sign * [v×]."""
    out[r0, c0 + 1] += -sign * v[2]
    out[r0, c0 + 2] += sign * v[1]
    out[r0 + 1, c0] += sign * v[2]
    out[r0 + 1, c0 + 2] += -sign * v[0]
    out[r0 + 2, c0] += -sign * v[1]
    out[r0 + 2, c0 + 1] += sign * v[0]


@njit(cache=True)
def _metres_maps(s, c, mh, nh, drm, drn, lat_dot, h_dot):
    """T (δp = T δr_geo: geodetic errors to metres E, N, U), T⁻¹ and dT/dt, for the
    meridian/normal radii ``mh``, ``nh`` (m, height included) and their latitude derivatives."""
    T = np.zeros((3, 3))
    T[0, 1] = nh * c
    T[1, 0] = mh
    T[2, 2] = 1.0
    Ti = np.zeros((3, 3))
    Ti[0, 1] = 1.0 / mh
    Ti[1, 0] = 1.0 / (nh * c)
    Ti[2, 2] = 1.0
    Td = np.zeros((3, 3))
    Td[0, 1] = (drn * lat_dot + h_dot) * c - nh * s * lat_dot
    Td[1, 0] = drm * lat_dot + h_dot
    return T, Ti, Td


@njit(cache=True)
def _navigation_blocks(F, lat_rad, alt_m, v_enu_mps, f_b_mps2, c_bn):
    """Rows 0-8 (position m, velocity ENU m/s, attitude rad) of F, columns 0-8, in place
    (paper eq. 5.1-5.4 with δp = T δr_geo)."""
    vE, vN, vU = v_enu_mps[0], v_enu_mps[1], v_enu_mps[2]
    s, c = math.sin(lat_rad), math.cos(lat_rad)
    t = s / c
    rm, rn, drm, drn = radii_and_derivatives(lat_rad)
    mh, nh = rm + alt_m, rn + alt_m
    _, dg_dlat, dg_dh = gravity_up(lat_rad, alt_m)
    W = OMEGA_IE_RPS
    # --- geodetic blocks, columns (δφ, δλ, δh) ---
    frr = np.zeros((3, 3))           # rows (φ', λ', h')
    frr[0, 0] = -vN * drm / mh ** 2
    frr[0, 2] = -vN / mh ** 2
    frr[1, 0] = vE * (s / (nh * c * c) - drn / (nh * nh * c))
    frr[1, 2] = -vE / (nh * nh * c)
    # ∂ω_IE/∂r and ∂ω_EN/∂r, ∂ω_EN/∂V (ENU components)
    die = np.zeros((3, 3))
    die[1, 0] = -W * s
    die[2, 0] = W * c
    den = np.zeros((3, 3))
    den[0, 0] = vN * drm / mh ** 2
    den[0, 2] = vN / mh ** 2
    den[1, 0] = -vE * drn / nh ** 2
    den[1, 2] = -vE / nh ** 2
    den[2, 0] = vE * (1.0 / (c * c * nh) - t * drn / nh ** 2)
    den[2, 2] = -vE * t / nh ** 2
    dev = np.zeros((3, 3))
    dev[0, 1] = -1.0 / mh
    dev[1, 0] = 1.0 / nh
    dev[2, 0] = t / nh
    w_ie = np.array([0.0, W * c, W * s])
    w_en = np.array([-vN / mh, vE / nh, vE * t / nh])
    w_in = w_ie + w_en
    vx = np.zeros((3, 3))
    _skew_into(vx, 0, 0, v_enu_mps, 1.0)
    fvr = vx @ (2.0 * die + den)
    fvr[2, 0] += dg_dlat
    fvr[2, 2] += dg_dh
    fer = die + den
    T, Ti, Td = _metres_maps(s, c, mh, nh, drm, drn, vN / mh, vU)  # δp = T δr_geo
    F[0:3, 0:3] = T @ frr @ Ti + Td @ Ti
    F[0, 3] = 1.0
    F[1, 4] = 1.0
    F[2, 5] = 1.0
    F[3:6, 0:3] = fvr @ Ti
    F[3:6, 3:6] = vx @ dev
    _skew_into(F, 3, 3, 2.0 * w_ie + w_en, -1.0)
    f_n = c_bn @ f_b_mps2
    _skew_into(F, 3, 6, f_n, 1.0)
    F[6:9, 0:3] = fer @ Ti
    F[6:9, 3:6] = dev
    _skew_into(F, 6, 6, w_in, -1.0)


@njit(cache=True)
def _sensor_blocks(F, a, w, c_bn, decay_rps):
    """Sensor-error columns 9-32 of F in place: accelerometer bias, gyro drift, scale factors,
    misalignments driven by the specific force ``a`` (m/s²) and rate ``w`` (rad/s) in body
    axes, and the Gauss-Markov decays on the diagonal (paper eq. 5.5-5.6)."""
    # --- sensor errors ---
    for i in range(3):
        for j in range(3):
            F[3 + i, 9 + j] = c_bn[i, j]
            F[6 + i, 12 + j] = -c_bn[i, j]
            F[3 + i, 15 + j] = c_bn[i, j] * a[j]
            F[6 + i, 18 + j] = -c_bn[i, j] * w[j]
        # misalignments: column (axis, multiplier) pairs (x: y, z), (y: x, z), (z: x, y)
        F[3 + i, 21] = c_bn[i, 0] * a[1]
        F[3 + i, 22] = c_bn[i, 0] * a[2]
        F[3 + i, 23] = c_bn[i, 1] * a[0]
        F[3 + i, 24] = c_bn[i, 1] * a[2]
        F[3 + i, 25] = c_bn[i, 2] * a[0]
        F[3 + i, 26] = c_bn[i, 2] * a[1]
        F[6 + i, 27] = -c_bn[i, 0] * w[1]
        F[6 + i, 28] = -c_bn[i, 0] * w[2]
        F[6 + i, 29] = -c_bn[i, 1] * w[0]
        F[6 + i, 30] = -c_bn[i, 1] * w[2]
        F[6 + i, 31] = -c_bn[i, 2] * w[0]
        F[6 + i, 32] = -c_bn[i, 2] * w[1]
    for k in range(24):
        F[9 + k, 9 + k] = -decay_rps[k]


@njit(cache=True)
def build_F(lat_rad, alt_m, v_enu_mps, f_b_mps2, w_ib_b_rps, c_bn, decay_rps, k1_rps, k2_rps2):
    """System matrix F (33×33) of the SINS error model at one true state (paper eq. 6.7, 5.1-5.6).

    Parameters
    ----------
    lat_rad, alt_m : true geodetic latitude (rad) and height (m).
    v_enu_mps : (3,) true velocity E, N, U, m/s.
    f_b_mps2 : (3,) true specific force in body FRD, m/s².
    w_ib_b_rps : (3,) true inertial angular rate in body FRD, rad/s.
    c_bn : (3, 3) C_B^N, body FRD → ENU.
    decay_rps : (24,) 1/τ of the sensor states 9..32 (0 for random walk/constant), 1/s.
    k1_rps, k2_rps2 : baro damping gains of the vertical channel (0, 0 = free), 1/s and 1/s².

    Returns
    -------
    F : (33, 33) array, 1/s in the units of the state vector.
    """
    F = np.zeros((33, 33))
    _navigation_blocks(F, lat_rad, alt_m, v_enu_mps, f_b_mps2, c_bn)
    _sensor_blocks(F, f_b_mps2, w_ib_b_rps, c_bn, decay_rps)
    # --- optional baro damping of the vertical channel (reference height error taken as 0) ---
    F[2, 2] -= k1_rps
    F[5, 2] -= k2_rps2
    return F


def noise_input_matrix(c_bn: np.ndarray) -> np.ndarray:
    """G (33×33): white noises η (eq. 6.9 order) into the state; blockdiag(0, C_B^N, -C_B^N, I)."""
    G = np.zeros((N_STATES, N_STATES))
    G[VEL, VEL] = c_bn
    G[ATT, ATT] = -c_bn
    G[9:, 9:] = np.eye(24)
    return G


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def mechanisation_rates(lat_rad: float, alt_m: float, v_enu_mps: np.ndarray, c_bn: np.ndarray,
                        f_b_mps2: np.ndarray, w_ib_b_rps: np.ndarray):
    """Right-hand side of the nonlinear ENU mechanisation (paper eq. 6.2-6.4).

    Returns (φ' rad/s, λ' rad/s, h' m/s, V' (3,) m/s², C' (3, 3) 1/s). Gravity has only an up
    component (:func:`gravity_up`). Used as the reference the linear model is checked against.
    """
    rm, rn = radii_m(lat_rad)
    v = np.asarray(v_enu_mps, float)
    lat_dot = v[1] / (rm + alt_m)
    lon_dot = v[0] / ((rn + alt_m) * math.cos(lat_rad))
    w_ie = earth_rate_enu(lat_rad)
    w_en = transport_rate_enu(lat_rad, alt_m, v)
    g = np.array([0.0, 0.0, gravity_up(lat_rad, alt_m)[0]])
    v_dot = c_bn @ f_b_mps2 - np.cross(2 * w_ie + w_en, v) + g
    c_dot = c_bn @ _skew(w_ib_b_rps) - _skew(w_ie + w_en) @ c_bn
    return lat_dot, lon_dot, v[2], v_dot, c_dot


def baro_gains(tau_s: float | None, lat_rad: float = 0.0) -> tuple[float, float]:
    """Gains (k1 1/s, k2 1/s²) of a critically damped baro loop with time constant ``tau_s``.

    Closed loop s² + k1 s + (k2 - ∂g_U/∂h) = (s + 1/τ)², ∂g_U/∂h ≈ 2g/a the free vertical
    channel's instability (:func:`gravity_up` at height 0, latitude ``lat_rad`` in rad); ``None``
    means no damping (0, 0).
    """
    if tau_s is None:
        return 0.0, 0.0
    w = 1.0 / tau_s
    return 2.0 * w, w * w + gravity_up(lat_rad, 0.0)[2]


def alignment_map(lat_rad: float, c_bn: np.ndarray, decay_rps: np.ndarray) -> np.ndarray:
    """A (33×33): initial state x0 = A z after a stationary self-alignment at attitude C_B^N.

    z holds independent initial errors (sensor states, and any extra position/velocity/attitude
    errors). Levelling nulls the horizontal velocity-error rate and gyrocompassing the east
    attitude-error rate at rest (f^N = (0, 0, g), ω_IB = Earth rate), so the attitude errors take
    up the sensor errors seen at alignment (s = sensor states, F_vs, F_εs the sensor columns of F):

        ε_N += (F_vs s)_E / g,   ε_E += -(F_vs s)_N / g,   ε_U += tan φ ε_N + (F_εs s)_E / (Ω cos φ)

    Parameters
    ----------
    lat_rad : latitude of the alignment, rad.
    c_bn : (3, 3) C_B^N at alignment (body FRD → ENU).
    decay_rps : (24,) sensor decay rates (they do not enter the result, F is built with them).
    """
    g = -gravity_up(lat_rad, 0.0)[0]
    w_ie = earth_rate_enu(lat_rad)
    f_b = c_bn.T @ np.array([0.0, 0.0, g])
    F = build_F(float(lat_rad), 0.0, np.zeros(3), f_b, c_bn.T @ w_ie, np.ascontiguousarray(c_bn),
                np.asarray(decay_rps, float), 0.0, 0.0)
    A = np.eye(N_STATES)
    fvs, fes = F[3:6, 9:], F[6:9, 9:]
    A[7, 9:] += fvs[0] / g                          # ε_N from the east accelerometer error
    A[6, 9:] += -fvs[1] / g                         # ε_E from the north accelerometer error
    A[8, 9:] += math.tan(lat_rad) * A[7, 9:] + fes[0] / (OMEGA_IE_RPS * math.cos(lat_rad))
    return A
