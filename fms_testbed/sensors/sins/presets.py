"""IMU error parameters: YAML files with units spelled out, converted to SI model arrays.

One file per IMU under ``imu/`` at the repository root (``imu/STIM300.yaml``); adding a preset
means adding one file. A scenario may also give the same mapping inline
(``navigation: {imu: {gyro: {...}, accelerometer: {...}}}``) or a path to a YAML file.

All values are 1σ. Noise densities (``arw_deg_per_sqrt_h``, ``vrw_mps_per_sqrt_h``,
``bias_rate_random_walk_*``) are **continuous-time** spectral densities; Gauss-Markov σ are
stationary standard deviations with their correlation time (driving density q = 2σ²/τ, paper
§5). A correlation time of ``null`` makes a scale factor / misalignment a random constant.

Biases: with no turn-on value, the in-run bias (``bias_instability_*``, ``bias_correlation_time_s``)
is a stationary Gauss-Markov state. With a turn-on (run-to-run) value the paper's model is used,
b' = η with b(0) ~ N(0, σ_turn_on²): the constant does not decay, and the in-run instability
becomes a random walk of density 2σ²/τ (the Gauss-Markov's initial growth; conservative beyond τ),
plus ``bias_rate_random_walk_*`` if given.

``quantization_rad`` / ``quantization_mps`` (the LSB of the angle and velocity increments) are
read only by the truth-side IMU of the strapdown navigation (:mod:`fms_testbed.sensors.imu`); the
33-state model has no quantisation state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import DEG_RAD, DPH_RPS, G0_MPS2
from fms_testbed.data import imu_dir as _data_imu_dir
from fms_testbed.sensors.sins.model import N_STATES

NonNeg = Annotated[float, Field(ge=0)]
PosOrNone = Annotated[float, Field(gt=0)] | None



class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class GyroSpec(_Frozen):
    """Gyro triad, 1σ per axis, units in the keys."""

    arw_deg_per_sqrt_h: NonNeg = 0.0
    bias_turn_on_deg_per_h: NonNeg = 0.0
    bias_instability_deg_per_h: NonNeg = 0.0
    bias_correlation_time_s: PosOrNone = None
    bias_rate_random_walk_deg_per_h_per_sqrt_h: NonNeg = 0.0
    scale_factor_ppm: NonNeg = 0.0
    scale_factor_correlation_time_s: PosOrNone = None
    misalignment_mrad: NonNeg = 0.0
    misalignment_correlation_time_s: PosOrNone = None
    quantization_rad: NonNeg = 0.0
    """LSB of the angle-increment output, rad (0: not quantised; the strapdown IMU only)."""


class AccelSpec(_Frozen):
    """Accelerometer triad, 1σ per axis, units in the keys (µg = 1e-6 g0, standard gravity)."""

    vrw_mps_per_sqrt_h: NonNeg = 0.0
    bias_turn_on_ug: NonNeg = 0.0
    bias_instability_ug: NonNeg = 0.0
    bias_correlation_time_s: PosOrNone = None
    bias_rate_random_walk_ug_per_sqrt_s: NonNeg = 0.0
    scale_factor_ppm: NonNeg = 0.0
    scale_factor_correlation_time_s: PosOrNone = None
    misalignment_mrad: NonNeg = 0.0
    misalignment_correlation_time_s: PosOrNone = None
    quantization_mps: NonNeg = 0.0
    """LSB of the velocity-increment output, m/s (0: not quantised; the strapdown IMU only)."""


class InitialSpec(_Frozen):
    """Initial navigation errors, 1σ per axis."""

    position_m: NonNeg = 0.0
    velocity_mps: NonNeg = 0.0
    tilt_mrad: NonNeg = 0.0
    heading_mrad: NonNeg = 0.0


class ImuSpec(_Frozen):
    """An IMU file (see the module docstring)."""

    name: str = "custom"
    grade: str = ""
    source: str = ""
    noise_model: str = Field("continuous", pattern="^continuous$")
    gyro: GyroSpec = GyroSpec()
    accelerometer: AccelSpec = AccelSpec()
    initial: InitialSpec = InitialSpec()


@dataclass(frozen=True)
class ImuModel:
    """SI arrays of the 33-state model for one IMU.

    decay_rps: (24,) 1/τ of states 9..32, 1/s (0: random walk or constant)
    q_psd: (33,) diagonal of the continuous noise density Q (eq. 6.9), state-unit²/s
    p0_var: (33,) initial variance of every state, state-unit²
    """

    name: str
    source: str
    decay_rps: np.ndarray
    q_psd: np.ndarray
    p0_var: np.ndarray

    def summary(self) -> str:
        """One line: the main figures in datasheet units."""
        s = np.sqrt(self.p0_var)
        return (f"{self.name}: ARW {math.sqrt(self.q_psd[6]) / DEG_RAD * 60:.3g} deg/sqrt(h), "
                f"VRW {math.sqrt(self.q_psd[3]) * 60:.3g} m/s/sqrt(h), "
                f"gyro bias {s[12] / DPH_RPS:.3g} deg/h, accel bias "
                f"{s[9] / G0_MPS2 * 1e6:.3g} ug (1 sigma)")


def _triad_states(bias_sigma_turn_on, bias_sigma_inst, bias_tau, bias_rrw, sf, sf_tau, mis,
                  mis_tau):
    """(decay, q, p0) for bias(3), scale factor(3), misalignment(6), SI."""
    def gm(sigma, tau):
        return (1.0 / tau, 2.0 * sigma * sigma / tau) if tau else (0.0, 0.0)

    if bias_tau and bias_sigma_turn_on == 0.0:
        # in-run bias alone: stationary first-order Gauss-Markov
        b_decay, b_q = gm(bias_sigma_inst, bias_tau)
        b_p0 = bias_sigma_inst ** 2
    else:
        # paper §5: b' = η, b(0) = d (run-to-run constant + random walk). A Gauss-Markov decay
        # would wrongly erode the turn-on constant, so a given instability becomes a random walk
        # with the same initial growth as the Gauss-Markov process (q = 2σ²/τ)
        b_decay = 0.0
        b_q = bias_rrw ** 2 + (2.0 * bias_sigma_inst ** 2 / bias_tau if bias_tau else 0.0)
        b_p0 = bias_sigma_turn_on ** 2
    k_decay, k_q = gm(sf, sf_tau)
    m_decay, m_q = gm(mis, mis_tau)
    return ((b_decay, b_q, b_p0, 3), (k_decay, k_q, sf * sf, 3), (m_decay, m_q, mis * mis, 6))


def imu_model(spec: ImuSpec) -> ImuModel:
    """Convert a validated :class:`ImuSpec` (datasheet units) to SI model arrays."""
    g, a, ini = spec.gyro, spec.accelerometer, spec.initial
    ug = 1e-6 * G0_MPS2
    acc = _triad_states(a.bias_turn_on_ug * ug, a.bias_instability_ug * ug,
                        a.bias_correlation_time_s, a.bias_rate_random_walk_ug_per_sqrt_s * ug,
                        a.scale_factor_ppm * 1e-6, a.scale_factor_correlation_time_s,
                        a.misalignment_mrad * 1e-3, a.misalignment_correlation_time_s)
    gyr = _triad_states(g.bias_turn_on_deg_per_h * DPH_RPS,
                        g.bias_instability_deg_per_h * DPH_RPS, g.bias_correlation_time_s,
                        g.bias_rate_random_walk_deg_per_h_per_sqrt_h * DPH_RPS / 60.0,
                        g.scale_factor_ppm * 1e-6, g.scale_factor_correlation_time_s,
                        g.misalignment_mrad * 1e-3, g.misalignment_correlation_time_s)
    # state order 9..32: b_a, b_g, k_a, k_g, β_a, β_g
    blocks = [acc[0], gyr[0], acc[1], gyr[1], acc[2], gyr[2]]
    decay = np.concatenate([np.full(n, d) for d, _, _, n in blocks])
    q = np.zeros(N_STATES)
    q[3:6] = (a.vrw_mps_per_sqrt_h / 60.0) ** 2          # m/s/√h → m/s/√s
    q[6:9] = (g.arw_deg_per_sqrt_h * DEG_RAD / 60.0) ** 2     # °/√h → rad/√s
    q[9:] = np.concatenate([np.full(n, qq) for _, qq, _, n in blocks])
    p0 = np.zeros(N_STATES)
    p0[0:3] = ini.position_m ** 2
    p0[3:6] = ini.velocity_mps ** 2
    p0[6:8] = (ini.tilt_mrad * 1e-3) ** 2
    p0[8] = (ini.heading_mrad * 1e-3) ** 2
    p0[9:] = np.concatenate([np.full(n, p) for _, _, p, n in blocks])
    return ImuModel(spec.name, spec.source, decay, q, p0)


def imu_dir() -> Path:
    """Folder of the IMU preset files (``fms_testbed/data/imu/NAME.yaml``)."""
    return _data_imu_dir()


def list_presets() -> list[str]:
    """Names of the shipped IMU presets."""
    return sorted(p.stem for p in imu_dir().glob("*.yaml"))


def _validate(data: Any, where: str) -> ImuSpec:
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: an IMU must be a mapping, got {type(data).__name__}")
    try:
        return ImuSpec.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = ".".join(str(p) for p in err["loc"])
        raise ConfigError(f"{where}: field {loc!r}: {err['msg']}") from None


def load_imu_spec(imu: str | Path | dict) -> ImuSpec:
    """Load an IMU from a preset name, a YAML path, or an inline mapping (datasheet units).

    Raises
    ------
    ConfigError : unknown preset, unreadable file, unknown key, or a bad value (file and field).
    """
    if isinstance(imu, dict):
        return _validate(imu, "navigation.imu")
    p = Path(imu)
    if p.suffix not in (".yaml", ".yml"):
        cand = {n.lower(): n for n in list_presets()}
        key = str(imu).lower().replace(" ", "_")
        if key not in cand:
            raise ConfigError(f"unknown IMU preset {imu!r}; presets in {imu_dir()}: "
                              f"{', '.join(list_presets())} (or give a .yaml file)")
        p = imu_dir() / f"{cand[key]}.yaml"
    try:
        data = yaml.safe_load(p.read_text())
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read IMU file: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{p}: not valid YAML: {exc}") from None
    spec = _validate(data, str(p))
    if spec.name == "custom":
        spec = spec.model_copy(update={"name": p.stem})
    return spec


def load_imu(imu: str | Path | dict) -> ImuModel:
    """Preset name, YAML path or mapping → :class:`ImuModel` (SI arrays).

    A MEMS gyro preset (``fms_testbed/data/mems/``) with compensation stages is accepted too:
    ``"STIM210"``, ``"STIM210+compensated"``, ``"STIM210+temperature+run-to-run"`` or
    ``{mems: STIM210, stages: [...]}`` (:mod:`fms_testbed.sensors.mems.equivalent`).
    """
    # imported here: the MEMS package builds on this module
    from fms_testbed.sensors.mems.equivalent import equivalent_imu, parse_mems_request

    mems = parse_mems_request(imu) if isinstance(imu, (str, dict)) else None
    if mems is not None:
        return equivalent_imu(*mems)
    return imu_model(load_imu_spec(imu))
