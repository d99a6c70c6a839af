"""MEMS gyro error model: the output of a gyro triad for a given true rate and temperature.

Per axis a (rad/s, t from switch-on, T the sensor temperature in °C)::

    ω_out = q( ω_true + P_a(T) + H_a h(T) + d_a + b_f(t) + b_K(t) + n(t) )

* P_a(T) = Σ_k c_ak (T - T_ref)^k — the zero signal vs temperature (seed Fig. 1);
* H_a h(T) — hysteresis: h ∈ [-1, 1] the state of a play operator of half-width w on T
  (:func:`~.temperature.hysteresis_state`), so heating and cooling branches differ by 2 H_a;
* d_a ~ N(0, σ_d²) — the run-to-run (switch-on) offset, one draw per switch-on;
* b_f — bias instability: flicker noise with one-sided PSD S(f) = h₋₁/f, whose Allan deviation
  is the flat floor √(2 ln 2 · h₋₁) = the datasheet's "bias instability" (IEEE 952 B·0.664),
  made by a causal filter (:func:`flicker_filter`) so a record can be generated in chunks;
* b_K — in-run slow drift: a rate random walk, b_K' = K η (Allan σ = K √(τ/3));
* n — angle random walk: white rate noise of density N (Allan σ = N / √τ);
* q — rounding to the output resolution.

A run draws its switch-on offset from the caller's ``numpy.random.Generator``, then spawns one
child generator each for the white noise, the flicker drive and the random walk; each child is
read sequentially, so the same seed gives the same numbers, and a run generated in chunks
(:class:`GyroStream`) gives the same numbers, bit for bit, whatever the chunk sizes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import sosfilt, sosfreqz

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


FLICKER_SECTIONS_PER_DECADE = 2
"""Pole-zero pairs per decade of the flicker filter (PSD ripple about the 1/f line < 1 dB)."""
FLICKER_LOW_FRACTION = 0.1
"""Lowest frequency of the flicker band, as a fraction of 1 / record length."""
FLICKER_HIGH_FRACTION = 0.25
"""Highest frequency of the flicker band, as a fraction of the sample rate (above it the flicker
PSD is flat at a level far below the white noise of any gyro)."""


def flicker_filter(floor_rps: float, f_lo_hz: float, f_hi_hz: float, rate_hz: float
                   ) -> np.ndarray:
    """Second-order sections (``scipy.signal.sosfilt``) that turn unit white noise into flicker
    rate noise whose Allan-deviation floor is ``floor_rps``.

    A DC-blocking section (1 - q⁻¹) / (1 - p₀ q⁻¹) at ``f_lo_hz`` and K = ⌈2 log₁₀(f_hi/f_lo)⌉
    first-order pole-zero pairs, poles f_k = f_lo r^k, zeros f_k √r (r = (f_hi/f_lo)^(1/K)),
    discretised by z = exp(-2π f Δt): the cascade's |H(f)|² follows 1/f between f_lo and f_hi
    (Keshner's pole-zero approximation) and falls as f² below f_lo. The gain g makes the
    log-mean over the band of f · S(f) equal h₋₁ = floor² / (2 ln 2), with S(f) = 2 Δt g² |H|²
    the one-sided PSD of the filtered unit white noise.

    Parameters
    ----------
    floor_rps : Allan-deviation floor (datasheet bias instability), rad/s
    f_lo_hz, f_hi_hz : band of the 1/f spectrum, Hz (0 < f_lo < f_hi < rate / 2)
    rate_hz : sample rate, Hz

    Returns
    -------
    sos : (K + 1, 6) sections
    """
    k = max(1, int(math.ceil(FLICKER_SECTIONS_PER_DECADE * math.log10(f_hi_hz / f_lo_hz))))
    r = (f_hi_hz / f_lo_hz) ** (1.0 / k)
    w = -2.0 * math.pi / rate_hz
    poles = f_lo_hz * r ** np.arange(k)
    sos = [[1.0, -1.0, 0.0, 1.0, -math.exp(w * f_lo_hz), 0.0]]
    sos += [[1.0, -math.exp(w * fp * math.sqrt(r)), 0.0, 1.0, -math.exp(w * fp), 0.0]
            for fp in poles]
    sos = np.array(sos)
    f = np.logspace(math.log10(f_lo_hz * r), math.log10(f_hi_hz / r), 400)
    _, resp = sosfreqz(sos, worN=f, fs=rate_hz)
    h = floor_rps ** 2 / (2.0 * math.log(2.0))
    sos[0, :3] *= math.sqrt(h / math.exp(np.mean(np.log(f * 2.0 / rate_hz * np.abs(resp) ** 2))))
    return sos


class GyroStream:
    """One switch-on of the gyro triad, generated in consecutive chunks (module docstring).

    Parameters
    ----------
    model : SI error model (:func:`~.preset.gyro_model`)
    profile : sensor temperature from switch-on (must cover ``duration_s``)
    duration_s : length of the run, s
    rate_hz : output rate, Hz
    rng : generator; the run draws its switch-on offset from it and spawns the noise generators

    Attributes
    ----------
    n : samples in the run
    switch_on_offset_rps : (3,) the run-to-run offset drawn for this switch-on, rad/s
    """

    def __init__(self, model: MemsGyroModel, profile: TemperatureProfile, duration_s: float,
                 rate_hz: float, rng: np.random.Generator):
        n = int(round(duration_s * rate_hz))
        if n < 2:
            raise ValueError(f"simulate_gyro: {duration_s} s at {rate_hz} Hz gives {n} samples")
        if profile.duration_s < (n - 1) / rate_hz - 1e-9:
            raise ValueError(f"simulate_gyro: profile {profile.name!r} covers "
                             f"{profile.duration_s} s, the run needs {(n - 1) / rate_hz} s")
        self.model, self.profile, self.n, self.rate_hz = model, profile, n, float(rate_hz)
        self.switch_on_offset_rps = model.run_to_run_rps * rng.standard_normal(3)
        self._white, self._flick, self._walk = rng.spawn(3)
        self._hyst = hysteresis_state(profile.temp_degC, model.hysteresis_width_degC)
        f_lo = FLICKER_LOW_FRACTION * rate_hz / n
        f_hi = FLICKER_HIGH_FRACTION * rate_hz
        self._sos = flicker_filter(model.bias_instability_rps, f_lo, f_hi, rate_hz) \
            if model.bias_instability_rps > 0 and f_lo < f_hi else None
        self._zi = None if self._sos is None else np.zeros((self._sos.shape[0], 2, 3))
        self._walk_sum = np.zeros(3)
        self.i = 0

    def next(self, k: int, true_rate_rps: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The next ``k`` samples (fewer at the end of the run): (t (k,) s, temperature (k,) °C,
        output (k, 3) rad/s).

        Parameters
        ----------
        k : samples requested
        true_rate_rps : optional (k, 3) true rate of these samples, rad/s (zero if None)
        """
        m = self.model
        i0, i1 = self.i, min(self.n, self.i + int(k))
        self.i = i1
        dt = 1.0 / self.rate_hz
        t = np.arange(i0, i1) * dt
        temp = self.profile.at(t)
        hyst = np.interp(t, self.profile.t_s, self._hyst)
        out = m.arw_rps_per_sqrt_hz / math.sqrt(dt) * self._white.standard_normal((i1 - i0, 3))
        drive = self._flick.standard_normal((i1 - i0, 3))
        if self._sos is not None:
            flick, self._zi = sosfilt(self._sos, drive, axis=0, zi=self._zi)
            out += flick
        walk = np.cumsum(np.vstack([self._walk_sum, m.rrw_rps_per_sqrt_s * math.sqrt(dt)
                                    * self._walk.standard_normal((i1 - i0, 3))]), axis=0)
        self._walk_sum = walk[-1].copy()
        out += walk[1:]
        out += zero_signal_rps(m, temp) + hyst[:, None] * m.hysteresis_rps \
            + self.switch_on_offset_rps
        if true_rate_rps is not None:
            if np.shape(true_rate_rps) != (i1 - i0, 3):
                raise ValueError(f"simulate_gyro: true_rate_rps must be ({i1 - i0}, 3), got "
                                 f"{np.shape(true_rate_rps)}")
            out += true_rate_rps
        if m.resolution_rps > 0:
            out = np.round(out / m.resolution_rps) * m.resolution_rps
        return t, temp, out


def simulate_gyro(model: MemsGyroModel, profile: TemperatureProfile, duration_s: float,
                  rate_hz: float, rng: np.random.Generator,
                  true_rate_rps: np.ndarray | None = None) -> GyroRecord:
    """Simulate one switch-on of the gyro triad whole: :class:`GyroStream` in one chunk.

    Parameters
    ----------
    model, profile, duration_s, rate_hz, rng : as :class:`GyroStream`
    true_rate_rps : optional (n, 3) true rate, rad/s (n = the number of samples); zero if None
    """
    stream = GyroStream(model, profile, duration_s, rate_hz, rng)
    true = np.zeros((stream.n, 3)) if true_rate_rps is None else np.asarray(true_rate_rps, float)
    t, temp, out = stream.next(stream.n, true)
    return GyroRecord(t, float(rate_hz), out, true, temp, stream.switch_on_offset_rps)
