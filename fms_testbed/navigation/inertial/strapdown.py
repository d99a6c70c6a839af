"""Strapdown mechanisation of N INS units in one compiled call per navigation step.

Each unit mechanises its IMU's measured increments with the discrete step of
:func:`fms_testbed.sensors.imu.kinematics.forward_step` (WGS-84 NED, Earth and transport rate,
two-sample coning and sculling, trapezoidal position, free vertical channel), after subtracting
the bias compensation the filter has fed back::

    Δθ_c = Δθ̃ - b̂_g Δt,   Δv_c = Δṽ - b̂_a Δt

:func:`bank_step` does a whole navigation step for all units: the slow sensor states advance
(:func:`~fms_testbed.sensors.imu.errors.advance_slow`), then per JSBSim frame the error-free
increments are synthesised once (:func:`~fms_testbed.sensors.imu.synthesis.imu_point`,
:func:`~fms_testbed.sensors.imu.kinematics.inverse_step`), each unit's errors applied
(:func:`~fms_testbed.sensors.imu.errors.measure`) and its state advanced; it returns each unit's
compensated measured specific force and rate averaged over the step, f̄ = ΣΔv_c / T,
ω̄ = ΣΔθ_c / T, and its output (:func:`outputs`).

Outputs refer to the aircraft's reference point, the CG, as an INS does with its installation
lever arm l: p_cg = p_imu - C_b^n l, v_cg = q(ρ) v_imu - C_b^n (ω_eb × l), q_cg = q(ρ) ⊗ q_imu
(ρ the rotation between the two points' local frames), ω_eb = ω - C_n^b ω_ie^n with ω the last
frame's compensated rate;
ENU velocity (E, N, U) = (v_E, v_N, -v_D); the height is given in JSBSim's sea-level datum
(:func:`fms_testbed.core.earth.sea_level_height_m`), the ``alt_m`` of the rest of the package.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.earth import earth_rate_ned, radii_m, sea_level_height_m
from fms_testbed.sensors.imu.errors import (N_ROW, ROW_A, ROW_E, ROW_LSB, ROW_RES, ROW_S,
                                            ROW_WSD, advance_slow, measure_row)
from fms_testbed.sensors.imu.kinematics import (cross3, forward_step, inverse_step, qconj, qmul,
                                                qnormalize, qrot, quat_to_euler, quat_to_rotvec,
                                                rotvec_to_quat)
from fms_testbed.sensors.imu.synthesis import frame_offset_rotation, imu_point, lever_to_imu

N_OUT = 9
"""Output columns: lat rad, lon rad, alt m (sea-level datum), V E N U m/s, roll, pitch, heading
rad."""


@njit(cache=True)
def _cg_position(row, lever):
    """(lat rad, lon rad, h m ellipsoidal) of the CG of a unit whose IMU state is ``row``, and
    the rotation ρ (rad) from the CG's local frame to the IMU's
    (:func:`~fms_testbed.sensors.imu.synthesis.frame_offset_rotation`)."""
    q = (row[6], row[7], row[8], row[9])
    d = qrot(q, (lever[0], lever[1], lever[2]))
    rm, rn = radii_m(row[0])
    rho = frame_offset_rotation(row[0], row[2], d)
    return (row[0] - d[0] / (rm + row[2]), row[1] - d[1] / ((rn + row[2]) * math.cos(row[0])),
            row[2] + d[2], rho)


@njit(cache=True)
def cg_state(row, lever, w_ib):
    """The CG's (φ rad, λ rad, h m ellipsoidal, q_b^n, v NED m/s, ω_eb rad/s) from a unit's IMU
    state ``row``, the lever arm (3,) m and the unit's latest measured rate ``w_ib`` (3,) rad/s:
    q = q(ρ) ⊗ q_imu, v = q(ρ) v_imu - C_b^n (ω_eb × l), ω_eb = ω_ib - C_n^b ω_ie^n."""
    lat, lon, h, rho = _cg_position(row, lever)
    r = rotvec_to_quat(rho)
    q = qmul(r, (row[6], row[7], row[8], row[9]))
    wie = qrot(qconj(q), earth_rate_ned(lat))
    w_eb = (w_ib[0] - wie[0], w_ib[1] - wie[1], w_ib[2] - wie[2])
    lv = qrot(q, cross3(w_eb, (lever[0], lever[1], lever[2])))
    v = qrot(r, (row[3], row[4], row[5]))
    return lat, lon, h, q, (v[0] - lv[0], v[1] - lv[1], v[2] - lv[2]), w_eb


@njit(cache=True)
def output_row(row, lever, w_ib, out):
    """One unit's output (:data:`N_OUT` columns) from its state row, the lever arm (3,) m and
    its latest measured rate ``w_ib`` (3,) rad/s (:func:`cg_state`); returns the CG frame's
    attitude quaternion."""
    lat, lon, h, q, v, _ = cg_state(row, lever, w_ib)
    out[0], out[1], out[2] = lat, lon, sea_level_height_m(lat, h)
    out[3], out[4], out[5] = v[1], v[0], -v[2]
    out[6], out[7], out[8] = quat_to_euler(q)
    return q


@njit(cache=True)
def outputs(rows, lever, w_ib, out):
    """:func:`output_row` of every unit: rows (n, NS), w_ib (n, 3) their latest measured rates
    (rad/s), out (n, 9)."""
    for i in range(rows.shape[0]):
        output_row(rows[i], lever, w_ib[i], out[i])


U_E, U_A, U_S, U_WSD, U_LSB, U_RES = ROW_E, ROW_A, ROW_S, ROW_WSD, ROW_LSB, ROW_RES
U_COMP, U_MEAN, U_W, N_U = N_ROW, N_ROW + 6, N_ROW + 12, N_ROW + 15
"""Column blocks of the per-unit array of :func:`bank_step` (one row per unit): the sensor row
of :data:`fms_testbed.sensors.imu.errors.ROW_E` (errors 36, their one-step a and s 30 each,
white σ per frame 6, quanta 6, quantisation residues 6), then the bias compensation b̂_a m/s²,
b̂_g rad/s (6), the step-mean f̄ m/s², ω̄ rad/s (6), the last frame's compensated rate rad/s
(3)."""
T_MEAN, N_T = 22, 28
"""The truth array of :func:`bank_step`: the IMU's error-free state row (22), then its
step-mean f̄, ω̄ (6)."""


@njit(cache=True)
def bank_step(frames, dt, lever, use_rates, T, rows, U, zslow, zwhite, w0, out):
    """One navigation step of every unit (module docstring).

    frames (n_f, ≥6): the step's JSBSim samples; dt: frame time, s; lever (3,) m; use_rates:
    frames carry body rates; T (:data:`N_T`,): the IMU's error-free state and step means
    (advanced); rows (n, NS): the units' states (advanced); U (n, :data:`N_U`): the units'
    sensor errors, coefficients, compensation and means (read and updated); zslow (n, 30)
    standard normals of the slow states; zwhite (n, ≥w0+n_f, 6) standard normals from row w0;
    out (n, 9) set to the outputs."""
    advance_slow(U, U[:, U_A:U_S], U[:, U_S:U_WSD], zslow)
    n_u = rows.shape[0]
    U[:, U_MEAN:U_W] = 0.0
    T[T_MEAN:] = 0.0
    for j in range(frames.shape[0]):
        v, q = imu_point(frames[j], lever, use_rates, T[0], T[2])
        dth, dv = inverse_step(T, v, q, dt)
        for c in range(3):
            T[T_MEAN + c] += dv[c]
            T[T_MEAN + 3 + c] += dth[c]
        for i in range(n_u):
            u = U[i]
            mth, mv = measure_row(u, dth, dv, dt, zwhite[i], w0 + j)
            cth = (mth[0] - u[U_COMP + 3] * dt, mth[1] - u[U_COMP + 4] * dt,
                   mth[2] - u[U_COMP + 5] * dt)
            cv = (mv[0] - u[U_COMP] * dt, mv[1] - u[U_COMP + 1] * dt, mv[2] - u[U_COMP + 2] * dt)
            forward_step(rows[i], cth, cv, dt)
            for c in range(3):
                u[U_MEAN + c] += cv[c]
                u[U_MEAN + 3 + c] += cth[c]
                u[U_W + c] = cth[c] / dt
    rT = 1.0 / (frames.shape[0] * dt)
    U[:, U_MEAN:U_W] *= rT
    for c in range(6):
        T[T_MEAN + c] *= rT
    outputs(rows, lever, U[:, U_W:N_U], out)


@njit(cache=True)
def mechanise(row, increments, dt):
    """Mechanise a sequence of increments (n, 6: Δθ rad, Δv m/s) from the state ``row`` (in
    place), each ``dt`` s; returns the states after every increment (n, NS)."""
    hist = np.empty((increments.shape[0], row.size))
    for k in range(increments.shape[0]):
        forward_step(row, (increments[k, 0], increments[k, 1], increments[k, 2]),
                     (increments[k, 3], increments[k, 4], increments[k, 5]), dt)
        hist[k] = row
    return hist


@njit(cache=True)
def correct_row(row, dx, lever, w_ib):
    """Feed a filter's estimate back into a unit's state (in place): dx (≥9,) δp E, N, U m of
    the CG, δV E, N, U m/s, ε about E, N, U rad, all *indicated minus true*, with the attitude
    convention C_ind = (I - [ε×]) C_true (ENU); ``w_ib`` (3,) rad/s the unit's mean measured
    rate (for the lever-arm velocity).

    The CG's attitude becomes q(ε_NED) ⊗ q_cg (ε_NED = (ε_N, ε_E, -ε_U)), its velocity v - δV,
    its position p - δp (metres to latitude and longitude at the corrected point); the IMU point
    is then put back where the CG and the lever arm place it
    (:func:`~fms_testbed.sensors.imu.synthesis.lever_to_imu`), and the extrapolation history
    moves with it."""
    lat, lon, h, q, v, w_eb = cg_state(row, lever, w_ib)
    v = (v[0] - dx[4], v[1] - dx[3], v[2] + dx[5])
    q = qnormalize(qmul(rotvec_to_quat((dx[7], dx[6], -dx[8])), q))
    rm, _ = radii_m(lat)
    lat = lat - dx[1] / (rm + h)
    h = h - dx[2]
    _, rn = radii_m(lat)
    lon = lon - dx[0] / ((rn + h) * math.cos(lat))
    v_imu, q_imu = lever_to_imu(q, v, w_eb, lever, lat, h)
    d = qrot(q, (lever[0], lever[1], lever[2]))
    rm, rn = radii_m(lat)
    lat_i = lat + d[0] / (rm + h)
    h_i = h - d[2]
    row[16] += lat_i - row[0]
    row[17] += h_i - row[2]
    row[0], row[1], row[2] = lat_i, lon + d[1] / ((rn + h) * math.cos(lat)), h_i
    for j in range(3):
        row[18 + j] += v_imu[j] - row[3 + j]
        row[3 + j] = v_imu[j]
    for j in range(4):
        row[6 + j] = q_imu[j]


def vertical_gains(tau_s: float, lat_rad: float = 0.0) -> tuple[float, float, float]:
    """Gains (k1 1/s, k2 1/s², k3 1/s³) of a third-order baro loop with its three poles at
    -1/τ: the aided vertical channel h' = -v_D - k1 e, v_D' = ... + k2 e + a_c, a_c' = k3 e
    (e = h_ind - h_baro) has the characteristic polynomial s³ + k1 s² + (k2 - ω_v²) s + k3 =
    (s + 1/τ)³, ω_v² = 2γ/R the free channel's instability (γ normal gravity, R = √(M N)).

    Parameters
    ----------
    tau_s : the loop's time constant τ, s
    lat_rad : latitude where γ and R are taken, rad
    """
    from fms_testbed.core.earth import normal_gravity_mps2
    rm, rn = radii_m(lat_rad)
    wv2 = 2.0 * normal_gravity_mps2(lat_rad, 0.0) / math.sqrt(rm * rn)
    w = 1.0 / tau_s
    return 3.0 * w, 3.0 * w * w + wv2, w ** 3


@njit(cache=True)
def vertical_aid(row, e_m, k1, k2, k3, acc, dt):
    """One step (Δt s) of the third-order baro loop (:func:`vertical_gains`) on a unit's
    state row, in place: e_m = h_ind - h_baro (m); acc (1,) the loop's vertical-acceleration
    correction a_c (m/s², down positive, updated). The extrapolation history moves with the
    state."""
    acc[0] += k3 * e_m * dt
    dh = -k1 * e_m * dt
    dv = (k2 * e_m + acc[0]) * dt
    row[2] += dh
    row[17] += dh
    row[5] += dv
    row[20] += dv


@njit(cache=True)
def nav_errors(out_ind, q_ind, lat, lon, alt, v_enu, q_true, err):
    """Navigation errors, indicated minus true, into err (9,): δp E, N, U m, δV E, N, U m/s, ε
    about E, N, U rad (C_ind = (I - [ε×]) C_true): ε_NED = -rotvec(q_ind ⊗ q_true*)."""
    rm, rn = radii_m(lat)
    err[0] = (out_ind[1] - lon) * (rn + alt) * math.cos(lat)
    err[1] = (out_ind[0] - lat) * (rm + alt)
    err[2] = out_ind[2] - alt
    for j in range(3):
        err[3 + j] = out_ind[3 + j] - v_enu[j]
    r = quat_to_rotvec(qmul(q_ind, qconj(q_true)))
    err[6], err[7], err[8] = -r[1], -r[0], r[2]


__all__ = ["vertical_aid", "vertical_gains", "N_OUT", "N_T", "N_U", "T_MEAN", "U_A", "U_COMP", "U_E", "U_LSB", "U_MEAN",
           "U_RES", "U_S", "U_W", "U_WSD", "bank_step", "cg_state", "correct_row", "mechanise", "nav_errors", "output_row",
           "outputs"]
