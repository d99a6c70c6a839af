"""Thresholds of seed 001's identification (one frozen table, SI units)."""

from __future__ import annotations

from dataclasses import dataclass

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import G0_MPS2


@dataclass(frozen=True)
class FdiTuning:
    """Thresholds of the two stages and of the fault-tolerant estimator.

    k_pair : stage 1 ε_N in σ of each channel difference of two units' outputs
    persist_s : a pair must disagree this long before ν_ij = 1, s
    k_est : stage 2 ε_K in σ of the differences among (Z_i, Ẑ, Ẑ_p)
    stage2_persist_s : stage 2 must name a unit this long before it is excluded, s
    predict_s : horizon of the estimator's prediction Ẑ_p, s
    window_s : stage-2 innovation window, s;  alpha : its false-alarm probability per test
    innovation_scale : the window test fails when Σ NIS > innovation_scale × χ²_{1−α}(Σ dof)
        (the innovations are not white: GNSS Markov errors, unmodelled sensor errors)
    sensor_test : the sensor-level statistic: ``"window"`` (window-mean difference against
        ``k_sensor`` σ) or ``"cusum"`` (Page's CUSUM against ``cusum_h``)
    k_sensor : sensor-level step threshold in σ of the window-mean difference
    cusum_h : CUSUM threshold (log-likelihood ratio, dimensionless)
    cusum_kappa : the CUSUM's manoeuvre bias bound, in σ of the declared scale-factor and
        misalignment difference times the change of the measured force or rate (dimensionless)
    cusum_freeze : while a pair's CUSUM is above ``cusum_freeze`` × ``cusum_h`` on some axis of
        a group its reference (regression) is held at its last value (dimensionless; ``inf``,
        the default: never held — a held reference has no release rule yet and its fault-free
        statistic runs away, so ``cusum_h`` is calibrated without it)
    cusum_accel_mps2, cusum_gyro_rps : the CUSUM's design change Δ, m/s² and rad/s
    accel_window_s, gyro_window_s : short windows of the sensor-level step test, s
    reference_s : the reference window before the short one, s
    k_residual : the fault-tolerant estimator's ε_i = k_residual √S_ii for |y_i − ŷ_i| ≤ ε_i
    baro_fails, baro_window_s : a unit's baro channel is excluded (its gain row zeroed for
        good) after ``baro_fails`` failed residual tests within ``baro_window_s`` s
    switch_noise : adaptive variant — a switched-off component's artificial noise variance
        ζ, as a multiple of its nominal R_ii (dimensionless)
    diverge_gamma : divergence test νᵀν > γ tr(S) (seed 001's covariance-trace check)
    diverge_count : consecutive divergent updates before the filter is reset

    Every threshold is a multiple of a σ derived from the declared unit performance: the
    filters' covariance for the output and estimator tests, the declared VRW/ARW densities and
    scale-factor/misalignment variances for the sensor-level test. The defaults of
    ``k_pair``, ``k_sensor``, ``k_est``, ``innovation_scale`` and ``cusum_h`` (with
    ``sensor_test="cusum"``) are calibrated: each is the
    value a Gumbel fit to the per-hour maxima of its statistic on the calibration set of
    fault-free flights exceeds at 3e-4 per hour, rounded up (``bench/bench_detection.py
    calibrate``, docs/navigation.md "Thresholds").
    """

    k_pair: float = 4.3
    persist_s: float = 1.0
    k_est: float = 3.0
    stage2_persist_s: float = 2.0
    predict_s: float = 2.0
    window_s: float = 10.0
    alpha: float = 1e-6
    innovation_scale: float = 1.1
    sensor_test: str = "window"
    k_sensor: float = 6.3
    cusum_h: float = 20.1
    cusum_kappa: float = 2.0
    cusum_freeze: float = float("inf")
    cusum_accel_mps2: float = 0.75e-3 * G0_MPS2
    cusum_gyro_rps: float = 22.0 * 3.141592653589793 / 180.0 / 3600.0
    accel_window_s: float = 1.0
    gyro_window_s: float = 10.0
    reference_s: float = 60.0
    k_residual: float = 5.0
    baro_fails: int = 5
    baro_window_s: float = 10.0
    switch_noise: float = 1e4
    diverge_gamma: float = 25.0
    diverge_count: int = 10


    def __post_init__(self):
        if self.sensor_test not in ("window", "cusum"):
            raise ConfigError(f"fdi.sensor_test: {self.sensor_test!r}; choose window or cusum")


__all__ = ["FdiTuning"]
