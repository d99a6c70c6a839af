"""The static ``imu-test``: one switch-on of a MEMS gyro at rest, compensated stage by stage.

:func:`run_static_test` simulates the factory calibration run (when the temperature stage is
applied) and the test run, applies the chosen stages (:class:`~.compensation.Compensator`) and
measures, per stage and axis: the residual zero signal (the largest |mean| of consecutive
``evaluation.zero_signal_window_s`` windows, as the seed's "maximum undercompensated zero
signal"), the mean drift (angle / duration) and the angle accumulated over the run. The result
object carries the series the plots draw (one sample per :func:`series_step_s`) and a JSON
summary with the seed's figures next to the measured ones.

The test run is generated, compensated and reduced in chunks of ``chunk_samples``
(:class:`~.model.GyroStream`, :class:`~.allan.OctaveAllan`), so its memory is bounded by the
chunk, the kept series (at most :data:`MAX_SERIES_ROWS` rows) and the 1-s temperature grid,
whatever the duration; every reduction carries its state or works on blocks aligned on the run,
so the numbers do not depend on the chunk size.

Seeds: ``numpy.random.SeedSequence(seed).spawn(2)`` gives the calibration run's and the test
run's generators, so the same seed gives the same numbers whatever the stages.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fms_testbed.core.units import DEG_RAD
from fms_testbed.sensors.mems.allan import AllanFit, BlockReducer, OctaveAllan
from fms_testbed.sensors.mems.compensation import (STAGES, Compensator, TemperatureCalibration,
                                                   factory_calibration)
from fms_testbed.sensors.mems.model import GyroStream
from fms_testbed.sensors.mems.preset import MemsSpec, gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import TemperatureProfile, profile_for

RAD2DEG = 1.0 / DEG_RAD
SERIES_STEP_S = 1.0
"""Step of the angle series kept for the CSV and the plots, s (longer runs: :func:`series_step_s`)."""
MAX_SERIES_ROWS = 360_000
"""Most steps of the kept angle series (100 h at 1 s)."""
CHUNK_SAMPLES = 2 ** 17
"""Samples of the test run generated and reduced at a time (22 min at 100 Hz)."""


def series_step_s(duration_s: float) -> float:
    """Step of the kept angle series, s: :data:`SERIES_STEP_S`, or the whole number of seconds
    that keeps at most :data:`MAX_SERIES_ROWS` steps, Δ = max(1 s, ⌈duration / rows⌉).

    Parameters
    ----------
    duration_s : length of the test, s
    """
    return max(SERIES_STEP_S, float(np.ceil(duration_s / MAX_SERIES_ROWS - 1e-9)))


@dataclass(frozen=True)
class StageResult:
    """Residual of one stage, per axis (x, y, z).

    residual_max_deg_per_s : (3,) largest |window mean| of the output error, °/s
    mean_drift_deg_per_s : (3,) angle / duration, °/s (signed)
    angle_deg : (3,) angle accumulated over the run, ° (signed)
    """

    residual_max_deg_per_s: np.ndarray
    mean_drift_deg_per_s: np.ndarray
    angle_deg: np.ndarray


@dataclass(frozen=True)
class StaticTestResult:
    """Everything one static test measured (see the module docstring).

    series_t_s : (m,) times of the kept series, s
    angle_series_deg : stage → (m, 3) accumulated angle, °
    window_t_s, window_temp_degC : (k,) centre time, s, and mean temperature, °C, of each window
    window_error_deg_per_s : stage → (k, 3) window means of the output error, °/s
    """

    imu: str
    seed: int
    duration_s: float
    rate_hz: float
    profile: TemperatureProfile
    stages: tuple[str, ...]
    stage: dict[str, StageResult]
    series_t_s: np.ndarray
    angle_series_deg: dict[str, np.ndarray]
    window_t_s: np.ndarray
    window_temp_degC: np.ndarray
    window_error_deg_per_s: dict[str, np.ndarray]
    calibration: TemperatureCalibration | None
    switch_on_offset_true_rps: np.ndarray
    switch_on_offset_estimated_rps: np.ndarray | None
    reference: dict
    allan: AllanFit | None = None
    allan_signal: str | None = None
    preset_allan: dict = field(default_factory=dict)
    wall_time_s: float = 0.0

    def angle_frame(self) -> pd.DataFrame:
        """Columns ``t_s`` and ``angle_<stage>_<axis>_deg`` (stage with ``_`` for ``-``)."""
        cols = {"t_s": self.series_t_s}
        for st, ang in self.angle_series_deg.items():
            for a, ax in enumerate("xyz"):
                cols[f"angle_{st.replace('-', '_')}_{ax}_deg"] = ang[:, a]
        return pd.DataFrame(cols)

    def reproduction(self) -> dict:
        """The seed's figures next to this run's: maxima over axes (the raw zero signal and the
        temperature residual from the calibration run, which covers the operating range), the
        uncompensated angle as the mean |angle| over axes, the compensated one as the max."""
        ref = self.reference
        out = {}

        def put(key, measured):
            out[key] = {"paper": ref[key], "measured": float(f"{measured:.5g}"),
                        "ratio": float(f"{measured / ref[key]:.4g}")}

        if self.calibration is not None:       # the calibration run covers the whole range
            put("raw_zero_signal_deg_per_s",
                float(np.abs(self.calibration.point_zero_rps).max()) * RAD2DEG)
            put("temperature_residual_deg_per_s",
                float(self.calibration.residual_max_rps.max()) * RAD2DEG)
        if "temperature" in self.stage:
            put("run_to_run_error_deg_per_s",
                float(self.stage["temperature"].residual_max_deg_per_s.max()))
        if "run-to-run" in self.stage:
            put("run_to_run_residual_deg_per_s",
                float(self.stage["run-to-run"].residual_max_deg_per_s.max()))
        if "none" in self.stage:
            put("angle_uncompensated_deg", float(np.abs(self.stage["none"].angle_deg).mean()))
        if "slow-drift" in self.stage:
            put("angle_compensated_deg", float(np.abs(self.stage["slow-drift"].angle_deg).max()))
        return out

    def summary(self) -> dict:
        """JSON-ready summary (strict JSON: finite numbers only)."""
        s = {
            "imu": self.imu, "seed": self.seed, "duration_s": self.duration_s,
            "rate_hz": self.rate_hz, "temperature_profile": self.profile.name,
            "temperature_degC": {"min": round(float(self.profile.temp_degC.min()), 3),
                                 "max": round(float(self.profile.temp_degC.max()), 3)},
            "stages": list(self.stages),
            "residual_window_s": float(self.window_t_s[1] - self.window_t_s[0])
            if self.window_t_s.size > 1 else self.duration_s,
            "per_stage": {st: {"residual_zero_signal_max_deg_per_s": _r(r.residual_max_deg_per_s),
                               "mean_drift_deg_per_s": _r(r.mean_drift_deg_per_s),
                               "angle_deg": _r(r.angle_deg)} for st, r in self.stage.items()},
            "switch_on_offset_deg_per_s": {
                "drawn": _r(self.switch_on_offset_true_rps * RAD2DEG),
                "estimated": None if self.switch_on_offset_estimated_rps is None
                else _r(self.switch_on_offset_estimated_rps * RAD2DEG)},
            "reproduction": self.reproduction(),
            "wall_time_s": round(self.wall_time_s, 3),
        }
        if self.calibration is not None:
            c = self.calibration
            s["calibration"] = {"residual_max_deg_per_s": _r(c.residual_max_rps * RAD2DEG),
                                "range_degC": [round(v, 3) for v in c.range_degC],
                                "points": int(c.point_temp_degC.size),
                                "polynomial_degree": int(c.coef_rps.shape[1] - 1)}
        if self.allan is not None:
            s["allan"] = {"signal": self.allan_signal, "fit": self.allan.to_dict(),
                          "preset": self.preset_allan}
        return s


def _r(a) -> list[float]:
    return [float(f"{v:.5g}") for v in np.asarray(a, float)]


class _StageReducer:
    """Angle, window means and kept angle series of one stage's output error, chunk by chunk."""

    def __init__(self, rate_hz: float, window_n: int, keep_every: int):
        self.rate_hz, self.keep = rate_hz, keep_every
        self._windows = BlockReducer(window_n, 3)
        self._sum = np.zeros(3)              # Σ error so far, rad/s (angle · rate)
        self.i = 0
        self.series = [np.zeros((1, 3))]
        self.window = []

    def update(self, err_rps: np.ndarray) -> None:
        c = np.cumsum(np.vstack([self._sum, err_rps]), axis=0)[1:]
        self._sum = c[-1].copy()
        first = (-(self.i + 1)) % self.keep          # first row whose sample number is kept
        self.series.append(c[first::self.keep] * (RAD2DEG / self.rate_hz))
        self.window.append(self._windows.means(err_rps) * RAD2DEG)
        self.i += err_rps.shape[0]

    def result(self) -> tuple[StageResult, np.ndarray, np.ndarray]:
        angle = self._sum * (RAD2DEG / self.rate_hz)
        win = np.vstack(self.window)
        res = StageResult(np.abs(win).max(axis=0), angle / (self.i / self.rate_hz), angle)
        return res, np.vstack(self.series), win


