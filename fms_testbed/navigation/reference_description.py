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
from numba import njit

from fms_testbed.core.earth import OMEGA_IE_RPS, radii_m
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.ins_filter import enu_difference_m
# navigation.sins first: its import runs the numba-cache guard of this package (the kernels below
# inline build_F, _picard_sins and the Earth model's radii)
from fms_testbed.navigation.sins import _c_bn
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.discretize import (PICARD_MAX_ORDER, PICARD_MAX_RATE_DT,
                                                 DiscretisationError, _picard_sins)
from fms_testbed.sensors.sins.model import build_F
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


@njit(cache=True)
def channel_process_noise(var_v_now, var_v_before, dt_s, track_tau_s):
    """Acceleration noise density q of the per-channel filter, (m/s²)²·s: the growth of the
    envelope's velocity variance over the step, and at least that variance over
    ``track_tau_s``.

    The growth alone is not enough: in a turn the free copy's velocity error turns with the
    heading (its components change by metres per second in seconds) while the envelope's
    variance of a component may stall or shrink, and a filter given q → 0 there stops following
    its measurement — it lagged the measured error by 5 m/s (0.8 σ) in a climbing turn, the cause
    of healthy units' exclusions (19 in 100 fault-free one-hour runs). With the floor the filter
    follows the measurement within its noise (the integrated solution's, metres and cm/s against
    an envelope of hundreds of metres and metres per second), so d is the measured error's.

    Parameters
    ----------
    var_v_now, var_v_before : the envelope's velocity variance of the channel after and before
        the step, (m/s)²;  dt_s : step, s;  track_tau_s : s
    """
    return max((var_v_now - var_v_before) / dt_s, var_v_now / track_tau_s, 1e-10)


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


# --- compiled forms used by the monitor (the same equations as the functions above; tests compare
# them to rounding): one call per reference epoch does F, (Φ, Q_k), every window's envelopes and
# free copies, the per-channel filters, the distances and the decision

_N_NAV = 9     # navigation states of the 33-state model; the 24 sensor states have diagonal Φ


@njit(cache=True)
def _sensor_nonzeros(M, nn, nz, cnt):
    """For each sensor row i of M (rows and columns from ``nn`` on): the columns of its non-zero
    sensor entries in nz[i, :cnt[i]] (nz, cnt overwritten)."""
    m = M.shape[0] - nn
    for i in range(m):
        cnt[i] = 0
        for j in range(m):
            if M[nn + i, nn + j] != 0.0:
                nz[i, cnt[i]] = nn + j
                cnt[i] += 1


@njit(cache=True, fastmath={"contract"})
def _propagate_blocks(P, D, phi, qk):
    """:func:`propagate` for one unit in place, on the blocks of Φ = [[Φ11, Φ12], [0, diag φ22]]
    (9 navigation states, 24 sensor states): C = Φ P, Pₙ = C Φᵀ + Q_k, P ← ½ (Pₙ + Pₙᵀ), D ← Φ D.

    The sums run in the order of the BLAS product of :func:`propagate` (each element accumulated
    over k in turn, fused multiply-add), skipping only exact zeros (of Φ, and of the sensor rows
    of P: the sensor states the filter does not carry stay uncorrelated with each other), so the
    envelope stays within rounding of :func:`propagate` over a whole window although P carries
    the free vertical channel's growth. P (33, 33), D (33,), state units² and state units."""
    n = P.shape[0]
    nn = _N_NAV
    m = n - nn
    nz = np.empty((m, m), np.int64)            # sensor rows of P: their non-zero sensor columns
    cnt = np.zeros(m, np.int64)
    _sensor_nonzeros(P, nn, nz, cnt)
    C = np.zeros((n, n))
    for r in range(nn):
        for p in range(n):
            a = phi[r, p]
            if a == 0.0:
                continue
            if p < nn:
                for c in range(n):
                    C[r, c] += a * P[p, c]
            else:
                for c in range(nn):
                    C[r, c] += a * P[p, c]
                for k in range(cnt[p - nn]):
                    c = nz[p - nn, k]
                    C[r, c] += a * P[p, c]
    for r in range(nn, n):
        a = phi[r, r]
        for c in range(n):
            C[r, c] = a * P[r, c]
    Ct = C.T.copy()                            # C Φᵀ with the outputs of one k in a row
    _sensor_nonzeros(Ct, nn, nz, cnt)          # sensor columns of C: their non-zero sensor rows
    U = np.zeros((nn, n))
    for c in range(nn):
        for p in range(n):
            b = phi[c, p]
            if b == 0.0:
                continue
            if p < nn:
                for r in range(n):
                    U[c, r] += Ct[p, r] * b
            else:
                for r in range(nn):
                    U[c, r] += Ct[p, r] * b
                for k in range(cnt[p - nn]):
                    r = nz[p - nn, k]
                    U[c, r] += Ct[p, r] * b
    T = np.empty((n, n))
    for r in range(n):
        for c in range(nn):
            T[r, c] = U[c, r] + qk[r, c]
        for c in range(nn, n):
            T[r, c] = C[r, c] * phi[c, c] + qk[r, c]
    for r in range(n):
        for c in range(r, n):
            v = 0.5 * (T[r, c] + T[c, r])
            P[r, c] = v
            P[c, r] = v
    dn = np.zeros(nn)
    for r in range(nn):
        for p in range(n):
            dn[r] += phi[r, p] * D[p]
    for r in range(nn):
        D[r] = dn[r]
    for r in range(nn, n):
        D[r] = phi[r, r] * D[r]


