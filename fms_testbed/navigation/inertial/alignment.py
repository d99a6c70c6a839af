"""Initial alignment of a strapdown INS from its own IMU's data.

Levelling and gyrocompassing (analytic coarse alignment; Britting 1971, Groves §5.6): from the
mean measured specific force f̄ and angular rate ω̄ over an interval at rest (body axes x
forward, y right, z down)::

    roll φ = atan2(-f̄_y, -f̄_z),   pitch θ = atan2(f̄_x, √(f̄_y² + f̄_z²))
    ω^h = R_y(θ) R_x(φ) ω̄ (the rate in the level, heading-fixed frame),  heading ψ = atan2(-ω^h_y, ω^h_x)

At rest the true f^b = -C_n^b g^n and ω^b = C_n^b ω_ie^n, so the sensors' errors leave, to
first order (ε the attitude error with C_ind = (I - [ε×]) C_true, about E, N, U as in the
33-state model; δf^n, δω^n the accelerometer and gyro errors resolved in the navigation frame;
φ latitude, Ω Earth rate, g gravity)::

    levelling:       ε_E = -δf^n_N / g,   ε_N = δf^n_E / g                 (tilt ≈ b_a / g)
    gyrocompassing:  ε_U = -δω^n_E / (Ω cos φ) + tan φ ε_N     (heading ≈ -b_g,E / (Ω cos φ))

these are the residuals every stationary alignment, coarse or fine, is left with: the sensors'
errors at rest are indistinguishable from a tilt and a heading offset (the observability limit),
so a Kalman fine alignment converges to the same values and only shortens the time the white
noise needs (its contribution over T is N/√T on f̄ and ω̄). Tests hold the computed residuals
against these closed forms.

Two starts (:func:`align`):

* ``stationary``: the unit is aligned for ``duration_s`` at rest at the start position with the
  start attitude (the 33-state model's convention, :func:`fms_testbed.sensors.sins.model.alignment_map`)
  and then starts at the start state carrying that alignment's attitude error; its f̄, ω̄ are
  the exact rest increments (:func:`~fms_testbed.sensors.imu.kinematics.inverse_step` between
  two identical samples) with the unit's own errors, plus white noise of σ N/√T.
* ``gnss_heading``: an in-air start: levelling from the measured specific force of the start
  state (the true one plus the unit's errors, the expected f^n = -g^n + (2 ω_ie + ω_en) × v from
  the GNSS velocity, no acceleration assumed: an acceleration a leaves a/g), heading from GNSS
  (dual antenna or track) with the 1σ ``heading_sigma_rad``.
"""

from __future__ import annotations

import math

import numpy as np

from fms_testbed.core.earth import OMEGA_IE_RPS, normal_gravity_mps2, radii_m
from fms_testbed.core.state import AircraftState
from fms_testbed.sensors.imu.errors import ImuErrors, measure
from fms_testbed.sensors.imu.kinematics import (cross3, euler_to_quat, inverse_step, new_row,
                                                qmul, qnormalize, rotvec_to_quat)

ALIGNMENTS = ("stationary", "gnss_heading")


def level_and_gyrocompass(f_b_mps2, w_b_rps) -> tuple[float, float, float]:
    """(roll, pitch, heading) rad of a body at rest (module docstring).

    Parameters
    ----------
    f_b_mps2 : (3,) mean specific force f̄ in body axes, m/s²
    w_b_rps : (3,) mean angular rate ω̄ in body axes, rad/s
    """
    f = np.asarray(f_b_mps2, float)
    w = np.asarray(w_b_rps, float)
    roll = math.atan2(-f[1], -f[2])
    pitch = math.atan2(f[0], math.hypot(f[1], f[2]))
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    wx = cp * w[0] + sp * (sr * w[1] + cr * w[2])      # R_y(θ) R_x(φ) ω̄, x and y rows
    wy = cr * w[1] - sr * w[2]
    return roll, pitch, math.atan2(-wy, wx) % (2.0 * math.pi)


