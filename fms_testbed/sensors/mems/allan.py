"""Allan-variance identification of a static gyro record (IEEE Std 952 noise terms).

The overlapping Allan deviation of each axis (``allantools.oadev`` on rate data) at log-spaced
averaging times τ from one sample to a tenth of the record is fitted with

    σ²(τ) = N² / τ + F² + K² τ / 3

by non-negative weighted least squares: N the angle random walk (rad/√s), F the flicker floor
— the "bias instability" as datasheets give it (the Allan-deviation minimum; IEEE 952's B is
F / 0.664), K the rate random walk (rad/s/√s). Weights are √edf / σ²(τ) with Greenhall's
equivalent degrees of freedom for flicker noise (``allantools.edf_greenhall``), i.e. relative
errors weighted by how well each τ is known.

:class:`OctaveAllan` is the same overlapping Allan variance accumulated over a record given in
chunks, at the octave averaging times m = 2^j samples, in memory that does not grow with the
record (phase kept only 2 m / d samples back, d the level's stride); :func:`fit_allan_curve`
fits either curve.
"""

from __future__ import annotations

from dataclasses import dataclass

import allantools
import numpy as np
from scipy.optimize import nnls

from fms_testbed.core.units import DEG_RAD, DPH_RPS

MAX_TAU_FRACTION = 0.1
"""Largest averaging time used, as a fraction of the record length."""
OVERLAP_OFFSETS = 1024
"""Start offsets per averaging time kept by :class:`OctaveAllan`: every offset (the overlapping
estimator) up to m = this many samples, every d-th beyond (d = m / this)."""
SUM_BLOCK = 4096
"""Terms per block of the sums of :class:`OctaveAllan`: blocks are aligned on the record, so
the sums do not depend on how the record is cut into chunks."""


@dataclass(frozen=True)
class AllanFit:
    """Allan deviation of a record and the fitted noise terms, per axis (x, y, z).

    tau_s : (k,) averaging times, s
    adev_rps : (k, 3) overlapping Allan deviation, rad/s
    arw_deg_per_sqrt_h : (3,) angle random walk N, °/√h
    bias_instability_deg_per_h : (3,) flicker floor F (Allan minimum convention), °/h
    rrw_deg_per_h_per_sqrt_h : (3,) rate random walk K, °/h/√h
    record_s : length of the record, s
    """

    tau_s: np.ndarray
    adev_rps: np.ndarray
    arw_deg_per_sqrt_h: np.ndarray
    bias_instability_deg_per_h: np.ndarray
    rrw_deg_per_h_per_sqrt_h: np.ndarray
    record_s: float

    def model_adev_rps(self, tau_s: np.ndarray) -> np.ndarray:
        """(k, 3) Allan deviation of the fitted model at ``tau_s`` (s), rad/s."""
        tau = np.asarray(tau_s, float)[:, None]
        n = self.arw_deg_per_sqrt_h * DEG_RAD / 60.0
        f = self.bias_instability_deg_per_h * DPH_RPS
        k = self.rrw_deg_per_h_per_sqrt_h * DPH_RPS / 60.0
        return np.sqrt(n ** 2 / tau + f ** 2 + k ** 2 * tau / 3.0)

    def to_dict(self) -> dict:
        """Fitted terms per axis in datasheet units (lists, JSON-ready)."""
        return {"arw_deg_per_sqrt_h": _r(self.arw_deg_per_sqrt_h),
                "bias_instability_deg_per_h": _r(self.bias_instability_deg_per_h),
                "rrw_deg_per_h_per_sqrt_h": _r(self.rrw_deg_per_h_per_sqrt_h),
                "record_s": self.record_s, "n_taus": int(self.tau_s.size)}


def _r(a) -> list[float]:
    return [float(f"{v:.5g}") for v in np.asarray(a, float)]


def averaging_times_s(n_samples: int, rate_hz: float, n_taus: int = 30) -> np.ndarray:
    """Log-spaced averaging times, s: whole multiples of the sample interval from one sample to
    ``MAX_TAU_FRACTION`` of the record (duplicates removed).

    Parameters
    ----------
    n_samples : record length, samples
    rate_hz : sample rate, Hz
    n_taus : number of log-spaced values requested (fewer after rounding to whole samples)
    """
    m_max = max(1, int(n_samples * MAX_TAU_FRACTION))
    m = np.unique(np.round(np.logspace(0.0, np.log10(m_max), n_taus)).astype(int))
    return m / rate_hz


