"""Loosely coupled error-state INS/GNSS Kalman filter for one INS (seed 004's 15 + 6 states).

State (SI, errors are *indicated minus true*, the SINS model's convention)::

    0:3   δp   INS position error E, N, U, m          3:6   δV   INS velocity error, m/s
    6:9   ε    INS attitude error about E, N, U, rad   9:12  b_a  accelerometer bias, body, m/s²
    12:15 b_g  gyro bias, body, rad/s                  15:18 m_p  GNSS position Markov error, m
    18:21 m_v  GNSS velocity Markov error, m/s         21    b_h  baro bias, m (with a baro)

The INS block of F is the first 15×15 of the project's 33-state model
(:func:`fms_testbed.sensors.sins.model.build_F`, free vertical channel), built at the INS's
*indicated* position, velocity and attitude with the INS's *compensated measured* specific force
and angular rate (:meth:`~fms_testbed.navigation.bank.InsBankLike.measured`, the step means
ΣΔv_c/T, ΣΔθ_c/T); the GNSS and baro states are first-order Gauss-Markov. Nothing in the filter
reads the true state. Φ_k, Q_k come from the Picard series
(:func:`fms_testbed.sensors.sins.discretize.discretize_sins`, Babich 2017 eq. 2.5-2.9/4.3-4.5) or
Van Loan. Measurements are plug-ins (:mod:`.measurements`: GNSS position and velocity of the
antenna with its lever arm and the receiver-reported σ, baro altitude, airspeed), each giving
(z, H, R) from the INS output at its time of validity, e.g.::

    z_p = p_INS + C l - p_GNSS = δp + [(C l)×] ε - m_p - w_p
    z_h = h_INS - h_baro = δp_U - b_h - w_h

A fix valid at t_m and used at t (latency) is compared with the INS output of t_m against the
estimate carried back, x̂(t_m) = Φ(t, t_m)⁻¹ x̂(t) (the process noise over the lag is neglected in
the cross-covariance). Each group passes an innovation gate (|ν_i| ≤ gate·√S_ii) before the
Joseph-form correction (:mod:`.kalman`). A measurement rejected ``reset_after`` times in a row
(a jump the filter's σ cannot follow: a GNSS re-acquisition after a long outage) resets the
covariance of the INS states it observes (rows and columns zeroed, variance ν² + R) and is used:
the estimate follows the sensor again instead of coasting on a confident, wrong P. Feedback: at every GNSS update the INS block of x̂ is
handed back (the INS subtracts it from its position, velocity, attitude and sensor-bias
compensation) and zeroed; the GNSS/baro states stay in the filter.

The truth INS has 33 states; the 18 scale-factor and misalignment errors the filter does not
carry are covered by (a) an equivalent-bias prior at 1 g (accelerometer misalignment and
scale factor seen as a bias in level flight), and (b) white process noise on δV and ε of density
2 σ² |Δf|² τ_u and 2 σ² |ω|² τ_u (σ² the declared scale-factor + misalignment variance, Δf the
specific force's departure from 1 g, ω the body rate, τ_u = ``unmodelled_tau_s``): they vanish
for an IMU without those errors, where the filter's model is the truth's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from fms_testbed.core.earth import OMEGA_IE_RPS
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.fdi import unmodelled_variances
from fms_testbed.navigation.kalman import (PredictionLag, correct, correct_delayed,
                                          predict)
from fms_testbed.navigation.measurements import (ATT, BARO, MP, MV, N_INS, POS, VEL,
                                                 BaroAltitude, Measurement, enu_difference_m,
                                                 gnss_measurements)
from fms_testbed.navigation.sins import _c_bn
from fms_testbed.sensors.baro import BaroReading, BaroSpec
from fms_testbed.sensors.gnss import GnssFix, GnssSpec
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.analysis import SinsOptions, initial_map, system_matrix
from fms_testbed.sensors.sins.discretize import (PICARD_MAX_ORDER, PICARD_MAX_RATE_DT,
                                                 DiscretisationError, _picard_sins, discretize)
from fms_testbed.sensors.sins.model import build_F
from fms_testbed.sensors.sins.presets import ImuModel

STATE_NAMES = (
    [f"dp_{c}_m" for c in "enu"] + [f"dv_{c}_mps" for c in "enu"]
    + [f"eps_{c}_rad" for c in "enu"] + [f"ba_{c}_mps2" for c in "xyz"]
    + [f"bg_{c}_rps" for c in "xyz"] + [f"gnss_mp_{c}_m" for c in "enu"]
    + [f"gnss_mv_{c}_mps" for c in "enu"] + ["baro_bias_m"])
_FREE = SinsOptions(vertical="free")


@dataclass(frozen=True)
class FilterTuning:
    """Filter settings.

    gate_sigma : innovation gate, in σ of each innovation component (PX4/ArduPilot use 5)
    unmodelled_tau_s : correlation time τ_u of the process noise standing in for the scale
        factors and misalignments the filter does not carry, s
    method : discretisation, ``picard`` or ``vanloan``
    predict_interval_s : longest interval the covariance is propagated over at once, s
        (:class:`PredictionInterval`; a measurement or a GNSS epoch ends an interval earlier;
        0: every navigation step)
    predict_rotation_deg : an interval also ends once the body has turned this much in it
        (∫|ω| dt, deg): F follows the attitude, and a held F̄ misses the commutator terms of a
        rotating F (2 % of the gyro-bias → velocity block of Φ over 0.9 s of a 3 °/s turn)
    reset_after : consecutive gate rejections of one measurement group after which the
        covariance of the INS states it observes is reset and the measurement used (0: never)
    """

    gate_sigma: float = 5.0
    unmodelled_tau_s: float = 20.0
    method: str = "picard"
    predict_interval_s: float = 1.0
    predict_rotation_deg: float = 1.0
    reset_after: int = 10

    def __post_init__(self):
        if not self.gate_sigma > 0:
            raise ConfigError("navigation.filter.gate_sigma: must be > 0")
        if not self.unmodelled_tau_s >= 0:
            raise ConfigError("navigation.filter.unmodelled_tau_s: must be >= 0 s")
        if self.method not in ("picard", "vanloan"):
            raise ConfigError("navigation.filter.method: picard or vanloan")
        if not 0 <= self.predict_interval_s <= 10:
            raise ConfigError("navigation.filter.predict_interval_s: must be in [0, 10] s")
        if not self.predict_rotation_deg > 0:
            raise ConfigError("navigation.filter.predict_rotation_deg: must be > 0 deg")
        if not self.reset_after >= 0:
            raise ConfigError("navigation.filter.reset_after: must be >= 0")


@dataclass(frozen=True)
class GroupResult:
    """One measurement group at one update: name (``gnss_pos``, ``gnss_vel``, ``baro``, ...), its
    innovation (units of the group), S, NIS, whether it passed the gate and was used, and
    whether it was used after a covariance reset (sustained rejection)."""

    name: str
    innovation: np.ndarray
    S: np.ndarray
    nis: float
    used: bool
    reset: bool = False
    components: tuple | None = None    # per component: used (channel test passed); None: all


@njit(cache=True)
def _predict_step(x, P, lat, alt, v, rpy, w_ib, f_b, decay24, decay, q, dt, tol):
    """Fused prediction: F at the INS output with the measured ω_ib, f
    (:func:`filter_F_measured`) → Picard (Φ, Q_k) → (Φ x, Φ P Φᵀ + Q_k, Φ, status); status 0 ok,
    1 Δt/τ beyond the Picard range, 2 no convergence. Returns (x, P, Φ, Q_k, status)."""
    phi, qk, status = _phi_q_of(filter_F_measured(x.size, lat, alt, v, rpy, w_ib, f_b, decay24,
                                                  decay), q, dt, tol)
    if status:
        return x, P, phi, qk, status
    xn, Pn = predict(x, P, phi, qk)
    return xn, Pn, phi, qk, 0


@njit(cache=True)
def _filter_F(n, lat, alt, v, rpy, w_eb, f_b, decay24, decay):
    """F (n×n) of the filter's model at one state with the body rate over the Earth ``w_eb``
    (:func:`filter_F_measured` with ω_ib = ω_eb + C_n^b ω_ie)."""
    c = _c_bn(rpy[0], rpy[1], rpy[2])
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    return filter_F_measured(n, lat, alt, v, rpy, w_eb + c.T @ w_ie, f_b, decay24, decay)


@njit(cache=True)
def filter_F_measured(n, lat, alt, v, rpy, w_ib, f_b, decay24, decay):
    """F (n×n) of the filter's model at an INS output (lat rad, alt m, V ENU m/s, roll, pitch,
    heading rad) with the INS's measured angular rate ``w_ib`` (3,) rad/s and specific force
    ``f_b`` (3,) m/s², body axes: the 33-state model's INS block (free vertical; Babich 2017
    eq. 6.7) and the GNSS/baro states' decay ``decay`` (n,) 1/s."""
    c = _c_bn(rpy[0], rpy[1], rpy[2])
    F33 = build_F(lat, alt, v, f_b, w_ib, c, decay24, 0.0, 0.0)
    F = np.zeros((n, n))
    F[:15, :15] = F33[:15, :15]
    for i in range(15, n):
        F[i, i] = -decay[i]
    return F


