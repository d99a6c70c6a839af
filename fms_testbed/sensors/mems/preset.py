"""MEMS gyro presets: YAML files under ``fms_testbed/data/mems/`` (``STIM210.yaml``), units in the
keys, each value's public source named in a comment, validated with pydantic and converted to SI.

A preset holds the sensor's error model (temperature polynomial, hysteresis, run-to-run offset,
bias instability, angle random walk, rate random walk, resolution), the temperature profiles of
the static test, the parameters of the three compensation stages of Vorobyov et al. (seed 000)
and the seed's published figures (``reference``) for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from fms_testbed.config.yamlfile import read_mapping, validation_message
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import DEG_RAD, DPH_RPS
from fms_testbed.data import data_root
from fms_testbed.sensors.sins.presets import AccelSpec

Pos = Annotated[float, Field(gt=0)]
NonNeg = Annotated[float, Field(ge=0)]
AXES = ("x", "y", "z")


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PolySpec(_Frozen):
    """Zero signal vs temperature per axis: coefficients of (T - T_ref)^k, deg/s/degC^k."""

    x: list[float] = Field(min_length=1, max_length=8)
    y: list[float] = Field(min_length=1, max_length=8)
    z: list[float] = Field(min_length=1, max_length=8)


class MemsGyroSpec(_Frozen):
    """Gyro triad error model, units in the keys (1σ per axis unless the key says otherwise)."""

    arw_deg_per_sqrt_h: NonNeg
    bias_instability_deg_per_h: NonNeg
    rate_random_walk_deg_per_h_per_sqrt_h: NonNeg = 0.0
    resolution_deg_per_h: NonNeg = 0.0
    scale_factor_ppm: NonNeg = 0.0
    misalignment_mrad: NonNeg = 0.0
    run_to_run_deg_per_s: NonNeg
    hysteresis_deg_per_s: list[float] = Field(min_length=3, max_length=3)
    hysteresis_width_degC: Pos
    zero_signal_reference_degC: float = 25.0
    zero_signal_poly_deg_per_s: PolySpec


class TemperatureSpec(_Frozen):
    """Temperature profiles of the static test and the calibration, degC / s."""

    operating_range_degC: list[float] = Field(min_length=2, max_length=2)
    warmup_ambient_degC: float
    warmup_self_heating_degC: float
    warmup_time_constant_s: Pos
    constant_degC: float
    ramp_soak_s: NonNeg = 0.0

    @field_validator("operating_range_degC")
    @classmethod
    def _ordered(cls, v):
        if not v[0] < v[1]:
            raise ValueError(f"expected [low, high] with low < high, got {v}")
        return v


class CalibrationSpec(_Frozen):
    """The simulated factory calibration run (chamber ramp over the operating range)."""

    duration_s: Pos
    sample_rate_hz: Pos
    window_s: Pos
    polynomial_degree: int = Field(ge=0, le=7)
    min_swing_degC: Pos


class RunToRunSpec(_Frozen):
    """Switch-on offset estimation."""

    initial_interval_s: Pos


class SlowDriftSpec(_Frozen):
    """Slow-drift extractor: sensitivity threshold and low-pass cut-off (seed: < 0.1 Hz)."""

    threshold_deg_per_s: Pos
    cutoff_hz: Annotated[float, Field(gt=0, le=0.1)]


class EvaluationSpec(_Frozen):
    """How residuals are measured."""

    zero_signal_window_s: Pos


class EquivalentSpec(_Frozen):
    """The static runs that measure the residual gyro error for the INS model."""

    duration_s: Pos
    seeds: int = Field(ge=1, le=100)
    correlation_time_s: Pos


class ReferenceSpec(_Frozen):
    """The seed's published figures (for comparison, never used by the model)."""

    raw_zero_signal_deg_per_s: Pos
    temperature_residual_deg_per_s: Pos
    run_to_run_error_deg_per_s: Pos
    run_to_run_residual_deg_per_s: Pos
    angle_uncompensated_deg: Pos
    angle_compensated_deg: Pos
    duration_s: Pos


