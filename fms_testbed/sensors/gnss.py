"""GNSS receiver, the truth side: position/velocity fixes = truth ⊕ errors, at a rate, late.

Error model per ENU axis (seed 004's GNSS Markov states, plus white noise)::

    δp = m_p + w_p (+ fault),   m_p' = -m_p/τ_p + η,  E[m_p²] = σ_mp²,   w_p ~ N(0, σ_wp²)
    δv = m_v + w_v,             m_v' = -m_v/τ_v + η,  E[m_v²] = σ_mv²,   w_v ~ N(0, σ_wv²)

The Markov states are propagated exactly between epochs, m_k = e^{-Δt/τ} m_{k-1} + √(σ²(1 -
e^{-2Δt/τ})) N. A fix is taken every ``1/rate_hz`` s (time of validity ``t_s``) and delivered
``latency_s`` later. The fix is of the antenna, at ``antenna_lever_arm_m`` (body axes, x forward,
y right, z down, m) from the CG: p_ant = p_cg + C_b^n l, v_ant = v_cg + C_b^n (ω_eb × l). A
time-tag error δt (``time_tag_error_s``: the receiver stamps a fix t that is valid at t - δt)
adds -v δt to the position (first order in δt). Each fix carries the σ the receiver reports
for it (``pos_sigma_m``, ``vel_sigma_mps``: its white part times ``reported_sigma_scale``; a
filter's R). Faults (truth side, the filter is not told): outages (no fix), outlier bursts
(extra white position noise of ``sigma_m``, the "outliers even with RAIM" of seed 000), and slow
ramps (a position error growing at ``rate_mps`` per ENU axis from ``start_s`` — the classic
integrity test). Every random draw comes from the receiver's own seeded generator, in epoch order,
so a fault does not change the draws of the fault-free part of a run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fms_testbed.core.earth import radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState
from fms_testbed.sensors.imu.kinematics import euler_to_quat, qrot


@dataclass(frozen=True)
class Interval:
    """A time interval [start_s, end_s) of simulated time, s (``end_s`` inf: to the end)."""

    start_s: float
    end_s: float = math.inf

    def __contains__(self, t_s: float) -> bool:
        return self.start_s <= t_s < self.end_s


@dataclass(frozen=True)
class OutlierBurst:
    """Extra white position noise ``sigma_m`` (m, per axis) on the fixes inside ``during``."""

    during: Interval
    sigma_m: float


@dataclass(frozen=True)
class Ramp:
    """Position error growing at ``rate_mps`` (ENU, m/s) from ``during.start_s`` until its end
    (then it stays at the value reached)."""

    during: Interval
    rate_mps: tuple[float, float, float]

    def offset_m(self, t_s: float) -> np.ndarray:
        """Ramp position error at ``t_s`` (s), ENU m."""
        if t_s < self.during.start_s:
            return np.zeros(3)
        return np.asarray(self.rate_mps) * (min(t_s, self.during.end_s) - self.during.start_s)


@dataclass(frozen=True)
class GnssSpec:
    """GNSS error model and timing, SI, per ENU axis (1σ).

    pos_markov_sigma_m, vel_markov_sigma_mps : stationary σ of the Markov errors, m, m/s
    pos_markov_tau_s, vel_markov_tau_s : their correlation times, s
    pos_white_sigma_m, vel_white_sigma_mps : white noise per fix, m, m/s
    rate_hz : fix rate, Hz;  latency_s : delivery delay after the time of validity, s
    outages, outliers, ramps : truth-side faults (see the module docstring)
    antenna_lever_arm_m : antenna position from the CG, body axes (x fwd, y right, z down), m
    time_tag_error_s : truth side: the fixes are valid ``time_tag_error_s`` before their stamp, s
    time_tag_sigma_s : declared 1σ of the time-tag error (what a filter allows for), s
    reported_sigma_scale : the receiver reports its white σ times this (1: honestly)
    """

    pos_markov_sigma_m: tuple[float, float, float] = (1.0, 1.0, 2.0)
    pos_markov_tau_s: float = 300.0
    pos_white_sigma_m: tuple[float, float, float] = (0.5, 0.5, 1.0)
    vel_markov_sigma_mps: tuple[float, float, float] = (0.02, 0.02, 0.04)
    vel_markov_tau_s: float = 60.0
    vel_white_sigma_mps: tuple[float, float, float] = (0.05, 0.05, 0.1)
    rate_hz: float = 1.0
    latency_s: float = 0.1
    outages: tuple[Interval, ...] = ()
    outliers: tuple[OutlierBurst, ...] = ()
    ramps: tuple[Ramp, ...] = ()
    antenna_lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    time_tag_error_s: float = 0.0
    time_tag_sigma_s: float = 0.0
    reported_sigma_scale: float = 1.0

    def __post_init__(self):
        for name in ("pos_markov_sigma_m", "pos_white_sigma_m", "vel_markov_sigma_mps",
                     "vel_white_sigma_mps"):
            v = getattr(self, name)
            if len(v) != 3 or not all(math.isfinite(x) and x >= 0 for x in v):
                raise ConfigError(f"navigation.gnss.{name}: three finite values >= 0 (E, N, U)")
        for name in ("pos_markov_tau_s", "vel_markov_tau_s", "rate_hz"):
            if not getattr(self, name) > 0:
                raise ConfigError(f"navigation.gnss.{name}: must be > 0")
        if not 0 <= self.latency_s < 1.0 / self.rate_hz:
            raise ConfigError(f"navigation.gnss.latency_s: must be >= 0 and below the fix "
                              f"period {1.0 / self.rate_hz:g} s, got {self.latency_s:g}")

    @property
    def markov_sigma(self) -> np.ndarray:
        """(6,) stationary σ of the Markov states [m_p E N U, m_v E N U], m and m/s."""
        return np.array(self.pos_markov_sigma_m + self.vel_markov_sigma_mps, float)

    @property
    def markov_tau_s(self) -> np.ndarray:
        """(6,) correlation times of the Markov states, s."""
        return np.array([self.pos_markov_tau_s] * 3 + [self.vel_markov_tau_s] * 3, float)

    @property
    def white_sigma(self) -> np.ndarray:
        """(6,) white-noise σ per fix [position m, velocity m/s]."""
        return np.array(self.pos_white_sigma_m + self.vel_white_sigma_mps, float)


@dataclass(frozen=True)
class GnssFix:
    """One fix as the receiver outputs it, and (truth side, for logs and tests) its error.

    t_s : time of validity, s;  t_delivered_s : when the navigation system gets it, s
    lat_rad, lon_rad, alt_m : position;  v_enu_mps : (3,) velocity, m/s
    err_enu_m, err_v_enu_mps : (3,) true fix error (fix - truth at the antenna), m, m/s
    markov : (6,) the Markov part of that error (what a filter's GNSS states estimate)
    pos_sigma_m, vel_sigma_mps : (3,) the 1σ the receiver reports (ENU), m, m/s
    """

    t_s: float
    t_delivered_s: float
    lat_rad: float
    lon_rad: float
    alt_m: float
    v_enu_mps: np.ndarray
    err_enu_m: np.ndarray
    err_v_enu_mps: np.ndarray
    markov: np.ndarray = field(repr=False)
    pos_sigma_m: np.ndarray | None = None
    vel_sigma_mps: np.ndarray | None = None


def antenna_offset_enu(truth: AircraftState, lever_arm_m) -> tuple[np.ndarray, np.ndarray]:
    """(C_b^n l, C_b^n (ω_eb × l)) in ENU, m and m/s: the antenna's position and velocity
    relative to the CG for the lever arm ``lever_arm_m`` (3,) m in body axes (x fwd, y right,
    z down), at the true attitude and body rate of ``truth``."""
    lv = np.asarray(lever_arm_m, float)
    if not np.any(lv):
        return np.zeros(3), np.zeros(3)
    q = euler_to_quat(truth.roll_rad, truth.pitch_rad, truth.heading_rad)
    w = np.array([truth.p_rps, truth.q_rps, truth.r_rps])
    d, dv = qrot(q, tuple(lv)), qrot(q, tuple(np.cross(w, lv)))
    return np.array([d[1], d[0], -d[2]]), np.array([dv[1], dv[0], -dv[2]])


class GnssReceiver:
    """A GNSS receiver on the truth side: call :meth:`update` with every true state; it returns
    the fixes delivered by then (time of validity + latency), oldest first.

    Parameters
    ----------
    spec : error model, timing and faults
    seed : seed of the receiver's error realisation
    """

    def __init__(self, spec: GnssSpec, seed: int = 0):
        self.spec = spec
        self.rng = np.random.default_rng(seed)
        self._sigma = spec.markov_sigma
        self._tau = spec.markov_tau_s
        self._white = spec.white_sigma
        self._reported = spec.white_sigma * spec.reported_sigma_scale
        self.markov = self._sigma * self.rng.standard_normal(6)    # stationary start
        self._t_markov: float | None = None
        self._next_epoch_s: float | None = None
        self._queue: list[GnssFix] = []
        self.period_s = 1.0 / spec.rate_hz
        self.last_epoch_s: float | None = None      # time of the last fix taken (outage or not)

    def available(self, t_s: float) -> bool:
        """True when a fix taken at ``t_s`` (s) would be output (no outage)."""
        return not any(t_s in o for o in self.spec.outages)

    def _propagate_markov(self, t_s: float) -> None:
        if self._t_markov is not None:
            dt = t_s - self._t_markov
            a = np.exp(-dt / self._tau)
            self.markov = a * self.markov + self._sigma * np.sqrt(1.0 - a * a) * \
                self.rng.standard_normal(6)
        self._t_markov = t_s

    def _fix(self, truth: AircraftState) -> GnssFix:
        t = truth.t_s
        self._propagate_markov(t)
        white = self._white * self.rng.standard_normal(6)
        extra = self.rng.standard_normal(3)     # drawn every epoch: faults keep the other draws
        err_p = self.markov[:3] + white[:3]
        for b in self.spec.outliers:
            if t in b.during:
                err_p = err_p + b.sigma_m * extra
        for r in self.spec.ramps:
            err_p = err_p + r.offset_m(t)
        err_v = self.markov[3:] + white[3:]
        p_ant, v_ant = antenna_offset_enu(truth, self.spec.antenna_lever_arm_m)
        v_true = np.asarray(truth.v_enu_mps, float) + v_ant
        err_p = err_p + p_ant - v_true * self.spec.time_tag_error_s
        rm, rn = radii_m(truth.lat_rad)
        h = truth.alt_m
        return GnssFix(t, t + self.spec.latency_s, truth.lat_rad + err_p[1] / (rm + h),
                       truth.lon_rad + err_p[0] / ((rn + h) * math.cos(truth.lat_rad)),
                       h + err_p[2], v_true + err_v, err_p - p_ant, err_v,
                       self.markov.copy(), self._reported[:3].copy(), self._reported[3:].copy())

    def update(self, truth: AircraftState) -> list[GnssFix]:
        """Take a fix when an epoch is due at ``truth.t_s`` and return the fixes delivered by
        ``truth.t_s`` (s). The first epoch is the first call's time; epochs then follow every
        ``1/rate_hz`` s (a fix is taken at the first true state at or after its epoch)."""
        t = truth.t_s
        if self._next_epoch_s is None:
            self._next_epoch_s = t
        if t >= self._next_epoch_s - 1e-9:
            self.last_epoch_s = t
            fix = self._fix(truth)
            if self.available(t):
                self._queue.append(fix)
            while self._next_epoch_s <= t + 1e-9:
                self._next_epoch_s += self.period_s
        out = [f for f in self._queue if f.t_delivered_s <= t + 1e-9]
        if out:
            self._queue = self._queue[len(out):]
        return out


__all__ = ["antenna_offset_enu", "GnssFix", "GnssReceiver", "GnssSpec", "Interval", "OutlierBurst", "Ramp"]
