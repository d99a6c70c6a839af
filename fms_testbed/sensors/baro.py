"""Barometric altimeter, the truth side: altitude = truth ⊕ a slowly varying bias ⊕ white noise.

    h_baro = h + b + w,   b' = -b/τ + η,  E[b²] = σ_b²   (pressure-field / QNH error),  w ~ N(0, σ_w²)

The bias is propagated exactly between readings (b_k = e^{-Δt/τ} b_{k-1} + √(σ_b²(1 - e^{-2Δt/τ})) N).
A failure (``failed_from_s``) freezes the output at its last value (a stuck static port): the
reading keeps coming, it just no longer follows the aircraft.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState


@dataclass(frozen=True)
class BaroSpec:
    """Baro error model, SI, 1σ.

    markov_sigma_m : stationary σ of the bias, m;  markov_tau_s : its correlation time, s
    white_sigma_m : white noise per reading, m;  rate_hz : reading rate, Hz
    failed_from_s : time the output freezes (stuck port), s (inf: never)
    """

    markov_sigma_m: float = 5.0
    markov_tau_s: float = 1800.0
    white_sigma_m: float = 0.5
    rate_hz: float = 1.0
    failed_from_s: float = math.inf

    def __post_init__(self):
        for name in ("markov_sigma_m", "white_sigma_m"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0):
                raise ConfigError(f"navigation.baro.{name}: must be finite and >= 0")
        for name in ("markov_tau_s", "rate_hz"):
            if not getattr(self, name) > 0:
                raise ConfigError(f"navigation.baro.{name}: must be > 0")


@dataclass(frozen=True)
class BaroReading:
    """One reading: time s, altitude m, and (truth side) its error m and bias part m."""

    t_s: float
    alt_m: float
    err_m: float
    bias_m: float


class BaroAltimeter:
    """A baro altimeter: :meth:`update` returns a reading when one is due at ``truth.t_s``.

    Parameters
    ----------
    spec : error model
    seed : seed of the bias and noise realisation
    """

    def __init__(self, spec: BaroSpec, seed: int = 0):
        self.spec = spec
        self.rng = np.random.default_rng(seed)
        self.bias_m = spec.markov_sigma_m * float(self.rng.standard_normal())
        self._t: float | None = None
        self._next_s: float | None = None
        self._last: BaroReading | None = None
        self.period_s = 1.0 / spec.rate_hz

    def update(self, truth: AircraftState) -> BaroReading | None:
        """The reading due at ``truth.t_s`` (s), or None between readings."""
        t = truth.t_s
        if self._next_s is None:
            self._next_s = t
        if t < self._next_s - 1e-9:
            return None
        while self._next_s <= t + 1e-9:
            self._next_s += self.period_s
        s = self.spec
        if self._t is not None:
            a = math.exp(-(t - self._t) / s.markov_tau_s)
            self.bias_m = a * self.bias_m + s.markov_sigma_m * math.sqrt(1.0 - a * a) * float(
                self.rng.standard_normal())
        self._t = t
        w = s.white_sigma_m * float(self.rng.standard_normal())
        if t >= s.failed_from_s and self._last is not None:
            last = self._last
            out = BaroReading(t, last.alt_m, last.alt_m - truth.alt_m, self.bias_m)
        else:
            out = BaroReading(t, truth.alt_m + self.bias_m + w, self.bias_m + w, self.bias_m)
        self._last = out
        return out


__all__ = ["BaroAltimeter", "BaroReading", "BaroSpec"]