class MemsSpec(_Frozen):
    """A MEMS gyro preset file (see the module docstring)."""

    name: str
    grade: str = ""
    source: str = ""
    sample_rate_hz: Pos
    gyro: MemsGyroSpec
    temperature: TemperatureSpec
    calibration: CalibrationSpec
    run_to_run: RunToRunSpec
    slow_drift: SlowDriftSpec
    evaluation: EvaluationSpec
    equivalent: EquivalentSpec
    accelerometer: AccelSpec = AccelSpec()
    reference: ReferenceSpec


@dataclass(frozen=True)
class MemsGyroModel:
    """SI parameters of the gyro error model (per axis arrays are (3,), axes x, y, z).

    poly_rps_per_degC_k : (3, K) zero-signal coefficients of (T - ref_degC)^k, rad/s/°C^k
    hysteresis_rps : (3,) half-height of the hysteresis loop, rad/s
    arw_rps_per_sqrt_hz : angle random walk N, rad/s/√Hz (= rad/√s)
    bias_instability_rps : Allan-deviation floor of the flicker bias, rad/s
    rrw_rps_per_sqrt_s : rate random walk K, rad/s/√s
    resolution_rps : output quantum, rad/s (0: none)
    run_to_run_rps : 1σ switch-on offset per axis, rad/s
    """

    poly_rps_per_degC_k: np.ndarray
    ref_degC: float
    hysteresis_rps: np.ndarray
    hysteresis_width_degC: float
    arw_rps_per_sqrt_hz: float
    bias_instability_rps: float
    rrw_rps_per_sqrt_s: float
    resolution_rps: float
    run_to_run_rps: float


def gyro_model(spec: MemsSpec) -> MemsGyroModel:
    """Datasheet units of a :class:`MemsSpec` → SI :class:`MemsGyroModel`.

    Parameters
    ----------
    spec : a validated preset (°/s, °/h, °/√h, °C in its keys)
    """
    g = spec.gyro
    p = g.zero_signal_poly_deg_per_s
    k = max(len(p.x), len(p.y), len(p.z))
    poly = np.zeros((3, k))
    for i, c in enumerate((p.x, p.y, p.z)):
        poly[i, :len(c)] = c
    return MemsGyroModel(
        poly_rps_per_degC_k=poly * DEG_RAD, ref_degC=g.zero_signal_reference_degC,
        hysteresis_rps=np.asarray(g.hysteresis_deg_per_s, float) * DEG_RAD,
        hysteresis_width_degC=g.hysteresis_width_degC,
        arw_rps_per_sqrt_hz=g.arw_deg_per_sqrt_h * DEG_RAD / 60.0,     # °/√h → rad/√s
        bias_instability_rps=g.bias_instability_deg_per_h * DPH_RPS,
        rrw_rps_per_sqrt_s=g.rate_random_walk_deg_per_h_per_sqrt_h * DPH_RPS / 60.0,
        resolution_rps=g.resolution_deg_per_h * DPH_RPS,
        run_to_run_rps=g.run_to_run_deg_per_s * DEG_RAD)


def mems_dir() -> Path:
    """Folder of the MEMS gyro presets (``fms_testbed/data/mems/NAME.yaml``)."""
    return data_root() / "mems"


def list_mems_presets() -> list[str]:
    """Names of the shipped MEMS gyro presets."""
    return sorted(p.stem for p in mems_dir().glob("*.yaml"))


def find_mems_preset(name: str) -> Path | None:
    """The preset file for ``name`` (case-insensitive), or None when there is none."""
    cand = {n.lower(): n for n in list_mems_presets()}
    key = str(name).strip().lower()
    return mems_dir() / f"{cand[key]}.yaml" if key in cand else None


def load_mems(preset: str | Path | MemsSpec) -> MemsSpec:
    """Load a MEMS gyro preset by name or YAML path (a :class:`MemsSpec` passes through).

    Raises
    ------
    ConfigError : unknown preset, unreadable file, unknown key or bad value (file and field named).
    """
    if isinstance(preset, MemsSpec):
        return preset
    p = Path(preset)
    if p.suffix not in (".yaml", ".yml"):
        found = find_mems_preset(str(preset))
        if found is None:
            raise ConfigError(f"unknown MEMS gyro preset {str(preset)!r}; presets in {mems_dir()}: "
                              f"{', '.join(list_mems_presets())} (or give a .yaml file)")
        p = found
    data = read_mapping(p, "MEMS gyro preset")
    try:
        return MemsSpec.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(validation_message(str(p), exc)) from None
