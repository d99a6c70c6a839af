"""Continuous → discrete: Φ_k, Q_k (and B_k) by the Picard series, Van Loan, or eq. 3.1.

For ``x' = F x + B u + G η`` with white η of density Q1 and Q = G Q1 Gᵀ (F, B, Q constant over
the step Δt), the discrete model is ``x_k = Φ x_{k-1} + B_k u_k + w_k``, ``w_k ~ N(0, Q_k)``.

* ``picard`` (Babich 2017, eq. 2.5-2.9 and 4.3-4.5): the truncated series, both at the same order ν,
  ``Φ_ν = Σ_{i=0..ν} N_i Δt^i/i!`` (N_0 = I, N_{i+1} = F N_i) and
  ``Q_ν = Σ_{i=1..ν} M_i Δt^i/i!`` (M_1 = Q, M_{i+1} = F M_i + M_i Fᵀ);
  ``B_k = Σ_{i=0..ν} F^i Δt^{i+1}/(i+1)! B``. Adaptive order when ``order`` is None: stop when the
  next term is below ``tol`` relative to the sum (max-abs of Φ and Q_k, and each diagonal
  element of Q_k). Compiled with numba.
* ``vanloan`` (Van Loan 1978): ``expm([[-F, Q], [0, Fᵀ]] Δt)`` → Φ = M22ᵀ, Q_k = Φ M12 (scipy).
* ``trapezoid`` (eq. 3.1 with eq. 4.7): Φ = I + FΔt + F²Δt²/2, Q_k = (Q + Φ Q Φᵀ) Δt/2.

The Picard series converges for any F, but it needs many terms, and loses digits to cancellation,
once Δt exceeds the shortest time constant; :func:`discretize` refuses (raises
:class:`DiscretisationError`) when Δt·max|F_ii| > ``PICARD_MAX_RATE_DT`` rather than returning a
poor answer, and tells the user to take ``vanloan``.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from numba import njit

from fms_testbed.core.errors import UserError

METHODS = ("picard", "vanloan", "trapezoid")
PICARD_MAX_RATE_DT = 0.1
"""Largest Δt/τ (Δt times the largest |F_ii|) the Picard series is used for (note: Δt/τ > 0.1)."""
PICARD_MAX_ORDER = 30


class DiscretisationError(UserError):
    """The chosen discretisation cannot give an accurate answer for this F and Δt."""


@njit(cache=True)
def _picard(F, Q, dt, order, tol, max_order):
    """Numba kernel: (Φ, Q_k, Γ, ν, converged) with Γ = Σ F^i Δt^{i+1}/(i+1)! (B_k = Γ B)."""
    n = F.shape[0]
    tn = F * dt                          # N_1 Δt / 1!
    tm = Q * dt                          # M_1 Δt / 1!
    phi = np.eye(n) + tn
    qk = tm.copy()
    gam = np.eye(n) * dt + tn * (dt / 2.0)
    buf = np.empty((n, n))
    L = np.empty((n, n))
    i = 1
    converged = order > 0
    target = order if order > 0 else max_order
    while i < target:
        k = i + 1
        h = dt / k
        hg = dt / (k + 1)
        _mm_into(F, tn, buf)             # products skip the zeros of F (sparse INS models)
        _mm_into(F, tm, L)
        t_p = b_p = t_q = b_q = 0.0
        diag_ok = True
        for r in range(n):
            for c in range(n):
                v = buf[r, c] * h
                tn[r, c] = v
                phi[r, c] += v
                gam[r, c] += v * hg
                w = (L[r, c] + L[c, r]) * h
                tm[r, c] = w
                qk[r, c] += w
                t_p = max(t_p, abs(v))
                b_p = max(b_p, abs(phi[r, c]))
                t_q = max(t_q, abs(w))
                b_q = max(b_q, abs(qk[r, c]))
            if abs(tm[r, r]) > tol * abs(qk[r, r]):
                diag_ok = False
        i = k
        if order <= 0 and i >= 2 and t_p <= tol * b_p and t_q <= tol * b_q and diag_ok:
            converged = True
            break
    return phi, qk, gam, i, converged


def picard_order_used(F: np.ndarray, Q: np.ndarray, dt: float, tol: float = 1e-12) -> int:
    """Number of series terms the adaptive Picard method takes for (F, Q, Δt s)."""
    return int(_picard(np.ascontiguousarray(F, float), np.ascontiguousarray(Q, float), float(dt),
                       0, tol, PICARD_MAX_ORDER)[3])


def _check_picard_range(F: np.ndarray, dt: float) -> None:
    rate = float(np.abs(np.diag(F)).max()) if F.size else 0.0
    if rate * dt > PICARD_MAX_RATE_DT:
        raise DiscretisationError(
            f"Picard series not suitable: dt/tau = {rate * dt:.3g} > {PICARD_MAX_RATE_DT} "
            f"(dt = {dt:g} s, fastest time constant {1 / rate:.3g} s); use method 'vanloan' "
            "or a smaller dt")


def discretize(F: np.ndarray, Q: np.ndarray, dt: float, method: str = "picard",
               order: int | None = None, tol: float = 1e-12, B: np.ndarray | None = None):
    """Discretise ``x' = F x + B u + G η`` over one step (paper eq. 2.9, 4.5, 3.1; Van Loan).

    Parameters
    ----------
    F : (n, n) system matrix, 1/s.
    Q : (n, n) noise density G Q1 Gᵀ, state-unit²/s (symmetric positive semidefinite).
    dt : step Δt, s (> 0).
    method : ``"picard"`` | ``"vanloan"`` | ``"trapezoid"``.
    order : Picard order ν (same for Φ and Q_k); None = adaptive until the next term < tol.
    tol : relative size of the next term at which the adaptive series stops.
    B : optional (n, m) input matrix; then B_k is returned too.

    Returns
    -------
    (Φ, Q_k) or (Φ, Q_k, B_k) : (n, n), (n, n) state-unit², (n, m).

    Raises
    ------
    DiscretisationError : Picard asked for Δt/τ > 0.1, or the adaptive series did not converge
        within 30 terms; unknown method; Δt ≤ 0.
    """
    F = np.ascontiguousarray(F, dtype=float)
    Q = np.ascontiguousarray(Q, dtype=float)
    if not dt > 0:
        raise DiscretisationError(f"discretize: dt must be > 0 s, got {dt!r}")
    if method == "picard":
        _check_picard_range(F, dt)
        if order is not None and order < 1:
            raise DiscretisationError(f"discretize: Picard order must be >= 1, got {order}")
        phi, qk, gam, nu, ok = _picard(F, Q, float(dt), 0 if order is None else int(order),
                                       float(tol), PICARD_MAX_ORDER)
        if not ok:
            raise DiscretisationError(
                f"Picard series did not reach tol {tol:g} in {PICARD_MAX_ORDER} terms "
                f"(dt = {dt:g} s); use method 'vanloan'")
        qk = 0.5 * (qk + qk.T)
        if B is None:
            return phi, qk
        return phi, qk, gam @ np.asarray(B, float)
    if method == "vanloan":
        return _van_loan(F, Q, dt, B)
    if method == "trapezoid":
        return _trapezoid(F, Q, dt, B)
    raise DiscretisationError(f"discretize: unknown method {method!r}; choose one of {METHODS}")


def _van_loan(F, Q, dt, B):
    """(Φ, Q_k[, B_k]) from the matrix exponential of Van Loan's block matrix
    [[-F, Q], [0, Fᵀ]] Δt (and of [[F, B], [0, 0]] Δt for B_k)."""
    n = F.shape[0]
    A = np.zeros((2 * n, 2 * n))
    A[:n, :n] = -F
    A[:n, n:] = Q
    A[n:, n:] = F.T
    E = scipy.linalg.expm(A * dt)
    phi = E[n:, n:].T.copy()
    qk = phi @ E[:n, n:]
    qk = 0.5 * (qk + qk.T)
    if B is None:
        return phi, qk
    B = np.asarray(B, float)
    m = B.shape[1]
    A2 = np.zeros((n + m, n + m))
    A2[:n, :n] = F
    A2[:n, n:] = B
    return phi, qk, scipy.linalg.expm(A2 * dt)[:n, n:]


def _trapezoid(F, Q, dt, B):
    """(Φ, Q_k[, B_k]) to second order: Φ = I + FΔt + F²Δt²/2, Q_k = (Q + ΦQΦᵀ)Δt/2."""
    n = F.shape[0]
    phi = np.eye(n) + F * dt + F @ F * (dt * dt / 2.0)
    qk = (Q + phi @ Q @ phi.T) * (dt / 2.0)
    if B is None:
        return phi, qk
    return phi, qk, (np.eye(n) * dt + F * (dt * dt / 2.0)) @ np.asarray(B, float)


@njit(cache=True)
def _mm_into(A, B, out):
    """out = A @ B for small dense blocks, skipping zero entries of A."""
    n, k = A.shape
    m = B.shape[1]
    for i in range(n):
        for j in range(m):
            out[i, j] = 0.0
        for p in range(k):
            a = A[i, p]
            if a != 0.0:
                for j in range(m):
                    out[i, j] += a * B[p, j]


@njit(cache=True)
def _phi_terms_next(A, C, d, n11, n12, n22, t11, t12, h):
    """Next Φ series terms in place: N12' = (A N12 + C diag(n22)) h, N11' = A N11 h,
    N22' = D N22 h."""
    nn, m = n12.shape
    _mm_into(A, n12, t12)
    for r in range(nn):
        for c in range(m):
            n12[r, c] = (t12[r, c] + C[r, c] * n22[c]) * h
    _mm_into(A, n11, t11)
    for r in range(nn):
        for c in range(nn):
            n11[r, c] = t11[r, c] * h
    for c in range(m):
        n22[c] = n22[c] * d[c] * h


