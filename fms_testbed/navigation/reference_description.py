"""Reference-description monitor of redundant INS (Zaitseva, Groshev, Gavrilenko; seed 000).

Each INS unit is compared not with the others (majority voting) but with what its own declared
performance lets it do along the route actually flown — its *reference description*:

1. **Envelope.** From the reference epoch t₀ (``start_s``, after the filters have converged) the
   33-state SINS error model (:func:`fms_testbed.sensors.sins.analysis.system_matrix`, free
   vertical channel) is propagated along the flown route with the unit's *declared* parameters::

       P_ref(t₀) = [[P_f,i(t₀) (15×15), 0], [0, diag p0_var[15:33]]]
       P_ref(t_k+1) = Φ_k P_ref(t_k) Φ_kᵀ + Q_k

   P_f,i is unit i's filter covariance of its residual error at t₀ (what the in-flight
   calibration left unknown); the 18 scale-factor and misalignment states the filter does not
   carry start at their declared variance; Q_k is the declared process noise (ARW, VRW, bias
   instability). σ_env,i,c(t) = √P_ref[c, c] is how far a free-running copy of unit i may drift
   from its state at t₀ if it performs as declared.
2. **Actual error.** The free-running copy's error since t₀ is the unit's output plus the
   corrections the filter has fed back since t₀, carried through the error dynamics::

       D(t₀) = 0,   D(t_k+1) = Φ_k D(t_k) + Σ dx (feedback over the step)
       z_i = (p_i + D_i,p - p_out, V_i + D_i,V - V_out)         (E, N; m and m/s)

   with p_out, V_out the integrated solution (its own error, metres, is the measurement noise).
   A per-channel Kalman filter (each of E and N: state [δp, δV], white-acceleration model with
   the envelope's own velocity-variance growth as process noise, R = the integrated solution's
   covariance) estimates the actual error ê_i from z_i — Zaitseva's "per-channel filter with a
   corrector".
3. **Decision** (:func:`reference_decision`, a function on arrays). The normalised distance of
   unit i from its reference description is d_i = max_c |ê_i,c| / √(P_ref,i[c, c] + P̂_i,c) over
   the horizontal channels c ∈ {δp_E, δp_N, δV_E, δV_N} (the free vertical channel is frozen
   and excluded). Units are ranked by d; a unit with d_i > ``k_sigma`` for ``persist_s`` is
   outside its declared performance and excluded (latched); if every unit is outside, the one
   closest to its reference description (smallest d) is used.

The vertical channel is not tested: without a baro loop it is unstable, and its envelope says
nothing about the unit (seed 001's channel freezing). Majority voting (the baseline) runs in the
same flight (:meth:`fms_testbed.navigation.fdi.TwoStageFdi.vote`); both outputs are logged.

Cost. The monitor runs at every navigation step (10 Hz) but works once per ``step_s``: one
compiled call (``_epoch``) builds F at the integrated solution and (Φ, Q_k) once per IMU model
(the Picard kernel of :func:`~fms_testbed.sensors.sins.analysis.step_discrete`), propagates every
window's units on the blocks of Φ, runs the per-channel filters in closed form and decides. The
numpy functions below (:func:`propagate`, :func:`channel_filter_step`,
:func:`normalised_distance`, :func:`reference_decision`) are the statements of the equations;
tests/navigation/test_reference_description_kernels.py checks the compiled forms equal them to
rounding (rtol 1e-12).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.ins_filter import enu_difference_m
from fms_testbed.navigation.reference_kernels import (  # noqa: F401  (tests read them here)
    _add_feedback, _channel_step, _decide, _distance, _epoch, _measure_into, _propagate_blocks,
    channel_process_noise)
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.discretize import (PICARD_MAX_ORDER, PICARD_MAX_RATE_DT,
                                                 DiscretisationError)
from fms_testbed.sensors.sins.presets import ImuModel

CHANNELS = (0, 1, 3, 4)
"""States of the 33-state model tested: δp_E, δp_N (m), δV_E, δV_N (m/s)."""

_FREE = SinsOptions(vertical="free")


@dataclass(frozen=True)
class ReferenceTuning:
    """Settings of the reference-description monitor (the one place for its threshold).

    k_sigma : a unit is outside its declared performance when its actual error exceeds
        ``k_sigma`` σ of its envelope on some horizontal channel — 5, from the false-alarm
        budget: at 4, 6 of 1,000 fault-free one-hour runs excluded a healthy unit (d 4.0-4.3);
        at 5, none (their largest d 4.85), at the cost of later identification (drift ×10:
        12.2 instead of 11.7 min; ×5 and HG1700 ×2 no longer within the hour's windows)
    persist_s : for this long before it is excluded, s
    start_s : reference epoch t₀ (time since the first navigation step), s
    step_s : envelope / free-copy propagation step, s
    window_s : life of one reference epoch before it restarts, s
    n_windows : staggered reference epochs (offset ``window_s / n_windows``)
    track_tau_s : the per-channel filter's acceleration noise is at least the envelope's velocity
        variance over this time, (m/s)²/s (:func:`channel_process_noise`)
    """

    k_sigma: float = 5.0
    persist_s: float = 10.0
    start_s: float = 120.0
    step_s: float = 1.0
    window_s: float = 1200.0
    n_windows: int = 2
    track_tau_s: float = 10.0


def envelope_start(P_filter: np.ndarray, imu: ImuModel) -> np.ndarray:
    """P_ref(t₀) (33×33): a unit's filter covariance of its 15 INS states (residual errors after
    feedback) and the declared variance of the 18 scale-factor/misalignment states — except the
    three seen as an accelerometer bias at 1 g (k_a,z and the x→z, y→z misalignments), which the
    filter's equivalent-bias prior already carries (:meth:`.ins_filter.InsGnssFilter.initialise`).

    Parameters
    ----------
    P_filter : (≥15, ≥15) the unit's filter covariance (state units², :mod:`.ins_filter`)
    imu : the unit's declared IMU model (``p0_var``)
    """
    P = np.zeros((33, 33))
    P[:15, :15] = P_filter[:15, :15]
    var = imu.p0_var[15:33].copy()
    var[[17 - 15, 22 - 15, 24 - 15]] = 0.0    # their effect at 1 g is in the filter's b_a
    P[np.arange(15, 33), np.arange(15, 33)] = var
    return P


def propagate(P: np.ndarray, D: np.ndarray, phi: np.ndarray, qk: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """One step of the envelope and of the free copies: P ← Φ P Φᵀ + Q_k, D ← Φ D.

    Parameters
    ----------
    P : (u, 33, 33) envelopes, state units²;  D : (u, 33) free-copy offsets, state units
    phi, qk : (33, 33) transition and declared process noise over the step
    """
    Pn = phi @ P @ phi.T + qk
    return 0.5 * (Pn + np.swapaxes(Pn, 1, 2)), D @ phi.T


def channel_filter_step(x: np.ndarray, Pc: np.ndarray, z: np.ndarray, r: np.ndarray,
                        q: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-channel Kalman filter of the actual error: state [δp, δV] per unit and axis, model
    δṗ = δV, δV̇ = w (w white, density q), measurement z = [δp, δV] + v, v ~ N(0, diag r).

    Parameters
    ----------
    x : (u, 2, 2) estimates [δp m, δV m/s] per unit and axis (E, N)
    Pc : (u, 2, 2, 2) their covariances
    z : (u, 2, 2) measurements;  r : (u, 2, 2) their variances (m², (m/s)²)
    q : (u, 2) acceleration noise density, (m/s²)²·s;  dt_s : step, s

    Returns
    -------
    (x, Pc) after prediction over ``dt_s`` and correction with z
    """
    F = np.array([[1.0, dt_s], [0.0, 1.0]])
    Qb = np.array([[dt_s ** 3 / 3, dt_s ** 2 / 2], [dt_s ** 2 / 2, dt_s]])
    x = x @ F.T
    Pc = F @ Pc @ F.T + q[..., None, None] * Qb
    S = Pc + r[..., :, None] * np.eye(2)
    K = np.linalg.solve(S, Pc).swapaxes(-1, -2)            # Pc S⁻¹ (both symmetric)
    x = x + (K @ (z - x)[..., None])[..., 0]
    A = np.eye(2) - K
    Pc = A @ Pc @ A.swapaxes(-1, -2) + K @ (r[..., :, None] * np.eye(2)) @ K.swapaxes(-1, -2)
    return x, Pc


