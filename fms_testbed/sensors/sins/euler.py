"""Attitude-error conversions between the rotation vector ε (ENU) and Euler-angle errors.

Convention: C_B^N* = (I - ε×) C_B^N with ε about E, N, U (rad); Euler angles body→NED
(heading ψ clockwise from true north, pitch θ nose up, roll γ right wing down), so the
paper's eq. 6.10 holds with these signs (checked against a perturbed DCM in the tests).
Both functions take scalars or arrays of equal shape (vectorised over samples).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def eps_to_euler_errors(eps_e_rad, eps_n_rad, eps_u_rad, pitch_rad, heading_rad):
    """Euler-angle errors from attitude errors (paper eq. 6.10).

    δγ = -sec θ (ε_E sin ψ + ε_N cos ψ);  δθ = -ε_E cos ψ + ε_N sin ψ;
    δψ = ε_U - tan θ (ε_E sin ψ + ε_N cos ψ).

    Parameters
    ----------
    eps_e_rad, eps_n_rad, eps_u_rad : attitude error about E, N, U, rad.
    pitch_rad, heading_rad : true pitch θ and heading ψ, rad.

    Returns
    -------
    (d_roll_rad, d_pitch_rad, d_heading_rad) : measured minus true, rad.
    """
    sp, cp = np.sin(heading_rad), np.cos(heading_rad)
    a = eps_e_rad * sp + eps_n_rad * cp
    d_roll = -a / np.cos(pitch_rad)
    d_pitch = -eps_e_rad * cp + eps_n_rad * sp
    d_head = eps_u_rad - np.tan(pitch_rad) * a
    return d_roll, d_pitch, d_head


@njit(cache=True)
def eps_to_euler_errors_scalar(eps_e_rad, eps_n_rad, eps_u_rad, pitch_rad, heading_rad):
    """:func:`eps_to_euler_errors` (paper eq. 6.10) for scalars, compiled — what the navigation
    kernels call per unit.

    Returns
    -------
    (d_roll_rad, d_pitch_rad, d_heading_rad) : measured minus true, rad.
    """
    sp, cp = math.sin(heading_rad), math.cos(heading_rad)
    a = eps_e_rad * sp + eps_n_rad * cp
    return (-a / math.cos(pitch_rad), -eps_e_rad * cp + eps_n_rad * sp,
            eps_u_rad - math.tan(pitch_rad) * a)


def euler_errors_to_eps(d_roll_rad, d_pitch_rad, d_heading_rad, pitch_rad, heading_rad):
    """Attitude errors from Euler-angle errors (inverse of eq. 6.10).

    ε_E = -δγ cos θ sin ψ - δθ cos ψ;  ε_N = -δγ cos θ cos ψ + δθ sin ψ;  ε_U = -δγ sin θ + δψ.

    Returns
    -------
    (eps_e_rad, eps_n_rad, eps_u_rad) : rad.
    """
    sp, cp = np.sin(heading_rad), np.cos(heading_rad)
    st, ct = np.sin(pitch_rad), np.cos(pitch_rad)
    eps_e = -d_roll_rad * ct * sp - d_pitch_rad * cp
    eps_n = -d_roll_rad * ct * cp + d_pitch_rad * sp
    eps_u = -d_roll_rad * st + d_heading_rad
    return eps_e, eps_n, eps_u


def euler_from_dcm_enu(c_bn: np.ndarray) -> tuple[float, float, float]:
    """(roll, pitch, heading) rad from C_B^N (body FRD → ENU); heading in [0, 2π)."""
    c_ned = c_bn[[1, 0, 2]] * np.array([[1.0], [1.0], [-1.0]])
    roll = float(np.arctan2(c_ned[2, 1], c_ned[2, 2]))
    pitch = float(-np.arcsin(np.clip(c_ned[2, 0], -1.0, 1.0)))
    heading = float(np.arctan2(c_ned[1, 0], c_ned[0, 0]) % (2 * np.pi))
    return roll, pitch, heading