@njit(cache=True)
def _q_terms_next(A, Ca, da, m11, m12, m22, L, t11, u12, m12t, h):
    """Next Q_k series terms in place: L = A M11 + C M12ᵀ, M11' = (L + Lᵀ) h,
    M12' = (A M12 + C M22 + M12 D) h, M22' = 2 D M22 h (noisy sensor columns only)."""
    nn, na = m12.shape
    for r in range(na):
        for c in range(nn):
            m12t[r, c] = m12[c, r]
    _mm_into(A, m11, L)
    _mm_into(Ca, m12t, t11)
    _mm_into(A, m12, u12)
    for r in range(nn):
        for c in range(na):
            m12[r, c] = (u12[r, c] + Ca[r, c] * m22[c] + m12[r, c] * da[c]) * h
        for c in range(nn):
            L[r, c] += t11[r, c]
    for r in range(nn):
        for c in range(nn):
            m11[r, c] = (L[r, c] + L[c, r]) * h
    for c in range(na):
        m22[c] = 2.0 * da[c] * m22[c] * h


@njit(cache=True)
def _accumulate(p11, p12, p22, q11, q12, q22, n11, n12, n22, m11, m12, m22, tol):
    """Add the new terms to the running sums; return the adaptive stop's (largest next Φ term,
    largest Φ sum, largest next Q_k term, largest Q_k sum, every Q_k diagonal term below tol)."""
    nn, m = n12.shape
    na = m12.shape[1]
    tp = bp = tq = bq = 0.0
    diag_ok = True
    for r in range(nn):
        for c in range(nn):
            p11[r, c] += n11[r, c]
            q11[r, c] += m11[r, c]
            tp = max(tp, abs(n11[r, c]))
            bp = max(bp, abs(p11[r, c]))
            tq = max(tq, abs(m11[r, c]))
            bq = max(bq, abs(q11[r, c]))
        if abs(m11[r, r]) > tol * abs(q11[r, r]):
            diag_ok = False
        for c in range(m):
            p12[r, c] += n12[r, c]
            tp = max(tp, abs(n12[r, c]))
            bp = max(bp, abs(p12[r, c]))
        for c in range(na):
            q12[r, c] += m12[r, c]
            tq = max(tq, abs(m12[r, c]))
            bq = max(bq, abs(q12[r, c]))
    for c in range(m):
        p22[c] += n22[c]
        tp = max(tp, abs(n22[c]))
        bp = max(bp, abs(p22[c]))
    for c in range(na):
        q22[c] += m22[c]
        tq = max(tq, abs(m22[c]))
        bq = max(bq, abs(q22[c]))
        if abs(m22[c]) > tol * abs(q22[c]):
            diag_ok = False
    return tp, bp, tq, bq, diag_ok