@njit(cache=True)
def _channel_step(x, Pc, z0, z1, r0, r1, q, dt):
    """:func:`channel_filter_step` for one unit and axis in place, closed form (2×2 inverse):
    x (2,) [δp m, δV m/s], Pc (2, 2), z0, z1 the measurement, r0, r1 its variances, q the
    acceleration noise density (m/s²)²·s, dt s."""
    q00, q01, q11 = q * (dt ** 3 / 3), q * (dt ** 2 / 2), q * dt
    x0 = x[0] + dt * x[1]
    x1 = x[1]
    a00, a01, a10, a11 = Pc[0, 0], Pc[0, 1], Pc[1, 0], Pc[1, 1]
    b00, b01, b10, b11 = a00 + dt * a10, a01 + dt * a11, a10, a11           # F Pc
    p00 = b00 + b01 * dt + q00                                              # F Pc Fᵀ + q Qb
    p01 = b01 + q01
    p10 = b10 + b11 * dt + q01
    p11 = b11 + q11
    s00, s01, s10, s11 = p00 + r0, p01, p10, p11 + r1                     # S = Pc + R
    det = s00 * s11 - s01 * s10
    i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
    k00 = i00 * p00 + i01 * p10            # K = (S⁻¹ Pc)ᵀ
    k10 = i00 * p01 + i01 * p11
    k01 = i10 * p00 + i11 * p10
    k11 = i10 * p01 + i11 * p11
    v0, v1 = z0 - x0, z1 - x1
    x[0] = x0 + k00 * v0 + k01 * v1
    x[1] = x1 + k10 * v0 + k11 * v1
    a00, a01, a10, a11 = 1.0 - k00, -k01, -k10, 1.0 - k11                  # A = I - K
    c00 = a00 * p00 + a01 * p10            # A Pc
    c01 = a00 * p01 + a01 * p11
    c10 = a10 * p00 + a11 * p10
    c11 = a10 * p01 + a11 * p11
    Pc[0, 0] = c00 * a00 + c01 * a01 + (k00 * r0 * k00 + k01 * r1 * k01)  # A Pc Aᵀ + K R Kᵀ
    Pc[0, 1] = c00 * a10 + c01 * a11 + (k00 * r0 * k10 + k01 * r1 * k11)
    Pc[1, 0] = c10 * a00 + c11 * a01 + (k10 * r0 * k00 + k11 * r1 * k01)
    Pc[1, 1] = c10 * a10 + c11 * a11 + (k10 * r0 * k10 + k11 * r1 * k11)


@njit(cache=True)
def _add_feedback(D, feedback):
    """D[:, :, :m] += feedback (u, m) in every window slot (the free copies' Σ dx)."""
    for w in range(D.shape[0]):
        for i in range(feedback.shape[0]):
            for j in range(feedback.shape[1]):
                D[w, i, j] += feedback[i, j]


