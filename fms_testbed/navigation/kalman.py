"""Discrete Kalman filter steps: prediction and the Joseph-form correction (with its innovation
statistics), as plain functions on numpy arrays — the estimator knows nothing of INS or GNSS.

    prediction:  x⁻ = Φ x,  P⁻ = Φ P Φᵀ + Q_k
    correction:  ν = z - H x⁻,  S = H P⁻ Hᵀ + R,  K = P⁻ Hᵀ S⁻¹,
                 x = x⁻ + K ν,  P = (I - K H) P⁻ (I - K H)ᵀ + K R Kᵀ   (Joseph form)

The Joseph form keeps P symmetric positive semidefinite for any gain (Bucy & Joseph 1968), which
matters here because a gain row may be zeroed (:func:`correct` with ``frozen``: a channel
excluded by the fault-tolerant estimator of seed 001 keeps its prediction) — the short form
(I - K H) P⁻ is only right for the optimal K.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg


@dataclass(frozen=True)
class Correction:
    """Result of one correction.

    x, P : corrected state and covariance
    innovation : ν = z - H x⁻ (measurement units);  S : its covariance
    nis : normalised innovation squared νᵀ S⁻¹ ν (χ² with len(z) degrees of freedom when the
        filter is consistent)
    """

    x: np.ndarray
    P: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    nis: float


def predict(x: np.ndarray, P: np.ndarray, phi: np.ndarray, qk: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """Prediction x⁻ = Φ x, P⁻ = Φ P Φᵀ + Q_k (symmetrised).

    Parameters
    ----------
    x : (n,) state;  P : (n, n) covariance, state units²
    phi : (n, n) transition over the step;  qk : (n, n) discrete process-noise covariance
    """
    P = phi @ P @ phi.T + qk
    return phi @ x, 0.5 * (P + P.T)


def innovation(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, float]:
    """(ν, S, NIS) of a measurement before it is used (gating, fault detection).

    Parameters
    ----------
    z : (m,) measurement;  H : (m, n);  R : (m, m) measurement-noise covariance
    """
    nu = z - H @ x
    S = H @ P @ H.T + R
    S = 0.5 * (S + S.T)
    c = scipy.linalg.cho_factor(S, lower=True, check_finite=False)
    return nu, S, float(nu @ scipy.linalg.cho_solve(c, nu, check_finite=False))


def correct(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray,
            frozen: np.ndarray | None = None) -> Correction:
    """Joseph-form correction with measurement z = H x + v, v ~ N(0, R).

    Parameters
    ----------
    x : (n,) predicted state;  P : (n, n) predicted covariance
    z : (m,) measurement;  H : (m, n);  R : (m, m)
    frozen : optional (n,) bool mask of states whose gain rows are zeroed: they keep their
        prediction (a channel excluded by the fault-tolerant estimator, seed 001); P stays the
        exact covariance of that sub-optimal estimate (Joseph form)

    Returns
    -------
    :class:`Correction`
    """
    nu, S, nis = innovation(x, P, z, H, R)
    PHt = P @ H.T
    K = scipy.linalg.solve(S, PHt.T, assume_a="pos", check_finite=False).T
    if frozen is not None:
        K[frozen] = 0.0
    A = np.eye(x.size) - K @ H
    P = A @ P @ A.T + K @ R @ K.T
    return Correction(x + K @ nu, 0.5 * (P + P.T), nu, S, nis)


__all__ = ["Correction", "correct", "innovation", "predict"]