@njit(cache=True)
def _assemble(n, act, p11, p12, p22, q11, q12, q22):
    """Full (Φ, Q_k) from the block sums (Q_k symmetrised on the navigation block)."""
    nn = p11.shape[0]
    m = n - nn
    phi = np.zeros((n, n))
    qk = np.zeros((n, n))
    phi[:nn, :nn] = p11
    phi[:nn, nn:] = p12
    for r in range(nn):
        for c in range(nn):
            qk[r, c] = 0.5 * (q11[r, c] + q11[c, r])
    for c in range(act.size):
        j = nn + act[c]
        qk[j, j] = q22[c]
        for r in range(nn):
            qk[r, j] = q12[r, c]
            qk[j, r] = q12[r, c]
    for j in range(m):
        phi[nn + j, nn + j] = p22[j]
    return phi, qk


@njit(cache=True)
def _picard_sins(F, q_diag, dt, tol, max_order):
    """Block-structured adaptive Picard for the SINS model (same series as :func:`_picard`).

    Uses F = [[A (9×9), C (9×m)], [0, D (diagonal)]] and a diagonal Q, so every product is on
    small blocks (explicit loops, no BLAS call overhead): N11' = A N11, N12' = A N12 + C N22,
    N22' = D N22; M11' = (A M11 + C M12ᵀ) + (·)ᵀ, M12' = A M12 + C M22 + M12 D, M22' = 2 D M22.
    A sensor state without process noise (q = 0: the run-to-run constants) keeps its M12 column
    and M22 entry at exactly zero through the series, so the Q_k terms are carried for the noisy
    sensor states only (the result is the same to the last bit).
    Returns (Φ, Q_k, ν, converged).
    """
    n = F.shape[0]
    nn = 9
    m = n - nn
    A = F[:nn, :nn].copy()
    C = F[:nn, nn:].copy()
    d = np.empty(m)
    for j in range(m):
        d[j] = F[nn + j, nn + j]
    act = np.nonzero(q_diag[nn:] != 0.0)[0]           # sensor states with process noise
    na = act.size
    Ca = np.empty((nn, na))
    da = np.empty(na)
    for c in range(na):
        da[c] = d[act[c]]
        for r in range(nn):
            Ca[r, c] = C[r, act[c]]
    n11, n12, n22 = A * dt, C * dt, d * dt            # Φ series terms N_i Δt^i / i!
    m11 = np.zeros((nn, nn))                           # Q_k series terms M_i Δt^i / i!
    for j in range(nn):
        m11[j, j] = q_diag[j] * dt
    m12 = np.zeros((nn, na))                           # noisy sensor columns only
    m22 = np.empty(na)
    for c in range(na):
        m22[c] = q_diag[nn + act[c]] * dt
    p11, p12, p22 = np.eye(nn) + n11, n12.copy(), 1.0 + n22     # running sums
    q11, q12, q22 = m11.copy(), m12.copy(), m22.copy()
    t11, t12 = np.empty((nn, nn)), np.empty((nn, m))
    L, u12, m12t = np.empty((nn, nn)), np.empty((nn, na)), np.empty((na, nn))
    i = 1
    ok = False
    while i < max_order:
        k = i + 1
        h = dt / k
        _phi_terms_next(A, C, d, n11, n12, n22, t11, t12, h)
        _q_terms_next(A, Ca, da, m11, m12, m22, L, t11, u12, m12t, h)
        tp, bp, tq, bq, diag_ok = _accumulate(p11, p12, p22, q11, q12, q22,
                                              n11, n12, n22, m11, m12, m22, tol)
        i = k
        if i >= 2 and tp <= tol * bp and tq <= tol * bq and diag_ok:
            ok = True
            break
    phi, qk = _assemble(n, act, p11, p12, p22, q11, q12, q22)
    return phi, qk, i, ok


def discretize_sins(F: np.ndarray, q_diag: np.ndarray, dt: float, tol: float = 1e-12):
    """Adaptive Picard (Φ, Q_k) for the 33-state SINS F (block structure, diagonal Q).

    Same series and stopping rule as ``discretize(F, diag(q), dt, "picard")`` but on the blocks
    of F = [[A, C], [0, D]] (navigation 9 states, sensor states with diagonal D), about 3× cheaper
    (bench/bench_sins.py).

    Parameters
    ----------
    F : (33, 33) from :func:`fms_testbed.sensors.sins.model.build_F`, 1/s.
    q_diag : (33,) diagonal of Q, state-unit²/s.
    dt : step, s.

    Raises
    ------
    DiscretisationError : Δt/τ > 0.1 or no convergence within 30 terms.
    """
    _check_picard_range(F, dt)
    phi, qk, _, ok = _picard_sins(F, q_diag, float(dt), float(tol), PICARD_MAX_ORDER)
    if not ok:
        raise DiscretisationError(
            f"Picard series did not reach tol {tol:g} in {PICARD_MAX_ORDER} terms (dt = {dt:g} s)")
    return phi, qk