@njit(cache=True)
def _phi_q_of(F, q, dt, tol):
    """(Φ, Q_k, status) of a held F over ``dt`` by the Picard series (status 0 ok, 1 Δt/τ
    beyond the Picard range, 2 no convergence; F returned twice when status != 0)."""
    rate = 0.0
    for i in range(F.shape[0]):
        rate = max(rate, abs(F[i, i]))
    if rate * dt > PICARD_MAX_RATE_DT:
        return F, F, 1
    phi, qk, _, ok = _picard_sins(F, q, dt, tol, PICARD_MAX_ORDER)
    if not ok:
        return F, F, 2
    return phi, qk, 0


@njit(cache=True)
def _filter_phi_q(n, lat, alt, v, rpy, w_eb, f_b, decay24, decay, q, dt, tol):
    """(Φ, Q_k, status) of the filter's n-state model over ``dt`` at the given state (see
    :func:`_predict_step`; status 0 ok, 1 Picard range, 2 no convergence; F returned twice when
    status != 0)."""
    return _phi_q_of(_filter_F(n, lat, alt, v, rpy, w_eb, f_b, decay24, decay), q, dt, tol)


def _w_eb(ins: NavSolution, w_ib) -> np.ndarray:
    """ω_eb = ω_ib - C_n^b ω_ie (3,) rad/s at the INS's indicated latitude and attitude."""
    c = _c_bn(ins.roll_rad, ins.pitch_rad, ins.heading_rad)
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(ins.lat_rad), OMEGA_IE_RPS * math.sin(ins.lat_rad)])
    return np.asarray(w_ib, float) - c.T @ w_ie


