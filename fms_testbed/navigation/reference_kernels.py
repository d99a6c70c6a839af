"""Compiled forms of the reference-description monitor
(:mod:`fms_testbed.navigation.reference_description`): the same equations as its numpy
functions (tests/navigation/test_reference_description_kernels.py compares them to rounding).
One call of :func:`_epoch` per reference epoch does F, (Φ, Q_k), every window's envelopes and
free copies, the per-channel filters, the distances and the decision."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.earth import OMEGA_IE_RPS, radii_m
# navigation.sins first: its import runs the numba-cache guard of this package (the kernels below
# inline build_F, _picard_sins and the Earth model's radii)
from fms_testbed.navigation.sins import _c_bn
from fms_testbed.sensors.sins.discretize import PICARD_MAX_ORDER, PICARD_MAX_RATE_DT, _picard_sins
from fms_testbed.sensors.sins.model import build_F

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
def _phi_times(P, phi, nz, cnt):
    """C = Φ P on the blocks of Φ (BLAS order, exact zeros skipped), (33, 33)."""
    n, nn = P.shape[0], _N_NAV
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
    return C


@njit(cache=True, fastmath={"contract"})
def _times_phi_t(C, phi, nz, cnt):
    """U = (C Φᵀ)ᵀ rows of the navigation states (BLAS order, exact zeros skipped), (9, 33)."""
    n, nn = C.shape[0], _N_NAV
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
    return U


@njit(cache=True, fastmath={"contract"})
def _propagate_blocks(P, D, phi, qk):
    """:func:`propagate` for one unit in place, on the blocks of Φ = [[Φ11, Φ12], [0, diag φ22]]
    (9 navigation states, 24 sensor states): C = Φ P, Pₙ = C Φᵀ + Q_k, P ← ½ (Pₙ + Pₙᵀ), D ← Φ D.

    The sums run in the order of the BLAS product of :func:`propagate` (each element accumulated
    over k in turn, fused multiply-add), skipping only exact zeros (of Φ, and of the sensor rows
    of P: the sensor states the filter does not carry stay uncorrelated with each other), so the
    envelope stays within rounding of :func:`propagate` over a whole window although P carries
    the free vertical channel's growth. P (33, 33), D (33,), state units² and state units."""
    n, nn = P.shape[0], _N_NAV
    nz = np.empty((n - nn, n - nn), np.int64)
    cnt = np.zeros(n - nn, np.int64)
    C = _phi_times(P, phi, nz, cnt)
    U = _times_phi_t(C, phi, nz, cnt)
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
def _models_phi_q(s, decay, q_psd, tol):
    """(status, Φ (m, 33, 33), Q_k (m, 33, 33)) of each IMU model over the step s[19] at the
    integrated solution ``s`` (see :func:`_epoch`); status 1: Δt/τ beyond the Picard range,
    2: no convergence, 3: Φ not of the block form."""
    n_mod, n = q_psd.shape
    dt = s[19]
    c = _c_bn(s[6], s[7], s[8])
    lat = s[0]
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    w_ib = s[9:12] + c.T @ w_ie
    phis = np.empty((n_mod, n, n))
    qks = np.empty((n_mod, n, n))
    for m in range(n_mod):
        F = build_F(lat, s[2], s[3:6].copy(), s[12:15].copy(), w_ib, c, decay[m], 0.0, 0.0)
        rate = 0.0
        for i in range(n):
            rate = max(rate, abs(F[i, i]))
        if rate * dt > PICARD_MAX_RATE_DT:
            return 1, phis, qks
        phi, qk, _, ok = _picard_sins(F, q_psd[m], dt, tol, PICARD_MAX_ORDER)
        if not ok:
            return 2, phis, qks
        for r in range(_N_NAV, n):             # the block form of Φ _propagate_blocks needs
            for j in range(n):
                if j != r and phi[r, j] != 0.0:
                    return 3, phis, qks
        phis[m] = phi
        qks[m] = qk
    return 0, phis, qks


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
    u = ins.shape[0]
    d = np.full(u, np.nan)
    status, phis, qks = _models_phi_q(s, decay, q_psd, tol)
    if status:
        return status, d, excluded.copy(), excluded.copy(), since.copy(), np.arange(u), False, \
            False
    dt = s[19]
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
