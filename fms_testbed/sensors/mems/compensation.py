"""The three drift-compensation stages of Vorobyov et al. (seed 000), each a separate function.

1. **Temperature** (:func:`fit_temperature_calibration`, :class:`TemperatureCalibration`): the
   zero signal is measured in a calibration run over the operating range (100-s means vs the
   mean temperature of each window) and a polynomial per axis is fitted; in use the polynomial
   at the measured temperature is subtracted. A fit over too small a temperature swing is
   refused (:class:`CalibrationError`).
2. **Run-to-run** (:func:`estimate_switch_on_offset`): the offset of this switch-on is the mean
   output over a static interval right after switch-on (after stage 1), and is subtracted.
3. **Slow drift** (:func:`extract_slow_drift`): each sample is compared with the sensor's
   sensitivity threshold; samples below it are treated as error, samples above it as useful
   signal. The below-threshold samples are low-passed (first order, cut-off < 0.1 Hz) into the
   slowly varying drift, which is subtracted from the output; while the signal stays above the
   threshold the drift estimate is held.

Stages are applied in that order (:func:`compensate`); ``none`` is the raw output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

from fms_testbed.core.errors import UserError
from fms_testbed.core.units import DEG_RAD
from fms_testbed.sensors.mems.model import GyroRecord, simulate_gyro
from fms_testbed.sensors.mems.preset import MemsSpec, gyro_model
from fms_testbed.sensors.mems.temperature import ramp_profile

STAGES = ("none", "temperature", "run-to-run", "slow-drift")
"""Compensation stages in the order they are applied (``none``: the raw output)."""


class CalibrationError(UserError):
    """A temperature calibration cannot be fitted from the run given (too little swing, too
    few points)."""


def parse_stages(text: str | list[str] | tuple[str, ...]) -> tuple[str, ...]:
    """Stage names → the stages in canonical order.

    Parameters
    ----------
    text : comma-separated names (``"none,temperature,run-to-run,slow-drift"``) or a list

    Raises
    ------
    UserError : an unknown stage name, or an empty list.
    """
    items = text.split(",") if isinstance(text, str) else list(text)
    items = [s.strip().lower() for s in items if s.strip()]
    bad = [s for s in items if s not in STAGES]
    if bad:
        raise UserError(f"unknown compensation stage {bad[0]!r}; stages: {', '.join(STAGES)}")
    if not items:
        raise UserError(f"no compensation stage given; stages: {', '.join(STAGES)}")
    return tuple(s for s in STAGES if s in items)


def window_means(x: np.ndarray, n_per_window: int) -> np.ndarray:
    """Means of consecutive non-overlapping windows of ``n_per_window`` samples along axis 0
    (the incomplete last window is dropped)."""
    n = (x.shape[0] // n_per_window) * n_per_window
    return x[:n].reshape(n // n_per_window, n_per_window, *x.shape[1:]).mean(axis=1)


@dataclass(frozen=True)
class TemperatureCalibration:
    """Fitted zero signal vs temperature per axis.

    coef_rps : (3, degree + 1) coefficients of (T - ref_degC)^k, rad/s/°C^k
    ref_degC : polynomial centre, °C
    range_degC : (low, high) calibrated temperatures, °C (the fit is held outside)
    point_temp_degC : (m,) mean temperature of each calibration window, °C
    point_zero_rps : (m, 3) mean output of each window (the measured zero signal), rad/s
    residual_max_rps : (3,) largest |measured - fitted| zero signal per axis, rad/s
    """

    coef_rps: np.ndarray
    ref_degC: float
    range_degC: tuple[float, float]
    point_temp_degC: np.ndarray
    point_zero_rps: np.ndarray
    residual_max_rps: np.ndarray

    @property
    def swing_degC(self) -> float:
        """Temperature swing of the calibration, °C."""
        return self.range_degC[1] - self.range_degC[0]

    def zero_signal_rps(self, temp_degC: np.ndarray) -> np.ndarray:
        """(n, 3) fitted zero signal at ``temp_degC`` (°C, held at the calibrated range), rad/s."""
        u = np.clip(np.asarray(temp_degC, float), *self.range_degC) - self.ref_degC
        return np.polynomial.polynomial.polyval(u, self.coef_rps.T).T.reshape(u.size, 3)

    def apply(self, rate_rps: np.ndarray, temp_degC: np.ndarray) -> np.ndarray:
        """Stage 1: output minus the fitted zero signal at the measured temperature, rad/s."""
        return rate_rps - self.zero_signal_rps(temp_degC)


def fit_temperature_calibration(temp_degC: np.ndarray, rate_rps: np.ndarray, rate_hz: float,
                                degree: int, min_swing_degC: float, window_s: float
                                ) -> TemperatureCalibration:
    """Fit the zero signal vs temperature from a static calibration run (stage 1).

    Parameters
    ----------
    temp_degC : (n,) measured sensor temperature, °C
    rate_rps : (n, 3) gyro output at rest, rad/s (true rate zero)
    rate_hz : sample rate, Hz
    degree : polynomial degree per axis
    min_swing_degC : smallest temperature swing accepted, °C
    window_s : averaging window of one zero-signal point, s

    Raises
    ------
    CalibrationError : the windows' temperatures swing less than ``min_swing_degC``, or there
        are fewer than 2 (degree + 1) windows.
    """
    m = max(1, int(round(window_s * rate_hz)))
    tw = window_means(np.asarray(temp_degC, float), m)
    zw = window_means(np.asarray(rate_rps, float), m)
    if tw.size < 2 * (degree + 1):
        raise CalibrationError(f"temperature calibration: {tw.size} zero-signal points of "
                               f"{window_s:g} s, at least {2 * (degree + 1)} needed for degree "
                               f"{degree}")
    lo, hi = float(tw.min()), float(tw.max())
    if hi - lo < min_swing_degC:
        raise CalibrationError(f"temperature calibration: the run swings {hi - lo:.1f} degC, at "
                               f"least {min_swing_degC:g} degC needed (a fit over a narrow range "
                               f"extrapolates the zero signal)")
    ref = 0.5 * (lo + hi)
    coef = np.polynomial.polynomial.polyfit(tw - ref, zw, degree).T      # (3, degree + 1)
    fit = np.polynomial.polynomial.polyval(tw - ref, coef.T).T
    return TemperatureCalibration(coef, ref, (lo, hi), tw, zw, np.abs(zw - fit).max(axis=0))


def factory_calibration(spec: MemsSpec, rng: np.random.Generator) -> TemperatureCalibration:
    """Simulate the factory calibration run and fit stage 1 from it.

    Parameters
    ----------
    spec : the preset (its ``calibration`` block: duration, rate, window, degree, swing)
    rng : generator of the calibration run (its own switch-on); the run is a chamber thermal
        cycle over the operating range from room temperature (``ramp``)
    """
    c = spec.calibration
    t = spec.temperature
    prof = ramp_profile(c.duration_s, *t.operating_range_degC, t.constant_degC, t.ramp_soak_s)
    rec = simulate_gyro(gyro_model(spec), prof, c.duration_s, c.sample_rate_hz, rng)
    return fit_temperature_calibration(rec.temp_degC, rec.rate_rps, c.sample_rate_hz,
                                       c.polynomial_degree, c.min_swing_degC, c.window_s)


def estimate_switch_on_offset(rate_rps: np.ndarray, rate_hz: float, interval_s: float
                              ) -> np.ndarray:
    """Stage 2: the switch-on offset (3,), rad/s — the mean output over a static interval.

    Parameters
    ----------
    rate_rps : (n, 3) output after stage 1 from switch-on, rad/s
    rate_hz : sample rate, Hz
    interval_s : length of the static interval right after switch-on, s
    """
    n = int(round(interval_s * rate_hz))
    if not 1 <= n <= rate_rps.shape[0]:
        raise UserError(f"run-to-run compensation: the initial interval of {interval_s:g} s "
                        f"needs {n} samples, the run has {rate_rps.shape[0]}")
    return rate_rps[:n].mean(axis=0)


class SlowDriftFilter:
    """Stage 3 over a record given in chunks: the slowly varying drift (n, 3), rad/s.

    Samples with |ω| < threshold are error (mask m = 1), the others useful signal (m = 0). The
    drift is the normalised first-order low-pass of the error samples,
    d_k = LP(m ω)_k / LP(m)_k with LP: y_k = y_{k-1} + α (u_k - y_{k-1}), α = 1 - exp(-2π f_c Δt),
    which holds its last value while the signal stays above the threshold (both filters decay
    alike) and is 0 before the first error sample. Causal: usable in real time; the filter
    states are carried from chunk to chunk, so the drift does not depend on the chunk sizes.

    Parameters
    ----------
    rate_hz : sample rate, Hz
    threshold_rps : sensitivity threshold, rad/s
    cutoff_hz : low-pass -3 dB frequency, Hz (the seed: below 0.1 Hz)
    """

    def __init__(self, rate_hz: float, threshold_rps: float, cutoff_hz: float):
        alpha = -math.expm1(-2.0 * math.pi * cutoff_hz / rate_hz)
        self.b, self.a = [alpha], [1.0, alpha - 1.0]
        self.threshold_rps = float(threshold_rps)
        self._zi_num = np.zeros((1, 3))
        self._zi_den = np.zeros((1, 3))
        self._last = np.zeros(3)          # drift held from the chunks before (0: none yet)

    def drift(self, rate_rps: np.ndarray) -> np.ndarray:
        """The drift (k, 3), rad/s, of the next chunk ``rate_rps`` (k, 3) of the output after the
        earlier stages, rad/s."""
        x = np.asarray(rate_rps, float)
        mask = (np.abs(x) < self.threshold_rps).astype(float)
        num, self._zi_num = lfilter(self.b, self.a, x * mask, axis=0, zi=self._zi_num)
        den, self._zi_den = lfilter(self.b, self.a, mask, axis=0, zi=self._zi_den)
        valid = den > 1e-12
        ratio = np.divide(num, den, out=np.zeros_like(num), where=valid)
        ratio = np.vstack([self._last, ratio])
        idx = np.where(np.vstack([np.ones((1, 3), bool), valid]),
                       np.arange(x.shape[0] + 1)[:, None], 0)
        np.maximum.accumulate(idx, axis=0, out=idx)
        out = np.take_along_axis(ratio, idx, axis=0)[1:]
        if out.shape[0]:
            self._last = out[-1].copy()
        return out


def extract_slow_drift(rate_rps: np.ndarray, rate_hz: float, threshold_rps: float,
                       cutoff_hz: float) -> np.ndarray:
    """Stage 3 on a whole record: the drift (n, 3), rad/s, to subtract from ``rate_rps``
    (:class:`SlowDriftFilter`, the equation there).

    Parameters
    ----------
    rate_rps : (n, 3) gyro output after the earlier stages, rad/s
    rate_hz : sample rate, Hz
    threshold_rps : sensitivity threshold, rad/s
    cutoff_hz : low-pass -3 dB frequency, Hz (the seed: below 0.1 Hz)
    """
    return SlowDriftFilter(rate_hz, threshold_rps, cutoff_hz).drift(rate_rps)


@dataclass(frozen=True)
class Compensated:
    """Outputs of a run after each applied stage (rad/s) and what the stages estimated.

    outputs : stage → (n, 3) output after that stage and the ones before it, rad/s
    switch_on_offset_rps : (3,) stage-2 estimate, rad/s (None if stage 2 was not applied)
    slow_drift_rps : (n, 3) stage-3 estimate, rad/s (None if stage 3 was not applied)
    """

    outputs: dict[str, np.ndarray]
    switch_on_offset_rps: np.ndarray | None
    slow_drift_rps: np.ndarray | None


class Compensator:
    """The stages applied to a run given in chunks (the first chunk must hold the run-to-run
    interval); each chunk's outputs are those of :func:`compensate` on the whole run.

    Parameters
    ----------
    stages : stages in canonical order (:func:`parse_stages`)
    spec : the preset (run-to-run interval, slow-drift threshold and cut-off)
    calibration : stage-1 fit, needed when ``temperature`` is among the stages
    rate_hz : sample rate, Hz

    Attributes
    ----------
    switch_on_offset_rps : (3,) stage-2 estimate after the first chunk, rad/s (None without
        stage 2)
    """

    def __init__(self, stages: tuple[str, ...], spec: MemsSpec,
                 calibration: TemperatureCalibration | None, rate_hz: float):
        if "temperature" in stages and calibration is None:
            raise ValueError("compensate: the temperature stage needs a calibration")
        self.stages, self.spec, self.calibration = tuple(stages), spec, calibration
        self.rate_hz = float(rate_hz)
        self.switch_on_offset_rps = None
        s = spec.slow_drift
        self._drift = SlowDriftFilter(rate_hz, s.threshold_deg_per_s * DEG_RAD, s.cutoff_hz) \
            if "slow-drift" in stages else None

    def step(self, rate_rps: np.ndarray, temp_degC: np.ndarray
             ) -> tuple[dict[str, np.ndarray], np.ndarray | None]:
        """(stage → (k, 3) output after that stage and the ones before it, rad/s; the stage-3
        drift (k, 3) rad/s or None) of the next chunk (output (k, 3) rad/s, temperature (k,) °C)."""
        x = rate_rps
        outputs: dict[str, np.ndarray] = {}
        drift = None
        if "none" in self.stages:
            outputs["none"] = x
        if "temperature" in self.stages:
            x = self.calibration.apply(x, temp_degC)
            outputs["temperature"] = x
        if "run-to-run" in self.stages:
            if self.switch_on_offset_rps is None:
                self.switch_on_offset_rps = estimate_switch_on_offset(
                    x, self.rate_hz, self.spec.run_to_run.initial_interval_s)
            x = x - self.switch_on_offset_rps
            outputs["run-to-run"] = x
        if self._drift is not None:
            drift = self._drift.drift(x)
            x = x - drift
            outputs["slow-drift"] = x
        return outputs, drift


def compensate(record: GyroRecord, stages: tuple[str, ...], spec: MemsSpec,
               calibration: TemperatureCalibration | None) -> Compensated:
    """Apply the stages to a whole run (:class:`Compensator` with one chunk).

    Parameters
    ----------
    record : the run (output, temperature, rate)
    stages : stages in canonical order (:func:`parse_stages`)
    spec : the preset (run-to-run interval, slow-drift threshold and cut-off)
    calibration : stage-1 fit, needed when ``temperature`` is among the stages
    """
    comp = Compensator(stages, spec, calibration, record.rate_hz)
    outputs, drift = comp.step(record.rate_rps, record.temp_degC)
    return Compensated(outputs, comp.switch_on_offset_rps, drift)
