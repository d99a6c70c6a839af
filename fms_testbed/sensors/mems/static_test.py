"""The static ``imu-test``: one switch-on of a MEMS gyro at rest, compensated stage by stage.

:func:`run_static_test` simulates the factory calibration run (when the temperature stage is
applied) and the test run, applies the chosen stages (:func:`~.compensation.compensate`) and
measures, per stage and axis: the residual zero signal (the largest |mean| of consecutive
``evaluation.zero_signal_window_s`` windows, as the seed's "maximum undercompensated zero
signal"), the mean drift (angle / duration) and the angle accumulated over the run. The result
object carries the series the plots draw (decimated to 1 s) and a JSON summary with the seed's
figures next to the measured ones.

Seeds: ``numpy.random.SeedSequence(seed).spawn(2)`` gives the calibration run's and the test
run's generators, so the same seed gives the same numbers whatever the stages.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fms_testbed.core.units import DEG_RAD
from fms_testbed.sensors.mems.allan import AllanFit, fit_allan
from fms_testbed.sensors.mems.compensation import (STAGES, TemperatureCalibration, compensate,
                                                   factory_calibration, window_means)
from fms_testbed.sensors.mems.model import simulate_gyro
from fms_testbed.sensors.mems.preset import MemsSpec, gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import TemperatureProfile, profile_for

RAD2DEG = 1.0 / DEG_RAD
SERIES_STEP_S = 1.0
"""Step of the angle series kept for the CSV and the plots, s."""


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


def _stage_result(err_rps: np.ndarray, rate_hz: float, window_n: int, keep_every: int
                  ) -> tuple[StageResult, np.ndarray, np.ndarray]:
    """(stage result, angle series (m, 3) °, window means (k, 3) °/s) of one output error."""
    angle = np.cumsum(err_rps, axis=0) * (RAD2DEG / rate_hz)
    win = window_means(err_rps, window_n) * RAD2DEG
    duration = err_rps.shape[0] / rate_hz
    res = StageResult(np.abs(win).max(axis=0), angle[-1] / duration, angle[-1].copy())
    series = np.vstack([np.zeros((1, 3)), angle[keep_every - 1::keep_every]])
    return res, series, win


def run_static_test(imu: str | MemsSpec = "STIM210", duration_s: float = 7200.0,
                    profile: str = "warmup", stages: tuple[str, ...] = STAGES, seed: int = 0,
                    allan: bool = False, rate_hz: float | None = None) -> StaticTestResult:
    """Simulate and compensate one static switch-on (module docstring).

    Parameters
    ----------
    imu : MEMS preset name, YAML path or loaded spec
    duration_s : length of the test, s
    profile : ``warmup`` | ``ramp`` | ``constant`` | path of a CSV profile
    stages : stages in canonical order (:func:`~.compensation.parse_stages`)
    seed : seed of the calibration and test runs
    allan : also fit the Allan deviation of the output of the last stage before slow drift
    rate_hz : output rate, Hz (default: the preset's ``sample_rate_hz``)
    """
    t0 = time.perf_counter()
    spec = load_mems(imu)
    rate = float(rate_hz or spec.sample_rate_hz)
    prof = profile_for(profile, spec, duration_s)
    cal_seq, run_seq = np.random.SeedSequence(int(seed)).spawn(2)
    cal = factory_calibration(spec, np.random.default_rng(cal_seq)) \
        if "temperature" in stages else None
    rec = simulate_gyro(gyro_model(spec), prof, duration_s, rate, np.random.default_rng(run_seq))
    comp = compensate(rec, stages, spec, cal)
    # a test shorter than one evaluation window is evaluated as one window
    window_n = min(max(1, int(round(spec.evaluation.zero_signal_window_s * rate))),
                   rec.rate_rps.shape[0])
    keep = max(1, int(round(SERIES_STEP_S * rate)))
    stage, series, windows = {}, {}, {}
    for st, out in comp.outputs.items():
        stage[st], series[st], windows[st] = _stage_result(out - rec.true_rate_rps, rate,
                                                           window_n, keep)
    n_series = next(iter(series.values())).shape[0]
    kw = {}
    if allan:
        sig = [s for s in comp.outputs if s != "slow-drift"]
        sig_name = sig[-1] if sig else "slow-drift"
        g = spec.gyro
        kw = dict(allan=fit_allan(comp.outputs[sig_name] - rec.true_rate_rps, rate),
                  allan_signal=sig_name,
                  preset_allan={"arw_deg_per_sqrt_h": g.arw_deg_per_sqrt_h,
                                "bias_instability_deg_per_h": g.bias_instability_deg_per_h,
                                "rrw_deg_per_h_per_sqrt_h":
                                    g.rate_random_walk_deg_per_h_per_sqrt_h})
    win_t = (np.arange(next(iter(windows.values())).shape[0]) + 0.5) * window_n / rate
    return StaticTestResult(
        imu=spec.name, seed=int(seed), duration_s=float(duration_s), rate_hz=rate, profile=prof,
        stages=tuple(stages), stage=stage, series_t_s=np.arange(n_series) * keep / rate,
        angle_series_deg=series, window_t_s=win_t,
        window_temp_degC=window_means(rec.temp_degC, window_n), window_error_deg_per_s=windows,
        calibration=cal, switch_on_offset_true_rps=rec.switch_on_offset_rps,
        switch_on_offset_estimated_rps=comp.switch_on_offset_rps,
        reference=spec.reference.model_dump(), wall_time_s=time.perf_counter() - t0, **kw)

