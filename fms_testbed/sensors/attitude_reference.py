"""Attitude reference under flight test, the truth side: its heading/roll/pitch errors, and the
errors of the flight-test strapdown computer that resolves accelerometers with its angles
(seed 004, Filyashkin & Rogozhin, Fig. 1).

The reference (a vertical gyro, a heading-and-attitude reference, an INS under test) outputs
angles, indicated minus true (rad)::

    δγ(t), δϑ(t), δψ(t) = θ_0 + ∫ d dt + ∫ w_θ dt,   ḋ = w_d

θ_0 the constant errors, d the drift of each angle (rad/s; the "systematic gyro errors" of the
reference, seen at its angle outputs after its own erection and slaving loops), w_θ an angle
random walk and w_d a drift random walk (white, densities ``arw`` and ``drift_rw``). These angles
form the direction-cosine matrix B of seed 004 that resolves a block of accurate accelerometers
(bias b_a, white noise) into the navigation frame; position and velocity are then integrated.
With C̃ = C(γ+δγ, ϑ+δϑ, ψ+δψ) = (I - ε×) C and ε = M(ϑ, ψ) (δγ, δϑ, δψ) (the inverse of eq. 6.10,
:func:`~fms_testbed.sensors.sins.euler.euler_errors_to_eps`), the computer's error state (15,
seed 004's order with the attitude errors as Euler angles)::

    0:3 δp E, N, U, m   3:6 δV E, N, U, m/s   6:9 δγ, δϑ, δψ, rad   9:12 d_γ, d_ϑ, d_ψ, rad/s
    12:15 b_a x, y, z (body), m/s²

obeys ẋ = F x + w with the position/velocity rows of the project's SINS model
(:func:`~fms_testbed.sensors.sins.model.build_F`, free vertical channel) and
δV̇ = … + [f^N ×] M (δγ, δϑ, δψ) + C b_a. This is the filter's model; the truth side is one of:

* ``truth_model: strapdown`` (default): :class:`FlightTestSensors` — the accelerometer block's
  measured increments (error-free increments of the sampled motion plus the preset's errors)
  and the reference's output angles (the sampled attitude plus :class:`ReferenceAngleErrors`);
  the computer that mechanises them is navigation's
  (:class:`fms_testbed.navigation.attitude_reference.FlightTestComputer`), so its errors are
  whatever the nonlinear mechanisation makes of the sensors' errors;
* ``truth_model: linear`` (the fast mode): :class:`FlightTestErrors` propagates this linear
  model at the true state (the project's convention for INS errors: truth ⊕ an error
  realisation), discretised by the Picard series
  (:func:`~fms_testbed.sensors.sins.discretize.discretize`).

Closed loop: the computer resolves the accelerometers with the reference's angles minus its
current estimate of their errors, c(t) (ċ = c_d, both updated by the filter's feedback,
:meth:`FlightTestErrors.reset`); the angle states above are then the *residual* errors
θ - c, d - c_d of the angles it uses, small once the filter has converged, so the linear model
stays exact to second order in the residual (with the reference's full 0.5° errors in the
model, the neglected ε×(ε×f) term reaches 1e-3 m/s² in a 25° turn — a 0.005° tilt). The
reference's own error is θ = (θ - c) + c.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.earth import radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState
from fms_testbed.sensors.imu.errors import (N_ROW, ROW_A, ROW_RES, ROW_S, ROW_WSD,
                                            ImuErrors, advance_slow, imu_error_params,
                                            measure_row)
from fms_testbed.sensors.imu.synthesis import (FRAME_PROPERTIES, frame_properties, sample_of,
                                              start_row, synthesize)
from fms_testbed.sensors.sins.discretize import discretize
from fms_testbed.sensors.sins.euler import euler_errors_to_eps
from fms_testbed.sensors.sins.model import build_F, dcm_body_to_enu
from fms_testbed.sensors.sins.presets import ImuModel

N_STATES = 15
POS, VEL, ANG, DRIFT, BA = (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 15))
ANGLES = ("roll", "pitch", "heading")
"""Order of the reference's angle errors in the state (δγ, δϑ, δψ)."""


