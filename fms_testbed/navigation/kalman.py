"""Discrete Kalman filter steps: prediction and the Joseph-form correction (with its innovation
statistics), as plain functions on numpy arrays — the estimator knows nothing of INS or GNSS.
Compiled with numba (a navigation step runs them several times at 10 Hz).

    prediction:  x⁻ = Φ x,  P⁻ = Φ P Φᵀ + Q_k
    correction:  ν = z - H x⁻,  S = H P⁻ Hᵀ + R,  K = P⁻ Hᵀ S⁻¹,
                 x = x⁻ + K ν,  P = (I - K H) P⁻ (I - K H)ᵀ + K R Kᵀ   (Joseph form)

The Joseph form keeps P symmetric positive semidefinite for any gain (Bucy & Joseph 1968), which
matters here because gain rows may be zeroed (``frozen``: a channel excluded by the
fault-tolerant estimator of seed 001 keeps its prediction) — the short form (I - K H) P⁻ is only
right for the optimal K.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def predict(x, P, phi, qk):
    """Prediction (x⁻, P⁻) = (Φ x, Φ P Φᵀ + Q_k), P⁻ symmetrised.

    Parameters
    ----------
    x : (n,) state;  P : (n, n) covariance, state units²
    phi : (n, n) transition over the step;  qk : (n, n) discrete process-noise covariance
    """
    Pn = phi @ P @ phi.T + qk
    return phi @ x, 0.5 * (Pn + Pn.T)


@njit(cache=True)
def innovation(x, P, z, H, R):
    """(ν, S, NIS) of a measurement z = H x + v, v ~ N(0, R), before it is used.

    Parameters
    ----------
    z : (m,) measurement;  H : (m, n);  R : (m, m) measurement-noise covariance

    Returns
    -------
    ν = z - H x (m,), S = H P Hᵀ + R (m, m), NIS = νᵀ S⁻¹ ν (χ²_m for a consistent filter)
    """
    nu = z - H @ x
    S = H @ P @ H.T + R
    S = 0.5 * (S + S.T)
    return nu, S, float(nu @ np.linalg.solve(S, nu))


@njit(cache=True)
def correct(x, P, z, H, R, frozen):
    """Joseph-form correction with measurement z = H x + v, v ~ N(0, R).

    Parameters
    ----------
    x : (n,) predicted state;  P : (n, n) predicted covariance
    z : (m,) measurement;  H : (m, n);  R : (m, m)
    frozen : (n,) bool, states whose gain rows are zeroed: they keep their prediction (a channel
        excluded by the fault-tolerant estimator, seed 001); P stays the exact covariance of that
        sub-optimal estimate (Joseph form)

    Returns
    -------
    (x, P, ν, S, NIS) : corrected state and covariance, innovation, its covariance, and
    νᵀ S⁻¹ ν
    """
    nu, S, nis = innovation(x, P, z, H, R)
    PHt = P @ H.T
    K = np.linalg.solve(S, PHt.T).T          # S symmetric: K = P Hᵀ S⁻¹
    for i in range(x.size):
        if frozen[i]:
            K[i, :] = 0.0
    # Joseph form (I - K H) P (I - K H)ᵀ + K R Kᵀ, each product by (I - K H) taken as a rank-m
    # update (M - K (H M)) — the terms of the dense product, O(n² m) instead of O(n³)
    AP = P - K @ (H @ P)
    Pn = AP - (AP @ H.T) @ K.T + K @ R @ K.T
    return x + K @ nu, 0.5 * (Pn + Pn.T), nu, S, nis


@njit(cache=True)
def correct_delayed(x, P, z, H, R, phi_lag, q_lag, frozen):
    """Correction with a measurement valid before the filter's time (latency), exact when no
    other measurement was used in between.

    With x(t) = Φ x(t_m) + w (w ~ N(0, Q_lag), independent of x(t_m)) and z = H x(t_m) + v:
    H_m = H Φ⁻¹, ν = z - H_m x̂(t), C = (P - Q_lag) H_mᵀ = Cov(x(t) - x̂, ν),
    S = H_m (P - Q_lag) H_mᵀ + R, K = C S⁻¹, x̂ += K ν,
    P ← P - K Cᵀ - C Kᵀ + K S Kᵀ (valid for any K, e.g. frozen rows; with Φ = I, Q_lag = 0 it is
    the Joseph form of :func:`correct`).

    Parameters
    ----------
    x, P : the filter's state and covariance at its time t
    z, H, R : measurement valid at t_m, its matrix for the state at t_m, its noise covariance
    phi_lag : Φ(t, t_m);  q_lag : process-noise covariance accumulated over (t_m, t]
    frozen : (n,) bool, states whose gain rows are zeroed

    Returns
    -------
    (x, P, ν, S, NIS)
    """
    Hm = np.linalg.solve(phi_lag.T, H.T).T           # H Φ⁻¹
    Pm = P - q_lag
    C = Pm @ Hm.T
    S = Hm @ C + R
    S = 0.5 * (S + S.T)
    nu = z - Hm @ x
    nis = float(nu @ np.linalg.solve(S, nu))
    K = np.linalg.solve(S, C.T).T
    for i in range(x.size):
        if frozen[i]:
            K[i, :] = 0.0
    KC = K @ C.T
    Pn = P - KC - KC.T + K @ S @ K.T
    return x + K @ nu, 0.5 * (Pn + Pn.T), nu, S, nis


class PredictionLag:
    """The last ``keep`` prediction steps (t_start_s, Φ_k, Q_k), for measurements that arrive
    with a latency (:func:`correct_delayed` needs Φ(t, t_m) and Q_lag over (t_m, t]).

    Parameters
    ----------
    keep : steps kept (at 10 Hz, 64 steps = 6.4 s of latency)
    """

    def __init__(self, keep: int = 64):
        self.keep = int(keep)
        self.steps: list[tuple[float, np.ndarray, np.ndarray]] = []

    def append(self, t0_s: float, phi: np.ndarray, qk: np.ndarray) -> None:
        """Keep the step that starts at ``t0_s`` (s) with its Φ_k and Q_k."""
        self.steps.append((t0_s, phi, qk))
        if len(self.steps) > self.keep:
            del self.steps[:-self.keep]

    def since(self, t_m: float) -> tuple[np.ndarray, np.ndarray] | None:
        """(Φ(t, t_m), Q_lag) over the kept steps that start at or after ``t_m`` (s):
        Φ ← Φ_k Φ, Q ← Φ_k Q Φ_kᵀ + Q_k; None when no step has started since."""
        steps = [(phi, qk) for t0, phi, qk in self.steps if t0 >= t_m - 1e-9]
        if not steps:
            return None
        phi_lag, q_lag = steps[0]
        for phi, qk in steps[1:]:
            phi_lag = phi @ phi_lag
            q_lag = phi @ q_lag @ phi.T + qk
        return phi_lag, q_lag


def rms_check_failure_probability(z, limit: float = 1.5, n_samples: int = 20000,
                                  seed: int = 0) -> float:
    """Probability that a *consistent* filter fails the per-run check RMS(e/σ) < ``limit`` on
    one state, given how its normalised errors are correlated in time.

    For a consistent filter z_k = e_k/σ_k (k = 1..N, one run) is zero-mean Gaussian with unit
    variance; with the autocorrelation ρ(L) of the runs ``z`` (runs, N), the run's mean square
    is zᵀz/N = Σ_i λ_i χ²_1,i / N with λ_i the eigenvalues of the Toeplitz matrix of ρ, so

        P(fail) = P(Σ_i λ_i χ²_1,i ≥ N limit²)

    (Monte Carlo over ``n_samples`` draws). ρ is pooled over the runs and normalised by their
    mean square, so only its *shape* enters, not the filter's σ; it is tapered by
    exp(-(L/N)²) and negative eigenvalues (sampling noise) are dropped, as are those below
    1e-3 of the largest. A state whose error stays
    correlated for a large part of the run (an effective sample count N²/Σλ² of a few) fails
    the check in a sizeable fraction of runs however honest σ is.

    Parameters
    ----------
    z : (runs, N) normalised errors of one state at equally spaced epochs
    limit : the check's bound on RMS(e/σ)
    n_samples : Monte-Carlo draws of the weighted χ² sum
    seed : seed of those draws
    """
    from scipy.linalg import toeplitz

    z = np.asarray(z, float)
    n = z.shape[1]
    ac = np.array([np.mean(z[:, :n - lag] * z[:, lag:]) for lag in range(n)]) / np.mean(z ** 2)
    ac *= np.exp(-(np.arange(n) / n) ** 2)
    lam = np.linalg.eigvalsh(toeplitz(ac))
    lam = lam[lam > 1e-3 * lam.max()]
    rng = np.random.default_rng(seed)
    total = np.zeros(n_samples)
    for chunk in np.array_split(np.arange(n_samples), max(1, n_samples // 2000)):
        total[chunk] = rng.standard_normal((chunk.size, lam.size)) ** 2 @ lam
    return float(np.mean(total >= n * limit ** 2))


__all__ = ["PredictionLag", "correct", "correct_delayed", "innovation", "predict",
           "rms_check_failure_probability"]
