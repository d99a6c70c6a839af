"""Loosely coupled error-state INS/GNSS Kalman filter for one INS (seed 004's 15 + 6 states).

State (SI, errors are *indicated minus true*, the SINS model's convention)::

    0:3   δp   INS position error E, N, U, m          3:6   δV   INS velocity error, m/s
    6:9   ε    INS attitude error about E, N, U, rad   9:12  b_a  accelerometer bias, body, m/s²
    12:15 b_g  gyro bias, body, rad/s                  15:18 m_p  GNSS position Markov error, m
    18:21 m_v  GNSS velocity Markov error, m/s         21    b_h  baro bias, m (with a baro)

The INS block of F is the first 15×15 of the project's 33-state model
(:func:`fms_testbed.sensors.sins.model.build_F`, free vertical channel), built at the INS's
*indicated* position, velocity and attitude with the IMU's rates and specific force; the GNSS and
baro states are first-order Gauss-Markov. Φ_k, Q_k come from the Picard series
(:func:`fms_testbed.sensors.sins.discretize.discretize_sins`, Babich 2017 eq. 2.5-2.9/4.3-4.5) or
Van Loan. Measurements (ENU, m and m/s)::

    z_p = p_INS - p_GNSS = δp - m_p - w_p           H_p = [I 0 0 0 0 -I 0]
    z_v = V_INS - V_GNSS = δV - m_v - w_v           H_v = [0 I 0 0 0 0 -I]
    z_h = h_INS - h_baro = δp_U - b_h - w_h

A fix valid at t_m and used at t (latency) is compared with the INS output of t_m against the
estimate carried back, x̂(t_m) = Φ(t, t_m)⁻¹ x̂(t) (the process noise over the lag is neglected in
the cross-covariance). Each group passes an innovation gate (|ν_i| ≤ gate·√S_ii) before the
Joseph-form correction (:mod:`.kalman`). Feedback: at every GNSS update the INS block of x̂ is
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

from fms_testbed.core.earth import OMEGA_IE_RPS, radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.fdi import unmodelled_variances
from fms_testbed.navigation.kalman import (PredictionLag, correct, correct_delayed, innovation,
                                          predict)
from fms_testbed.navigation.sins import _c_bn
from fms_testbed.sensors.baro import BaroReading, BaroSpec
from fms_testbed.sensors.gnss import GnssFix, GnssSpec
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.analysis import SinsOptions, initial_map, system_matrix
from fms_testbed.sensors.sins.discretize import (PICARD_MAX_ORDER, PICARD_MAX_RATE_DT,
                                                 DiscretisationError, _picard_sins, discretize)
from fms_testbed.sensors.sins.model import build_F
from fms_testbed.sensors.sins.presets import ImuModel

N_INS = 15
POS, VEL, ATT, BA, BG = (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 15))
MP, MV = slice(15, 18), slice(18, 21)
BARO = 21
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
    """

    gate_sigma: float = 5.0
    unmodelled_tau_s: float = 20.0
    method: str = "picard"

    def __post_init__(self):
        if not self.gate_sigma > 0:
            raise ConfigError("navigation.filter.gate_sigma: must be > 0")
        if not self.unmodelled_tau_s >= 0:
            raise ConfigError("navigation.filter.unmodelled_tau_s: must be >= 0 s")
        if self.method not in ("picard", "vanloan"):
            raise ConfigError("navigation.filter.method: picard or vanloan")


@dataclass(frozen=True)
class GroupResult:
    """One measurement group at one update: name (``gnss_pos``, ``gnss_vel``, ``baro``), its
    innovation (units of the group), S, NIS, and whether it passed the gate and was used."""

    name: str
    innovation: np.ndarray
    S: np.ndarray
    nis: float
    used: bool


def enu_difference_m(a_lat_rad, a_lon_rad, a_alt_m, b_lat_rad, b_lon_rad, b_alt_m) -> np.ndarray:
    """Position a - b in local ENU at a, m (small differences: radii of curvature at a)."""
    rm, rn = radii_m(a_lat_rad)
    return np.array([(a_lon_rad - b_lon_rad) * (rn + a_alt_m) * math.cos(a_lat_rad),
                     (a_lat_rad - b_lat_rad) * (rm + a_alt_m), a_alt_m - b_alt_m])


@njit(cache=True)
def _predict_step(x, P, lat, alt, v, rpy, w_eb, f_b, decay24, decay, q, dt, tol):
    """Fused prediction: F at the INS output (33-state model's INS block, free vertical; the
    GNSS/baro states' decay) → Picard (Φ, Q_k) → (Φ x, Φ P Φᵀ + Q_k, Φ, status); status 0 ok,
    1 Δt/τ beyond the Picard range, 2 no convergence. Returns (x, P, Φ, Q_k, status)."""
    phi, qk, status = _filter_phi_q(x.size, lat, alt, v, rpy, w_eb, f_b, decay24, decay, q, dt,
                                    tol)
    if status:
        return x, P, phi, qk, status
    xn, Pn = predict(x, P, phi, qk)
    return xn, Pn, phi, qk, 0


