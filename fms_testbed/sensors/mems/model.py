"""MEMS gyro error model: the output of a gyro triad for a given true rate and temperature.

Per axis a (rad/s, t from switch-on, T the sensor temperature in °C)::

    ω_out = q( ω_true + P_a(T) + H_a h(T) + d_a + b_f(t) + b_K(t) + n(t) )

* P_a(T) = Σ_k c_ak (T - T_ref)^k — the zero signal vs temperature (seed Fig. 1);
* H_a h(T) — hysteresis: h ∈ [-1, 1] the state of a play operator of half-width w on T
  (:func:`~.temperature.hysteresis_state`), so heating and cooling branches differ by 2 H_a;
* d_a ~ N(0, σ_d²) — the run-to-run (switch-on) offset, one draw per switch-on;
* b_f — bias instability: flicker noise with one-sided PSD S(f) = h₋₁/f, whose Allan deviation
  is the flat floor √(2 ln 2 · h₋₁) = the datasheet's "bias instability" (IEEE 952 B·0.664);
* b_K — in-run slow drift: a rate random walk, b_K' = K η (Allan σ = K √(τ/3));
* n — angle random walk: white rate noise of density N (Allan σ = N / √τ);
* q — rounding to the output resolution.

Every draw comes from one ``numpy.random.Generator`` in a fixed order (offset, white noise,
flicker per axis, random walk), so the same seed gives the same numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.sensors.mems.preset import MemsGyroModel
from fms_testbed.sensors.mems.temperature import TemperatureProfile, hysteresis_state


@dataclass(frozen=True)
class GyroRecord:
    """A simulated gyro run (static unless a true rate was given).

    t_s : (n,) sample times from switch-on, s
    rate_hz : output rate, Hz
    rate_rps : (n, 3) gyro output, rad/s (axes x, y, z)
    true_rate_rps : (n, 3) true angular rate, rad/s
    temp_degC : (n,) sensor temperature, °C
    switch_on_offset_rps : (3,) the run-to-run offset drawn for this switch-on, rad/s
    """

    t_s: np.ndarray
    rate_hz: float
    rate_rps: np.ndarray
    true_rate_rps: np.ndarray
    temp_degC: np.ndarray
    switch_on_offset_rps: np.ndarray

    @property
    def dt_s(self) -> float:
        """Sample interval, s."""
        return 1.0 / self.rate_hz

    @property
    def error_rps(self) -> np.ndarray:
        """(n, 3) output minus true rate, rad/s."""
        return self.rate_rps - self.true_rate_rps


def zero_signal_rps(model: MemsGyroModel, temp_degC: np.ndarray) -> np.ndarray:
    """(n, 3) zero signal P_a(T), rad/s, of the error ``model`` at temperatures ``temp_degC`` (°C)."""
    u = np.asarray(temp_degC, float) - model.ref_degC
    return np.polynomial.polynomial.polyval(u, model.poly_rps_per_degC_k.T).T.reshape(u.size, 3)


def flicker_noise(n: int, dt_s: float, floor_rps: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) flicker (1/f) rate noise whose Allan deviation floor is ``floor_rps`` (rad/s).

    Spectral synthesis: complex Gaussian Fourier coefficients with one-sided PSD
    S(f) = h₋₁ / f, h₋₁ = floor² / (2 ln 2) (Allan variance of flicker: 2 ln 2 · h₋₁), zero mean
    (no content at f = 0, none below 1 / (n dt)).

    Parameters
    ----------
    n : number of samples
    dt_s : sample interval, s
    floor_rps : Allan-deviation floor (datasheet bias instability), rad/s
    rng : generator (draws 2 · (n // 2 + 1) normals)
    """
    f = np.fft.rfftfreq(n, dt_s)
    z = rng.standard_normal((2, f.size))
    if floor_rps == 0.0 or n < 4:
        return np.zeros(n)
    h = floor_rps ** 2 / (2.0 * math.log(2.0))
    amp = np.zeros(f.size)
    amp[1:] = np.sqrt(h / f[1:] * (1.0 / (n * dt_s)) / 2.0) * n   # var S·df per bin, irfft's 1/n
    coef = (z[0] + 1j * z[1]) / math.sqrt(2.0) * amp
    if n % 2 == 0:                                                # Nyquist bin is real
        coef[-1] = coef[-1].real * math.sqrt(2.0)
    return np.fft.irfft(coef, n)


def simulate_gyro(model: MemsGyroModel, profile: TemperatureProfile, duration_s: float,
                  rate_hz: float, rng: np.random.Generator,
                  true_rate_rps: np.ndarray | None = None) -> GyroRecord:
    """Simulate one switch-on of the gyro triad (module docstring for the terms).

    Parameters
    ----------
    model : SI error model (:func:`~.preset.gyro_model`)
    profile : sensor temperature from switch-on (must cover ``duration_s``)
    duration_s : length of the run, s
    rate_hz : output rate, Hz
    rng : generator; the run draws its switch-on offset and noises from it
    true_rate_rps : optional (n, 3) true rate, rad/s (n = the number of samples); zero if None
    """
    n = int(round(duration_s * rate_hz))
    if n < 2:
        raise ValueError(f"simulate_gyro: {duration_s} s at {rate_hz} Hz gives {n} samples")
    if profile.duration_s < (n - 1) / rate_hz - 1e-9:
        raise ValueError(f"simulate_gyro: profile {profile.name!r} covers {profile.duration_s} s, "
                         f"the run needs {(n - 1) / rate_hz} s")
    dt = 1.0 / rate_hz
    t = np.arange(n) * dt
    temp = profile.at(t)
    hyst = np.interp(t, profile.t_s, hysteresis_state(profile.temp_degC,
                                                       model.hysteresis_width_degC))
    offset = model.run_to_run_rps * rng.standard_normal(3)
    out = model.arw_rps_per_sqrt_hz / math.sqrt(dt) * rng.standard_normal((n, 3))
    for a in range(3):
        out[:, a] += flicker_noise(n, dt, model.bias_instability_rps, rng)
    out += np.cumsum(model.rrw_rps_per_sqrt_s * math.sqrt(dt) * rng.standard_normal((n, 3)),
                     axis=0)
    out += zero_signal_rps(model, temp) + hyst[:, None] * model.hysteresis_rps + offset
    true = np.zeros((n, 3)) if true_rate_rps is None else np.asarray(true_rate_rps, float)
    if true.shape != (n, 3):
        raise ValueError(f"simulate_gyro: true_rate_rps must be ({n}, 3), got {true.shape}")
    out += true
    if model.resolution_rps > 0:
        out = np.round(out / model.resolution_rps) * model.resolution_rps
    return GyroRecord(t, float(rate_hz), out, true, temp, offset)
