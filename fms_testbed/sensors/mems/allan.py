"""Allan-variance identification of a static gyro record (IEEE Std 952 noise terms).

The overlapping Allan deviation of each axis (``allantools.oadev`` on rate data) at log-spaced
averaging times τ from one sample to a tenth of the record is fitted with

    σ²(τ) = N² / τ + F² + K² τ / 3

by non-negative weighted least squares: N the angle random walk (rad/√s), F the flicker floor
— the "bias instability" as datasheets give it (the Allan-deviation minimum; IEEE 952's B is
F / 0.664), K the rate random walk (rad/s/√s). Weights are √edf / σ²(τ) with Greenhall's
equivalent degrees of freedom for flicker noise (``allantools.edf_greenhall``), i.e. relative
errors weighted by how well each τ is known.
"""

from __future__ import annotations

from dataclasses import dataclass

import allantools
import numpy as np
from scipy.optimize import nnls

from fms_testbed.core.units import DEG_RAD, DPH_RPS

MAX_TAU_FRACTION = 0.1
"""Largest averaging time used, as a fraction of the record length."""


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


def fit_allan(rate_rps: np.ndarray, rate_hz: float, n_taus: int = 30) -> AllanFit:
    """Overlapping Allan deviation of a static (n, 3) record and its N, F, K fit (module doc).

    Parameters
    ----------
    rate_rps : (n, 3) gyro output at rest, rad/s (constants do not matter)
    rate_hz : sample rate, Hz
    n_taus : number of log-spaced averaging times requested
    """
    x = np.asarray(rate_rps, float)
    n = x.shape[0]
    taus = averaging_times_s(n, rate_hz, n_taus)
    adev = np.empty((taus.size, 3))
    tau_used = taus
    for a in range(3):
        tau_used, adev[:, a], _, _ = allantools.oadev(x[:, a], rate=rate_hz, data_type="freq",
                                                      taus=taus)
    m = np.round(tau_used * rate_hz).astype(int)
    edf = np.array([allantools.edf_greenhall(alpha=-1, d=2, m=int(mm), N=n, overlapping=True,
                                             modified=False) for mm in m])
    design = np.vstack([1.0 / tau_used, np.ones_like(tau_used), tau_used / 3.0]).T
    coef = np.empty((3, 3))
    for a in range(3):
        avar = adev[:, a] ** 2
        w = np.sqrt(edf) / avar
        coef[a], _ = nnls(design * w[:, None], avar * w)
    root = np.sqrt(coef)
    return AllanFit(tau_used, adev, root[:, 0] / DEG_RAD * 60.0, root[:, 1] / DPH_RPS,
                    root[:, 2] / DPH_RPS * 60.0, n / rate_hz)
