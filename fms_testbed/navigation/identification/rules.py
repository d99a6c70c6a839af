"""Seed 001's identification rules over arrays of realisations × units × channels.

Every function takes stacks: ``y`` (R, U, C) comparison vectors of U units in R realisations
(C channels; channel :data:`HEADING` is an angle, wrapped to ±π in every difference), ``sig``
(R, U, C) their σ in the same units. One realisation is R = 1. The per-flight source and the
Monte-Carlo engine both call these functions, through :class:`.two_stage.TwoStage`.

Table 1 of seed 001 (three sources, ν_ij = 1 when |Z_i − Z_j| > ε)::

    ν12 ν13 ν23 → (1 1 0) source 1 failed,  (1 0 1) source 2,  (0 1 1) source 3,  (0 0 0) none

It serves twice: stage 1 over three units (:func:`named_unit`), and stage 2 over the three
sources (Z_i, Ẑ, Ẑ_p) — a unit, the estimator's estimate and its prediction
(:func:`three_way`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

PAIRS = ((0, 1), (0, 2), (1, 2))
"""The pairs of three sources in the order of (ν12, ν13, ν23)."""

MAJORITY = {(1, 1, 0): 0, (1, 0, 1): 1, (0, 1, 1): 2}
"""Seed 001's table 1 for three sources: (ν12, ν13, ν23) → index of the failed source."""

HEADING = 8
"""Index of the heading channel (an angle: differences wrapped to ±π)."""

_NAMED = np.full(8, -1, np.int64)
for _nu, _src in MAJORITY.items():
    _NAMED[_nu[0] + 2 * _nu[1] + 4 * _nu[2]] = _src

_PAIR_A = np.array([a for a, _ in PAIRS], np.int64)
_PAIR_B = np.array([b for _, b in PAIRS], np.int64)

UNIT_FAILED, ESTIMATE_FAILED, PREDICTION_FAILED = 0, 1, 2
"""Verdicts of :func:`three_way` (the failed source of table 1); -1: none named."""