def run_static_test(imu: str | MemsSpec = "STIM210", duration_s: float = 7200.0,
                    profile: str = "warmup", stages: tuple[str, ...] = STAGES, seed: int = 0,
                    allan: bool = False, rate_hz: float | None = None,
                    chunk_samples: int = CHUNK_SAMPLES) -> StaticTestResult:
    """Simulate and compensate one static switch-on, in chunks (module docstring).

    Parameters
    ----------
    imu : MEMS preset name, YAML path or loaded spec
    duration_s : length of the test, s
    profile : ``warmup`` | ``ramp`` | ``constant`` | path of a CSV profile
    stages : stages in canonical order (:func:`~.compensation.parse_stages`)
    seed : seed of the calibration and test runs
    allan : also fit the octave Allan deviation of the output of the last stage before slow
        drift
    rate_hz : output rate, Hz (default: the preset's ``sample_rate_hz``)
    chunk_samples : samples generated and reduced at a time (at least the run-to-run interval;
        the numbers do not depend on it)
    """
    t0 = time.perf_counter()
    spec = load_mems(imu)
    rate = float(rate_hz or spec.sample_rate_hz)
    prof = profile_for(profile, spec, duration_s)
    cal_seq, run_seq = np.random.SeedSequence(int(seed)).spawn(2)
    cal = factory_calibration(spec, np.random.default_rng(cal_seq)) \
        if "temperature" in stages else None
    src = GyroStream(gyro_model(spec), prof, duration_s, rate, np.random.default_rng(run_seq))
    comp = Compensator(stages, spec, cal, rate)
    # a test shorter than one evaluation window is evaluated as one window
    window_n = min(max(1, int(round(spec.evaluation.zero_signal_window_s * rate))), src.n)
    keep = max(1, int(round(series_step_s(duration_s) * rate)))
    chunk = max(int(chunk_samples), int(round(spec.run_to_run.initial_interval_s * rate)))
    reducers = {st: _StageReducer(rate, window_n, keep) for st in stages}
    temp_windows, temp_means = BlockReducer(window_n), []
    sig = [s for s in stages if s != "slow-drift"]
    sig_name = sig[-1] if sig else "slow-drift"
    octave = OctaveAllan(src.n, rate) if allan else None
    while src.i < src.n:
        _, temp, out = src.next(chunk)
        outputs, _ = comp.step(out, temp)
        for st, y in outputs.items():            # static: the output is the error
            reducers[st].update(y)
        temp_means.append(temp_windows.means(temp))
        if octave is not None:
            octave.update(outputs[sig_name])
    stage, series, windows = {}, {}, {}
    for st, red in reducers.items():
        stage[st], series[st], windows[st] = red.result()
    n_series = next(iter(series.values())).shape[0]
    kw = {}
    if allan:
        g = spec.gyro
        kw = dict(allan=octave.fit(), allan_signal=sig_name,
                  preset_allan={"arw_deg_per_sqrt_h": g.arw_deg_per_sqrt_h,
                                "bias_instability_deg_per_h": g.bias_instability_deg_per_h,
                                "rrw_deg_per_h_per_sqrt_h":
                                    g.rate_random_walk_deg_per_h_per_sqrt_h})
    win_t = (np.arange(next(iter(windows.values())).shape[0]) + 0.5) * window_n / rate
    return StaticTestResult(
        imu=spec.name, seed=int(seed), duration_s=float(duration_s), rate_hz=rate, profile=prof,
        stages=tuple(stages), stage=stage, series_t_s=np.arange(n_series) * keep / rate,
        angle_series_deg=series, window_t_s=win_t,
        window_temp_degC=np.concatenate(temp_means), window_error_deg_per_s=windows,
        calibration=cal, switch_on_offset_true_rps=src.switch_on_offset_rps,
        switch_on_offset_estimated_rps=comp.switch_on_offset_rps,
        reference=spec.reference.model_dump(), wall_time_s=time.perf_counter() - t0, **kw)