@njit(cache=True)
def _measure_into(z, D, ins, s):
    """z (u, 2, 2) of :meth:`ReferenceDescriptionMonitor._measure`: free copies (offsets D (u, 33))
    of the units ``ins`` (u, 5: lat rad, lon rad, alt m, V_E, V_N m/s) against the integrated
    solution s[0:5] (lat, lon, alt, V_E, V_N); position difference in ENU at the unit (radii of
    curvature at its latitude, :func:`.ins_filter.enu_difference_m`)."""
    for i in range(ins.shape[0]):
        rm, rn = radii_m(ins[i, 0])
        z[i, 0, 0] = (ins[i, 1] - s[1]) * (rn + ins[i, 2]) * math.cos(ins[i, 0]) + D[i, 0]
        z[i, 1, 0] = (ins[i, 0] - s[0]) * (rm + ins[i, 2]) + D[i, 1]
        z[i, 0, 1] = (ins[i, 3] - s[3]) + D[i, 3]
        z[i, 1, 1] = (ins[i, 4] - s[4]) + D[i, 4]


@njit(cache=True)
def _distance(P, Pc, x):
    """:func:`normalised_distance` of one unit from its window's P (33, 33), Pc (2, 2, 2), x (2, 2);
    NaN if any channel is NaN (as ``np.max``)."""
    best = -np.inf
    for c in range(4):
        ax, k = c % 2, c // 2                  # pE, pN, vE, vN
        st = 3 * k + ax
        v = abs(x[ax, k]) / math.sqrt(P[st, st] + Pc[ax, k, k])
        if math.isnan(v):
            return np.nan
        if v > best:
            best = v
    return best


@njit(cache=True)
def _decide(d, excluded, since, t_s, k_sigma, persist_s):
    """:func:`reference_decision` on scalars: (used, excluded, since, rank), new arrays."""
    n = d.size
    out = d > k_sigma
    new_since = np.empty(n)
    new = np.empty(n, np.bool_)
    for i in range(n):
        if out[i]:
            new_since[i] = t_s if math.isnan(since[i]) else since[i]
        else:
            new_since[i] = np.nan
        persisted = out[i] and t_s - new_since[i] >= persist_s - 1e-9
        new[i] = excluded[i] or persisted
    rank = np.empty(n, np.int64)               # stable argsort, NaN last (as numpy)
    for i in range(n):
        j = i
        while j > 0:
            a, b = d[rank[j - 1]], d[i]
            if not (math.isnan(b) or (not math.isnan(a) and a <= b)):
                rank[j] = rank[j - 1]
                j -= 1
            else:
                break
        rank[j] = i
    all_new = True
    for i in range(n):
        all_new = all_new and new[i]
    if all_new:
        used = np.zeros(n, np.bool_)
        used[rank[0]] = True
        return used, excluded.copy(), new_since, rank
    return np.logical_not(new), new, new_since, rank


