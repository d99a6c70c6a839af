"""The scenario's ``navigation:`` block: which navigation source guidance flies on, with that
source's own keys — a discriminated union on ``source``, so a key another source would take is
an error, not silently ignored.

A new source adds its block here (a model with ``source: Literal["name"]``, added to
:data:`NavigationBlock`) and its class in :mod:`fms_testbed.navigation` (the registry).

Seed precedence: ``navigation.seed``, when given, seeds the navigation errors; otherwise the run's
seed (``--seed``) does. The summary reports both (``seed``, ``navigation_seed``).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, model_validator

_FINITE = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


class TruthBlock(BaseModel):
    """``navigation: {source: truth}`` — the solution is the true state."""

    model_config = _FINITE
    source: Literal["truth"] = "truth"


class SinsBlock(BaseModel):
    """``navigation: {source: sins, imu: PRESET, ...}`` — truth ⊕ the 33-state SINS error model
    (free inertial, baro-damped vertical channel by default)."""

    model_config = _FINITE
    source: Literal["sins"]
    imu: str | dict[str, Any] = Field(
        description="IMU preset name (fms_testbed/data/imu/), a .yaml path, or an inline mapping")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="seed of the error realisation (default: the run's seed)")
    method: Literal["picard", "vanloan", "trapezoid"] = Field(
        "picard", description="discretisation of the error model (Babich: Picard series)")
    dt_s: Annotated[float, Field(gt=0, le=10)] = Field(
        0.1, description="nominal navigation step, s")
    vertical: Literal["baro", "free"] = Field(
        "baro", description="vertical channel: baro-damped, or free (unstable)")
    baro_tau_s: Annotated[float, Field(gt=0, le=3600)] = Field(
        60.0, description="baro loop time constant, s")
    tol: Annotated[float, Field(gt=0, lt=1e-3)] = Field(
        1e-12, description="adaptive Picard tolerance (relative)")
    truth_model: Literal["linear", "strapdown"] = Field(
        "linear", description="truth ⊕ the 33-state model, or a strapdown mechanisation of a "
                              "simulated IMU (vertical baro-aided or free)")
    alignment: Literal["stationary", "none", "gnss_heading"] = Field(
        "stationary", description="initial attitude errors from a stationary self-alignment, "
                                  "or independent")
    matrices_dt_s: Annotated[float, Field(ge=0, le=60)] = Field(
        0.0, description="reuse Φ_k, S_k this long before rebuilding F, s (0: every step)")
    matrices_rotation_deg: Annotated[float, Field(gt=0)] = Field(
        1e9, description="... and only while the body has turned less than this since they "
                         "were built, deg (default: no limit)")


class IntervalBlock(BaseModel):
    """A time interval of simulated time, s (``end_s`` omitted: to the end of the flight)."""

    model_config = _FINITE
    start_s: Annotated[float, Field(ge=0)] = Field(description="start, s")
    end_s: Annotated[float, Field(gt=0)] | None = Field(None, description="end, s")

    @model_validator(mode="after")
    def _order(self):
        if self.end_s is not None and self.end_s <= self.start_s:
            raise ValueError(f"end_s {self.end_s:g} s must be after start_s {self.start_s:g} s")
        return self


class OutlierBlock(IntervalBlock):
    """GNSS outlier burst: extra white position noise on the fixes inside the interval."""

    sigma_m: Annotated[float, Field(gt=0, le=1e5)] = Field(
        description="σ of the extra position noise per axis, m")


class RampBlock(IntervalBlock):
    """Slow GNSS ramp fault: a position error growing at ``rate_mps`` (E, N, U) from ``start_s``."""

    rate_mps: Annotated[list[Annotated[float, Field(ge=-100, le=100)]],
                        Field(min_length=3, max_length=3)] = Field(
        description="ramp rate E, N, U, m/s")


_Sig3 = Annotated[list[Annotated[float, Field(ge=0, le=1e4)]], Field(min_length=3, max_length=3)]
"""Three values E, N, U (a YAML list)."""


class GnssBlock(BaseModel):
    """GNSS receiver: error model per ENU axis (1σ), timing, and truth-side faults."""

    model_config = _FINITE
    rate_hz: Annotated[float, Field(gt=0, le=50)] = Field(1.0, description="fix rate, Hz")
    latency_s: Annotated[float, Field(ge=0, le=5)] = Field(
        0.1, description="delivery delay after the time of validity, s (< the fix period)")
    pos_markov_sigma_m: _Sig3 = Field([1.0, 1.0, 2.0], description="position Markov σ E, N, U, m")
    pos_markov_tau_s: Annotated[float, Field(ge=1, le=1e5)] = Field(
        300.0, description="position Markov correlation time, s")
    pos_white_sigma_m: _Sig3 = Field([0.5, 0.5, 1.0], description="position white σ E, N, U, m")
    vel_markov_sigma_mps: _Sig3 = Field([0.02, 0.02, 0.04],
                                        description="velocity Markov σ E, N, U, m/s")
    vel_markov_tau_s: Annotated[float, Field(ge=1, le=1e5)] = Field(
        60.0, description="velocity Markov correlation time, s")
    vel_white_sigma_mps: _Sig3 = Field([0.05, 0.05, 0.1],
                                       description="velocity white σ E, N, U, m/s")
    outages: list[IntervalBlock] = Field(default_factory=list, description="no fix inside these")
    outliers: list[OutlierBlock] = Field(default_factory=list, description="outlier bursts")
    ramps: list[RampBlock] = Field(default_factory=list, description="slow ramp faults")
    antenna_lever_arm_m: Annotated[list[Annotated[float, Field(ge=-100, le=100)]],
                                   Field(min_length=3, max_length=3)] = Field(
        [0.0, 0.0, 0.0], description="antenna position from the CG, body x fwd/y right/z down, m")
    time_tag_error_s: Annotated[float, Field(ge=-1, le=1)] = Field(
        0.0, description="truth side: fixes are valid this long before their time stamp, s")
    time_tag_sigma_s: Annotated[float, Field(ge=0, le=1)] = Field(
        0.0, description="declared 1σ of the time-tag error (the filter's R allows for it), s")

    @model_validator(mode="after")
    def _latency(self):
        if self.latency_s >= 1.0 / self.rate_hz:
            raise ValueError(f"latency_s {self.latency_s:g} s must be below the fix period "
                             f"{1.0 / self.rate_hz:g} s")
        return self


class BaroBlock(BaseModel):
    """Baro altimeter: Gauss-Markov bias plus white noise (1σ)."""

    model_config = _FINITE
    markov_sigma_m: Annotated[float, Field(ge=0, le=1000)] = Field(5.0, description="bias σ, m")
    markov_tau_s: Annotated[float, Field(ge=1, le=1e6)] = Field(
        1800.0, description="bias correlation time, s")
    white_sigma_m: Annotated[float, Field(gt=0, le=100)] = Field(0.5, description="white σ, m")
    rate_hz: Annotated[float, Field(gt=0, le=50)] = Field(1.0, description="reading rate, Hz")
    failed_from_s: Annotated[float, Field(ge=0)] | None = Field(
        None, description="the output freezes from this time (stuck static port), s")


class FilterBlock(BaseModel):
    """INS/GNSS filter settings."""

    model_config = _FINITE
    gate_sigma: Annotated[float, Field(gt=0, le=100)] = Field(
        5.0, description="innovation gate per component, σ")
    unmodelled_tau_s: Annotated[float, Field(ge=0, le=1e5)] = Field(
        20.0, description="correlation time of the noise standing in for the scale factors "
                           "and misalignments the filter does not carry, s")
    method: Literal["picard", "vanloan"] = Field("picard", description="discretisation")
    predict_interval_s: Annotated[float, Field(ge=0, le=10)] = Field(
        1.0, description="longest interval the covariance is propagated over at once (F "
                         "averaged over it), s; a measurement or a GNSS epoch ends one too; "
                         "0: every navigation step")
    reset_after: Annotated[int, Field(ge=0, le=1000)] = Field(
        10, description="consecutive gate rejections of a measurement after which the "
                        "covariance of the states it observes is reset (0: never)")
    predict_rotation_deg: Annotated[float, Field(gt=0, le=90)] = Field(
        1.0, description="an interval also ends once the body has turned this much in it, deg")


class InsGnssBlock(BaseModel):
    """``navigation: {source: ins_gnss, imu: PRESET, ...}`` — INS(s) from the 33-state error
    model, a GNSS receiver and a baro on the truth side, and a loosely coupled error-state
    Kalman filter per INS (15 INS + 6 GNSS Markov + 1 baro states)."""

    model_config = _FINITE
    source: Literal["ins_gnss"]
    imu: str | dict[str, Any] = Field(
        description="IMU preset name (fms_testbed/data/imu/), a .yaml path, or an inline mapping")
    n_ins: Annotated[int, Field(ge=1, le=3)] = Field(1, description="number of INS units")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="seed of every error realisation (default: the run's seed)")
    gnss: GnssBlock = Field(default_factory=GnssBlock, description="GNSS receiver")
    baro: BaroBlock | None = Field(default_factory=BaroBlock,
                                   description="baro altimeter (null: none)")
    filter: FilterBlock = Field(default_factory=FilterBlock, description="filter settings")
    truth_model: Literal["strapdown", "linear"] = Field(
        "strapdown", description="truth side of the INS units: strapdown mechanisation of a "
                                 "simulated IMU, or truth ⊕ the linear 33-state error model")
    alignment: Literal["stationary", "gnss_heading"] = Field(
        "stationary", description="strapdown units' initial alignment (levelling + "
                                  "gyrocompassing at rest, or in-air levelling + GNSS heading)")
    adaptive: bool = Field(
        False, description="seed 001's adaptive variant of the fault-tolerant estimator: a "
                           "component failing its residual test switched off (artificial noise)"
                           ", divergence reset")
    record_sensors: bool = Field(
        False, description="write the flight's IMU/GNSS/init files (the nav-replay format) "
                           "into the run folder's sensors/")
    matrices_dt_s: Annotated[float, Field(ge=0, le=10)] = Field(
        1.0, description="the INS units' error model (truth side) reuses its Φ_k, S_k this long, "
                         "s (0: every step) ...")
    matrices_rotation_deg: Annotated[float, Field(gt=0, le=90)] = Field(
        1.0, description="... while the body has turned less than this since they were built, "
                         "deg")
    alert_delay_s: Annotated[float, Field(ge=0, le=30)] | None = Field(
        None, description="ANP > RNP must persist this long before the RNP alert, s (default: "
                          "2 s, within the 10 s time to alert of terminal/approach)")


_Ang3 = Annotated[list[Annotated[float, Field(ge=0, le=90)]], Field(min_length=3, max_length=3)]
"""Three values roll, pitch, heading (a YAML list)."""
_Val3 = Annotated[list[Annotated[float, Field(ge=-360, le=360)]], Field(min_length=3, max_length=3)]


class ReferenceErrorBlock(BaseModel):
    """Error model of the attitude reference under test (roll, pitch, heading; 1σ): constant
    errors plus drift (seed 004), optional random walks; the injected values are drawn from
    the σ by the seed unless ``bias_deg`` / ``drift_dph`` give them."""

    model_config = _FINITE
    bias_sigma_deg: _Ang3 = Field([0.1, 0.1, 0.5], description="σ of the constant errors, deg")
    drift_sigma_dph: _Ang3 = Field([0.5, 0.5, 1.0], description="σ of the drift rates, deg/h")
    arw_deg_rh: _Ang3 = Field([0.003, 0.003, 0.003],
                              description="angle random walk, deg/√h")
    drift_rw_dph_rh: _Ang3 = Field([0.0, 0.0, 0.0], description="drift random walk, deg/h/√h")
    bias_deg: _Val3 | None = Field(None, description="injected constant errors, deg")
    drift_dph: _Val3 | None = Field(None, description="injected drift rates, deg/h")


class AttitudeReferenceBlock(BaseModel):
    """``navigation: {source: attitude_reference, ...}`` — flight-test mode of seed 004: an
    attitude reference with injected heading/roll/pitch errors resolves an accurate
    accelerometer block; a Kalman filter (15 error states + 6 GNSS Markov states) estimates the
    reference's errors from GNSS position and velocity."""

    model_config = _FINITE
    source: Literal["attitude_reference"]
    imu: str | dict[str, Any] = Field(
        "HG9900", description="accelerometer block: IMU preset, .yaml path or mapping (only its "
                              "accelerometers are used)")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="seed of every error realisation (default: the run's seed)")
    reference: ReferenceErrorBlock = Field(default_factory=ReferenceErrorBlock,
                                           description="the attitude reference's error model")
    gnss: GnssBlock = Field(default_factory=GnssBlock, description="GNSS receiver")
    init_pos_sigma_m: Annotated[float, Field(gt=0, le=1000)] = Field(
        1.0, description="σ of the computer's initial position error per axis, m")
    init_vel_sigma_mps: Annotated[float, Field(gt=0, le=100)] = Field(
        0.05, description="σ of the computer's initial velocity error per axis, m/s")
    gate_sigma: Annotated[float, Field(gt=0, le=100)] = Field(
        5.0, description="innovation gate per component, σ")
    truth_model: Literal["strapdown", "linear"] = Field(
        "strapdown", description="truth side: the accelerometers' measured increments resolved "
                                 "with the reference's angles by a strapdown computer, or "
                                 "truth ⊕ the computer's linear 15-state error model")


NavigationBlock = Annotated[Union[TruthBlock, SinsBlock, InsGnssBlock, AttitudeReferenceBlock],
                            Field(discriminator="source")]
"""The navigation block of a scenario, discriminated by ``source``."""


def with_default_source(raw: Any) -> Any:
    """A navigation mapping without ``source`` means truth."""
    if isinstance(raw, dict) and "source" not in raw:
        return {"source": "truth", **raw}
    return raw


__all__ = ["AttitudeReferenceBlock", "ReferenceErrorBlock", "BaroBlock", "FilterBlock", "GnssBlock", "InsGnssBlock", "NavigationBlock", "SinsBlock",
           "TruthBlock", "with_default_source"]