@dataclass(frozen=True)
class AttitudeReferenceSpec:
    """Error model of the attitude reference, SI, per angle (roll, pitch, heading), 1σ.

    bias_sigma_rad : σ of the constant errors θ_0, rad
    drift_sigma_rps : σ of the drift rates d (random constants), rad/s
    arw_rad_rs : angle random walk density, rad/√s
    drift_rw_rps_rs : drift random walk density, rad/s/√s
    bias_rad, drift_rps : the injected values (rad, rad/s); None: drawn from the σ by the seed
    """

    bias_sigma_rad: tuple[float, float, float]
    drift_sigma_rps: tuple[float, float, float]
    arw_rad_rs: tuple[float, float, float] = (0.0, 0.0, 0.0)
    drift_rw_rps_rs: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bias_rad: tuple[float, float, float] | None = None
    drift_rps: tuple[float, float, float] | None = None

    def __post_init__(self):
        for name in ("bias_sigma_rad", "drift_sigma_rps", "arw_rad_rs", "drift_rw_rps_rs"):
            v = getattr(self, name)
            if len(v) != 3 or not all(math.isfinite(x) and x >= 0 for x in v):
                raise ConfigError(f"navigation.reference.{name}: three finite values >= 0 "
                                  "(roll, pitch, heading)")
        for name in ("bias_rad", "drift_rps"):
            v = getattr(self, name)
            if v is not None and (len(v) != 3 or not all(math.isfinite(x) for x in v)):
                raise ConfigError(f"navigation.reference.{name}: three finite values")


def euler_to_eps_matrix(pitch_rad: float, heading_rad: float) -> np.ndarray:
    """M (3×3): ε (E, N, U, rad) = M (δγ, δϑ, δψ) — the inverse of paper eq. 6.10 as a matrix.

    Parameters
    ----------
    pitch_rad, heading_rad : pitch ϑ and heading ψ, rad
    """
    cols = [euler_errors_to_eps(*np.eye(3)[j], pitch_rad, heading_rad) for j in range(3)]
    return np.array(cols, float).T


def system_matrix(lat_rad: float, alt_m: float, v_enu_mps, f_b_mps2, rpy_rad,
                  ba_decay_rps) -> np.ndarray:
    """F (15×15) of the flight-test computer's error model (module docstring).

    Parameters
    ----------
    lat_rad, alt_m : latitude (rad) and height (m) the model is linearised at
    v_enu_mps : (3,) velocity E, N, U, m/s
    f_b_mps2 : (3,) specific force, body forward/right/down, m/s²
    rpy_rad : (roll, pitch, heading), rad
    ba_decay_rps : (3,) 1/τ of the accelerometer biases (0: random constant/walk), 1/s
    """
    c = dcm_body_to_enu(*rpy_rad)
    # body rates do not enter the rows taken here (no gyro states): a zero rate is exact
    F33 = build_F(float(lat_rad), float(alt_m), np.asarray(v_enu_mps, float),
                  np.asarray(f_b_mps2, float), np.zeros(3), c, np.zeros(24), 0.0, 0.0)
    F = np.zeros((N_STATES, N_STATES))
    F[0:6, 0:6] = F33[0:6, 0:6]
    F[VEL, ANG] = F33[3:6, 6:9] @ euler_to_eps_matrix(rpy_rad[1], rpy_rad[2])
    F[VEL, BA] = F33[3:6, 9:12]
    F[ANG, DRIFT] = np.eye(3)
    F[BA, BA] = -np.diag(np.asarray(ba_decay_rps, float))
    return F


def noise_density(spec: AttitudeReferenceSpec, imu: ImuModel) -> np.ndarray:
    """(15,) diagonal of the continuous white-noise density: accelerometer white noise on δV,
    the reference's angle and drift random walks, the accelerometer bias instability
    (state-unit²/s; the IMU's body-axis densities, isotropic, are the same in ENU)."""
    q = np.zeros(N_STATES)
    q[VEL] = imu.q_psd[3:6]
    q[ANG] = np.square(spec.arw_rad_rs)
    q[DRIFT] = np.square(spec.drift_rw_rps_rs)
    q[BA] = imu.q_psd[9:12]
    return q


def initial_variance(spec: AttitudeReferenceSpec, imu: ImuModel, pos_sigma_m: float,
                     vel_sigma_mps: float) -> np.ndarray:
    """(15,) prior variance: the computer initialised on a GNSS fix (σ of position, velocity),
    the reference's declared constant errors and drifts, the accelerometers' turn-on bias."""
    p = np.zeros(N_STATES)
    p[POS] = pos_sigma_m ** 2
    p[VEL] = vel_sigma_mps ** 2
    p[ANG] = np.square(spec.bias_sigma_rad)
    p[DRIFT] = np.square(spec.drift_sigma_rps)
    p[BA] = imu.p0_var[9:12]
    return p