def wrapped_difference(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a − b with the heading channel wrapped to [−π, π) (rad; other channels as given)."""
    d = np.asarray(a, float) - np.asarray(b, float)
    if d.shape[-1] > HEADING:
        d[..., HEADING] = np.remainder(d[..., HEADING] + math.pi, 2 * math.pi) - math.pi
    return d


def exceeds(a: np.ndarray, b: np.ndarray, sa: np.ndarray, sb: np.ndarray, k: float,
            mask: np.ndarray | None = None) -> np.ndarray:
    """ν = 1 when some channel of |a − b| > ε = k √(σ_a² + σ_b²) (seed 001, eq. 1 and 3).

    Parameters
    ----------
    a, b : (..., C) the two signals (units of each channel)
    sa, sb : (..., C) their σ, same units;  k : threshold in σ
    mask : (C,) or (..., C) bool, channels compared (None: all)

    Returns
    -------
    (...,) bool
    """
    bad = np.abs(wrapped_difference(a, b)) > k * np.sqrt(np.square(sa) + np.square(sb))
    if mask is not None:
        bad &= np.asarray(mask, bool)
    return bad.any(axis=-1)


def ratio(a: np.ndarray, b: np.ndarray, sa: np.ndarray, sb: np.ndarray,
          mask: np.ndarray | None = None) -> np.ndarray:
    """The largest |a − b| / √(σ_a² + σ_b²) over the channels in ``mask`` (..., C) → (...,):
    the statistic :func:`exceeds` compares with k (dimensionless); ``sa``, ``sb`` the σ of
    ``a``, ``b`` in their units."""
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.abs(wrapped_difference(a, b)) / np.sqrt(np.square(sa) + np.square(sb))
    if mask is not None:
        r = np.where(np.asarray(mask, bool), r, 0.0)
    return np.nanmax(r, axis=-1)


@njit(cache=True, error_model="numpy")
def _wrap(d: float) -> float:
    """d wrapped to [−π, π) (rad)."""
    return (d + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True, error_model="numpy")
def _nan_max(a: float, b: float) -> float:
    """max(a, b), NaN when either is NaN (numpy's ``maximum``)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@njit(cache=True, error_model="numpy")
def _exceeds(a, b, sa, sb, k, mask) -> bool:
    """ν = 1 when some channel c in ``mask`` has |a_c − b_c| > k √(σ_a,c² + σ_b,c²) (heading
    channel wrapped; a NaN channel never exceeds)."""
    for c in range(a.shape[0]):
        d = a[c] - b[c]
        if c == HEADING:
            d = _wrap(d)
        if mask[c] and abs(d) > k * math.sqrt(sa[c] * sa[c] + sb[c] * sb[c]):
            return True
    return False


@njit(cache=True, error_model="numpy")
def _ratio(a, b, sa, sb, mask) -> float:
    """max over the channels of |a − b| / √(σ_a² + σ_b²), 0 outside ``mask``, NaN channels
    skipped (NaN when every channel is NaN)."""
    out, seen = -math.inf, False
    for c in range(a.shape[0]):
        if mask[c]:
            d = a[c] - b[c]
            if c == HEADING:
                d = _wrap(d)
            r = abs(d) / math.sqrt(sa[c] * sa[c] + sb[c] * sb[c])
        else:
            r = 0.0
        if r == r:
            seen = True
            if r > out:
                out = r
    return out if seen else math.nan


@njit(cache=True, error_model="numpy")
def _table1(n1: bool, n2: bool, n3: bool) -> int:
    """Table 1: the source (0, 1, 2) that (ν12, ν13, ν23) names, −1 for none."""
    return _NAMED[int(n1) + 2 * int(n2) + 4 * int(n3)]


@njit(cache=True, error_model="numpy")
def _pair_flags(y, sig, k, live, mask, out) -> None:
    """``out`` (R, 3) ← :func:`pair_flags` (compiled; ``live`` (R, U), ``mask`` (R, C))."""
    R, U = y.shape[0], y.shape[1]
    for r in range(R):
        for p in range(3):
            a, b = _PAIR_A[p], _PAIR_B[p]
            out[r, p] = (b < U and live[r, a] and live[r, b]
                         and _exceeds(y[r, a], y[r, b], sig[r, a], sig[r, b], k, mask[r]))


def pair_flags(y: np.ndarray, sig: np.ndarray, k: float, live: np.ndarray | None = None,
               mask: np.ndarray | None = None) -> np.ndarray:
    """Stage 1 of one instant: (ν12, ν13, ν23) per realisation, ν_ij = 1 when some channel c
    in ``mask`` has |y_i,c − y_j,c| > k √(σ_i,c² + σ_j,c²) (:func:`exceeds`, compiled).

    Parameters
    ----------
    y, sig : (R, U, C) comparison vectors and their σ, U = 2 or 3
    k : threshold ε_N in σ of each channel difference
    live : (R, U) bool, units compared (None: all); a pair with a unit not live reads 0, and so
        do the pairs of a unit beyond U
    mask : (C,) or (R, C) bool channels compared

    Returns
    -------
    (R, 3) bool
    """
    y = np.ascontiguousarray(y, dtype=float)
    sig = np.ascontiguousarray(sig, dtype=float)
    R, U, C = y.shape
    lv = (np.ones((R, U), bool) if live is None
          else np.ascontiguousarray(np.broadcast_to(np.asarray(live, bool), (R, U))))
    m = (np.ones((R, C), bool) if mask is None
         else np.ascontiguousarray(np.broadcast_to(np.asarray(mask, bool), (R, C))))
    out = np.zeros((R, 3), bool)
    _pair_flags(y, np.ascontiguousarray(np.broadcast_to(sig, y.shape)), float(k), lv, m, out)
    return out


def named_unit(nu: np.ndarray, n_live: np.ndarray | None = None) -> np.ndarray:
    """Table 1: (R,) index of the source ``nu`` (R, 3) = (ν12, ν13, ν23) names as failed, −1 for none; only
    where ``n_live`` (R,) is 3 when given (two sources cannot name one)."""
    nu = np.asarray(nu, np.int64)
    out = _NAMED[nu[:, 0] + 2 * nu[:, 1] + 4 * nu[:, 2]]
    return out if n_live is None else np.where(n_live == 3, out, -1)


def fuse(y: np.ndarray, sig: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The estimate Ẑ of the output block from the units' ``y`` (R, U, C) with σ ``sig``
    (R, U, C) where ``w`` (R, U) is true: the
    inverse-variance weighted mean per channel, σ_Ẑ = (Σ σ_i⁻²)^-½ (units independent);
    the heading is averaged as wrapped offsets from the first unit. Realisations without a
    unit give NaN.

    Returns
    -------
    (Ẑ (R, C), σ_Ẑ (R, C))
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        inv = np.where(np.asarray(w, bool)[..., None], 1.0 / np.square(sig), 0.0)
        tot = inv.sum(axis=1)
        ref = y[:, :1]
        d = wrapped_difference(y, ref)
        z = ref[:, 0] + (inv * d).sum(axis=1) / tot
        s = 1.0 / np.sqrt(tot)
    return z, s


def three_way(z: np.ndarray, sz: np.ndarray, zhat: np.ndarray, shat: np.ndarray,
              zpred: np.ndarray, spred: np.ndarray, k: float,
              mask: np.ndarray | None = None) -> np.ndarray:
    """Stage 2: table 1 on the three sources (Z_i, Ẑ, Ẑ_p) for every unit.

    Parameters
    ----------
    z, sz : (R, U, C) the units' signals Z_i and σ
    zhat, shat : (R, C) the estimator's estimate Ẑ and σ (:func:`fuse`)
    zpred, spred : (R, C) its prediction Ẑ_p and σ
    k : threshold ε_K in σ;  mask : (C,) bool channels compared

    Returns
    -------
    (R, U) int: :data:`UNIT_FAILED` for (1 1 0) — unit i disagrees with both the estimate and
    the prediction, which agree —, :data:`ESTIMATE_FAILED` (1 0 1), :data:`PREDICTION_FAILED`
    (0 1 1), −1 otherwise
    """
    a = exceeds(z, zhat[:, None], sz, shat[:, None], k, mask)
    b = exceeds(z, zpred[:, None], sz, spred[:, None], k, mask)
    c = np.broadcast_to(exceeds(zhat, zpred, shat, spred, k, mask)[:, None], a.shape)
    nu = np.stack([a, b, c], axis=-1).astype(np.int64)
    return _NAMED[nu[..., 0] + 2 * nu[..., 1] + 4 * nu[..., 2]]


def vote(flags: np.ndarray, n_units: int) -> np.ndarray:
    """Majority voting: (R, U) bool, every unit but the one the instant's table 1 on ``flags``
    (R, 3) names (all units for ``n_units`` U < 3 or no name). No persistence, no estimator, no memory."""
    R = flags.shape[0]
    out = np.ones((R, n_units), bool)
    if n_units == 3:
        bad = named_unit(flags)
        has = bad >= 0
        out[np.nonzero(has)[0], bad[has]] = False
    return out


__all__ = ["ESTIMATE_FAILED", "HEADING", "MAJORITY", "PAIRS", "PREDICTION_FAILED",
           "UNIT_FAILED", "exceeds", "fuse", "named_unit", "pair_flags", "ratio", "three_way",
           "vote",
           "wrapped_difference"]