@njit(cache=True)
def _scaled_r(R, sc):
    """R with its entries scaled by √(sc_i sc_j) (adaptive-R inflation; sc all 1: R itself)."""
    for v in sc:
        if v != 1.0:
            return R * np.sqrt(np.outer(sc, sc))
    return R


@njit(cache=True)
def _passes(nu, S, gate):
    """The innovation gate: every |ν_i| ≤ gate √S_ii."""
    for i in range(nu.size):
        if not abs(nu[i]) <= gate * math.sqrt(S[i, i]):
            return False
    return True


@njit(cache=True)
def _gated_correct(x, P, z, H, R, sc, frozen, gate):
    """:func:`~.kalman.correct` with R scaled by the adaptive inflation ``sc`` and the
    innovation gate; returns (x, P, ν, S, NIS, passed) — x, P corrected whether or not it
    passed (the caller keeps them only if it did)."""
    xn, Pn, nu, S, nis = correct(x, P, z, H, _scaled_r(R, sc), frozen)
    return xn, Pn, nu, S, nis, _passes(nu, S, gate)


@njit(cache=True)
def _gated_correct_delayed(x, P, z, H, R, sc, phi_lag, q_lag, frozen, gate):
    """:func:`_gated_correct` with :func:`~.kalman.correct_delayed`."""
    xn, Pn, nu, S, nis = correct_delayed(x, P, z, H, _scaled_r(R, sc), phi_lag, q_lag, frozen)
    return xn, Pn, nu, S, nis, _passes(nu, S, gate)


