"""Flight-test attitude-reference mode (seed 004, Filyashkin & Rogozhin): estimate the heading,
roll and pitch errors of an attitude reference in flight from GNSS position and velocity.

The reference's angles resolve an accurate accelerometer block in a strapdown computer
(:class:`FlightTestComputer` on the sensors' measurements, ``truth_model: strapdown``; or truth ⊕
the computer's linear error model, ``truth_model: linear``,
:mod:`fms_testbed.sensors.attitude_reference`); the differences between the
computer's and the GNSS receiver's position and velocity feed a discrete Kalman filter over
seed 004's state vector — 15 computer/reference errors (δp, δV, the reference's δγ, δϑ, δψ, their
drifts, accelerometer biases) plus 6 GNSS Markov errors (position, velocity)::

    z_p = p_comp - p_GNSS = δp - m_p - w_p      z_v = V_comp - V_GNSS = δV - m_v - w_v

Φ_k and Q_k come from the Picard series over F at the computer's indicated state and the
accelerometers' measured specific force
(:func:`~fms_testbed.sensors.attitude_reference.system_matrix`, at the angles the computer
resolves with); prediction and the Joseph-form correction (delayed for a late fix) are
:mod:`.kalman`'s. After a used fix the estimate of (δp, δV, angle and drift residuals) is fed
back: the computer resets its position and velocity and adds the angle and drift parts to its
correction c, c_d of the reference's angles (the reference itself is not touched: it is the unit
under test). The estimate of the reference's errors is c + x̂_θ, its σ the filter's (the
covariance of the residual). What guidance flies on is the computer's solution corrected by the
filter.

Scenario block (``navigation:``, validated by
:class:`~fms_testbed.config.navigation.AttitudeReferenceBlock`)::

    source: attitude_reference
    imu: HG9900                       # the accelerometer block (its accelerometers only)
    reference: {bias_sigma_deg: [0.1, 0.1, 0.5], drift_sigma_dph: [0.5, 0.5, 1.0],
                arw_deg_rh: [0.003, 0.003, 0.003], bias_deg: [..], drift_dph: [..]}
    gnss: {...}                       # as for ins_gnss
    init_pos_sigma_m: 1.0
    init_vel_sigma_mps: 0.05
    gate_sigma: 5
    truth_model: strapdown            # strapdown (measured increments) | linear (fast mode)

Logged columns (``NavSolution.errors``), per angle in (roll, pitch, heading):
``att_ref_err_<a>_deg`` (injected: the reference's error, indicated minus true),
``att_ref_est_<a>_deg`` (the filter's estimate), ``att_ref_sigma_<a>_deg`` (its 1σ), plus
``anp_m`` and ``nse_{east,north,up}_m``. :func:`attitude_reference_summary` turns them into the
``summary.json`` block: the estimation error at 60 s and after, against the paper's goal and the
filter's 3σ.

Observability (why the profiles matter): the reference's errors reach the velocity only through
[f^N ×] ε. In straight and level flight f^N ≈ (0, 0, g): the tilt errors show (against the
accelerometer biases, which they cannot be told from while the heading is constant: the floor
is σ_ba/g), the heading error does not — it needs horizontal specific force (turns, speed
changes).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from pydantic import ValidationError

from fms_testbed.config.navigation import AttitudeReferenceBlock
from fms_testbed.config.yamlfile import validation_message
from fms_testbed.core.contracts import NavigationSourceBase
from fms_testbed.core.earth import radii_m, sea_level_height_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import DEG_RAD, DPH_RPS, G0_MPS2
from fms_testbed.navigation.fdi import unmodelled_variances
from fms_testbed.navigation.ins_bank import derive_seeds
from fms_testbed.navigation.measurements import enu_difference_m
from fms_testbed.navigation.ins_gnss import gnss_spec
from fms_testbed.navigation.inertial.strapdown import cg_state, correct_row
from fms_testbed.navigation.kalman import (PredictionLag, correct, correct_delayed, innovation,
                                          predict)
from fms_testbed.sensors.attitude_reference import (ANGLES, N_STATES, AttitudeReferenceSpec,
                                                    FlightTestErrors, FlightTestSensors,
                                                    initial_variance,
                                                    noise_density, system_matrix)
from fms_testbed.sensors.gnss import GnssFix, GnssReceiver, GnssSpec
from fms_testbed.sensors.sins.analysis import horizontal_radius
from fms_testbed.sensors.imu.kinematics import (euler_to_quat, forward_step, inverse_step, qmul,
                                                qrot, rotvec_to_quat)
from fms_testbed.sensors.imu.synthesis import frame_offset_rotation
from fms_testbed.sensors.sins.discretize import discretize
from fms_testbed.sensors.sins.presets import ImuModel, load_imu

N_FILTER = N_STATES + 6
MP, MV = slice(15, 18), slice(18, 21)
GOAL_DEG = {"roll": 0.01, "pitch": 0.02, "heading": 0.06}
"""Seed 004's reported estimation errors of the reference's angles (after 50-120 s), deg."""
GOAL_AT_S = 60.0
"""Time by which the goal is to be met (and held), s."""
_BUFFER_S = 2.0


class AttitudeReferenceFilter:
    """The 21-state Kalman filter of the flight-test mode (module docstring).

    The accelerometers' scale factor k and misalignment β (declared in ``imu``, not states
    here) are covered as in the INS/GNSS filter: their 1 g equivalent bias (β_xz g, β_yz g,
    k_z g) widens the bias prior, and white noise of density 2 σ² |Δf|² τ_u (σ² the declared
    scale-factor + misalignment variance, Δf the specific force's departure from 1 g) is added
    on δV; both vanish for a block without those errors.

    Parameters
    ----------
    spec : the reference's declared error model;  imu : the accelerometer block
    gnss : the GNSS receiver's declared error model
    p0 : (15,) prior variance of the computer/reference states (GNSS states: stationary)
    gate_sigma : innovation gate per component, σ
    unmodelled_tau_s : correlation time τ_u of the process noise standing in for the
        accelerometers' scale-factor and misalignment errors the filter does not carry, s
    """

    def __init__(self, spec: AttitudeReferenceSpec, imu: ImuModel, gnss: GnssSpec,
                 p0: np.ndarray, gate_sigma: float = 5.0, unmodelled_tau_s: float = 20.0):
        n = N_FILTER
        self._var_acc = unmodelled_variances(imu)[0]
        self._tau_u = float(unmodelled_tau_s)
        p0 = np.array(p0, float)
        p0[12:15] += np.array([imu.p0_var[22], imu.p0_var[24], imu.p0_var[17]]) * G0_MPS2 ** 2
        self.gnss, self.gate_sigma = gnss, float(gate_sigma)
        self.q = np.zeros(n)
        self.q[:N_STATES] = noise_density(spec, imu)
        self.q[15:21] = 2.0 * gnss.markov_sigma ** 2 / gnss.markov_tau_s
        self._decay = np.zeros(n)
        self._decay[15:21] = 1.0 / gnss.markov_tau_s
        self._ba_decay = np.asarray(imu.decay_rps[0:3], float)
        self.x = np.zeros(n)
        self.P = np.diag(np.r_[p0, gnss.markov_sigma ** 2])
        self._no_freeze = np.zeros(n, np.bool_)
        self._lag = PredictionLag()
        self._H_pos = np.zeros((3, n))
        self._H_pos[:, 0:3], self._H_pos[:, MP] = np.eye(3), -np.eye(3)
        self._H_vel = np.zeros((3, n))
        self._H_vel[:, 3:6], self._H_vel[:, MV] = np.eye(3), -np.eye(3)
        w = gnss.white_sigma ** 2
        self._r_pos, self._r_vel = np.diag(w[:3]), np.diag(w[3:6])

    def predict(self, t_s: float, lat_rad: float, alt_m: float, v_enu_mps, rpy_rad, f_b_mps2,
                dt_s: float) -> None:
        """Propagate over ``dt_s`` (s) from ``t_s`` with F at the computer's indicated state
        (latitude rad, height m, velocity m/s, the reference's angles rad) and the specific
        force (body, m/s², the accelerometers' measured mean over the step): x⁻ = Φ x,
        P⁻ = Φ P Φᵀ + Q_k (Picard, Babich eq. 2.9, 4.5), Q with the unmodelled term (class
        docstring)."""
        F = np.zeros((N_FILTER, N_FILTER))
        F[:N_STATES, :N_STATES] = system_matrix(lat_rad, alt_m, v_enu_mps, f_b_mps2, rpy_rad,
                                                self._ba_decay)
        F[np.arange(15, 21), np.arange(15, 21)] = -self._decay[15:21]
        q = self.q
        if self._var_acc > 0 and self._tau_u > 0:
            f = np.asarray(f_b_mps2, float)
            df2 = max(float(f @ f) - 2.0 * G0_MPS2 * abs(float(f[2])) + G0_MPS2 ** 2, 0.0)
            q = q.copy()
            q[3:6] += 2.0 * self._var_acc * df2 * self._tau_u
        phi, qk = discretize(F, np.diag(q), dt_s, method="picard")
        self.x, self.P = predict(self.x, self.P, phi, qk)
        self._lag.append(t_s, phi, qk)

    def _lag_since(self, t_m: float):
        return self._lag.since(t_m)

    def _group(self, z, H, R, lag) -> tuple[np.ndarray, float, bool]:
        if lag is None:
            nu, S, nis = innovation(self.x, self.P, z, H, R)
        else:
            _, _, nu, S, nis = correct_delayed(self.x, self.P, z, H, R, lag[0], lag[1],
                                               self._no_freeze)
        used = bool(np.all(np.abs(nu) <= self.gate_sigma * np.sqrt(np.diag(S))))
        if used:
            if lag is None:
                self.x, self.P, *_ = correct(self.x, self.P, z, H, R, self._no_freeze)
            else:
                self.x, self.P, *_ = correct_delayed(self.x, self.P, z, H, R, lag[0], lag[1],
                                                     self._no_freeze)
        return nu, nis, used

    def gnss_update(self, fix: GnssFix, comp_at_fix: tuple) -> list[tuple[str, float, bool]]:
        """Use a fix (position, then velocity) against the computer's output at its time of
        validity, ``(lat rad, lon rad, alt m, V (3,) m/s)``; returns (group, NIS, used) each."""
        lag = self._lag_since(fix.t_s)
        lat, lon, alt, v = comp_at_fix
        zp = enu_difference_m(lat, lon, alt, fix.lat_rad, fix.lon_rad, fix.alt_m)
        zv = np.asarray(v, float) - fix.v_enu_mps
        out = []
        for name, z, H, R in (("gnss_pos", zp, self._H_pos, self._r_pos),
                              ("gnss_vel", zv, self._H_vel, self._r_vel)):
            _, nis, used = self._group(z, H, R, lag)
            out.append((name, nis, used))
        return out

    def take_feedback(self) -> np.ndarray:
        """The (δp, δV, angle, drift) block of x̂ (12,), handed to the computer; zeroed in the
        filter (the accelerometer-bias and GNSS states stay)."""
        dx = self.x[0:12].copy()
        self.x[0:12] = 0.0
        return dx


class FlightTestComputer:
    """The flight-test strapdown computer on measured data (``truth_model: strapdown``).

    Per frame it resolves the accelerometers' measured Δv with the attitude the reference's
    output angles minus its correction c give, q_k = q(γ̃ - c_γ, ϑ̃ - c_ϑ, ψ̃ - c_ψ), and advances
    position and velocity with the project's strapdown step
    (:func:`~fms_testbed.sensors.imu.kinematics.forward_step`: WGS-84, Earth and transport rate,
    rotation and sculling terms, gravity, Coriolis). The body rotation those terms need is the
    one the angle samples imply, Δθ with q_k = q(-ζ) ⊗ q_{k-1} ⊗ q(Δθ + Δθ' × Δθ/12)
    (:func:`~fms_testbed.sensors.imu.kinematics.inverse_step` of the attitude at the frame's
    start velocity); the attitude is then set to q_k. With the accelerometers at a lever arm l
    from the CG (:meth:`set_lever_arm`) the computer mechanises the IMU point — its attitude
    q(-ρ) ⊗ q_k in the IMU point's local frame (ρ the frame rotation over the offset C_b^n l) —
    and moves its output to the CG, v_cg = q(ρ) v_imu - C_b^n (ω_eb × l) with the rate the angle
    samples imply (:func:`~fms_testbed.navigation.inertial.strapdown.cg_state`), as an INS
    compensates its installation lever arm. Nothing here reads the true state: the
    sensors (:class:`~fms_testbed.sensors.attitude_reference.FlightTestSensors`) make the only
    reads, and the output of :meth:`computer_position` is the computer's own.

    Parameters
    ----------
    sensors : the flight-test sensors (accelerometer block, attitude reference)
    seed : seed of the computer's initial position and velocity error
    pos_sigma_m, vel_sigma_mps : σ of that error per ENU axis (the initialising fix), m, m/s
    """

    truth_model = "strapdown"

    def __init__(self, sensors: FlightTestSensors, seed: int, pos_sigma_m: float = 1.0,
                 vel_sigma_mps: float = 0.05):
        self.sensors = sensors
        self.spec = sensors.spec
        self._rng = np.random.default_rng(seed)
        self._sig = (float(pos_sigma_m), float(vel_sigma_mps))
        self.row: np.ndarray | None = None
        self.ref_out = np.zeros(3)          # the reference's last output angles, rad
        self.c_rad = np.zeros(3)            # the computer's angle correction c, rad
        self.c_rps = np.zeros(3)            # and its drift correction c_d, rad/s
        self._f = np.zeros(3)
        self._scratch = np.zeros(22)
        self._zero3 = np.zeros(3)
        self.lever = np.zeros(3)            # the lever arm the computer compensates, m
        self._w_ib = np.zeros(3)            # the last frame's angle-implied rate, rad/s

    @property
    def frame_properties(self):
        """The JSBSim samples the sensors need per frame."""
        return self.sensors.frame_properties

    def set_lever_arm(self, lever_arm_m, compensate: bool = True) -> None:
        """Place the accelerometer block at ``lever_arm_m`` (3,) m from the CG (body axes),
        before the first update; ``compensate``: the computer knows that lever arm and moves
        its output to the CG (False: it takes the IMU point for the CG)."""
        self.sensors.set_lever_arm(lever_arm_m)
        self.lever = self.sensors.lever_arm_m if compensate else np.zeros(3)

    def _imu_attitude(self, a) -> tuple:
        """q_b^n of the IMU point's local frame for the CG attitude of Euler angles ``a``."""
        q = euler_to_quat(a[0], a[1], a[2])
        if not self.lever.any():
            return q
        r = self.row
        rho = frame_offset_rotation(r[0], r[2], qrot(q, (self.lever[0], self.lever[1],
                                                         self.lever[2])))
        return qmul(rotvec_to_quat((-rho[0], -rho[1], -rho[2])), q)

    def _set_attitude(self) -> None:
        self.row[6:10] = self._imu_attitude(self.ref_out - self.c_rad)

    def update(self, truth: AircraftState, frames=None) -> None:
        """Take the sensors' measurements up to ``truth.t_s`` and mechanise them (the first
        call initialises on the sensors' first sample and an initial fix error)."""
        if self.row is None:
            self.ref_out = self.sensors.start(truth)
            self.row = self.sensors.T.copy()
            self.row[10:] = 0.0
            p, v = self._sig
            self.reset(np.r_[-p * self._rng.standard_normal(3), -v * self._rng.standard_normal(3),
                             np.zeros(6)])
            return
        dt, dv, ang = self.sensors.step(truth, frames)
        row, scr = self.row, self._scratch
        c0 = self.c_rad
        for j in range(dv.shape[0]):
            c = c0 + self.c_rps * (dt * (j + 1))
            q1 = self._imu_attitude(ang[j] - c)
            scr[:] = row
            dth, _ = inverse_step(scr, (row[3], row[4], row[5]), q1, dt)
            forward_step(row, dth, (dv[j, 0], dv[j, 1], dv[j, 2]), dt)
            row[6:10] = q1
        self.c_rad = c0 + self.c_rps * (dt * dv.shape[0])
        self.ref_out = ang[-1].copy()
        self._w_ib = np.asarray(dth, float) / dt
        self._f = dv.sum(axis=0) / (dt * dv.shape[0])

    def specific_force_mps2(self) -> np.ndarray:
        """(3,) the accelerometers' mean measured specific force over the last step, m/s²."""
        return self._f.copy()

    def angle_errors_rad(self) -> np.ndarray:
        """(3,) the reference's current errors, indicated minus true, rad (truth side: logged,
        not used by the computer or the filter)."""
        return self.sensors.angle_errors_rad()

    def computer_angles(self, truth=None) -> tuple[float, float, float]:
        """(roll, pitch, heading) the computer resolves with: the reference's minus c, rad."""
        a = self.ref_out - self.c_rad
        return float(a[0]), float(a[1]), float(a[2]) % (2 * math.pi)

    def computer_position(self, truth=None) -> tuple[float, float, float, np.ndarray]:
        """(lat rad, lon rad, alt m (sea-level datum), V ENU (3,) m/s) of the computer at the
        CG."""
        r = self.row
        if self.lever.any():
            lat, lon, h, _, v, _ = cg_state(r, self.lever, self._w_ib)
            return (float(lat), float(lon), float(sea_level_height_m(lat, h)),
                    np.array([v[1], v[0], -v[2]]))
        return (float(r[0]), float(r[1]), float(sea_level_height_m(r[0], r[2])),
                np.array([r[4], r[3], -r[5]]))

    def reset(self, dx: np.ndarray) -> None:
        """Feedback of an estimate (12,) of (δp ENU m, δV ENU m/s, angle and drift residuals
        rad, rad/s; indicated minus true): position and velocity corrected
        (:func:`~fms_testbed.navigation.inertial.strapdown.correct_row`, no attitude part), the
        angle and drift parts added to c, c_d and the attitude re-resolved."""
        dx = np.asarray(dx, float)
        d9 = np.zeros(9)
        d9[:6] = dx[:6]
        correct_row(self.row, d9, self.lever, self._w_ib)
        self.c_rad = self.c_rad + dx[6:9]
        self.c_rps = self.c_rps + dx[9:12]
        self._set_attitude()


def reference_spec(block) -> AttitudeReferenceSpec:
    """:class:`AttitudeReferenceSpec` (SI) from a validated ``navigation.reference`` block."""
    def rad(v):
        return None if v is None else tuple(x * DEG_RAD for x in v)

    def rps(v):
        return None if v is None else tuple(x * DPH_RPS for x in v)

    # deg/√h → rad/√s: deg→rad, and 1/√h = 1/60 per √s
    return AttitudeReferenceSpec(
        rad(block.bias_sigma_deg), rps(block.drift_sigma_dph),
        tuple(x * DEG_RAD / 60.0 for x in block.arw_deg_rh),
        tuple(x * DPH_RPS / 60.0 for x in block.drift_rw_dph_rh), rad(block.bias_deg),
        rps(block.drift_dph))


class AttitudeReferenceNavigation(NavigationSourceBase):
    """Navigation source of the flight-test mode; see the module docstring for the keys.

    Parameters
    ----------
    errors : the truth-side reference and computer errors
    receiver : the GNSS receiver;  flt : the filter
    """

    #: per-frame JSBSim samples the truth side needs (none: it reads the outer-step state)
    frame_properties: tuple[tuple[str, float], ...] = ()

    def __init__(self, errors: FlightTestErrors, receiver: GnssReceiver,
                 flt: AttitudeReferenceFilter):
        self.errors, self.receiver, self.filter = errors, receiver, flt
        self.truth_model = errors.truth_model
        self.frame_properties = tuple(getattr(errors, "frame_properties", ()))
        self.events: list[dict] = []
        self._prev: tuple | None = None        # (t_s, computer output, angles it resolves with)
        self._buffer: list[tuple[float, tuple]] = []
        self._gate_open = {"gnss_pos": True, "gnss_vel": True}
        self.nis_log: list[tuple[float, str, float]] = []

    @classmethod
    def from_spec(cls, spec: dict, seed: int | None = None) -> "AttitudeReferenceNavigation":
        """Build from a scenario's ``navigation`` mapping (``spec['seed']`` wins over ``seed``).

        Raises
        ------
        ConfigError : unknown key or bad value (named ``navigation.<key>``), unknown IMU
        """
        try:
            b = AttitudeReferenceBlock.model_validate(spec)
        except ValidationError as err:
            msg = validation_message("navigation", err)
            raise ConfigError(msg.replace("navigation: field '", "field 'navigation.", 1)) from None
        imu = load_imu(b.imu)
        sd = b.seed if b.seed is not None else (0 if seed is None else int(seed))
        s_gnss, s_ref = derive_seeds(sd, 2)
        ref, g = reference_spec(b.reference), gnss_spec(b.gnss)
        if b.truth_model == "strapdown":
            s_sens, s_comp = derive_seeds(s_ref, 2)
            errs = FlightTestComputer(FlightTestSensors(ref, b.imu, s_sens), s_comp,
                                      b.init_pos_sigma_m, b.init_vel_sigma_mps)
        else:
            errs = FlightTestErrors(ref, imu, s_ref, b.init_pos_sigma_m, b.init_vel_sigma_mps)
        p0 = initial_variance(ref, imu, b.init_pos_sigma_m, b.init_vel_sigma_mps)
        src = cls(errs, GnssReceiver(g, s_gnss), AttitudeReferenceFilter(ref, imu, g, p0,
                                                                         b.gate_sigma))
        src.seed = sd
        return src

    def install_imu(self, lever_arm_m) -> None:
        """The accelerometers' position from the CG (the aircraft file's ``imu_lever_arm_m``,
        body axes, m), set before the first update; the computer compensates it. The linear
        model has none."""
        if isinstance(self.errors, FlightTestComputer):
            self.errors.set_lever_arm(lever_arm_m)
            self.frame_properties = tuple(self.errors.frame_properties)

    def _at(self, t_s: float) -> tuple | None:
        for t, comp in reversed(self._buffer):
            if abs(t - t_s) <= 1e-6:
                return comp
        return None

    def update(self, truth: AircraftState, frames=None) -> NavSolution:
        """Advance to ``truth.t_s``: truth-side errors, prediction, any delivered GNSS fix
        (gated; then the computer's reset); return the corrected solution."""
        errs, flt = self.errors, self.filter
        errs.update(truth, frames)
        comp = errs.computer_position(truth)
        ref = errs.computer_angles(truth)
        prev = self._prev
        if prev is not None and truth.t_s > prev[0]:
            pt, pc, pr = prev
            flt.predict(pt, pc[0], pc[2], pc[3], pr, errs.specific_force_mps2(), truth.t_s - pt)
        self._buffer.append((truth.t_s, comp))
        while self._buffer and self._buffer[0][0] < truth.t_s - _BUFFER_S:
            self._buffer.pop(0)
        for fix in self.receiver.update(truth):
            at = self._at(fix.t_s)
            if at is None:
                continue
            groups = flt.gnss_update(fix, at)
            for name, nis, used in groups:
                self.nis_log.append((fix.t_s, name, nis))
                if self._gate_open[name] != used:
                    self.events.append({"t_s": round(truth.t_s, 3), "unit": "gnss",
                                        "kind": "reconfigured" if used else "detected",
                                        "stage": "innovation_gate",
                                        "reason": f"{name} {'accepted again' if used else 'rejected'}"})
                self._gate_open[name] = used
            if any(u for _, _, u in groups):
                errs.reset(flt.take_feedback())
                comp = errs.computer_position(truth)
                ref = errs.computer_angles(truth)
                self._buffer[-1] = (truth.t_s, comp)
        self._prev = (truth.t_s, comp, ref)
        return self.solution(truth, comp, ref)

    def solution(self, truth: AircraftState, comp: tuple, ref: tuple) -> NavSolution:
        """The computer's output and angles (the reference's minus c) minus the filter's
        estimates, with the logged columns (module docstring)."""
        x, P = self.filter.x, self.filter.P
        est = self.errors.c_rad + x[6:9]         # estimate of the reference's errors, rad
        lat0, lon0, h0, v0 = comp
        rm, rn = radii_m(lat0)
        lat = lat0 - x[1] / (rm + h0)
        lon = lon0 - x[0] / ((rn + h0) * math.cos(lat0))
        alt = h0 - x[2]
        v = np.asarray(v0, float) - x[3:6]
        roll, pitch = ref[0] - x[6], ref[1] - x[7]
        hdg = (ref[2] - x[8]) % (2 * math.pi)
        rmt, rnt = radii_m(truth.lat_rad)
        injected = self.errors.angle_errors_rad()
        errors = {"anp_m": horizontal_radius(P[0, 0], P[1, 1], P[0, 1]),
                  "nse_east_m": (lon - truth.lon_rad) * (rnt + truth.alt_m)
                  * math.cos(truth.lat_rad),
                  "nse_north_m": (lat - truth.lat_rad) * (rmt + truth.alt_m),
                  "nse_up_m": alt - truth.alt_m}
        for i, a in enumerate(ANGLES):
            errors[f"att_ref_err_{a}_deg"] = math.degrees(injected[i])
            errors[f"att_ref_est_{a}_deg"] = math.degrees(est[i])
            errors[f"att_ref_sigma_{a}_deg"] = math.degrees(math.sqrt(max(P[6 + i, 6 + i], 0.0)))
        return NavSolution(truth.t_s, lat, lon, alt, v, roll, pitch, hdg, errors,
                           pos_cov_enu_m2=P[:3, :3].copy())


def attitude_reference_summary(df: pd.DataFrame, at_s: float = GOAL_AT_S,
                               goal_deg: dict[str, float] | None = None) -> dict | None:
    """The ``attitude_reference`` block of ``summary.json`` from a run's timeseries.

    Per angle: the estimation error e = estimate - injected (deg) at ``at_s`` and its largest
    magnitude from ``at_s`` on, the filter's σ at ``at_s``, the largest |e|/σ from ``at_s`` on,
    ``meets_goal`` (|e| ≤ goal at every sample from ``at_s`` on; seed 004: 0.06° heading, 0.01°
    roll, 0.02° pitch), ``inside_3sigma`` (|e| ≤ 3σ at every sample from ``at_s`` on), and
    ``within_goal_from_s`` (the time after which |e| stays within the goal; None: it never
    does). None when the run has no attitude-reference columns.

    Parameters
    ----------
    df : the timeseries (``t_s``, ``att_ref_{err,est,sigma}_<angle>_deg``)
    at_s : the time from which the goal is judged, s
    goal_deg : goal per angle, deg (default :data:`GOAL_DEG`)
    """
    if "att_ref_err_roll_deg" not in df:
        return None
    goal = dict(GOAL_DEG if goal_deg is None else goal_deg)
    t = df["t_s"].to_numpy(float)
    if t[-1] < at_s:
        return {"at_s": at_s, "goal_deg": goal, "angles": {}, "meets_goal": False,
                "inside_3sigma": False, "reason": f"flight ended at {t[-1]:.1f} s < {at_s:g} s"}
    k0 = int(np.searchsorted(t, at_s - 1e-9))
    angles = {}
    for a in ANGLES:
        e = df[f"att_ref_est_{a}_deg"].to_numpy(float) - df[f"att_ref_err_{a}_deg"].to_numpy(float)
        s = df[f"att_ref_sigma_{a}_deg"].to_numpy(float)
        after, ratio = np.abs(e[k0:]), np.abs(e[k0:]) / s[k0:]
        out = np.flatnonzero(np.abs(e) > goal[a])
        within = (float(t[0]) if out.size == 0 else
                  (float(t[out[-1] + 1]) if out[-1] + 1 < t.size else None))
        angles[a] = {
            "injected_at_s_deg": round(float(df[f"att_ref_err_{a}_deg"].iloc[k0]), 5),
            "err_at_s_deg": round(float(e[k0]), 5),
            "max_abs_err_after_deg": round(float(after.max()), 5),
            "sigma_at_s_deg": round(float(s[k0]), 5),
            "max_err_over_sigma_after": round(float(ratio.max()), 3),
            "goal_deg": goal[a],
            "meets_goal": bool(after.max() <= goal[a]),
            "inside_3sigma": bool(ratio.max() <= 3.0),
            "within_goal_from_s": None if within is None else round(within, 2)}
    return {"at_s": at_s, "goal_deg": goal, "angles": angles,
            "meets_goal": all(v["meets_goal"] for v in angles.values()),
            "inside_3sigma": all(v["inside_3sigma"] for v in angles.values())}


__all__ = ["AttitudeReferenceFilter", "AttitudeReferenceNavigation", "GOAL_AT_S", "GOAL_DEG",
           "attitude_reference_summary", "reference_spec"]