def fit_allan_curve(tau_s: np.ndarray, adev_rps: np.ndarray, n_samples: int, rate_hz: float
                    ) -> AllanFit:
    """Fit σ²(τ) = N²/τ + F² + K²τ/3 per axis to an Allan curve (module doc).

    Non-negative least squares on σ² with weights √edf / σ², edf Greenhall's equivalent degrees
    of freedom of the overlapping estimator for flicker noise at each τ.

    Parameters
    ----------
    tau_s : (k,) averaging times, s (whole multiples of the sample interval)
    adev_rps : (k, 3) Allan deviation at ``tau_s``, rad/s
    n_samples : record length, samples
    rate_hz : sample rate, Hz
    """
    tau = np.asarray(tau_s, float)
    adev = np.asarray(adev_rps, float)
    m = np.round(tau * rate_hz).astype(int)
    edf = np.array([allantools.edf_greenhall(alpha=-1, d=2, m=int(mm), N=n_samples,
                                             overlapping=True, modified=False) for mm in m])
    design = np.vstack([1.0 / tau, np.ones_like(tau), tau / 3.0]).T
    coef = np.empty((3, 3))
    for a in range(3):
        avar = adev[:, a] ** 2
        w = np.sqrt(edf) / avar
        coef[a], _ = nnls(design * w[:, None], avar * w)
    root = np.sqrt(coef)
    return AllanFit(tau, adev, root[:, 0] / DEG_RAD * 60.0, root[:, 1] / DPH_RPS,
                    root[:, 2] / DPH_RPS * 60.0, n_samples / rate_hz)


def fit_allan(rate_rps: np.ndarray, rate_hz: float, n_taus: int = 30) -> AllanFit:
    """Overlapping Allan deviation of a static (n, 3) record and its N, F, K fit (module doc).

    Parameters
    ----------
    rate_rps : (n, 3) gyro output at rest, rad/s (constants do not matter)
    rate_hz : sample rate, Hz
    n_taus : number of log-spaced averaging times requested
    """
    x = np.asarray(rate_rps, float)
    taus = averaging_times_s(x.shape[0], rate_hz, n_taus)
    adev = np.empty((taus.size, 3))
    tau_used = taus
    for a in range(3):
        tau_used, adev[:, a], _, _ = allantools.oadev(x[:, a], rate=rate_hz, data_type="freq",
                                                      taus=taus)
    return fit_allan_curve(tau_used, adev, x.shape[0], rate_hz)


class BlockReducer:
    """Sums or means of consecutive blocks of ``block`` rows of a stream given in chunks.

    The blocks are aligned on the stream (rows 0..block-1, block..2 block-1, ...), the rows of a
    block not yet complete are held (at most ``block - 1``), and each block is reduced as one
    contiguous array — so the results are the same, bit for bit, whatever the chunk sizes.

    Parameters
    ----------
    block : rows per block
    width : columns per row (None: a 1-D stream)
    """

    def __init__(self, block: int, width: int | None = None):
        self.block = int(block)
        shape = (0,) if width is None else (0, width)
        self._held = np.empty(shape)

    def means(self, x: np.ndarray) -> np.ndarray:
        """Means of the blocks completed by ``x`` (rows appended to the stream), (k, ...)."""
        return self._blocks(x).mean(axis=1)

    def sums(self, x: np.ndarray) -> np.ndarray:
        """Sums of the blocks completed by ``x`` (rows appended to the stream), (k, ...)."""
        return self._blocks(x).sum(axis=1)

    def rest_sum(self) -> np.ndarray:
        """Sum of the rows held (the incomplete last block)."""
        return self._held.sum(axis=0)

    def _blocks(self, x: np.ndarray) -> np.ndarray:
        x = np.concatenate([self._held, np.asarray(x, float)])
        k = x.shape[0] // self.block
        self._held = x[k * self.block:]
        return x[:k * self.block].reshape(k, self.block, *x.shape[1:])