def _correct(f, z, H, R, sc, lag, frozen, gate):
    """(x, P, ν, S, NIS, passed): filter ``f``'s gated correction, delayed when ``lag`` is
    set."""
    if lag is None:
        return _gated_correct(f.x, f.P, z, H, R, sc, frozen, gate)
    return _gated_correct_delayed(f.x, f.P, z, H, R, sc, lag[0], lag[1], frozen, gate)


def _components(f, z, H, R, sc, lag, nu, S):
    """Seed 001's channel test |y_i − ŷ_i| ≤ ε_i = ``channel_test`` √S_ii per component:
    the failed components' gain columns are zeroed (the correction uses the passing rows of
    z, H, R alone), and a failed vertical component (index 2) also zeroes the gain rows
    ``hold_vertical`` (those states keep their prediction). Returns (None, True) when every
    component passes, ((ok, (x, P)), True) when some do, (None, False) when none does."""
    ok = np.abs(nu) <= f.channel_test * np.sqrt(np.diag(S))
    if ok.all() or not ok.any():
        return None, bool(ok.all())
    frozen = f.frozen
    if not ok[2] and f.hold_vertical is not None:
        frozen = frozen | f.hold_vertical
    Rs = np.ascontiguousarray(R[np.ix_(ok, ok)])
    x, P, *_ = _correct(f, np.ascontiguousarray(z[ok]), np.ascontiguousarray(H[ok]), Rs,
                        np.ascontiguousarray(sc[ok]), lag, frozen, math.inf)
    return (ok, (x, P)), True