def _sample_factor(Q: np.ndarray) -> np.ndarray:
    """L with L Lᵀ = Q for a symmetric positive semidefinite Q (eigen-decomposition)."""
    w, V = np.linalg.eigh(0.5 * (Q + Q.T))
    return V * np.sqrt(np.clip(w, 0.0, None))


class FlightTestErrors:
    """The truth-side errors of the attitude reference and of the flight-test computer.

    Parameters
    ----------
    spec : the reference's error model (and injected values, when given)
    imu : the accelerometer block (its accelerometer bias and noise are used, not its gyros)
    seed : seed of this realisation
    pos_sigma_m, vel_sigma_mps : σ of the computer's initial position/velocity error, m, m/s
    """

    def __init__(self, spec: AttitudeReferenceSpec, imu: ImuModel, seed: int,
                 pos_sigma_m: float = 1.0, vel_sigma_mps: float = 0.05):
        self.spec, self.imu = spec, imu
        self.rng = np.random.default_rng(seed)
        p0 = initial_variance(spec, imu, pos_sigma_m, vel_sigma_mps)
        self.x = np.sqrt(p0) * self.rng.standard_normal(N_STATES)
        if spec.bias_rad is not None:
            self.x[ANG] = spec.bias_rad
        if spec.drift_rps is not None:
            self.x[DRIFT] = spec.drift_rps
        self.q = noise_density(spec, imu)
        self._ba_decay = np.asarray(imu.decay_rps[0:3], float)
        self._prev: AircraftState | None = None
        self.c_rad = np.zeros(3)            # the computer's angle correction c, rad
        self.c_rps = np.zeros(3)            # and its drift correction c_d, rad/s
        self._f_meas: np.ndarray | None = None

    truth_model = "linear"

    def update(self, truth: AircraftState, frames=None) -> None:
        """Propagate the errors from the previous true state to ``truth.t_s`` (F at the previous
        true state, Picard Φ_k and Q_k, one Gaussian draw of the discrete noise; ``frames`` are
        not used)."""
        prev = self._prev
        self._prev = truth
        if prev is None or truth.t_s <= prev.t_s:
            return
        self._f_meas = np.asarray(prev.f_body_mps2, float) + self.x[BA]
        F = system_matrix(prev.lat_rad, prev.alt_m, prev.v_enu_mps, prev.f_body_mps2,
                          (prev.roll_rad, prev.pitch_rad, prev.heading_rad), self._ba_decay)
        dt = truth.t_s - prev.t_s
        phi, qk = discretize(F, np.diag(self.q), dt, method="picard")
        self.x = phi @ self.x + _sample_factor(qk) @ self.rng.standard_normal(N_STATES)
        self.c_rad = self.c_rad + self.c_rps * dt

    def angle_errors_rad(self) -> np.ndarray:
        """(3,) the reference's current errors (δγ, δϑ, δψ), indicated minus true, rad."""
        return self.x[ANG] + self.c_rad

    def specific_force_mps2(self) -> np.ndarray:
        """(3,) the accelerometers' output over the last step in this model, m/s² (body): the
        true specific force at the step's start plus the block's bias realisation, f + b_a."""
        return self._f_meas.copy()

    def reference_angles(self, truth: AircraftState) -> tuple[float, float, float]:
        """(roll, pitch, heading) the reference outputs, rad (heading in [0, 2π))."""
        d = self.angle_errors_rad()
        return (truth.roll_rad + d[0], truth.pitch_rad + d[1],
                (truth.heading_rad + d[2]) % (2 * math.pi))

    def computer_angles(self, truth: AircraftState) -> tuple[float, float, float]:
        """(roll, pitch, heading) the computer resolves with: the reference's minus c, rad."""
        d = self.x[ANG]
        return (truth.roll_rad + d[0], truth.pitch_rad + d[1],
                (truth.heading_rad + d[2]) % (2 * math.pi))

    def computer_position(self, truth: AircraftState) -> tuple[float, float, float, np.ndarray]:
        """(lat rad, lon rad, alt m, V ENU (3,) m/s) the flight-test computer outputs."""
        rm, rn = radii_m(truth.lat_rad)
        h = truth.alt_m
        dp = self.x[POS]
        return (truth.lat_rad + dp[1] / (rm + h),
                truth.lon_rad + dp[0] / ((rn + h) * math.cos(truth.lat_rad)), h + dp[2],
                np.asarray(truth.v_enu_mps, float) + self.x[VEL])

    def reset(self, dx: np.ndarray) -> None:
        """Feedback of an estimate (12,) of (δp, δV, angle and drift residuals): the computer
        subtracts (δp, δV) from its position and velocity and adds the angle and drift parts to
        its corrections c, c_d (a linear model: the same as subtracting them from the error)."""
        dx = np.asarray(dx, float)
        self.x[0:12] -= dx
        self.c_rad = self.c_rad + dx[6:9]
        self.c_rps = self.c_rps + dx[9:12]