@njit(cache=True)
def _epoch(P, D, X, PC, slots, s, ins, decay, q_psd, model, tol, excluded, since, detected,
           k_sigma, persist_s, track_tau_s):
    """One reference epoch (the body of :meth:`ReferenceDescriptionMonitor.update`), compiled.

    P (W, u, 33, 33), D (W, u, 33), X (W, u, 2, 2), PC (W, u, 2, 2, 2): the window slots, updated
    in place for ``slots`` (oldest first); s: the integrated solution (lat, lon, alt, V (3),
    roll, pitch, heading), the body rates p, q, r rad/s, specific force (3) m/s², the
    integrated solution's variances (E p, E v, N p, N v; m², (m/s)²), Δt s and t s; ins (u, 5); decay, q_psd (m, 33) per IMU model, model (u,) each unit's. F at the
    integrated solution and (Φ, Q_k) once per model (:func:`system_matrix` with a free vertical,
    :func:`step_discrete` Picard). Returns (status 0 ok, 1 Δt/τ beyond the Picard range, 2 no
    convergence, 3 Φ not of the block form [[Φ11, Φ12], [0, diag]] — nothing updated then; d, used, excluded, since, rank; notify: a unit newly
    outside or a change of the latch; all_out: every unit excluded or outside).
    """
    n_mod, n = q_psd.shape
    u = ins.shape[0]
    dt = s[19]
    c = _c_bn(s[6], s[7], s[8])
    lat = s[0]
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    w_ib = s[9:12] + c.T @ w_ie
    phis = np.empty((n_mod, n, n))
    qks = np.empty((n_mod, n, n))
    d = np.full(u, np.nan)
    for m in range(n_mod):
        F = build_F(lat, s[2], s[3:6].copy(), s[12:15].copy(), w_ib, c, decay[m], 0.0, 0.0)
        rate = 0.0
        for i in range(n):
            rate = max(rate, abs(F[i, i]))
        if rate * dt > PICARD_MAX_RATE_DT:
            return 1, d, excluded.copy(), excluded.copy(), since.copy(), np.arange(u), False, False
        phi, qk, _, ok = _picard_sins(F, q_psd[m], dt, tol, PICARD_MAX_ORDER)
        if not ok:
            return 2, d, excluded.copy(), excluded.copy(), since.copy(), np.arange(u), False, False
        for r in range(_N_NAV, n):             # the block form of Φ _propagate_blocks needs
            for j in range(n):
                if j != r and phi[r, j] != 0.0:
                    return 3, d, excluded.copy(), excluded.copy(), since.copy(), np.arange(u), \
                        False, False
        phis[m] = phi
        qks[m] = qk
    z = np.empty((u, 2, 2))
    for w in slots:
        v0 = np.empty((u, 2))
        for i in range(u):
            v0[i, 0], v0[i, 1] = P[w, i, 3, 3], P[w, i, 4, 4]
            _propagate_blocks(P[w, i], D[w, i], phis[model[i]], qks[model[i]])
        _measure_into(z, D[w], ins, s)
        for i in range(u):
            for ax in range(2):
                q = channel_process_noise(P[w, i, 3 + ax, 3 + ax], v0[i, ax], dt, track_tau_s)
                _channel_step(X[w, i, ax], PC[w, i, ax], z[i, ax, 0], z[i, ax, 1],
                              max(s[15 + 2 * ax], 1e-6), max(s[16 + 2 * ax], 1e-6), q, dt)
    w = slots[0]                                                    # the oldest
    for i in range(u):
        d[i] = _distance(P[w, i], PC[w, i], X[w, i])
    used, exc, since_n, rank = _decide(d, excluded, since, s[20], k_sigma, persist_s)
    notify, all_out = False, True
    for i in range(u):
        notify = notify or (d[i] > k_sigma and not detected[i]) or exc[i] != excluded[i]
        all_out = all_out and (exc[i] or d[i] > k_sigma)
    return 0, d, used, exc, since_n, rank, notify, all_out


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
        s, v, f = self._s, out[3], truth.f_body_mps2
        s[0], s[1], s[2], s[3], s[4], s[5] = out[0], out[1], out[2], v[0], v[1], v[2]
        s[6], s[7], s[8] = out[4], out[5], out[6]
        s[9], s[10], s[11] = truth.p_rps, truth.q_rps, truth.r_rps
        s[12], s[13], s[14] = f[0], f[1], f[2]
        s[15], s[16], s[17], s[18] = P_out[0, 0], P_out[3, 3], P_out[1, 1], P_out[4, 4]
        s[19], s[20] = dt, t
        a = self._ins
        for i, u in enumerate(ins):
            vu = u.v_enu_mps
            a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4] = (u.lat_rad, u.lon_rad, u.alt_m,
                                                           vu[0], vu[1])
        status, d, used, excluded, since, rank, notify, all_out = _epoch(
            self._P, self._D, self._X, self._PC, np.array([w.slot for w in self.windows]), s, a,
            self._decay, self._q_psd, self._model, _FREE.tol, self.excluded, self.since,
            self._detected, tn.k_sigma, tn.persist_s, tn.track_tau_s)
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
        was_excluded = self.excluded
        self.d, self.used, self.excluded, self.since, self.rank = d, used, excluded, since, rank
        # staggered reference epochs: restart the oldest at window_s, open the next in turn
        w = self.windows[0]
        if t - w.start_s >= tn.window_s - 1e-9:
            self.windows.pop(0)
        last = self.windows[-1].start_s if self.windows else -math.inf
        if not self.windows or (len(self.windows) < tn.n_windows
                                and t - last >= tn.window_s / tn.n_windows - 1e-9):
            self.windows.append(self._arm(t, ins, out, P_out, P_filters))
        if notify or all_out != self._all_out:
            return self._events(t, was_excluded)
        return []

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
           "channel_process_noise",
           "envelope_start", "normalised_distance", "propagate", "reference_decision"]
