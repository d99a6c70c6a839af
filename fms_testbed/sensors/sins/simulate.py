"""Simulation of the discrete model x_k = Φ_k x_{k-1} + B_k u_k + S_k N_k (paper eq. 6.11).

S_k S_kᵀ = Q_k with N_k ~ N(0, I). Q_k of the SINS model is only positive *semidefinite*
(run-to-run constants are not driven; a low Picard order makes it singular or indefinite), so
plain Cholesky fails: :func:`factor_psd` is a semidefinite LDLᵀ/Cholesky that zeroes pivots at
rounding level, keeps only the driven columns, and raises :class:`IndefiniteCovarianceError`
when a pivot is negative beyond rounding. Every random draw comes from a seeded
``numpy.random.Generator``; realisations are columns (vectorised over the Monte-Carlo set).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fms_testbed.core.errors import UserError
from fms_testbed.sensors.sins.discretize import discretize

FACTOR_RTOL = 1e-9
"""Pivots within ±FACTOR_RTOL × (own diagonal of Q_k) count as zero."""


class IndefiniteCovarianceError(UserError):
    """Q_k has a negative pivot beyond rounding (e.g. a too-low Picard order)."""


@njit(cache=True)
def _psd_cholesky(Q, rtol):
    """Lower factor L (n×n, zero columns for null pivots) and the first bad pivot index (or -1).

    Rows of Q that are exactly zero (states without covariance, e.g. the SINS run-to-run
    constants within one step's Q_k) are skipped up front: their column of L is zero and their
    terms are exact zeros, so L is the same as without the skip, at a fraction of the cost.
    """
    n = Q.shape[0]
    L = np.zeros((n, n))
    live = np.empty(n, np.int64)
    nl = 0
    for j in range(n):
        for i in range(n):
            if Q[j, i] != 0.0:
                live[nl] = j
                nl += 1
                break
    for jj in range(nl):
        j = live[jj]
        d = Q[j, j]
        for kk in range(jj):
            k = live[kk]
            d -= L[j, k] * L[j, k]
        scale = abs(Q[j, j])
        if d < -rtol * scale or Q[j, j] < 0.0:
            return L, j
        if d <= rtol * scale:
            # null pivot: column j stays zero, which is only right if the rest of the Schur
            # column is zero too (|s|² ≤ d_j d_i for a PSD matrix); otherwise Q is indefinite
            for ii in range(jj + 1, nl):
                i = live[ii]
                s = Q[i, j]
                for kk in range(jj):
                    k = live[kk]
                    s -= L[i, k] * L[j, k]
                if s * s > 4.0 * rtol * scale * abs(Q[i, i]):
                    return L, j
            continue
        ljj = np.sqrt(d)
        L[j, j] = ljj
        for ii in range(jj + 1, nl):
            i = live[ii]
            s = Q[i, j]
            for kk in range(jj):
                k = live[kk]
                s -= L[i, k] * L[j, k]
            L[i, j] = s / ljj
    return L, -1


def factor_psd(Q: np.ndarray, rtol: float = FACTOR_RTOL) -> np.ndarray:
    """S (n × r) with S Sᵀ = Q for a positive semidefinite Q (r = number of non-null pivots).

    Parameters
    ----------
    Q : (n, n) symmetric covariance, state-unit².
    rtol : pivots with |d| ≤ rtol·Q_jj are taken as zero (rounding).

    Raises
    ------
    IndefiniteCovarianceError : a pivot is below -rtol·Q_jj (Q indefinite beyond rounding).
    """
    Q = np.ascontiguousarray(Q, dtype=float)
    L, bad = _psd_cholesky(Q, float(rtol))
    if bad >= 0:
        raise IndefiniteCovarianceError(
            f"Q_k is indefinite: pivot {bad} is negative beyond rounding (rtol {rtol:g}); "
            "raise the Picard order or use the adaptive order / 'vanloan'")
    keep = np.flatnonzero(np.diag(L) > 0.0)
    return np.ascontiguousarray(L[:, keep])


def step(x: np.ndarray, phi: np.ndarray, s: np.ndarray, rng: np.random.Generator,
         bk: np.ndarray | None = None, u: np.ndarray | None = None) -> np.ndarray:
    """One step x_k = Φ x_{k-1} + B_k u_k + S N_k for one state (n,) or realisations (n, m)."""
    noise_shape = (s.shape[1],) + x.shape[1:]
    out = phi @ x + s @ rng.standard_normal(noise_shape)
    if bk is not None and u is not None:
        out += (bk @ u) if x.ndim == 1 else (bk @ u)[:, None]
    return out


def simulate_lti(F: np.ndarray, Q: np.ndarray, dt: float, n_steps: int, p0: np.ndarray,
                 n_real: int, seed: int, method: str = "picard") -> np.ndarray:
    """Monte-Carlo of a time-invariant model: states at every step, shape (n_steps+1, n, n_real).

    x_0 ~ N(0, P0) (P0 (n, n) or its diagonal (n,)), Δt in s; reproducible from ``seed``.
    """
    rng = np.random.default_rng(seed)
    phi, qk = discretize(F, Q, dt, method=method)
    s = factor_psd(qk)
    p0 = np.diag(p0) if np.ndim(p0) == 1 else np.asarray(p0, float)
    x = factor_psd(p0) @ rng.standard_normal((factor_psd(p0).shape[1], n_real))
    out = np.empty((n_steps + 1,) + x.shape)
    out[0] = x
    for k in range(n_steps):
        x = step(x, phi, s, rng)
        out[k + 1] = x
    return out