@njit(cache=True)
def _filter_phi_q(n, lat, alt, v, rpy, w_eb, f_b, decay24, decay, q, dt, tol):
    """(Φ, Q_k, status) of the filter's n-state model over ``dt`` at the given state (see
    :func:`_predict_step`; status 0 ok, 1 Picard range, 2 no convergence; F returned twice when
    status != 0)."""
    c = _c_bn(rpy[0], rpy[1], rpy[2])
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    w_ib = w_eb + c.T @ w_ie
    F33 = build_F(lat, alt, v, f_b, w_ib, c, decay24, 0.0, 0.0)
    F = np.zeros((n, n))
    F[:15, :15] = F33[:15, :15]
    rate = 0.0
    for i in range(n):
        if i >= 15:
            F[i, i] = -decay[i]
        rate = max(rate, abs(F[i, i]))
    if rate * dt > PICARD_MAX_RATE_DT:
        return F, F, 1
    phi, qk, _, ok = _picard_sins(F, q, dt, tol, PICARD_MAX_ORDER)
    if not ok:
        return F, F, 2
    return phi, qk, 0


@njit(cache=True)
def _predict_many(X, P, lat, alt, V, RPY, w_eb, f_b, decay24, decay, q, dt, tol):
    """:func:`_predict_step` for k filters of one IMU model at once (one call instead of k):
    X (k, n), P (k, n, n), lat/alt (k,), V/RPY (k, 3) their INS outputs; the same arithmetic per
    filter, so the same numbers. Returns (X, P, Φ (k, n, n), Q_k (k, n, n), status (k,))."""
    k, n = X.shape
    Xn, Pn = np.empty_like(X), np.empty_like(P)
    phis, qks = np.empty_like(P), np.empty_like(P)
    status = np.zeros(k, np.int64)
    for i in range(k):
        x, Pi, phi, qk, st = _predict_step(X[i], P[i], lat[i], alt[i], V[i], RPY[i], w_eb, f_b,
                                           decay24, decay, q, dt, tol)
        status[i] = st
        if st == 0:
            Xn[i], Pn[i], phis[i], qks[i] = x, Pi, phi, qk
    return Xn, Pn, phis, qks, status


