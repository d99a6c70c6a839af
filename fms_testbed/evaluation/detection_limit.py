"""The detection limit T*: the expected delay of the optimal sequential test for a change
against the declared sensor noise, at a false-alarm budget.

Lorden (1971); Basseville & Nikiforov, *Detection of Abrupt Changes* (1993), § 5.2: Page's
CUSUM with mean time between false alarms ARL0 (samples) has a worst-case mean delay

    T* ≈ ln(ARL0) / K   samples,

K the Kullback-Leibler information per sample of the change. For a mean shift Δ in Gaussian
noise of σ₁ per sample, K = (Δ/σ₁)² / 2; for a variance change σ₀² → σ₁² = ρ σ₀²,
K = (ρ − 1 − ln ρ) / 2 per component. A ramp of rate r is a mean growing as r t: its
log-likelihood ratio after n samples is (r/σ₁)² Σ t² / 2 ≈ (r/σ₁)² n³ Δt² / 6, which reaches
ln(ARL0) at n = (6 ln(ARL0) σ₁² / (r Δt)²)^(1/3).

The budget: a false-alarm rate λ (per hour) shared by ``n_streams`` independent statistics
gives each ARL0 = n_streams / λ hours.
"""

from __future__ import annotations

import math

HOUR_S = 3600.0


def arl0_samples(rate_per_h: float, n_streams: int, dt_s: float) -> float:
    """ARL0 of each of ``n_streams`` statistics sampled every ``dt_s`` (s) sharing a false-alarm
    rate ``rate_per_h`` (1/h): n_streams / rate hours, in samples."""
    return n_streams / rate_per_h * HOUR_S / dt_s


def cusum_mean_shift_s(delta: float, sigma1: float, dt_s: float, arl0: float) -> float:
    """T* (s) of a mean shift ``delta`` in white noise of ``sigma1`` per sample (same units),
    samples every ``dt_s`` (s), mean time to false alarm ``arl0`` samples: ln(ARL0) / (Δ²/2σ₁²)
    samples, at least one."""
    k = 0.5 * (delta / sigma1) ** 2
    return max(1.0, math.log(arl0) / k) * dt_s


def cusum_variance_s(rho: float, n_comp: int, dt_s: float, arl0: float) -> float:
    """T* (s) of a variance change by the factor ``rho`` on ``n_comp`` independent components
    sampled every ``dt_s`` (s), ``arl0`` samples to a false alarm: ln(ARL0) /
    (n_comp (ρ − 1 − ln ρ)/2) samples, at least one."""
    k = n_comp * 0.5 * (rho - 1.0 - math.log(rho))
    return max(1.0, math.log(arl0) / k) * dt_s


def ramp_s(rate: float, sigma1: float, dt_s: float, arl0: float) -> float:
    """T* (s) of a ramp of ``rate`` (units/s) in white noise ``sigma1`` per sample every
    ``dt_s`` (s), ``arl0`` samples to a false alarm: n = (6 ln(ARL0) σ₁² / (r Δt)²)^(1/3) samples, at least one."""
    n = (6.0 * math.log(arl0) * sigma1 ** 2 / (rate * dt_s) ** 2) ** (1.0 / 3.0)
    return max(1.0, n) * dt_s


def unit_against_others_sigma(sigma_unit: float, n_others: int) -> float:
    """σ of one unit's sample (``sigma_unit``) against the mean of ``n_others`` like units (same units):
    σ √(1 + 1/n) — the information a redundant set holds on which unit changed."""
    return sigma_unit * math.sqrt(1.0 + 1.0 / n_others)


__all__ = ["arl0_samples", "cusum_mean_shift_s", "cusum_variance_s", "ramp_s",
           "unit_against_others_sigma"]
