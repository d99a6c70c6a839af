"""Multi-rate covariance propagation of a group of INS/GNSS filters (:mod:`.ins_filter`): one F
for the group, built at the mean of their units' indicated states with the units' mean
measured specific force and rate, held over an interval of navigation steps (Groves 2013,
§14.2.4) and discretised by the Picard series (Babich 2017 eq. 2.5-2.9).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.state import NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.ins_filter import (N_INS, InsGnssFilter, _phi_q_of,
                                               filter_F_measured)
from fms_testbed.navigation.kalman import predict
from fms_testbed.sensors.sins.discretize import PICARD_MAX_RATE_DT, DiscretisationError


@njit(cache=True)
def _predict_trapezoid(X, P, F0, F1, q_bar, dt, tol):
    """Prediction of k filters over ``dt`` with one F̄ = (F0 + F1)/2 ((n, n) each, F at the
    interval's start and end) and the interval-mean process-noise density q̄ (n,): Picard →
    Φ x, Φ P Φᵀ + Q_k for each. Returns (X, P, Φ, Q_k, status)."""
    phi, qk, st = _phi_q_of(0.5 * (F0 + F1), q_bar, dt, tol)
    if st:
        return X, P, phi, qk, st
    Xn, Pn = np.empty_like(X), np.empty_like(P)
    for i in range(X.shape[0]):
        x, Pi = predict(X[i], P[i], phi, qk)
        Xn[i], Pn[i] = x, Pi
    return Xn, Pn, phi, qk, 0


def mean_state(ins: list[NavSolution]) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(lat rad, alt m, V (3,) m/s, [roll, pitch, heading] rad): the mean of INS outputs
    (circular mean of heading) — where a group of filters builds its one F.

    Parameters
    ----------
    ins : the units' indicated solutions
    """
    n = len(ins)
    if n == 1:
        s = ins[0]
        return s.lat_rad, s.alt_m, np.asarray(s.v_enu_mps, float), np.array(
            [s.roll_rad, s.pitch_rad, s.heading_rad])
    lat = alt = roll = pitch = sh = ch = 0.0
    v = np.zeros(3)
    for s in ins:
        lat += s.lat_rad
        alt += s.alt_m
        v += s.v_enu_mps
        roll += s.roll_rad
        pitch += s.pitch_rad
        sh += math.sin(s.heading_rad)
        ch += math.cos(s.heading_rad)
    return lat / n, alt / n, v / n, np.array([roll / n, pitch / n, math.atan2(sh, ch)])


class PredictionInterval:
    """Multi-rate propagation of a group of filters (one IMU model, receiver, baro, tuning).

    The INS is mechanised at every navigation step, but the filters' covariance is propagated
    over an *interval* of steps at once (Groves 2013, §14.2.4: the system propagation may run
    at a lower rate than the INS update, with F averaged over the interval): F and the
    F is taken at the interval's start and end and averaged (trapezoidal rule, second order in
    the interval); the process-noise density, whose unmodelled part follows |ω|² and |Δf|² and
    jumps in a roll, is integrated step by step (each step's value at its start, as the per-step
    filter) and averaged; Φ, Q_k = Picard(F̄, q̄, Δt) (Babich 2017 eq.
    2.5-2.9), x ← Φ x, P ← Φ P Φᵀ + Q_k. The end of one interval is the start of the next.
    Between boundaries P and x are those of the last boundary.

    The group's filters share one F, built at the mean of their units' indicated states: the
    units differ by metres and milliradians, which changes F's entries by a relative 1e-6..1e-3
    (Coriolis and specific-force cross products) — the Monte-Carlo engine builds its filters'
    F at the true state for the same reason (:mod:`.montecarlo`).

    Parameters
    ----------
    filters : the group (:func:`can_share_prediction`)
    """

    def __init__(self, filters: list[InsGnssFilter]):
        self.filters = filters
        tn = filters[0].tuning
        rate = float(np.max(filters[0].decay))      # the fastest decay the series must span
        self.max_s = (tn.predict_interval_s if rate <= 0 else
                      min(tn.predict_interval_s, 0.9 * PICARD_MAX_RATE_DT / rate))
        """Longest interval, s: ``predict_interval_s``, within the Picard range."""
        self.rotation_max_rad = math.radians(tn.predict_rotation_deg)
        self.rotation_rad = 0.0     # ∫|ω| dt over the interval so far
        self.dt_s = 0.0
        self.t0_s: float | None = None
        self._F0: np.ndarray | None = None
        self._w2dt = self._df2dt = 0.0   # ∫|ω|² dt, ∫max(|f|² - 2 g |f_z| + g², 0) dt

    def _F_q(self, ins: list[NavSolution], f_b: np.ndarray, w_ib: np.ndarray) -> np.ndarray:
        f0 = self.filters[0]
        lat, alt, v, rpy = mean_state(ins)
        return filter_F_measured(f0.n, lat, alt, v, rpy, np.asarray(w_ib, float),
                                 np.asarray(f_b, float), f0._decay24, f0.decay)

    def start(self, ins: list[NavSolution], t_s: float, f_b, w_ib) -> None:
        """Open the first interval at the INS outputs ``ins`` of time ``t_s`` (s) with the
        units' mean measured specific force ``f_b`` (3,) m/s² and rate ``w_ib`` (3,) rad/s."""
        self._F0 = self._F_q(ins, f_b, w_ib)
        self.t0_s, self.dt_s = t_s, 0.0

    def add(self, f_b, w_ib, dt_s: float) -> bool:
        """One more navigation step of ``dt_s`` (s) with the measured specific force ``f_b``
        (3,) m/s² and rate ``w_ib`` (3,) rad/s (its means) in the interval; True when the
        interval is full (``max_s`` or the rotation limit)."""
        w = np.asarray(w_ib, float)
        f = np.asarray(f_b, float)
        w2 = float(w @ w)
        df2 = float(f @ f) - 2.0 * G0_MPS2 * abs(float(f[2])) + G0_MPS2 ** 2
        self.dt_s += float(dt_s)
        self.rotation_rad += math.sqrt(w2) * dt_s
        self._w2dt += w2 * dt_s
        self._df2dt += max(df2, 0.0) * dt_s
        return (self.dt_s >= self.max_s - 1e-9
                or self.rotation_rad >= self.rotation_max_rad - 1e-12)

    def ins_transition(self) -> np.ndarray:
        """Φ (15×15) of the INS error states from the filters' time (the interval's start) to
        now: I + A Δt + (A Δt)²/2, A the INS block of F at the start (Δt ≤ the interval; the
        next term is below 1e-4 of the first for Δt ≤ 1 s). Feedback of an estimate made at the
        filters' time to the INS of now goes through it."""
        A = self._F0[:N_INS, :N_INS] * self.dt_s
        return np.eye(N_INS) + A + 0.5 * (A @ A)

    def flush(self, ins: list[NavSolution], t_s: float, f_b, w_ib) -> None:
        """Close the interval at the INS outputs ``ins`` of time ``t_s`` (s) with the measured
        ``f_b`` (3,) m/s², ``w_ib`` (3,) rad/s of the last step: predict every filter over it
        and open the next (nothing when it is empty).

        Raises
        ------
        DiscretisationError : Picard asked for Δt/τ > 0.1 or did not converge (use vanloan)
        """
        if self.dt_s <= 0.0:
            return
        F1 = self._F_q(ins, f_b, w_ib)
        dt = self.dt_s
        X = np.array([f.x for f in self.filters])
        P = np.array([f.P for f in self.filters])
        q_bar = self.filters[0].process_noise_mean(self._df2dt / dt, self._w2dt / dt)
        X, P, phi, qk, status = _predict_trapezoid(X, P, self._F0, F1, q_bar, dt, 1e-12)
        if status:
            raise DiscretisationError(
                f"navigation.filter: Picard series unsuitable over {dt:g} s (Δt/τ > "
                f"{PICARD_MAX_RATE_DT} or no convergence); set navigation.filter.method: vanloan"
                " or a shorter predict_interval_s")
        for i, f in enumerate(self.filters):
            f.x, f.P = X[i], P[i]
            f._record_step(self.t0_s, phi, qk, dt)
        self._F0 = F1
        self.t0_s, self.dt_s, self.rotation_rad = t_s, 0.0, 0.0
        self._w2dt = self._df2dt = 0.0


def can_share_prediction(filters: list[InsGnssFilter]) -> bool:
    """True when the filters can be propagated together (:class:`PredictionInterval`, one
    compiled call): one IMU model, receiver, baro and tuning, the Picard method."""
    f0 = filters[0]
    return (f0.tuning.method == "picard"
            and all(f.imu is f0.imu and f.gnss is f0.gnss and f.baro is f0.baro
                    and f.tuning == f0.tuning for f in filters[1:]))



__all__ = ["PredictionInterval", "can_share_prediction", "mean_state"]