def predict_filters(filters: list["InsGnssFilter"], ins: list[NavSolution],
                    truth: AircraftState, dt_s: float) -> None:
    """``filters[i].predict(ins[i], truth, dt_s)`` for every filter, in one compiled call when
    they share one IMU model, receiver, baro and tuning with the Picard method (the process noise
    of the step, which depends only on the truth and the IMU model, is computed once); the same
    numbers as the per-filter calls.

    Raises
    ------
    DiscretisationError : as :meth:`InsGnssFilter.predict`
    """
    f0 = filters[0]
    if (len(filters) == 1 or f0.tuning.method != "picard"
            or any(f.imu is not f0.imu or f.gnss is not f0.gnss or f.baro is not f0.baro
                   or f.tuning != f0.tuning for f in filters[1:])):
        for f, sol in zip(filters, ins):
            f.predict(sol, truth, dt_s)
        return
    lat = np.array([s.lat_rad for s in ins])
    alt = np.array([s.alt_m for s in ins])
    V = np.array([s.v_enu_mps for s in ins], float)
    RPY = np.array([(s.roll_rad, s.pitch_rad, s.heading_rad) for s in ins])
    X = np.array([f.x for f in filters])
    P = np.array([f.P for f in filters])
    X, P, phis, qks, status = _predict_many(
        X, P, lat, alt, V, RPY, np.array([truth.p_rps, truth.q_rps, truth.r_rps]),
        np.asarray(truth.f_body_mps2, float), f0._decay24, f0.decay, f0._process_noise(truth),
        float(dt_s), 1e-12)
    if status.any():
        raise DiscretisationError(
            f"navigation.filter: Picard series unsuitable at dt = {dt_s:g} s (Δt/τ > "
            f"{PICARD_MAX_RATE_DT} or no convergence); set navigation.filter.method: vanloan")
    for i, f in enumerate(filters):
        f.x, f.P = X[i], P[i]
        f._record_step(ins[i].t_s, phis[i], qks[i], dt_s)


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
        self.r_scale = {"gnss_pos": np.ones(3), "gnss_vel": np.ones(3), "baro": np.ones(1)}
        self._lag = PredictionLag()   # (t_start_s, Φ, Q_k) of the recent steps
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
    def initialise(self, ins: NavSolution) -> None:
        """P0 at the first INS output: the INS block from the alignment (A diag(p0) Aᵀ of the
        33-state model, :func:`~fms_testbed.sensors.sins.analysis.initial_map`, at the indicated
        attitude, widened by the spread of A over the heading error σ_ψ) plus the
        equivalent-bias variance of the unmodelled accelerometer errors at 1 g; the GNSS and baro
        states at their stationary variance."""
        imu = self.imu
        rpy = (ins.roll_rad, ins.pitch_rad, ins.heading_rad)
        A = initial_map(ins.lat_rad, rpy, imu, SinsOptions())
        P33 = (A * imu.p0_var) @ A.T
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

    def system_matrix(self, ins: NavSolution, truth: AircraftState) -> np.ndarray:
        """F (n×n) at the INS's indicated state; IMU rates and specific force from ``truth``
        (the IMU's errors change them by < 1e-3 relative, far below what F is sensitive to)."""
        F33 = system_matrix(ins.lat_rad, ins.alt_m, ins.v_enu_mps,
                            (ins.roll_rad, ins.pitch_rad, ins.heading_rad),
                            (truth.p_rps, truth.q_rps, truth.r_rps), truth.f_body_mps2,
                            self.imu, _FREE)
        F = np.zeros((self.n, self.n))
        F[:15, :15] = F33[:15, :15]
        F[np.arange(15, self.n), np.arange(15, self.n)] = -self.decay[15:]
        return F

    def _process_noise(self, truth: AircraftState) -> np.ndarray:
        q = self.q.copy()
        tau = self.tuning.unmodelled_tau_s
        if tau > 0 and (self._var_acc > 0 or self._var_gyro > 0):
            f = np.asarray(truth.f_body_mps2, float)
            df2 = float(f @ f) - 2.0 * G0_MPS2 * abs(float(f[2])) + G0_MPS2 ** 2
            w2 = truth.p_rps ** 2 + truth.q_rps ** 2 + truth.r_rps ** 2
            q[VEL] += 2.0 * self._var_acc * max(df2, 0.0) * tau
            q[ATT] += 2.0 * self._var_gyro * w2 * tau
        return q

    def predict(self, ins: NavSolution, truth: AircraftState, dt_s: float) -> None:
        """Propagate x, P over ``dt_s`` (s) with F at the INS output ``ins`` of the step start.

        Raises
        ------
        DiscretisationError : Picard asked for Δt/τ > 0.1 or did not converge (use vanloan)
        """
        q = self._process_noise(truth)
        if self.tuning.method == "picard":
            x, P, phi, qk, status = _predict_step(
                self.x, self.P, ins.lat_rad, ins.alt_m, np.asarray(ins.v_enu_mps, float),
                np.array([ins.roll_rad, ins.pitch_rad, ins.heading_rad]),
                np.array([truth.p_rps, truth.q_rps, truth.r_rps]),
                np.asarray(truth.f_body_mps2, float), self._decay24, self.decay, q, float(dt_s),
                1e-12)
            if status:
                raise DiscretisationError(
                    f"navigation.filter: Picard series unsuitable at dt = {dt_s:g} s (Δt/τ > "
                    f"{PICARD_MAX_RATE_DT} or no convergence); set navigation.filter.method: "
                    "vanloan")
        else:
            F = self.system_matrix(ins, truth)
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

    def _group(self, name, z, H, R, lag) -> GroupResult:
        sc = self.r_scale[name]
        if (sc != 1.0).any():
            R = R * np.sqrt(np.outer(sc, sc))
        if lag is None:
            nu, S, nis = innovation(self.x, self.P, z, H, R)
        else:
            _, _, nu, S, nis = correct_delayed(self.x, self.P, z, H, R, lag[0], lag[1],
                                               self._no_freeze)
        used = bool(np.all(np.abs(nu) <= self.tuning.gate_sigma * np.sqrt(np.diag(S))))
        if used:
            if lag is None:
                self.x, self.P, _, _, _ = correct(self.x, self.P, z, H, R, self._no_freeze)
            else:
                self.x, self.P, _, _, _ = correct_delayed(self.x, self.P, z, H, R, lag[0],
                                                          lag[1], self._no_freeze)
        return GroupResult(name, nu, S, nis, used)

    def gnss_update(self, fix: GnssFix, ins_at_fix: NavSolution) -> list[GroupResult]:
        """Use a fix (position, then velocity) against the INS output at its time of validity."""
        lag = self._lag_since(fix.t_s)
        zp = enu_difference_m(ins_at_fix.lat_rad, ins_at_fix.lon_rad, ins_at_fix.alt_m,
                              fix.lat_rad, fix.lon_rad, fix.alt_m)
        zv = np.asarray(ins_at_fix.v_enu_mps, float) - fix.v_enu_mps
        return [self._group("gnss_pos", zp, self._H_pos, self._r_pos, lag),
                self._group("gnss_vel", zv, self._H_vel, self._r_vel, lag)]

    def baro_update(self, reading: BaroReading, ins: NavSolution) -> GroupResult:
        """Use a baro reading taken at the time of the INS output ``ins``."""
        if self.baro is None:
            raise ConfigError("navigation.baro: this filter has no baro state")
        z = np.array([ins.alt_m - reading.alt_m])
        return self._group("baro", z, self._H_baro, self._r_baro, None)

    def take_feedback(self) -> np.ndarray:
        """The INS block of x̂ (15,), handed to the INS; the filter's INS block is zeroed."""
        dx = self.x[:N_INS].copy()
        self.x[:N_INS] = 0.0
        return dx


__all__ = ["FilterTuning", "GroupResult", "InsGnssFilter", "STATE_NAMES", "enu_difference_m",
           "predict_filters"]
