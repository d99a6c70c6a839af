"""A compensated MEMS gyro as the IMU of the SINS navigation source.

The SINS error model (:mod:`fms_testbed.sensors.sins`) takes random-constant, Gauss-Markov and
random-walk sensor errors (:class:`~fms_testbed.sensors.sins.presets.ImuModel`). The gyro terms
of a MEMS preset with a set of compensation stages are *measured*: ``equivalent.seeds`` static
warm-up switch-ons of ``equivalent.duration_s`` are simulated and compensated
(:func:`~.static_test.run_static_test`), and the residual output error gives

* ``bias_turn_on_deg_per_h`` — RMS over switch-ons and axes of the residual's run mean;
* ``bias_instability_deg_per_h`` — RMS of the residual's ``evaluation.zero_signal_window_s``
  window means about that run mean, with the angle random walk's share (N² / T_w) removed, as a
  Gauss-Markov σ with ``equivalent.correlation_time_s`` (the SINS preset rules then treat it as
  a random walk of density 2σ²/τ on top of the turn-on constant);
* ``arw_deg_per_sqrt_h``, scale factor and misalignment — the preset's (no stage changes them).

The accelerometer terms are the preset's ``accelerometer`` block. Requests accepted by
:func:`parse_mems_request` (and by ``load_imu``): ``"STIM210"`` (no compensation),
``"STIM210+compensated"`` (all three stages), ``"STIM210+temperature+run-to-run"`` (those
stages), or a mapping ``{mems: STIM210, stages: [temperature, run-to-run, slow-drift]}``.

Limits: the residual is that of a static test. In flight the slow-drift stage holds its estimate
while the rate is above the threshold, and it would take true rates below the threshold (Earth
rate, transport rate, slow turns) for drift unless they are removed first; the equivalent model
has neither effect.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.core.units import DEG_RAD, DPH_RPS
from fms_testbed.sensors.mems.compensation import STAGES, parse_stages
from fms_testbed.sensors.mems.preset import MemsSpec, find_mems_preset, load_mems
from fms_testbed.sensors.mems.static_test import run_static_test
from fms_testbed.sensors.sins.presets import ImuModel, ImuSpec, imu_model

ALL_STAGES = "compensated"
"""Request suffix meaning all three compensation stages."""


@dataclass(frozen=True)
class EquivalentGyro:
    """Measured residual gyro error of a MEMS preset after some stages (datasheet units, 1σ).

    bias_turn_on_deg_per_h : constant part (RMS of run means)
    bias_instability_deg_per_h : in-run part (RMS of window means about the run mean, ARW removed)
    correlation_time_s : correlation time given to the in-run part
    arw_deg_per_sqrt_h : angle random walk (the preset's)
    """

    preset: str
    stages: tuple[str, ...]
    bias_turn_on_deg_per_h: float
    bias_instability_deg_per_h: float
    correlation_time_s: float
    arw_deg_per_sqrt_h: float
    seeds: int
    duration_s: float


def parse_mems_request(imu) -> tuple[str, tuple[str, ...]] | None:
    """``"NAME[+STAGE...]"`` or ``{mems: NAME, stages: [...]}`` → (preset, compensation stages);
    None when ``imu`` names no MEMS preset (an ordinary IMU preset, path or mapping).

    Raises
    ------
    ConfigError : a MEMS request with an unknown stage or preset, or a bad mapping.
    """
    if isinstance(imu, dict):
        if "mems" not in imu:
            return None
        extra = sorted(set(imu) - {"mems", "stages"})
        if extra:
            raise ConfigError(f"navigation.imu.{extra[0]}: unknown key; a MEMS IMU takes "
                              "'mems' and 'stages'")
        name, stages = str(imu["mems"]), imu.get("stages", [])
        try:
            load_mems(name)
        except ConfigError as exc:
            raise ConfigError(f"navigation.imu.mems: {exc}") from None
    elif isinstance(imu, str):
        name, *stages = imu.split("+")
        if find_mems_preset(name) is None:
            return None
    else:
        return None
    if isinstance(stages, str):
        stages = stages.split(",")
    stages = [s for s in stages if str(s).strip()]
    if any(str(s).strip().lower() == ALL_STAGES for s in stages):
        stages = list(STAGES[1:])
    try:
        chosen = parse_stages(["none", *stages])
    except UserError as exc:
        raise ConfigError(f"navigation.imu (MEMS {name}): {exc}") from None
    return name, tuple(s for s in chosen if s != "none")


def measure_equivalent_gyro(spec: MemsSpec, stages: tuple[str, ...]) -> EquivalentGyro:
    """Measure the residual gyro error after ``stages`` (module docstring).

    Parameters
    ----------
    spec : the MEMS preset
    stages : compensation stages (without ``none``), canonical order
    """
    eq, g = spec.equivalent, spec.gyro
    chain = ("none", *stages)
    last = chain[-1]
    means, devs = [], []
    window_s = spec.evaluation.zero_signal_window_s
    for seed in range(eq.seeds):
        r = run_static_test(spec, eq.duration_s, "warmup", chain, seed)
        st = r.stage[last]
        means.append(st.mean_drift_deg_per_s)
        devs.append(r.window_error_deg_per_s[last] - st.mean_drift_deg_per_s)
    turn_on_dps = float(np.sqrt(np.mean(np.square(means))))
    var_win = float(np.mean(np.square(np.concatenate(devs))))
    arw_var = (g.arw_deg_per_sqrt_h / 60.0) ** 2 / window_s          # (°/s)² of one window
    in_run_dps = float(np.sqrt(max(var_win - arw_var, 0.0)))
    to_dph = DEG_RAD / DPH_RPS
    return EquivalentGyro(spec.name, tuple(stages), turn_on_dps * to_dph, in_run_dps * to_dph,
                          eq.correlation_time_s, g.arw_deg_per_sqrt_h, eq.seeds, eq.duration_s)


@lru_cache(maxsize=32)
def _measured(name: str, stages: tuple[str, ...]) -> EquivalentGyro:
    return measure_equivalent_gyro(load_mems(name), stages)


def equivalent_imu_spec(preset: str | MemsSpec, stages: tuple[str, ...]) -> ImuSpec:
    """The SINS preset (:class:`ImuSpec`, datasheet units) of a MEMS preset after ``stages``.

    Parameters
    ----------
    preset : MEMS preset name or path (measurements of names are cached), or a spec
    stages : compensation stages without ``none`` (any order; canonical order is used)
    """
    stages = tuple(s for s in parse_stages(["none", *stages]) if s != "none")
    if isinstance(preset, MemsSpec):
        spec, eqg = preset, measure_equivalent_gyro(preset, stages)
    else:
        spec, eqg = load_mems(preset), _measured(str(preset), stages)
    label = "+".join([spec.name, *stages]) if stages else spec.name
    g = spec.gyro
    source = (f"MEMS gyro {spec.name} after compensation stages "
              f"[{', '.join(stages) or 'none'}]: residual measured by fms_testbed.sensors.mems."
              f"equivalent over {eqg.seeds} static warm-up switch-ons of {eqg.duration_s:g} s "
              f"(turn-on {eqg.bias_turn_on_deg_per_h:.4g} deg/h, in-run "
              f"{eqg.bias_instability_deg_per_h:.4g} deg/h, tau {eqg.correlation_time_s:g} s); "
              f"ARW, scale factor, misalignment and accelerometers from the preset. "
              f"Preset sources: {spec.source}")
    return ImuSpec.model_validate({
        "name": label, "grade": spec.grade, "source": source,
        "gyro": {"arw_deg_per_sqrt_h": g.arw_deg_per_sqrt_h,
                 "bias_turn_on_deg_per_h": eqg.bias_turn_on_deg_per_h,
                 "bias_instability_deg_per_h": eqg.bias_instability_deg_per_h,
                 "bias_correlation_time_s": eqg.correlation_time_s,
                 "scale_factor_ppm": g.scale_factor_ppm,
                 "misalignment_mrad": g.misalignment_mrad},
        "accelerometer": spec.accelerometer.model_dump()})


def equivalent_imu(preset: str | MemsSpec, stages: tuple[str, ...] = ()) -> ImuModel:
    """The SINS :class:`ImuModel` (SI arrays) of a MEMS preset after ``stages`` (module doc)."""
    return imu_model(equivalent_imu_spec(preset, stages))