class OctaveAllan:
    """Overlapping Allan variance of a (n, 3) rate record given in chunks (module doc).

    At the octave averaging times m = 2^j samples up to ``MAX_TAU_FRACTION`` of the record, with
    x the phase (x_0 = 0, x_i = Δt Σ_{k<i} (y_k - y_0)) and d = max(1, m / offsets)::

        σ²(mΔt) = Σ_i (x_{i+2m} - 2 x_{i+m} + x_i)² / (2 (mΔt)² n_m),   i = 0, d, 2d, ...

    n_m the number of terms; for d = 1 this is ``allantools.oadev`` on the same record (which
    removes the record's mean instead of y_0: a constant, the same σ²). For d > 1 the estimator
    keeps every d-th start (the mean of the overlapping estimator's terms at those offsets).
    Memory: 2 ``offsets`` phase values per stride, whatever the record length.

    Parameters
    ----------
    n_samples : record length the octaves are chosen for, samples
    rate_hz : sample rate, Hz
    offsets : start offsets kept per averaging time (:data:`OVERLAP_OFFSETS`)
    """

    def __init__(self, n_samples: int, rate_hz: float, offsets: int = OVERLAP_OFFSETS):
        self.rate_hz = float(rate_hz)
        m_max = max(1, int(n_samples * MAX_TAU_FRACTION))
        self.m = 2 ** np.arange(int(np.log2(m_max)) + 1)
        self.stride = np.maximum(1, self.m // int(offsets))
        self._tail = {int(d): np.zeros((0, 3)) for d in np.unique(self.stride)}
        self._sums = [BlockReducer(SUM_BLOCK, 3) for _ in self.m]
        self._total = np.zeros((self.m.size, 3))
        self._count = np.zeros(self.m.size, dtype=np.int64)
        self._n = 0                       # samples seen (phase values x_1..x_n)
        self._y0 = None
        self._phase_sum = np.zeros(3)     # Σ (y - y0) so far (the phase / Δt)

    def update(self, rate_rps: np.ndarray) -> None:
        """Append a chunk (k, 3) of the record, rad/s."""
        y = np.asarray(rate_rps, float)
        if self._y0 is None:
            self._y0 = y[0].copy()
            self._tail = {d: np.zeros((1, 3)) for d in self._tail}      # x_0 = 0
        c = np.cumsum(np.vstack([self._phase_sum, y - self._y0]), axis=0)
        self._phase_sum = c[-1].copy()
        x = c[1:] * (1.0 / self.rate_hz)                  # x_{n+1} .. x_{n+k}
        idx = np.arange(self._n + 1, self._n + 1 + y.shape[0])
        self._n += y.shape[0]
        for d in list(self._tail):
            new = x if d == 1 else x[idx % d == 0]
            z = np.vstack([self._tail[d], new])
            old = z.shape[0] - new.shape[0]
            for j in np.flatnonzero(self.stride == d):
                q = int(self.m[j] // d)
                lo = max(old, 2 * q)
                if lo < z.shape[0]:
                    t = z[lo:] - 2.0 * z[lo - q:z.shape[0] - q] + z[lo - 2 * q:z.shape[0] - 2 * q]
                    for s in self._sums[j].sums(t * t):
                        self._total[j] += s
                    self._count[j] += z.shape[0] - lo
            keep = 2 * int(self.m[self.stride == d].max() // d)
            self._tail[d] = z[-keep:]

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        """(τ (k,), s; Allan deviation (k, 3), rad/s) at the octaves with at least one term."""
        ok = self._count > 0
        total = self._total + np.array([r.rest_sum() for r in self._sums])
        tau = self.m / self.rate_hz
        avar = total[ok] / (2.0 * tau[ok, None] ** 2 * self._count[ok, None])
        return tau[ok], np.sqrt(avar)

    def fit(self) -> AllanFit:
        """The N, F, K fit (:func:`fit_allan_curve`) of the curve so far."""
        tau, adev = self.result()
        return fit_allan_curve(tau, adev, self._n, self.rate_hz)