class ReferenceAngleErrors:
    """The attitude reference's own angle errors, indicated minus true (rad): constant + drift
    + random walks (module docstring), advanced by their exact discretisation over Δt::

        θ ← θ + d Δt + w_θ,  d ← d + w_d,   w_θ ~ N(0, N_θ² Δt + N_d² Δt³/3),
        w_d ~ N(0, N_d² Δt),  cov(w_θ, w_d) = N_d² Δt²/2

    (N_θ the angle random walk, N_d the drift random walk, per angle). The constant errors and
    drifts are drawn from the spec's σ (or are its injected values).

    Parameters
    ----------
    spec : the reference's error model;  rng : its random stream
    """

    def __init__(self, spec: AttitudeReferenceSpec, rng: np.random.Generator):
        self.rng = rng
        self.theta_rad = np.asarray(spec.bias_sigma_rad, float) * rng.standard_normal(3)
        self.drift_rps = np.asarray(spec.drift_sigma_rps, float) * rng.standard_normal(3)
        if spec.bias_rad is not None:
            self.theta_rad = np.asarray(spec.bias_rad, float).copy()
        if spec.drift_rps is not None:
            self.drift_rps = np.asarray(spec.drift_rps, float).copy()
        self._qa = np.square(spec.arw_rad_rs)
        self._qd = np.square(spec.drift_rw_rps_rs)

    def advance(self, dt_s: float) -> None:
        """Advance θ and d over ``dt_s`` (s), one Gaussian draw per angle (class docstring)."""
        dt = float(dt_s)
        self.theta_rad = self.theta_rad + self.drift_rps * dt
        if np.any(self._qa > 0) or np.any(self._qd > 0):
            z = self.rng.standard_normal((2, 3))
            v_t = self._qa * dt + self._qd * dt ** 3 / 3.0
            c = self._qd * dt ** 2 / 2.0
            v_d = self._qd * dt
            s_t = np.sqrt(v_t)
            k = np.divide(c, s_t, out=np.zeros(3), where=s_t > 0)
            self.theta_rad = self.theta_rad + s_t * z[0]
            self.drift_rps = self.drift_rps + k * z[0] + np.sqrt(np.clip(v_d - k * k, 0, None)) * z[1]