def normalised_distance(e_hat: np.ndarray, var_env: np.ndarray) -> np.ndarray:
    """d_i = max_c |ê_i,c| / σ_i,c: each unit's distance from its reference description.

    Parameters
    ----------
    e_hat : (u, c) estimated actual errors per channel;  var_env : (u, c) envelope variances
        (plus the estimate's own), same units²
    """
    return np.max(np.abs(e_hat) / np.sqrt(var_env), axis=1)


def reference_decision(d: np.ndarray, excluded: np.ndarray, outside_since: np.ndarray,
                       t_s: float, tuning: ReferenceTuning = ReferenceTuning()
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Zaitseva's rule on the normalised distances of one instant.

    Parameters
    ----------
    d : (u,) normalised distances (:func:`normalised_distance`)
    excluded : (u,) bool, units already excluded (latched)
    outside_since : (u,) time each unit's d first exceeded ``k_sigma`` in its current excursion,
        s (NaN: inside)
    t_s : now, s;  tuning : ``k_sigma``, ``persist_s``

    Returns
    -------
    (used, excluded, outside_since, rank) : used (u,) bool — the units not excluded, or, when
    every unit is outside, only the one with the smallest d; the updated latch and timers; and
    the ranking (indices, closest to the reference description first)
    """
    d = np.asarray(d, float)
    out = d > tuning.k_sigma
    since = np.where(out, np.where(np.isnan(outside_since), t_s, outside_since), np.nan)
    persisted = out & (t_s - np.nan_to_num(since, nan=np.inf) >= tuning.persist_s - 1e-9)
    rank = np.argsort(d, kind="stable")
    new = excluded | persisted
    if new.all():                        # all outside: use the closest, exclude none more
        used = np.zeros(d.size, bool)
        used[rank[0]] = True
        return used, excluded.copy(), since, rank
    return ~new, new, since, rank


def rank_weights(d: np.ndarray) -> np.ndarray:
    """Weights of the units in the output from their distances to their reference descriptions:
    w_i = (1 + d_i²)⁻¹ / Σ_j (1 + d_j²)⁻¹ — the best-ranked unit weighs most, a unit at d σ
    weighs about 1/d² of one on its description (equal weights when the d are equal).

    Parameters
    ----------
    d : (u,) normalised distances (:func:`normalised_distance`), dimensionless
    """
    w = 1.0 / (1.0 + np.asarray(d, float) ** 2)
    return w / w.sum()


def _raise_status(status: int, dt: float) -> None:
    """The epoch kernel's failures as errors (``status`` of :func:`.reference_kernels._epoch`,
    ``dt`` the step, s)."""
    if status == 1:
        raise DiscretisationError(
            f"reference description: Picard series not suitable for the envelope step "
            f"(dt/tau > {PICARD_MAX_RATE_DT}, dt = {dt:g} s); use a smaller step_s")
    if status == 2:
        raise DiscretisationError(
            f"Picard series did not reach tol {_FREE.tol:g} in {PICARD_MAX_ORDER} terms "
            f"(dt = {dt:g} s)")
    if status:
        raise ValueError("reference description: Φ of the SINS model is not of the block form "
                         "[[Φ11, Φ12], [0, diagonal]] the envelope propagation assumes")


@dataclass
class _Window:
    """One reference epoch: the envelopes, free-copy offsets and per-channel filters since it
    (views of the monitor's window slot ``slot``)."""

    start_s: float
    P: np.ndarray                   # (u, 33, 33)
    D: np.ndarray                   # (u, 33)
    x: np.ndarray                   # (u, 2, 2)
    Pc: np.ndarray                  # (u, 2, 2, 2)
    slot: int = 0


class ReferenceDescriptionMonitor:
    """The monitor over ``n`` INS units (see the module docstring).

    Reference epochs are staggered: a window restarts every ``window_s`` (re-armed from the
    filters' covariance of that moment, so the envelope starts from what the in-flight
    calibration knows then, e.g. the heading once a turn has made it observable), with
    ``n_windows`` windows offset by ``window_s / n_windows``; the decision uses the oldest
    running window. One compiled call per reference epoch does the work (F and (Φ, Q_k) once
    per IMU model, every window's units, the per-channel filters, the decision).

    Parameters
    ----------
    imus : each unit's declared IMU model;  tuning : :class:`ReferenceTuning`
    """

    def __init__(self, imus: list[ImuModel], tuning: ReferenceTuning = ReferenceTuning()):
        self.imus, self.tuning, self.n = list(imus), tuning, len(imus)
        self.t0_s: float | None = None            # first navigation step
        self.windows: list[_Window] = []
        self._t_last: float | None = None
        self.excluded = np.zeros(self.n, bool)
        self.since = np.full(self.n, np.nan)
        self.used = np.ones(self.n, bool)
        self.d = np.full(self.n, np.nan)
        self.rank = np.arange(self.n)
        self._all_out = False
        self._detected = np.zeros(self.n, bool)
        models: dict[int, int] = {}                # units sharing an IMU model share (Φ, Q_k)
        for imu in self.imus:
            models.setdefault(id(imu), len(models))
        self._model = np.array([models[id(imu)] for imu in self.imus], np.int64)
        first = list({id(imu): imu for imu in self.imus}.values())     # in model order
        self._decay = np.array([np.asarray(imu.decay_rps, float) for imu in first])
        self._q_psd = np.array([np.asarray(imu.q_psd, float) for imu in first])
        w = max(int(tuning.n_windows), 1)          # window slots (at most n_windows run at once)
        self._P = np.zeros((w, self.n, 33, 33))
        self._D = np.zeros((w, self.n, 33))
        self._X = np.zeros((w, self.n, 2, 2))
        self._PC = np.zeros((w, self.n, 2, 2, 2))
        self._s = np.empty(21)                     # the epoch kernel's scalars (see _epoch)
        self._ins = np.empty((self.n, 5))

    def _measure(self, D: np.ndarray, ins: list[NavSolution], out: tuple) -> np.ndarray:
        """z (u, 2 axes, [δp, δV]) of the free copies (offsets ``D``) against the integrated
        solution ``out`` (lat rad, lon rad, alt m, V (3,) m/s)."""
        z = np.empty((self.n, 2, 2))
        for i, s in enumerate(ins):
            dp = enu_difference_m(s.lat_rad, s.lon_rad, s.alt_m, out[0], out[1], out[2])
            dv = np.asarray(s.v_enu_mps, float) - np.asarray(out[3], float)
            z[i, :, 0] = dp[:2] + D[i, 0:2]
            z[i, :, 1] = dv[:2] + D[i, 3:5]
        return z

    def _arm(self, t: float, ins, out, P_out, P_filters) -> _Window:
        used = {w.slot for w in self.windows}
        k = next(j for j in range(self._P.shape[0]) if j not in used)
        self._P[k] = np.stack([envelope_start(Pf, imu) for Pf, imu in zip(P_filters, self.imus)])
        self._D[k] = 0.0
        r = np.broadcast_to(self._r(P_out), (self.n, 2, 2))
        self._X[k] = self._measure(self._D[k], ins, out)
        self._PC[k] = r[..., :, None] * np.eye(2)
        return _Window(t, self._P[k], self._D[k], self._X[k], self._PC[k], k)

    def update(self, truth: AircraftState, ins: list[NavSolution], out: tuple,
               P_out: np.ndarray, P_filters: list[np.ndarray], feedback: np.ndarray
               ) -> list[dict]:
        """One navigation step.

        Parameters
        ----------
        truth : the true state (its body rates and specific force are what the IMUs measure)
        ins : the units' outputs (after this step's feedback)
        out : the integrated solution (lat rad, lon rad, alt m, V (3,) m/s, roll, pitch,
            heading rad)
        P_out : its covariance (≥6×6, position m², velocity (m/s)²)
        P_filters : each unit's filter covariance (used at each reference epoch)
        feedback : (u, 15) corrections fed back to each unit since the last call

        Returns
        -------
        events (``detected``, ``excluded``, ``reconfigured`` with ``stage`` ``reference``)
        """
        t, tn = truth.t_s, self.tuning
        if self.t0_s is None:
            self.t0_s = t
        if self.windows:                   # every slot: a free one is cleared when armed
            _add_feedback(self._D, feedback)
        if t - self.t0_s < tn.start_s - 1e-9:
            return []
        if not self.windows:
            self._t_last = t
            self.windows.append(self._arm(t, ins, out, P_out, P_filters))
            return []
        dt = t - self._t_last
        if dt < tn.step_s - 1e-9:
            return []
        self._t_last = t
        self._fill(truth, ins, out, P_out, dt)
        status, d, used, excluded, since, rank, notify, all_out = _epoch(
            self._P, self._D, self._X, self._PC, np.array([w.slot for w in self.windows]),
            self._s, self._ins, self._decay, self._q_psd, self._model, _FREE.tol, self.excluded,
            self.since, self._detected, tn.k_sigma, tn.persist_s, tn.track_tau_s)
        _raise_status(status, dt)
        was_excluded = self.excluded
        self.d, self.used, self.excluded, self.since, self.rank = d, used, excluded, since, rank
        self._restart(t, ins, out, P_out, P_filters)
        if notify or all_out != self._all_out:
            return self._events(t, was_excluded)
        return []

    def _fill(self, truth, ins, out, P_out, dt) -> None:
        """The epoch kernel's scalars (see :func:`.reference_kernels._epoch`) and unit outputs."""
        s, v, f = self._s, out[3], truth.f_body_mps2
        s[0], s[1], s[2], s[3], s[4], s[5] = out[0], out[1], out[2], v[0], v[1], v[2]
        s[6], s[7], s[8] = out[4], out[5], out[6]
        s[9], s[10], s[11] = truth.p_rps, truth.q_rps, truth.r_rps
        s[12], s[13], s[14] = f[0], f[1], f[2]
        s[15], s[16], s[17], s[18] = P_out[0, 0], P_out[3, 3], P_out[1, 1], P_out[4, 4]
        s[19], s[20] = dt, truth.t_s
        a = self._ins
        for i, u in enumerate(ins):
            vu = u.v_enu_mps
            a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4] = (u.lat_rad, u.lon_rad, u.alt_m,
                                                           vu[0], vu[1])

    def _restart(self, t, ins, out, P_out, P_filters) -> None:
        """Staggered reference epochs: restart the oldest at ``window_s``, open the next in
        turn."""
        tn = self.tuning
        if t - self.windows[0].start_s >= tn.window_s - 1e-9:
            self.windows.pop(0)
        last = self.windows[-1].start_s if self.windows else -math.inf
        if not self.windows or (len(self.windows) < tn.n_windows
                                and t - last >= tn.window_s / tn.n_windows - 1e-9):
            self.windows.append(self._arm(t, ins, out, P_out, P_filters))

    @staticmethod
    def _r(P_out: np.ndarray) -> np.ndarray:
        r = np.empty(2 * 2)
        r[:] = [P_out[0, 0], P_out[3, 3], P_out[1, 1], P_out[4, 4]]
        return np.broadcast_to(np.maximum(r, 1e-6).reshape(2, 2), (1, 2, 2)).copy()

    def _events(self, t: float, was_excluded: np.ndarray) -> list[dict]:
        ev: list[dict] = []
        k = self.tuning.k_sigma
        for i in range(self.n):
            if self.d[i] > k and not self._detected[i]:
                self._detected[i] = True
                ev.append({"t_s": round(t, 3), "unit": f"ins{i + 1}", "kind": "detected",
                           "stage": "reference",
                           "reason": f"actual error {self.d[i]:.1f} σ of its reference "
                                     f"description (> {k:g})"})
                if int((self.d > k).sum()) == 1:            # the ranking names it alone
                    ev.append({"t_s": round(t, 3), "unit": f"ins{i + 1}", "kind": "isolated",
                               "stage": "reference",
                               "reason": "the only unit outside its declared performance "
                                         f"(ranking {' < '.join(f'ins{j + 1}' for j in self.rank)})"})
            if self.excluded[i] and not was_excluded[i]:
                ev.append({"t_s": round(t, 3), "unit": f"ins{i + 1}", "kind": "excluded",
                           "stage": "reference",
                           "reason": f"outside its declared performance for "
                                     f"{self.tuning.persist_s:g} s ({self.d[i]:.1f} σ > {k:g})"})
        left = [f"ins{j + 1}" for j in range(self.n) if self.used[j]]
        all_out = bool((self.excluded | (self.d > k)).all())
        if (self.excluded != was_excluded).any() or all_out != self._all_out:
            why = ("every unit outside: the closest to its reference description, "
                   if all_out else "reference output from ")
            ev.append({"t_s": round(t, 3), "unit": "fms", "kind": "reconfigured",
                       "stage": "reference", "reason": why + ", ".join(left)})
        self._all_out = all_out
        return ev


__all__ = ["CHANNELS", "ReferenceDescriptionMonitor", "ReferenceTuning", "channel_filter_step",
           "channel_process_noise", "rank_weights",
           "envelope_start", "normalised_distance", "propagate", "reference_decision"]
