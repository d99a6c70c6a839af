"""Error-free IMU increments at the IMU position from JSBSim's per-frame samples.

A navigation source asks the flight loop for :data:`FRAME_PROPERTIES` after every JSBSim frame
(120 Hz), plus :data:`RATE_PROPERTIES` when the IMU sits away from the centre of gravity
(``imu_lever_arm_m`` in the aircraft file). Per frame k the IMU point moves with

    v_imu = q(-ρ) (v_cg + C_b^n (ω_eb^b × l)),   q_b^n,imu = q(-ρ) ⊗ q_b^n (JSBSim's Euler angles),

l the lever arm (body axes, m), ω_eb^b JSBSim's body rate relative to the Earth
(``velocities/p-rad_sec`` ...; measured: p_i - p = C_n^b ω_ie^n to 1e-13 rad/s), and q(-ρ) the
change from the CG's local NED frame to the IMU's (:func:`frame_offset_rotation`, 1.9e-6 rad for
12 m: without it a 115 m/s velocity would read 2e-4 m/s off vertically and the position drift
0.14 m in 10 minutes). The IMU's position is the trapezoidal integral of v_imu from
the start (``position_step``), the rule the mechanisation itself uses, so the samples are
consistent with it by construction; JSBSim's own positions agree with that integral to about
1e-5 m over 10 minutes (measured; the docs' strapdown page), and the height is ellipsoidal
(JSBSim's ``position/geod-alt-ft``; its ``position/h-sl-ft``, the package's ``alt_m``, is a
radial height 1.7 cm above it at 3 km and 47°, :func:`fms_testbed.core.earth.sea_level_height_m`).
Each frame's increments are :func:`~.kinematics.inverse_step` of the previous and the new sample:
mechanised error-free, they reproduce the sampled velocity and attitude to round-off.

JSBSim's properties used (JSBSim 1.3.3): ``velocities/v-north-fps``, ``v-east-fps``,
``v-down-fps`` (velocity of the CG over the Earth in the local geodetic NED frame),
``attitude/phi-rad``, ``theta-rad``, ``psi-rad`` (Euler angles body → local NED), and the rates
``velocities/p-rad_sec``, ``q-rad_sec``, ``r-rad_sec``. The frame time is the navigation step
divided by the number of frames in it (JSBSim's fixed frame time).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.earth import ellipsoidal_height_m, radii_m
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import FT_M
from fms_testbed.sensors.imu.kinematics import (cross3, euler_to_quat, inverse_step, new_row,
                                                qmul, qrot, rotvec_to_quat)

FRAME_PROPERTIES: tuple[tuple[str, float], ...] = (
    ("velocities/v-north-fps", FT_M), ("velocities/v-east-fps", FT_M),
    ("velocities/v-down-fps", FT_M), ("attitude/phi-rad", 1.0), ("attitude/theta-rad", 1.0),
    ("attitude/psi-rad", 1.0))
"""Per-frame samples of the IMU synthesis (``(property, scale to SI)``): NED velocity, Euler."""
RATE_PROPERTIES: tuple[tuple[str, float], ...] = (
    ("velocities/p-rad_sec", 1.0), ("velocities/q-rad_sec", 1.0), ("velocities/r-rad_sec", 1.0))
"""Added when the lever arm is not zero: body rates relative to the Earth, rad/s."""


def frame_properties(lever_arm_m) -> tuple[tuple[str, float], ...]:
    """The properties the IMU needs per frame for lever arm ``lever_arm_m`` (3,) m."""
    return FRAME_PROPERTIES + (RATE_PROPERTIES if np.any(np.asarray(lever_arm_m) != 0.0) else ())


def sample_of(truth: AircraftState) -> np.ndarray:
    """One frame row (v_N, v_E, v_D m/s, roll, pitch, heading rad, p, q, r rad/s) from the true
    state ``truth``: bitwise the values :data:`FRAME_PROPERTIES` read at the same instant."""
    v = truth.v_enu_mps
    return np.array([v[1], v[0], -v[2], truth.roll_rad, truth.pitch_rad, truth.heading_rad,
                     truth.p_rps, truth.q_rps, truth.r_rps])


@njit(cache=True)
def frame_offset_rotation(lat, h, d):
    """ρ (rad): the rotation of the local NED frame between two points ``d`` (NED, m) apart at
    (φ rad, h m), ρ = (d_E/(N + h), -d_N/(M + h), -d_E tan φ/(N + h)) (the transport rate's
    form); NED components transform from the first point's frame to the second's by q(-ρ)."""
    rm, rn = radii_m(lat)
    return (d[1] / (rn + h), -d[0] / (rm + h), -d[1] * math.tan(lat) / (rn + h))


@njit(cache=True)
def lever_to_imu(q, v, w_eb, lever, lat, h):
    """(v_imu NED m/s, q_b^n of the IMU's frame) of a CG moving with velocity ``v`` (NED m/s,
    the CG's local frame) in attitude ``q`` and body rate ``w_eb`` (rad/s, relative to the
    Earth), for the lever arm ``lever`` (3,) m at (φ rad, h m): v_imu = q(-ρ) (v + C_b^n
    (ω_eb × l)), q_imu = q(-ρ) ⊗ q (ρ of :func:`frame_offset_rotation` for the offset C_b^n l)."""
    lv = qrot(q, cross3(w_eb, (lever[0], lever[1], lever[2])))
    rho = frame_offset_rotation(lat, h, qrot(q, (lever[0], lever[1], lever[2])))
    r = rotvec_to_quat((-rho[0], -rho[1], -rho[2]))
    return qrot(r, (v[0] + lv[0], v[1] + lv[1], v[2] + lv[2])), qmul(r, q)


@njit(cache=True)
def imu_point(f, lever, use_rates, lat, h):
    """(v_imu NED m/s, q_b^n) of one frame row ``f`` (:func:`lever_to_imu`; without rates, the
    CG's own velocity and attitude)."""
    q = euler_to_quat(f[3], f[4], f[5])
    v = (f[0], f[1], f[2])
    if use_rates:
        return lever_to_imu(q, v, (f[6], f[7], f[8]), lever, lat, h)
    return v, q


@njit(cache=True)
def synthesize(row, frames, dt, lever, use_rates, out):
    """Error-free increments of every frame: out[j] = (Δθ rad (3), Δv m/s (3)) carrying the IMU
    state ``row`` (:mod:`.kinematics` layout, advanced in place) to frame j of ``frames``
    (n, ≥6 or ≥9 with rates), each frame ``dt`` s long."""
    for j in range(frames.shape[0]):
        v, q = imu_point(frames[j], lever, use_rates, row[0], row[2])
        dth, dv = inverse_step(row, v, q, dt)
        for c in range(3):
            out[j, c] = dth[c]
            out[j, 3 + c] = dv[c]


def start_row(truth: AircraftState, lever_arm_m) -> np.ndarray:
    """The IMU's state row at ``truth`` (the first sample) for the lever arm ``lever_arm_m``
    (3,) m: the CG position moved by C_b^n l (NED offsets to latitude, longitude, height), the
    IMU point's velocity and attitude (:func:`lever_to_imu`); heights ellipsoidal
    (:func:`fms_testbed.core.earth.ellipsoidal_height_m` of ``alt_m``)."""
    lever = np.ascontiguousarray(lever_arm_m, dtype=float)
    f = sample_of(truth)
    h = ellipsoidal_height_m(truth.lat_rad, truth.alt_m)
    v, q = imu_point(f, lever, True, truth.lat_rad, h)
    d = qrot(euler_to_quat(f[3], f[4], f[5]), (lever[0], lever[1], lever[2]))
    rm, rn = radii_m(truth.lat_rad)
    lat = truth.lat_rad + d[0] / (rm + h)
    lon = truth.lon_rad + d[1] / ((rn + h) * math.cos(truth.lat_rad))
    return new_row(lat, lon, h - d[2], v, q)


class ImuSynthesizer:
    """Error-free increments of the IMU at ``lever_arm_m`` from per-frame JSBSim samples.

    Parameters
    ----------
    lever_arm_m : IMU position relative to the CG, body axes (x forward, y right, z down), m
    """

    def __init__(self, lever_arm_m=(0.0, 0.0, 0.0)):
        self.lever = np.ascontiguousarray(lever_arm_m, dtype=float).reshape(3)
        self.use_rates = bool(np.any(self.lever != 0.0))
        self.frame_properties = frame_properties(self.lever)
        self.row: np.ndarray | None = None
        self.t_s: float | None = None

    def start(self, truth: AircraftState) -> None:
        """Start at the true state ``truth`` (no increment yet)."""
        self.row = start_row(truth, self.lever)
        self.t_s = truth.t_s

    def frame_dt(self, truth: AircraftState, frames: np.ndarray | None) -> tuple[np.ndarray, float]:
        """(frames, frame time s) for a navigation step ending at ``truth``; without frames the
        true state is the step's only sample."""
        if frames is None:
            frames = sample_of(truth)[None, :]
        return frames, (truth.t_s - self.t_s) / frames.shape[0]

    def increments(self, truth: AircraftState, frames: np.ndarray | None
                   ) -> tuple[np.ndarray, float]:
        """((n, 6) Δθ rad, Δv m/s per frame, frame time s) from the previous call to ``truth``.

        Raises
        ------
        RuntimeError : not started
        """
        if self.row is None:
            raise RuntimeError("ImuSynthesizer.increments before start()")
        frames, dt = self.frame_dt(truth, frames)
        out = np.empty((frames.shape[0], 6))
        synthesize(self.row, np.ascontiguousarray(frames), dt, self.lever, self.use_rates, out)
        self.t_s = truth.t_s
        return out, dt


__all__ = ["FRAME_PROPERTIES", "RATE_PROPERTIES", "ImuSynthesizer", "frame_properties",
           "frame_offset_rotation", "imu_point", "lever_to_imu", "sample_of", "start_row", "synthesize"]