class InsGnssFilter:
    """The error-state filter of one INS (see the module docstring).

    Parameters
    ----------
    imu : the INS's declared IMU model (its biases and noise densities are the filter's)
    gnss : the GNSS receiver's declared error model
    baro : the baro's declared model, or None (no baro measurement, 21 states)
    tuning : gate and unmodelled-error settings
    """

    def __init__(self, imu: ImuModel, gnss: GnssSpec, baro: BaroSpec | None,
                 tuning: FilterTuning = FilterTuning()):
        self.imu, self.gnss, self.baro, self.tuning = imu, gnss, baro, tuning
        self.n = n = 21 + (baro is not None)
        decay = np.zeros(n)
        decay[9:15] = imu.decay_rps[:6]
        decay[15:21] = 1.0 / gnss.markov_tau_s
        q = np.zeros(n)
        q[:15] = imu.q_psd[:15]
        q[15:21] = 2.0 * gnss.markov_sigma ** 2 / gnss.markov_tau_s
        if baro is not None:
            decay[BARO] = 1.0 / baro.markov_tau_s
            q[BARO] = 2.0 * baro.markov_sigma_m ** 2 / baro.markov_tau_s
        self.decay, self.q = decay, q
        self._var_acc, self._var_gyro = unmodelled_variances(imu)
        self.x = np.zeros(n)
        self.P = np.zeros((n, n))
        self._decay24 = np.ascontiguousarray(imu.decay_rps, float)
        self._no_freeze = np.zeros(n, np.bool_)
        # public view of the gain-row mask (seed 001's fault-tolerant estimator, set by
        # fdi.FaultTolerantEstimator) and the adaptive-R inflation per group (1: nominal R)
        self.frozen = self._no_freeze
        # seed 001's channel test per component (eq. 8; ``channel_test``: its ε_i in σ of S_ii,
        # 0: the group gate) and the vertical rows held when a vertical component fails on a
        # unit without another altitude channel (``hold_vertical``: the states, or None)
        self.channel_test, self.hold_vertical = 0.0, None
        self.r_scale = {"gnss_pos": np.ones(3), "gnss_vel": np.ones(3), "baro": np.ones(1)}
        self._lag = PredictionLag()   # (t_start_s, Φ, Q_k) of the recent steps
        self._rejected: dict[str, int] = {}   # consecutive gate rejections per group
        self.t_s: float | None = None
        R = np.zeros(n)
        R[:6] = gnss.white_sigma ** 2
        self._r_pos, self._r_vel = np.diag(R[:3]), np.diag(R[3:6])
        self._H_pos = np.zeros((3, n))
        self._H_pos[:, POS] = np.eye(3)
        self._H_pos[:, MP] = -np.eye(3)
        self._H_vel = np.zeros((3, n))
        self._H_vel[:, VEL] = np.eye(3)
        self._H_vel[:, MV] = -np.eye(3)
        if baro is not None:
            self._H_baro = np.zeros((1, n))
            self._H_baro[0, 2], self._H_baro[0, BARO] = 1.0, -1.0
            self._r_baro = np.array([[baro.white_sigma_m ** 2]])

    # -- initialisation and prediction ----------------------------------------------------
    def initialise(self, ins: NavSolution, alignment_s: float | None = None) -> None:
        """P0 at the first INS output: the INS block from the alignment (A diag(p0) Aᵀ of the
        33-state model, :func:`~fms_testbed.sensors.sins.analysis.initial_map`, at the indicated
        attitude, widened by the spread of A over the heading error σ_ψ) plus the
        equivalent-bias variance of the unmodelled accelerometer errors at 1 g; the GNSS and baro
        states at their stationary variance. ``alignment_s`` (s): the duration T of a
        stationary alignment on a noisy IMU, whose white-noise means (VRW²/T, ARW²/T) level and
        gyrocompass like a bias that the sensor's own bias state does not share: they add
        A_b diag(q/T) A_bᵀ to the navigation block only (None: no such term)."""
        imu = self.imu
        rpy = (ins.roll_rad, ins.pitch_rad, ins.heading_rad)
        A = initial_map(ins.lat_rad, rpy, imu, SinsOptions())
        P33 = (A * imu.p0_var) @ A.T
        if alignment_s:
            Ab = A[:9, 9:15]
            P33[:9, :9] += (Ab * (imu.q_psd[3:9] / float(alignment_s))) @ Ab.T
        # the map is built at the indicated heading, off by the alignment's own heading error:
        # add the first-order spread of A over that error, σ_ψ² (∂A/∂ψ) diag(p0) (∂A/∂ψ)ᵀ —
        # without it the nearly singular (ε_U, b_g) block of P0 is confidently wrong
        h = 1e-4
        dA = (initial_map(ins.lat_rad, (rpy[0], rpy[1], rpy[2] + h), imu, SinsOptions())
              - initial_map(ins.lat_rad, (rpy[0], rpy[1], rpy[2] - h), imu, SinsOptions())) / (2 * h)
        P33 += P33[8, 8] * (dA * imu.p0_var) @ dA.T
        P = np.zeros((self.n, self.n))
        P[:15, :15] = P33[:15, :15]
        g2 = G0_MPS2 ** 2
        P[9, 9] += g2 * imu.p0_var[22]        # x: misalignment of x towards z, times a_z
        P[10, 10] += g2 * imu.p0_var[24]      # y: misalignment of y towards z, times a_z
        P[11, 11] += g2 * imu.p0_var[17]      # z: scale factor of z, times a_z
        P[15:21, 15:21] = np.diag(self.gnss.markov_sigma ** 2)
        if self.baro is not None:
            P[BARO, BARO] = self.baro.markov_sigma_m ** 2
        self.P = P
        self.x[:] = 0.0
        self.t_s = ins.t_s

    def system_matrix(self, ins: NavSolution, f_b, w_ib) -> np.ndarray:
        """F (n×n) at the INS's indicated state ``ins`` with its compensated measured specific
        force ``f_b`` (3,) m/s² and rate ``w_ib`` (3,) rad/s (body axes)."""
        F33 = system_matrix(ins.lat_rad, ins.alt_m, ins.v_enu_mps,
                            (ins.roll_rad, ins.pitch_rad, ins.heading_rad),
                            _w_eb(ins, w_ib), np.asarray(f_b, float), self.imu, _FREE)
        F = np.zeros((self.n, self.n))
        F[:15, :15] = F33[:15, :15]
        F[np.arange(15, self.n), np.arange(15, self.n)] = -self.decay[15:]
        return F

    def _process_noise(self, state) -> np.ndarray:
        """:meth:`process_noise_at` the specific force and body rate of ``state`` (an object
        with ``f_body_mps2``, ``p_rps``, ``q_rps``, ``r_rps``: the Monte-Carlo engine's twin
        passes the sampled trajectory)."""
        return self.process_noise_at(state.f_body_mps2, (state.p_rps, state.q_rps, state.r_rps))

    def process_noise_at(self, f_b, w_b) -> np.ndarray:
        """Process-noise density (n,) at the specific force ``f_b`` (3,) m/s² and body rate
        ``w_b`` (3,) rad/s (:meth:`process_noise_mean` of their squares)."""
        f = np.asarray(f_b, float)
        w = np.asarray(w_b, float)
        df2 = float(f @ f) - 2.0 * G0_MPS2 * abs(float(f[2])) + G0_MPS2 ** 2
        return self.process_noise_mean(max(df2, 0.0), float(w @ w))

    def process_noise_mean(self, df2_mps4: float, w2_rps2: float) -> np.ndarray:
        """Process-noise density (n,) for a specific-force departure from 1 g of mean square
        ``df2_mps4`` ((m/s²)²) and a body rate of mean square ``w2_rps2`` ((rad/s)²): the
        declared densities plus the unmodelled scale-factor/misalignment terms
        2 σ² |Δf|² τ_u on δV and 2 σ² |ω|² τ_u on ε (module docstring)."""
        q = self.q.copy()
        tau = self.tuning.unmodelled_tau_s
        if tau > 0 and (self._var_acc > 0 or self._var_gyro > 0):
            q[VEL] += 2.0 * self._var_acc * df2_mps4 * tau
            q[ATT] += 2.0 * self._var_gyro * w2_rps2 * tau
        return q

    def predict(self, ins: NavSolution, f_b, w_ib, dt_s: float) -> None:
        """Propagate x, P over ``dt_s`` (s) with F at the INS output ``ins`` of the step start
        and the INS's compensated measured ``f_b`` (3,) m/s², ``w_ib`` (3,) rad/s of the step.

        Raises
        ------
        DiscretisationError : Picard asked for Δt/τ > 0.1 or did not converge (use vanloan)
        """
        q = self.process_noise_at(f_b, w_ib)
        if self.tuning.method == "picard":
            x, P, phi, qk, status = _predict_step(
                self.x, self.P, ins.lat_rad, ins.alt_m, np.asarray(ins.v_enu_mps, float),
                np.array([ins.roll_rad, ins.pitch_rad, ins.heading_rad]),
                np.asarray(w_ib, float), np.asarray(f_b, float), self._decay24, self.decay, q,
                float(dt_s), 1e-12)
            if status:
                raise DiscretisationError(
                    f"navigation.filter: Picard series unsuitable at dt = {dt_s:g} s (Δt/τ > "
                    f"{PICARD_MAX_RATE_DT} or no convergence); set navigation.filter.method: "
                    "vanloan")
        else:
            F = self.system_matrix(ins, f_b, w_ib)
            with single_thread_blas():
                phi, qk = discretize(F, np.diag(q), dt_s, method="vanloan")
            x, P = predict(self.x, self.P, phi, qk)
        self.x, self.P = x, P
        self._record_step(ins.t_s, phi, qk, dt_s)

    def _record_step(self, t0_s: float, phi: np.ndarray, qk: np.ndarray, dt_s: float) -> None:
        """Keep a prediction step's (Φ, Q_k) for delayed measurements; advance the time."""
        self._lag.append(t0_s, phi, qk)
        self.t_s = t0_s + dt_s

    # -- measurements ----------------------------------------------------------------------
    def _lag_since(self, t_m: float):
        """(Φ(t, t_m), Q_lag) over the prediction steps since ``t_m`` (None: no step since)."""
        return self._lag.since(t_m)

    def nominal_r(self, name: str) -> np.ndarray:
        """The declared measurement covariance of group ``name`` (before adaptive inflation)."""
        return {"gnss_pos": self._r_pos, "gnss_vel": self._r_vel}.get(name) if name != "baro" \
            else self._r_baro

    def use(self, meas: Measurement, sol: NavSolution, w_eb_rps=(0.0, 0.0, 0.0)
            ) -> GroupResult | None:
        """Use one measurement (:mod:`.measurements`) against the INS output ``sol`` at its time
        of validity (``w_eb_rps`` (3,) rad/s: the INS's measured body rate, for lever arms):
        delayed correction when the filter has predicted past it, the innovation gate, and the
        covariance reset after ``tuning.reset_after`` consecutive rejections. None when the
        measurement cannot be formed."""
        m = meas.matrices(sol, self.n, np.asarray(w_eb_rps, float))
        if m is None:
            return None
        z, H, R = m
        name = meas.name
        sc = self.r_scale.setdefault(name, np.ones(z.size))
        lag = self._lag_since(meas.t_s)
        n_rej = self._rejected.get(name, 0)
        reset = 0 < self.tuning.reset_after <= n_rej
        gate = math.inf if reset else self.tuning.gate_sigma
        P_in = self.P
        if reset:
            self.P = self._reset_covariance(meas, z, H, R, lag)
        x, P, nu, S, nis, used = _correct(self, z, H, R, sc, lag, self.frozen, gate)
        comp = None
        if self.channel_test > 0 and not reset and name.startswith("gnss"):
            comp, used = _components(self, z, H, R, sc, lag, nu, S)
            if comp is not None and used:
                x, P = comp[1]
                comp = tuple(comp[0])
        if used:
            self.x, self.P = x, P
            self._rejected[name] = 0
        else:
            self.P = P_in
            self._rejected[name] = n_rej + 1
        return GroupResult(name, nu, S, nis, bool(used), reset, comp)

    def _reset_covariance(self, meas: Measurement, z, H, R, lag) -> np.ndarray:
        """P with the rows and columns of ``meas.reset_states`` zeroed and their variance set
        to the largest ν² + R_ii of the measurement (same units as those states)."""
        Hm = H if lag is None else np.linalg.solve(lag[0].T, H.T).T
        nu = z - Hm @ self.x
        var = float(np.max(nu ** 2 + np.diag(R)))
        P = self.P.copy()
        idx = np.arange(self.n)[meas.reset_states]
        P[idx, :] = 0.0
        P[:, idx] = 0.0
        P[idx, idx] = var
        return P

    def gnss_update(self, fix: GnssFix, ins_at_fix: NavSolution,
                    w_eb_rps=(0.0, 0.0, 0.0)) -> list[GroupResult]:
        """Use a fix (position, then velocity of the antenna; the receiver's σ, or the declared
        white σ when it reports none) against the INS output at its time of validity."""
        ms = gnss_measurements(fix, self.gnss.antenna_lever_arm_m, self.gnss.time_tag_sigma_s,
                               self.gnss.white_sigma)
        return [g for g in (self.use(m, ins_at_fix, w_eb_rps) for m in ms) if g is not None]

    def baro_update(self, reading: BaroReading, ins: NavSolution) -> GroupResult:
        """Use a baro reading taken at the time of the INS output ``ins``."""
        if self.baro is None:
            raise ConfigError("navigation.baro: this filter has no baro state")
        return self.use(BaroAltitude(ins.t_s, reading.alt_m, self.baro.white_sigma_m), ins)

    def take_feedback(self) -> np.ndarray:
        """The INS block of x̂ (15,), handed to the INS; the filter's INS block is zeroed."""
        dx = self.x[:N_INS].copy()
        self.x[:N_INS] = 0.0
        return dx


__all__ = ["FilterTuning", "GroupResult", "InsGnssFilter", "STATE_NAMES", "enu_difference_m",
           "filter_F_measured"]