def rest_increments(lat_rad: float, alt_m: float, q_bn, dt_s: float) -> tuple:
    """Error-free (Δθ rad, Δv m/s) of one frame at rest:
    :func:`~fms_testbed.sensors.imu.kinematics.inverse_step` between two identical samples
    (C_n^b ω_ie^n Δt and -C_n^b g^n Δt to the step's own precision).

    Parameters
    ----------
    lat_rad : geodetic latitude, rad;  alt_m : ellipsoidal height, m
    q_bn : (4,) attitude q_b^n;  dt_s : frame time, s
    """
    row = new_row(lat_rad, 0.0, alt_m, (0.0, 0.0, 0.0), q_bn)
    q = tuple(float(x) for x in q_bn)
    return inverse_step(row, (0.0, 0.0, 0.0), q, dt_s)


def _mean_measured(errors: ImuErrors, unit: int, dth, dv, dt_s: float, duration_s: float,
                   rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(f̄ m/s², ω̄ rad/s) of unit ``unit`` measuring (Δθ, Δv) per frame for ``duration_s``:
    its deterministic errors at the frame increments plus the mean of its white noise."""
    p = errors.params[unit]
    mth, mv = measure(errors.E[unit], dth, dv, dt_s, np.zeros(6), np.zeros(6))
    noise = np.sqrt(p.white_psd / duration_s) * rng.standard_normal(6)
    return np.array(mv) / dt_s + noise[:3], np.array(mth) / dt_s + noise[3:]


def stationary_attitude(errors: ImuErrors, unit: int, lat_rad: float, alt_m: float, q_true,
                        duration_s: float, rng: np.random.Generator, dt_s: float = 1.0 / 120.0
                        ) -> tuple:
    """q_b^n a unit finds by levelling and gyrocompassing at rest (module docstring).

    Parameters
    ----------
    errors : the IMUs' error states;  unit : which unit
    lat_rad : latitude, rad;  alt_m : ellipsoidal height, m;  q_true : (4,) true attitude
    duration_s : alignment time T, s;  rng : draws the white-noise mean (σ N/√T)
    dt_s : frame time of the rest increments, s
    """
    dth, dv = rest_increments(lat_rad, alt_m, q_true, dt_s)
    f, w = _mean_measured(errors, unit, dth, dv, dt_s, duration_s, rng)
    return euler_to_quat(*level_and_gyrocompass(f, w))


def expected_specific_force_ned(lat_rad: float, alt_m: float, v_ned_mps) -> np.ndarray:
    """f^n in unaccelerated flight, m/s²: -g^n + (2 ω_ie^n + ω_en^n) × v (NED).

    Parameters
    ----------
    lat_rad : latitude, rad;  alt_m : ellipsoidal height, m;  v_ned_mps : (3,) velocity, m/s
    """
    rm, rn = radii_m(lat_rad)
    v = np.asarray(v_ned_mps, float)
    om = OMEGA_IE_RPS
    w = np.array([2 * om * math.cos(lat_rad) + v[1] / (rn + alt_m), -v[0] / (rm + alt_m),
                  -2 * om * math.sin(lat_rad) - v[1] * math.tan(lat_rad) / (rn + alt_m)])
    return np.cross(w, v) - np.array([0.0, 0.0, normal_gravity_mps2(lat_rad, alt_m)])


def gnss_heading_attitude(errors: ImuErrors, unit: int, truth: AircraftState, alt_m: float,
                          heading_sigma_rad: float, rng: np.random.Generator) -> tuple:
    """q_b^n of an in-air start (module docstring).

    Parameters
    ----------
    errors : the IMUs' error states;  unit : which unit
    truth : the true state (its specific force plus the unit's errors is levelled against the
        expected f^n of :func:`expected_specific_force_ned`)
    alt_m : ellipsoidal height, m
    heading_sigma_rad : 1σ of the GNSS heading, rad;  rng : draws the heading error
    """
    f_true = np.asarray(truth.f_body_mps2, float)
    w_true = np.array([truth.p_rps, truth.q_rps, truth.r_rps])
    mth, mv = measure(errors.E[unit], tuple(w_true), tuple(f_true), 1.0, np.zeros(6),
                      np.zeros(6))
    f = np.array(mv)
    roll, pitch, _ = level_and_gyrocompass(f, np.zeros(3))
    heading = truth.heading_rad + heading_sigma_rad * float(rng.standard_normal())
    q0 = euler_to_quat(roll, pitch, heading)
    v = truth.v_enu_mps
    u = -expected_specific_force_ned(truth.lat_rad, alt_m, (v[1], v[0], -v[2]))
    u = tuple(u / np.linalg.norm(u))
    axis = cross3((0.0, 0.0, 1.0), u)                 # tilt taking "down" to the apparent down
    s = math.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2)
    ang = math.atan2(s, u[2])
    k = ang / s if s > 0 else 0.0
    return qnormalize(qmul(rotvec_to_quat((k * axis[0], k * axis[1], k * axis[2])), q0))


def initial_errors_applied(row: np.ndarray, p0_var: np.ndarray, rng: np.random.Generator) -> None:
    """Add independent initial errors to a state ``row`` in place.

    Parameters
    ----------
    row : a unit's state row (:mod:`fms_testbed.sensors.imu.kinematics` layout)
    p0_var : variances, of which [:9] are used: δp E, N, U m², δV E, N, U m²/s², ε E, N, U
        rad² (an IMU file's ``initial`` block)
    rng : draws the errors
    """
    sd = np.sqrt(np.asarray(p0_var[:9], float))
    if not np.any(sd > 0):
        return
    z = sd * rng.standard_normal(9)
    rm, rn = radii_m(row[0])
    row[0] += z[1] / (rm + row[2])
    row[1] += z[0] / ((rn + row[2]) * math.cos(row[0]))
    row[2] += z[2]
    row[3:6] += (z[4], z[3], -z[5])
    q = qmul(rotvec_to_quat((-z[7], -z[6], z[8])), tuple(row[6:10]))
    row[6:10] = qnormalize(q)


def align(kind: str, errors: ImuErrors, unit: int, imu_row: np.ndarray, truth: AircraftState,
          rng: np.random.Generator, duration_s: float = 300.0,
          heading_sigma_rad: float = 0.0) -> np.ndarray:
    """The unit's initial state row: the true IMU state ``imu_row`` (the synthesis' start row)
    with the attitude its alignment ``kind`` finds (module docstring).

    Parameters
    ----------
    kind : ``stationary`` or ``gnss_heading``
    errors : the IMUs' error states;  unit : which unit
    imu_row : the IMU's true start state (:func:`fms_testbed.sensors.imu.synthesis.start_row`)
    truth : the true state at the start
    rng : the unit's alignment stream (white-noise mean, GNSS heading error)
    duration_s : stationary alignment time T, s
    heading_sigma_rad : 1σ of the GNSS heading, rad

    Raises
    ------
    ValueError : unknown ``kind``
    """
    row = imu_row.copy()
    row[10:] = 0.0                                   # no history, no previous increments
    q_true = tuple(float(x) for x in imu_row[6:10])
    if kind == "stationary":
        q = stationary_attitude(errors, unit, row[0], row[2], q_true, duration_s, rng)
    elif kind == "gnss_heading":
        q = gnss_heading_attitude(errors, unit, truth, row[2], heading_sigma_rad, rng)
    else:
        raise ValueError(f"alignment {kind!r}: expected one of {', '.join(ALIGNMENTS)}")
    row[6:10] = q
    return row


__all__ = ["ALIGNMENTS", "align", "expected_specific_force_ned", "gnss_heading_attitude",
           "initial_errors_applied", "level_and_gyrocompass", "rest_increments",
           "stationary_attitude"]