class FlightTestSensors:
    """The flight-test sensors on the strapdown truth: an accelerometer block with its preset's
    errors, at the centre of gravity or at a lever arm from it (:meth:`set_lever_arm`), and the
    attitude reference's angles.

    Per JSBSim frame (``FRAME_PROPERTIES`` samples, at least the navigation step) the error-free
    increments are those of :func:`~fms_testbed.sensors.imu.synthesis.synthesize` (exact for the
    sampled motion); the accelerometers' outputs are
    :func:`~fms_testbed.sensors.imu.errors.measure_row` of them (turn-on bias, bias instability,
    random walk, scale factor, misalignment, VRW, quantisation; the block's gyros are not used);
    the reference outputs the sampled Euler angles plus its errors
    (:class:`ReferenceAngleErrors`, advanced once per step and interpolated linearly across its
    frames).

    Parameters
    ----------
    spec : the reference's error model
    imu : the accelerometer block: preset name, YAML path, mapping, spec or model
    seed : seed of this realisation (the reference's errors, the accelerometers' turn-on,
        slow and white noise, each from its own stream)
    """

    frame_properties = FRAME_PROPERTIES

    def set_lever_arm(self, lever_arm_m) -> None:
        """Place the accelerometer block at ``lever_arm_m`` (3,) m from the CG (body axes x
        forward, y right, z down; the aircraft file's ``imu_lever_arm_m``) before the first
        step: its increments are then those of the IMU point, v_imu = v + C_b^n (ω_eb × l)
        (:func:`~fms_testbed.sensors.imu.synthesis.lever_to_imu`), which needs the body rates
        per frame (:func:`~fms_testbed.sensors.imu.synthesis.frame_properties`)."""
        if self.T is not None:
            raise RuntimeError("FlightTestSensors.set_lever_arm after start()")
        self._lever = np.ascontiguousarray(lever_arm_m, dtype=float).reshape(3)
        self.frame_properties = frame_properties(self._lever)

    @property
    def lever_arm_m(self) -> np.ndarray:
        """(3,) the block's position from the CG, body axes, m."""
        return self._lever.copy()

    def __init__(self, spec: AttitudeReferenceSpec, imu, seed: int):
        self.spec = spec
        s_ref, s_acc = np.random.SeedSequence(int(seed)).spawn(2)
        self.reference = ReferenceAngleErrors(spec, np.random.default_rng(s_ref))
        self.accel = ImuErrors([imu_error_params(imu)], [int(s_acc.generate_state(1)[0])])
        self.U = np.zeros((1, N_ROW))
        self.U[:, :36] = self.accel.E
        self.accel.E = self.U[:, :36]
        self.accel.res = self.U[:, ROW_RES:N_ROW]
        self.T: np.ndarray | None = None           # the IMU's error-free state row
        self.t_s: float | None = None
        self._key: tuple | None = None
        self._lever = np.zeros(3)

    def start(self, truth: AircraftState) -> np.ndarray:
        """Start at ``truth``; returns the reference's first output angles (roll, pitch,
        heading), rad."""
        self.T = start_row(truth, self._lever)
        self.t_s = truth.t_s
        return np.array([truth.roll_rad, truth.pitch_rad, truth.heading_rad]) + \
            self.reference.theta_rad

    def _coefficients(self, step_s: float, frame_s: float) -> None:
        key = (step_s, frame_s, self.accel.version)
        if key != self._key:
            self.accel.pack_rows(self.U, step_s, frame_s)
            self._key = key

    def step(self, truth: AircraftState, frames: np.ndarray | None = None
             ) -> tuple[float, np.ndarray, np.ndarray]:
        """The measurements from the last call to ``truth.t_s``: (frame time s, measured Δv
        (n, 3) m/s body, the reference's output angles (n, 3) rad at each frame's end).

        Raises
        ------
        ValueError : time did not advance;  RuntimeError : not started
        """
        if self.T is None:
            raise RuntimeError("FlightTestSensors.step before start()")
        if frames is None:
            frames = sample_of(truth)[None, :]
        n_f = frames.shape[0]
        dt = (truth.t_s - self.t_s) / n_f
        if dt <= 0.0:
            raise ValueError(f"FlightTestSensors.step: time did not advance ({truth.t_s} s)")
        self._coefficients(n_f * dt, dt)
        acc = self.accel
        advance_slow(self.U, self.U[:, ROW_A:ROW_S], self.U[:, ROW_S:ROW_WSD],
                     acc.rng_slow[0].standard_normal((1, 30)))
        inc = np.empty((n_f, 6))
        synthesize(self.T, np.ascontiguousarray(frames), dt, self._lever,
                   bool(np.any(self._lever != 0.0)), inc)
        z = acc.rng_white[0].standard_normal((n_f, 6))
        u = self.U[0]
        dv = np.empty((n_f, 3))
        for j in range(n_f):
            _, mv = measure_row(u, (inc[j, 0], inc[j, 1], inc[j, 2]),
                                (inc[j, 3], inc[j, 4], inc[j, 5]), dt, z, j)
            dv[j] = mv
        th0 = self.reference.theta_rad
        self.reference.advance(n_f * dt)
        s = (np.arange(1, n_f + 1) / n_f)[:, None]
        angles = frames[:, 3:6] + th0 + s * (self.reference.theta_rad - th0)
        self.t_s = truth.t_s
        return dt, dv, angles

    def angle_errors_rad(self) -> np.ndarray:
        """(3,) the reference's current errors (δγ, δϑ, δψ), indicated minus true, rad."""
        return self.reference.theta_rad.copy()


__all__ = ["ANGLES", "AttitudeReferenceSpec", "FlightTestErrors", "FlightTestSensors",
           "ReferenceAngleErrors", "N_STATES", "euler_to_eps_matrix",
           "initial_variance", "noise_density", "system_matrix"]
