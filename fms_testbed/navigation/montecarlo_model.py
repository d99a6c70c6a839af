"""The configuration, faults and results of the Monte-Carlo engine
(:mod:`fms_testbed.navigation.montecarlo`), and each realisation's random stream."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.ins_filter import FilterTuning
from fms_testbed.sensors.baro import BaroSpec
from fms_testbed.sensors.gnss import GnssSpec

BLOCK_STEPS = 100
"""Steps of noise a realisation draws per call of its generator (fixed: part of the stream)."""

N_UNITS = 3
_AXIS = {"x": 0, "y": 1, "z": 2}
_NSE_EDGES_M = np.concatenate([[0.0], np.logspace(-3, 5, 1601)])
"""Histogram bin edges of the horizontal NSE, m (0.5 % wide bins from 1 mm to 100 km)."""

FAULT_KINDS = ("gyro_bias_step", "accel_bias_step", "gyro_drift_scale", "baro_step")
_FAULT_UNIT = {"gyro_bias_step": "deg/h", "accel_bias_step": "ug", "gyro_drift_scale": "x",
               "baro_step": "m"}


@dataclass(frozen=True)
class McFault:
    """A fault injected on the truth side at ``t_s`` (s): ``gyro_bias_step`` (``size`` deg/h on
    ``axis`` of unit ``unit``, 0..2), ``accel_bias_step`` (``size`` µg), ``gyro_drift_scale``
    (the unit's gyro drift × ``size``: an excess (size − 1) × declared σ on every axis and the
    drift's driving noise × size) or ``baro_step`` (the baro's bias steps by ``size`` m; the
    baro is common to the units). GNSS ramps and outlier bursts are :class:`GnssSpec` entries."""

    kind: str
    size: float
    t_s: float
    unit: int = 1
    axis: str = "x"

    def __post_init__(self):
        if self.kind not in FAULT_KINDS:
            raise ConfigError(f"montecarlo fault: kind {self.kind!r}; choose one of "
                              f"{', '.join(FAULT_KINDS)}")
        if self.axis not in _AXIS:
            raise ConfigError(f"montecarlo fault: axis {self.axis!r}; choose x, y or z")
        if self.unit not in range(N_UNITS):
            raise ConfigError(f"montecarlo fault: unit {self.unit + 1} (ins1..ins3)")

    @property
    def label(self) -> str:
        """e.g. ``gyro_bias_step z 20 deg/h``."""
        return f"{self.kind} {self.axis} {self.size:g} {_FAULT_UNIT[self.kind]}"

    def delta(self) -> tuple[int, float]:
        """(state index, step in state units: rad/s or m/s²) of a bias step."""
        if self.kind == "gyro_bias_step":
            return 12 + _AXIS[self.axis], self.size * DPH_RPS
        return 9 + _AXIS[self.axis], self.size * 1e-6 * G0_MPS2


@dataclass(frozen=True)
class McConfig:
    """The models of a Monte-Carlo run (SI).

    imu : IMU preset of the three units;  gnss, baro : sensor models (``gnss.outages`` are the
    outages of every realisation);  tuning, fdi : filter and identification settings
    rnp_m : RNP for the containment statistics, m
    component_channels : seed 001's fault-tolerant correction per measured component instead of
        the all-or-nothing gate: a GNSS component failing |ν_i| ≤ k_residual √S_ii has its gain
        column zeroed, and with the baro named failed a failed vertical component also zeroes
        the gain rows of the vertical channel (ẑ_H, Ŵ_Z held, :func:`~.montecarlo._channel_update`)
    """

    imu: str = "STIM300"
    gnss: GnssSpec = GnssSpec()
    baro: BaroSpec = BaroSpec()
    tuning: FilterTuning = FilterTuning()
    fdi: FdiTuning = FdiTuning()
    rnp_m: float = 555.6
    component_channels: bool = False


@dataclass
class McResult:
    """Per-realisation outcomes of a batch (arrays over realisations) and pooled histograms.

    index : (R,) realisation indices;  t_detect_s, t_isolate_s, t_exclude_s : first detection (R,),
    isolation and exclusion (R, 3) times, s (NaN never);  nse_max_m : (R,) max horizontal NSE of
    the output, m;  nse_outage_max_m : (R,) its max during GNSS outages (NaN: none), m;
    hist_gnss, hist_coast : pooled sample counts of the horizontal NSE per bin of
    :data:`_NSE_EDGES_M` with a fix used recently / coasting;  outage_samples, outage_nse_in,
    outage_anp_in : counts of outage samples, of those with NSE ≤ RNP and with ANP ≤ RNP;
    anp_max_outage_m : (R,) max ANP in outages, m;  duration_s : simulated time per realisation;
    wall_s : wall time of the batch, s;  n_cov_groups_max : most covariance groups held at once;
    t_gnss_s, t_baro_s : (R,) time the GNSS / baro was named failed (NaN never), s;
    hist_vote : pooled NSE counts of the majority-voting baseline (raw outputs voted);
    vote_in : (R, 3) fraction of samples after the fault (all samples without one) each unit
    was in the vote;  stat_max : (R, 4) largest test statistic of the fault-free run, in σ —
    stage-1 output pair |Δ|/σ, sensor-level |z|, stage-2 |Z_i − Ẑ|/σ, innovation window
    Σ NIS / χ²_{1−α} quantile (for calibrating the thresholds)
    """

    index: np.ndarray
    t_detect_s: np.ndarray
    t_isolate_s: np.ndarray
    t_exclude_s: np.ndarray
    nse_max_m: np.ndarray
    nse_outage_max_m: np.ndarray
    anp_max_outage_m: np.ndarray
    hist_gnss: np.ndarray
    hist_coast: np.ndarray
    outage_samples: int = 0
    outage_nse_in: int = 0
    outage_anp_in: int = 0
    duration_s: float = 0.0
    wall_s: float = 0.0
    n_cov_groups_max: int = 1
    fault: McFault | None = None
    t_gnss_s: np.ndarray | None = None
    t_baro_s: np.ndarray | None = None
    hist_vote: np.ndarray | None = None
    vote_in: np.ndarray | None = None
    stat_max: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    _PER_REAL = ("index", "t_detect_s", "t_isolate_s", "t_exclude_s", "nse_max_m",
                 "nse_outage_max_m", "anp_max_outage_m", "t_gnss_s", "t_baro_s", "vote_in",
                 "stat_max")
    _SUMMED = ("hist_gnss", "hist_coast", "hist_vote", "outage_samples", "outage_nse_in",
               "outage_anp_in", "wall_s")

    @staticmethod
    def concat(parts: list["McResult"]) -> "McResult":
        """Join batches of the same configuration (histograms and counts summed)."""
        a = parts[0]
        kw = {n: np.concatenate([getattr(p, n) for p in parts]) for n in McResult._PER_REAL}
        kw.update({n: sum(getattr(p, n) for p in parts) for n in McResult._SUMMED})
        return McResult(**kw, duration_s=a.duration_s, fault=a.fault,
                        n_cov_groups_max=max(p.n_cov_groups_max for p in parts))


def percentile_from_hist(hist: np.ndarray, q: float) -> float:
    """The ``q`` (0..100) percentile of pooled samples from a histogram over
    :data:`_NSE_EDGES_M` (upper edge of the bin reaching it: ≤ 0.5 % high), m; NaN if empty."""
    n = hist.sum()
    if n == 0:
        return math.nan
    k = int(np.searchsorted(np.cumsum(hist), q / 100.0 * n))
    return float(_NSE_EDGES_M[min(k + 1, len(_NSE_EDGES_M) - 1)])


def realisation_rng(seed: int, index: int) -> np.random.Generator:
    """Realisation ``index``'s generator: ``default_rng(SeedSequence([seed, index]))``."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(index)]))


__all__ = ["BLOCK_STEPS", "FAULT_KINDS", "McConfig", "McFault", "McResult", "N_UNITS",
           "percentile_from_hist", "realisation_rng"]
