"""Two-stage fault identification over redundant INS units (seed 001) and the majority-voting
baseline.

Stage 1 compares the units pairwise twice: at sensor level (:class:`SensorComparator`, seed
001's "duplicate same-type sources": a step in the difference of two units' raw accelerometer or
gyro outputs) and at output level (below). Each unit i gives a comparison vector y_i (position E, N, U m relative to a common point,
velocity E, N, U m/s, roll, pitch, heading rad — its filter-corrected output) and per-channel
σ_i from its filter's covariance.

Stage 1 (fast, pairwise): ν_ij = 1 when some channel of y_i - y_j exceeds
ε_N = k_pair √(σ_i² + σ_j²) for ``persist_s``; for three units the majority table names the
failed unit::

    ν12 ν13 ν23 → (1 1 0) unit 1,  (1 0 1) unit 2,  (0 1 1) unit 3,  (0 0 0) none

Stage 2 (the estimator): a candidate is confirmed when its own filter's GNSS innovations fail a
windowed χ² test (sum of NIS over ``window_s`` against its 1 - ``alpha`` quantile), or when it
disagrees with the mean of the other units beyond k_est √(σ_i² + σ_others²) (the prediction
check). A confirmed unit is excluded and the output is reconfigured on the others. When stage 1
cannot name a unit (two units left, or every pair disagreeing) stage 2 alone decides, if exactly
one unit fails it.

Majority voting (the baseline, Zaitseva's foil): the mean of the units the majority table does
not flag at this instant — no persistence, no estimator check, no memory; a unit that stays
inside the pairwise thresholds is averaged in however wrong its sensors are.

The per-step parts (the pair test, :func:`channel_sigmas`, the sensor comparator's running
sums and z test) are compiled with numba and take the numpy statement's operations in its order,
so their numbers are bitwise those of the numpy code they replace.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from scipy.stats import chi2

MAJORITY = {(1, 1, 0): 0, (1, 0, 1): 1, (0, 1, 1): 2}
"""Seed 001's table for three units: (ν12, ν13, ν23) → index of the failed unit."""

PAIRS = ((0, 1), (0, 2), (1, 2))

_F8 = np.dtype(np.float64)
_TWO_PI = 2 * math.pi
_BITS = tuple((b & 1, (b >> 1) & 1, (b >> 2) & 1) for b in range(8))   # bit k: ν of PAIRS[k]
_BAD = tuple(MAJORITY.get(nu) for nu in _BITS)
_VOTE = tuple(tuple(i for i in range(3) if i != bad) for bad in _BAD)
_ALL9 = np.ones(9, bool)


@dataclass(frozen=True)
class FdiTuning:
    """Thresholds of the two stages.

    k_pair : stage-1 threshold in σ of each channel difference
    persist_s : a pair must disagree this long before ν_ij = 1, s
    k_est : stage-2 prediction threshold in σ
    window_s : stage-2 innovation window, s
    alpha : stage-2 false-alarm probability per test of the innovation window
    isolate_s : a unit named by the majority table this long is excluded without an estimator
        confirmation (a persistent 2-of-3 vote), s
    k_sensor : sensor-level step threshold in σ of the window-mean difference
    accel_window_s, gyro_window_s : short windows of the sensor-level step test, s
    reference_s : the reference window before the short one, s
    k_residual : the fault-tolerant estimator's ε_i = k_residual √S_ii for |y_i - ŷ_i| ≤ ε_i
    baro_fails, baro_window_s : a unit's baro channel is excluded (its gain column zeroed for
        good) after ``baro_fails`` failed residual tests within ``baro_window_s`` s
    k_adapt : adaptive R — a component with |ν_i| > k_adapt √S_ii inflates its R_ii
    adapt_max : largest R inflation factor;  adapt_decay : per-update decay of the inflation
        back towards 1
    diverge_gamma : divergence check νᵀν > γ tr(S) (seed 001's covariance-trace test)

    Every threshold is a multiple of a σ derived from the declared unit performance: the
    filters' covariance (built from the declared IMU/GNSS/baro models) for the output and
    estimator tests, the declared VRW/ARW densities and scale-factor/misalignment variances
    (:func:`declared_sensor_noise`) for the sensor-level test.
    """

    k_pair: float = 6.0
    persist_s: float = 1.0
    k_est: float = 6.0
    window_s: float = 10.0
    alpha: float = 1e-6
    isolate_s: float = 3.0
    k_sensor: float = 6.0
    accel_window_s: float = 1.0
    gyro_window_s: float = 10.0
    reference_s: float = 60.0
    k_residual: float = 5.0
    baro_fails: int = 5
    baro_window_s: float = 10.0
    k_adapt: float = 3.0
    adapt_max: float = 100.0
    adapt_decay: float = 0.9
    diverge_gamma: float = 25.0


@dataclass
class FdiState:
    """Run-time state: which units are in use, pair persistence timers, recent NIS."""

    used: list[bool]
    since: dict = field(default_factory=dict)          # pair → first time it disagreed, s
    nis: list = field(default_factory=list)            # per unit: [(t_s, nis, dim)]


def channel_sigmas(P: np.ndarray, unmodelled_var: tuple[float, float] = (0.0, 0.0),
                   roll_rad: float = 0.0, pitch_rad: float = 0.0,
                   load_factor: float = 1.0) -> np.ndarray:
    """σ of the 9 comparison channels of one unit.

    Position (3), velocity (3) and roll, pitch, heading (ε components as small angles; roll and
    pitch take the larger tilt σ) from the filter covariance ``P``, plus the attitude error the
    filter does not model: the scale factors and misalignments of the 33-state model
    (``unmodelled_var`` = (accelerometer, gyro) scale-factor + 2 × misalignment variance per
    axis, dimensionless: :func:`declared_sensor_noise`).

    - Accelerometers: a misaligned or mis-scaled triad measures the specific force f with an
      error of about √var_a |f|; without those states the filter absorbs it into its tilt,
      so roll and pitch carry an error of √var_a |f|/g.
    - Gyros: a rotation away from the level attitude the unit was aligned in becomes an
      attitude error of about √var_g × |rotation|.

    So, with n = |f|/g the load factor and φ, θ roll and pitch (rad)::

        σ_tilt² = P_tilt + var_a n² + var_g (φ² + θ²),   σ_heading² = P_ψ + var_g (φ² + θ²)

    Without these terms a fault-free STIM300 (1 mrad misalignments) differs from its neighbours
    by 4-5 filter σ in roll in level flight, and 3 of 1,000 fault-free one-hour Monte-Carlo runs
    excluded a healthy unit (``fms-testbed montecarlo --runs 1000 --outage 1800:1920``).
    """
    var_a, var_g = unmodelled_var
    if not (type(P) is np.ndarray and P.dtype == _F8 and P.ndim == 2
            and P.shape[0] >= 9 and P.shape[1] >= 9):
        return _channel_sigmas_np(P, var_a, var_g, roll_rad, pitch_rad, load_factor)
    if var_a > 0.0 or var_g > 0.0:
        # the same operations as _channel_sigmas_np: Python's x ** 2 is libm pow, not x * x
        tilt2 = var_a * load_factor ** 2
        rot2 = var_g * (roll_rad ** 2 + pitch_rad ** 2)
        if not (tilt2 >= 0.0 and rot2 >= 0.0):     # negative variance or NaN: numpy's errors
            return _channel_sigmas_np(P, var_a, var_g, roll_rad, pitch_rad, load_factor)
        return _channel_sigmas_k(P, True, float(tilt2), float(rot2), 2.0)
    return _channel_sigmas_k(P, False, 0.0, 0.0, 2.0)


def _channel_sigmas_np(P, var_a, var_g, roll_rad, pitch_rad, load_factor) -> np.ndarray:
    """:func:`channel_sigmas` in numpy (inputs the compiled kernel does not take)."""
    d = np.sqrt(np.maximum(P.diagonal()[:9], 0.0))
    d[6] = d[7] = max(d[6], d[7])
    if var_a > 0.0 or var_g > 0.0:
        rot2 = var_g * (roll_rad ** 2 + pitch_rad ** 2)
        d[6:8] = np.sqrt(d[6:8] ** 2 + var_a * load_factor ** 2 + rot2)
        d[8] = math.sqrt(d[8] ** 2 + rot2)
    return d


@njit(cache=True)
def _channel_sigmas_k(P, extra, tilt2, rot2, two):
    """:func:`channel_sigmas` compiled, operation for operation: ``d ** two`` with ``two`` = 2.0
    passed at run time is libm pow, as numpy's scalar ``d[8] ** 2`` (a literal exponent would
    compile to d * d, which differs from pow in the last bit for ~1 in 1,000 values)."""
    d = np.empty(9)
    for i in range(9):
        p = P[i, i]
        d[i] = np.sqrt(p if (p > 0.0 or p != p) else 0.0)       # np.maximum(p, 0.0)
    m = d[7] if d[7] > d[6] else d[6]                             # Python's max(d6, d7)
    if extra:
        m = np.sqrt(m * m + tilt2 + rot2)
        d[8] = np.sqrt(d[8] ** two + rot2)
    d[6] = m
    d[7] = m
    return d


VERTICAL_CHANNELS = (2, 5)
"""Comparison channels of the vertical channel: position U and velocity U."""

VERTICAL_STATES = (2, 5, 21)
"""Filter states of the vertical channel: δp_U, δV_U and the baro bias (when there is one)."""


def declared_sensor_noise(imus: list, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The declared unit performance the sensor-level thresholds are built from.

    Parameters
    ----------
    imus : each unit's declared :class:`~fms_testbed.sensors.sins.presets.ImuModel`
    dt_s : sample interval, s

    Returns
    -------
    (q_white (n, 6): accelerometer VRW² ((m/s²)²·s) and gyro ARW² (rad²/s) densities,
    sf_var (n, 2): accelerometer and gyro scale-factor + 2 × misalignment variance), the inputs
    of :class:`SensorComparator`
    """
    q = np.array([np.r_[imu.q_psd[3:6], imu.q_psd[6:9]] for imu in imus])
    sf = np.array([unmodelled_variances(imu) for imu in imus])
    return q, sf


def unmodelled_variances(imu) -> tuple[float, float]:
    """(accelerometer, gyro) scale-factor + 2 × misalignment variance per axis of a declared
    :class:`~fms_testbed.sensors.sins.presets.ImuModel`, dimensionless / rad²: the 33-state
    errors the filters do not carry."""
    p = imu.p0_var
    return (float(p[15:18].mean() + 2.0 * p[21:27].mean()),
            float(p[18:21].mean() + 2.0 * p[27:33].mean()))


def channel_mask(vertical_frozen: bool) -> np.ndarray:
    """(9,) bool: the comparison channels in use — all, or all but the vertical ones when the
    vertical channel is frozen (seed 001: no altitude → the vertical channel is excluded)."""
    return (_MASK_VERTICAL if vertical_frozen else _ALL9).copy()


_MASK_VERTICAL = np.ones(9, bool)
_MASK_VERTICAL[list(VERTICAL_CHANNELS)] = False


def pair_flags(y: np.ndarray, sig: np.ndarray, k: float,
               mask: np.ndarray | None = None) -> np.ndarray:
    """Stage 1 of one instant: ν_ij = 1 when some channel of y_i - y_j exceeds
    ε_N = k √(σ_i² + σ_j²) (seed 001), for the pairs (1,2), (1,3), (2,3).

    Parameters
    ----------
    y : (n, 9) comparison vectors (position m, velocity m/s, roll/pitch/heading rad)
    sig : (n, 9) their σ (:func:`channel_sigmas`);  k : threshold in σ
    mask : (9,) bool channels compared (None: all)

    Returns
    -------
    (3,) int, 0 for a pair with a unit beyond ``n``
    """
    y, sig = np.asarray(y, float), np.asarray(sig, float)
    m = _ALL9 if mask is None else np.asarray(mask, bool)
    if y.ndim == 2 and y.shape[1] == 9 and sig.shape == y.shape and m.shape == (9,):
        bits = _flags_rows(y, sig, m, float(k))
        if bits >= 0:
            return np.array(_BITS[bits])
    return _pair_flags_np(y, sig, k, mask)


def _pair_flags_np(y, sig, k, mask) -> np.ndarray:
    """:func:`pair_flags` in numpy (any shape; math.remainder's error on an infinite heading)."""
    y, sig = np.asarray(y, float), np.asarray(sig, float)
    m = np.ones(y.shape[1], bool) if mask is None else np.asarray(mask, bool)
    out = np.zeros(3, int)
    for k_, (a, b) in enumerate(PAIRS):
        if b < y.shape[0]:
            d = _diff(y[a], y[b])
            out[k_] = int((np.abs(d) > k * np.sqrt(sig[a] ** 2 + sig[b] ** 2))[m].any())
    return out


def _unit_flag_bits(y, sig, k: float, mask) -> int:
    """:func:`pair_flags` of a list of 2 or 3 (9,) vectors as bits (bit k: pair k), without
    stacking them; other inputs go through :func:`pair_flags`."""
    n = len(y)
    m = _ALL9 if mask is None else mask
    if ((n == 3 or n == 2) and len(sig) == n and type(m) is np.ndarray
            and m.dtype == np.bool_ and m.shape == (9,)):
        y0, y1, y2 = (y[0], y[1], y[2]) if n == 3 else (y[0], y[1], y[1])
        s0, s1, s2 = (sig[0], sig[1], sig[2]) if n == 3 else (sig[0], sig[1], sig[1])
        if (_vec9(y0) and _vec9(y1) and _vec9(y2) and _vec9(s0) and _vec9(s1)
                and _vec9(s2)):
            bits = _flags_units(y0, y1, y2, s0, s1, s2, m, float(k), n)
            if bits >= 0:
                return bits
    f = pair_flags(np.array(y), np.array(sig), k, mask)
    return int(f[0]) | int(f[1]) << 1 | int(f[2]) << 2


def _vec9(a) -> bool:
    """A float64 vector of the 9 comparison channels (what the compiled pair test takes)."""
    return type(a) is np.ndarray and a.dtype == _F8 and a.shape == (9,)


@njit(cache=True)
def _remainder_2pi(x):
    """math.remainder(x, 2π) of a finite x, CPython's exact algorithm (fmod, then the nearer
    multiple, ties to even)."""
    absx = abs(x)
    m = np.fmod(absx, _TWO_PI)
    c = _TWO_PI - m
    if m < c:
        r = m
    elif m > c:
        r = -c
    else:
        r = m - 2.0 * np.fmod(0.5 * (absx - m), _TWO_PI)
    return math.copysign(1.0, x) * r


@njit(cache=True)
def _pair_bad(ya, yb, sa, sb, mask, k):
    """1 when some channel in ``mask`` of ya - yb (heading wrapped) exceeds
    k √(sa² + sb²), else 0; -1 for an infinite heading difference (math.remainder raises)."""
    d8 = ya[8] - yb[8]
    if np.isinf(d8):
        return -1
    d8 = _remainder_2pi(d8)
    for c in range(9):
        d = d8 if c == 8 else ya[c] - yb[c]
        if mask[c] and abs(d) > k * np.sqrt(sa[c] * sa[c] + sb[c] * sb[c]):
            return 1
    return 0


@njit(cache=True)
def _flags_units(y0, y1, y2, s0, s1, s2, mask, k, n):
    """Bits of :func:`pair_flags` for units given one by one (n = 2: units 1 and 2 only)."""
    r = _pair_bad(y0, y1, s0, s1, mask, k)
    if r < 0 or n < 3:
        return r
    r2 = _pair_bad(y0, y2, s0, s2, mask, k)
    if r2 < 0:
        return r2
    r3 = _pair_bad(y1, y2, s1, s2, mask, k)
    if r3 < 0:
        return r3
    return r | r2 << 1 | r3 << 2


@njit(cache=True)
def _flags_rows(y, sig, mask, k):
    """Bits of :func:`pair_flags` for (n, 9) arrays."""
    n = y.shape[0]
    bits = 0
    for p in range(3):
        a = 0 if p < 2 else 1
        b = 1 if p == 0 else 2
        if b < n:
            r = _pair_bad(y[a], y[b], sig[a], sig[b], mask, k)
            if r < 0:
                return r
            bits |= r << p
    return bits


def majority(nu) -> int | None:
    """Seed 001's table: the failed unit's index for (ν12, ν13, ν23), None when it names none."""
    return MAJORITY.get(tuple(int(v) for v in nu))


def residual_ok(nu: np.ndarray, S: np.ndarray, k: float) -> np.ndarray:
    """Seed 001's channel test |y_i - ŷ_i| ≤ ε_i, ε_i = k √S_ii, per measurement component.

    Parameters
    ----------
    nu : (m,) innovations y - H ẑ;  S : (m, m) their covariance;  k : threshold in σ
    """
    return np.abs(nu) <= k * np.sqrt(np.diag(S))


def frozen_states(n_states: int, vertical: bool) -> np.ndarray:
    """(n,) bool gain-row mask of the fault-tolerant estimator ż = Φ(ẑ) + K (y - H ẑ): rows of
    a frozen channel are zeroed (those states keep their prediction); ``vertical`` freezes
    :data:`VERTICAL_STATES` (those that exist)."""
    m = np.zeros(n_states, bool)
    if vertical:
        m[[s for s in VERTICAL_STATES if s < n_states]] = True
    return m


def adaptive_r(scale: np.ndarray, nu: np.ndarray, S: np.ndarray, R: np.ndarray,
               tuning: FdiTuning = FdiTuning()) -> tuple[np.ndarray, bool]:
    """Adaptive-R step (seed 001's adaptive variant) for one measurement group.

    A component with |ν_i| > k_adapt √S_ii gets R_ii inflated to what its innovation says,
    R_ii ← ν_i² - (H P Hᵀ)_ii (innovation matching, H P Hᵀ = S - R_used), capped at
    ``adapt_max`` × nominal; otherwise the inflation decays by ``adapt_decay`` towards 1.
    Divergence check: νᵀν > γ tr(S') with S' = H P Hᵀ + R at the new inflation and that
    inflation at its cap — more R cannot explain the residual, the channel is diverging.

    Parameters
    ----------
    scale : (m,) current inflation of the nominal R's diagonal (≥ 1)
    nu : (m,) innovations;  S : (m, m) their covariance with the inflated R
    R : (m, m) nominal measurement covariance;  tuning : ``k_adapt``, ``adapt_max``,
        ``adapt_decay``, ``diverge_gamma``

    Returns
    -------
    (new scale (m,), diverging)
    """
    scale = np.asarray(scale, float)
    r0 = np.diag(R)
    hph = np.diag(S) - r0 * scale
    bad = ~residual_ok(nu, S, tuning.k_adapt)
    want = np.clip((np.asarray(nu) ** 2 - hph) / r0, 1.0, tuning.adapt_max)
    new = np.where(bad, np.maximum(scale, want), np.maximum(1.0, scale * tuning.adapt_decay))
    S_new = hph.sum() + float(r0 @ new)                   # tr(S) with the new inflation
    diverging = bool(float(nu @ nu) > tuning.diverge_gamma * S_new
                     and (new >= tuning.adapt_max - 1e-9).any())
    return new, diverging


def _diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = a - b
    d[8] = math.remainder(d[8], 2 * math.pi)
    return d


class TwoStageFdi:
    """Seed 001's two-stage identification for N = 2 or 3 units.

    Parameters
    ----------
    n_units : number of INS units;  tuning : thresholds

    Attributes
    ----------
    state : :class:`FdiState`;  nu : (ν12, ν13, ν23) of the last :meth:`update`
    flags : (ν12, ν13, ν23) of the last output comparison at that instant, over all units,
        without persistence (:func:`pair_flags`): pass it to :meth:`vote` on the same inputs
        instead of comparing again
    """

    def __init__(self, n_units: int, tuning: FdiTuning = FdiTuning()):
        self.n, self.tuning = n_units, tuning
        self.state = FdiState([True] * n_units, nis=[[] for _ in range(n_units)])
        self.nu = (0, 0, 0)
        self.flags = (0, 0, 0)
        self._bits = 0                                        # self.flags as bits
        self._suspect: tuple[int, float] | None = None        # (unit, since t_s)
        self._isf: dict = {}                                  # (alpha, dof) → χ² quantile

    def add_innovation(self, i: int, t_s: float, nis: float, dim: int) -> None:
        """Record unit i's GNSS innovation statistic (NIS of a group of dimension ``dim``)."""
        self.state.nis[i].append((t_s, nis, dim))

    def _innovation_fails(self, i: int, t_s: float) -> bool:
        buf = self.state.nis[i]
        while buf and buf[0][0] < t_s - self.tuning.window_s:
            buf.pop(0)
        if not buf:
            return False
        total, dof = sum(b[1] for b in buf), sum(b[2] for b in buf)
        key = (self.tuning.alpha, dof)
        q = self._isf.get(key)
        if q is None:
            q = self._isf[key] = chi2.isf(self.tuning.alpha, dof)
        return total > q

    def pairwise(self, t_s: float, y: list[np.ndarray], sig: list[np.ndarray],
                 mask: np.ndarray | None = None) -> tuple:
        """Stage 1: (ν12, ν13, ν23) with persistence (pairs with a unit out of use read 0) over
        the channels in ``mask`` (:func:`channel_mask`); sets :attr:`flags`."""
        bits = _unit_flag_bits(y, sig, self.tuning.k_pair, mask)
        self._bits, self.flags = bits, _BITS[bits]
        used, since = self.state.used, self.state.since
        if bits == 0 and not since:            # nothing flagged and no timer to reset
            return (0, 0, 0)
        out = []
        for k, (a, b) in enumerate(PAIRS):
            if b >= self.n or not (used[a] and used[b]):
                out.append(0)
                continue
            if bits >> k & 1:
                t0 = since.setdefault((a, b), t_s)
                out.append(int(t_s - t0 >= self.tuning.persist_s - 1e-9))
            else:
                since.pop((a, b), None)
                out.append(0)
        return tuple(out)

    def _prediction_fails(self, i: int, y, sig, mask=None) -> bool:
        others = [j for j in range(self.n) if j != i and self.state.used[j]]
        if not others:
            return False
        ym = sum(y[j] for j in others) / len(others)
        sm2 = sum(sig[j] ** 2 for j in others) / len(others)
        bad = np.abs(_diff(y[i], ym)) > self.tuning.k_est * np.sqrt(sig[i] ** 2 + sm2)
        return bool(bad[mask].any() if mask is not None else bad.any())

    def update(self, t_s: float, y: list[np.ndarray], sig: list[np.ndarray],
               nu_sensor: tuple = (0, 0, 0), mask: np.ndarray | None = None) -> list[dict]:
        """Run both stages at ``t_s`` (s) on the output comparison (``y``, ``sig``, channels in
        ``mask``) and the sensor-level pair verdicts ``nu_sensor``; return the events
        (detected, isolated, excluded, reconfigured) and update :attr:`state.used`."""
        events: list[dict] = []
        nu_out = self.pairwise(t_s, y, sig, mask)
        if type(nu_sensor) is tuple and nu_sensor == (0, 0, 0):
            nu = nu_out                      # what the expression below gives for no flags
        else:
            nu = tuple(int(a or (b and self._pair_live(k))) for k, (a, b) in
                       enumerate(zip(nu_out, nu_sensor)))
        if any(nu) and not any(self.nu):
            where = "outputs" if any(nu_out) else "sensors"
            events.append({"t_s": round(t_s, 3), "unit": "ins", "kind": "detected",
                           "stage": "pairwise", "reason": f"(ν12, ν13, ν23) = {nu} ({where})"})
        self.nu = nu
        live = [i for i in range(self.n) if self.state.used[i]]
        suspect = MAJORITY.get(nu) if len(live) == 3 else None
        if suspect is None:
            self._suspect = None
        elif self._suspect is None or self._suspect[0] != suspect:
            self._suspect = (suspect, t_s)
        if suspect is not None:
            events.append({"t_s": round(t_s, 3), "unit": f"ins{suspect + 1}", "kind": "isolated",
                           "stage": "pairwise", "reason": f"majority table {nu}"})
            if (self._innovation_fails(suspect, t_s)
                    or self._prediction_fails(suspect, y, sig, mask)):
                events += self._exclude(suspect, t_s, "estimator check failed")
            elif t_s - self._suspect[1] >= self.tuning.isolate_s - 1e-9:
                events += self._exclude(suspect, t_s, f"named by the majority table for "
                                                      f"{self.tuning.isolate_s:g} s")
        elif any(nu) or len(live) < 3:
            fails = [i for i in live if self._innovation_fails(i, t_s)]
            if len(fails) == 1 and len(live) > 1:
                events += self._exclude(fails[0], t_s, "innovation test failed alone")
        # keep only what changed: 'isolated' once per unit
        return [e for e in events if e["kind"] != "isolated" or self._new_isolation(e)]

    def _pair_live(self, k: int) -> bool:
        a, b = PAIRS[k]
        return b < self.n and self.state.used[a] and self.state.used[b]

    def _new_isolation(self, e: dict) -> bool:
        key = ("iso", e["unit"])
        if key in self.state.since:
            return False
        self.state.since[key] = e["t_s"]
        return True

    def _exclude(self, i: int, t_s: float, why: str) -> list[dict]:
        self.state.used[i] = False
        left = [f"ins{j + 1}" for j in range(self.n) if self.state.used[j]]
        return [{"t_s": round(t_s, 3), "unit": f"ins{i + 1}", "kind": "excluded",
                 "stage": "estimator", "reason": why},
                {"t_s": round(t_s, 3), "unit": "fms", "kind": "reconfigured",
                 "stage": "estimator", "reason": "output from " + (", ".join(left) or "none")}]

    def vote(self, y: list[np.ndarray], sig: list[np.ndarray],
             mask: np.ndarray | None = None, flags=None) -> list[int]:
        """Majority voting: the units the majority table of this instant's output comparison
        (all units, no persistence, no sensor level, no estimator) does not flag.

        ``flags``: that comparison's (ν12, ν13, ν23) (:func:`pair_flags` of ``y``, ``sig``,
        ``mask``) when already made — :attr:`flags` after :meth:`update` on the same inputs;
        None: compared here."""
        if self.n != 3:
            return list(range(self.n))
        if flags is None:
            return list(_VOTE[_unit_flag_bits(y, sig, self.tuning.k_pair, mask)])
        if flags is self.flags:
            return list(_VOTE[self._bits])
        bad = majority(flags)
        return [i for i in range(self.n) if i != bad]


class SensorComparator:
    """Stage 1 at sensor level: a step in the difference of two units' raw IMU outputs.

    For each pair and channel (3 accelerometers, 3 gyros) the mean difference over a short window
    (``accel_window_s`` / ``gyro_window_s``) is compared with its mean over the ``reference_s``
    before: Δ = mean_short - mean_ref, σ_Δ² = σ_sample² (1/N_short + 1/N_ref) + σ_k² |Δu|², with
    σ_sample² the two units' white-noise variances per sample (VRW/ARW densities over the sample
    interval) and the last term the declared scale-factor/misalignment variance of the pair
    (σ_k², dimensionless) times the change of the measured specific force or rate between the
    windows (a manoeuvre changes the difference of two healthy units by that much).
    ν_ij = 1 when some |Δ| > k_sensor σ_Δ (tested once both windows are full). Windows are
    counted in samples of the interval ``dt_s`` (the navigation step).

    Parameters
    ----------
    n_units : 2 or 3;  q_white : (n, 6) white-noise densities (accel (m/s²)²·s, gyro rad²/s)
    dt_s : sample interval, s;  sf_var : (n, 2) declared scale-factor + 2 × misalignment
        variance (accelerometer, gyro) per unit;  tuning : thresholds and windows
    """

    def __init__(self, n_units: int, q_white: np.ndarray, dt_s: float, sf_var: np.ndarray,
                 tuning: FdiTuning = FdiTuning()):
        self.n, self.tuning, self.dt_s = n_units, tuning, dt_s
        self.pairs = [p for p in PAIRS if p[1] < n_units]
        ia = [p[0] for p in self.pairs]
        ib = [p[1] for p in self.pairs]
        self.ia, self.ib = ia, ib
        q = np.asarray(q_white, float)
        sf = np.asarray(sf_var, float)
        self.var = (q[ia] + q[ib]) / dt_s                              # (pairs, 6)
        self.sf = np.repeat(sf[ia] + sf[ib], 3, axis=1)                # (pairs, 6)
        self.n_short, self.n_long = [], []
        # four running-sum rings (accel short, accel long, gyro short, gyro long) of rows
        # [pair differences (pairs × 3), u (3)], one after the other in one buffer; per ring
        # (first row, rows, next row, count)
        self._width = 3 * len(self.pairs) + 3
        rings = []
        for w in (tuning.accel_window_s, tuning.gyro_window_s):        # group 0 accel, 1 gyro
            ns = max(1, int(round(w / dt_s)))
            nl = ns + max(1, int(round(tuning.reference_s / dt_s)))
            self.n_short.append(ns)
            self.n_long.append(nl)
            rings += [ns, nl]
        self._ring = np.zeros((4, 4), np.int64)
        self._ring[:, 0] = np.cumsum([0] + rings[:3])
        self._ring[:, 1] = rings
        self._buf = np.zeros((sum(rings), self._width))
        self._sum = np.zeros((4, self._width))
        self._ia, self._ib = np.array(ia, np.int64), np.array(ib, np.int64)
        self._rows = max(ib, default=-1) + 1                         # rows errs must have
        self._out = tuple(tuple(int(bits >> self.pairs.index(p) & 1) if p in self.pairs else 0
                                for p in PAIRS) for bits in range(1 << len(self.pairs)))
        self.last_z = np.zeros((len(self.pairs), 6))

    def update(self, t_s: float, errs: np.ndarray, f_mps2, w_rps) -> tuple:
        """Add the units' raw-output errors (n, 6) at ``t_s`` (s) with the measured specific
        force (3,) m/s² and rate (3,) rad/s; return (ν12, ν13, ν23)."""
        errs = np.asarray(errs)
        if errs.ndim != 2 or errs.shape[0] < self._rows or errs.shape[1] < 6:
            raise ValueError(f"sensor errors of shape {errs.shape}, not ({self.n}, 6)")
        f0, f1, f2 = f_mps2
        w0, w1, w2 = w_rps
        bits = _comparator_step(errs, self._ia, self._ib, float(f0), float(f1),
                                float(f2), float(w0), float(w1), float(w2), self._buf,
                                self._sum, self._ring, self.var, self.sf,
                                float(self.tuning.k_sensor), self.last_z)
        return self._out[bits]


@njit(cache=True, error_model="numpy")
def _comparator_step(errs, ia, ib, f0, f1, f2, w0, w1, w2, buf, sums, ring, var, sf, k,
                     last_z):
    """One :meth:`SensorComparator.update`: push the pair differences and u into the four
    rings, then the step test of each group whose long ring is full; returns the flagged pairs
    as bits. Element for element the same operations, in the same order, as numpy on whole
    rows: sum - oldest + newest, Δ = S_s/N_s - (S_l - S_s)/N_r, z = Δ / √var."""
    n_p = ia.size
    width = 3 * n_p + 3
    v = np.empty(width)
    bits = 0
    for g in range(2):
        for p in range(n_p):
            for ax in range(3):
                v[3 * p + ax] = errs[ia[p], 3 * g + ax] - errs[ib[p], 3 * g + ax]
        if g == 0:
            v[3 * n_p], v[3 * n_p + 1], v[3 * n_p + 2] = f0, f1, f2
        else:
            v[3 * n_p], v[3 * n_p + 1], v[3 * n_p + 2] = w0, w1, w2
        for r in (2 * g, 2 * g + 1):
            row = ring[r, 0] + ring[r, 2]
            full = ring[r, 3] == ring[r, 1]
            for c in range(width):
                if full:
                    sums[r, c] -= buf[row, c]
                buf[row, c] = v[c]
                sums[r, c] += v[c]
            if not full:
                ring[r, 3] += 1
            ring[r, 2] = (ring[r, 2] + 1) % ring[r, 1]
        rs, rl = 2 * g, 2 * g + 1
        if ring[rl, 3] < ring[rl, 1]:
            continue
        ns = ring[rs, 1]
        nr = ring[rl, 1] - ns
        du2 = 0.0
        for ax in range(3):
            c = 3 * n_p + ax
            du = sums[rs, c] / ns - (sums[rl, c] - sums[rs, c]) / nr
            du2 = du2 + du * du if ax else du * du               # float(du @ du)
        wsum = 1.0 / ns + 1.0 / nr
        for p in range(n_p):
            for ax in range(3):
                c = 3 * p + ax
                delta = sums[rs, c] / ns - (sums[rl, c] - sums[rs, c]) / nr
                z = delta / np.sqrt(var[p, 3 * g + ax] * wsum + sf[p, 3 * g + ax] * du2)
                last_z[p, 3 * g + ax] = z
                if abs(z) > k:
                    bits |= 1 << p
    return bits


class FaultTolerantEstimator:
    """Seed 001's fault-tolerant estimator around the units' filters: the channel test
    |y_i - ŷ_i| ≤ ε_i on every measurement component, latched exclusion of a unit's baro
    channel (its gain column zeroed for good), freezing of the vertical channel when a unit has
    no altitude measurement left (its gain rows zeroed, :func:`frozen_states`, and the vertical
    comparison channels excluded, :func:`channel_mask`), and the adaptive-R variant
    (:func:`adaptive_r`, off unless ``adaptive``).

    Parameters
    ----------
    filters : the units' filters (their public ``frozen`` mask and ``r_scale`` are set)
    tuning : thresholds;  adaptive : run the adaptive-R variant
    """

    def __init__(self, filters: list, tuning: FdiTuning = FdiTuning(), adaptive: bool = False):
        self.filters, self.tuning, self.adaptive = filters, tuning, bool(adaptive)
        n = len(filters)
        self.baro_excluded = [False] * n
        self.vertical_frozen = [False] * n
        self._baro_fails: list[list[float]] = [[] for _ in range(n)]
        self._diverging = [dict() for _ in range(n)]

    def _unit(self, i: int, sensor: str) -> str:
        return sensor if len(self.filters) == 1 else f"{sensor}@ins{i + 1}"

    def check(self, i: int, t_s: float, groups: list) -> list[dict]:
        """Residual tests of unit ``i``'s measurement groups (:class:`.ins_filter.GroupResult`)
        at ``t_s`` (s); returns the events (baro channel excluded, adaptive-R divergence)."""
        ev: list[dict] = []
        f = self.filters[i]
        for g in groups:
            ok = residual_ok(g.innovation, g.S, self.tuning.k_residual)
            if g.name == "baro" and not self.baro_excluded[i]:
                buf = self._baro_fails[i]
                if not ok.all():
                    buf.append(t_s)
                while buf and buf[0] < t_s - self.tuning.baro_window_s:
                    buf.pop(0)
                if len(buf) >= self.tuning.baro_fails:
                    self.baro_excluded[i] = True
                    ev.append({"t_s": round(t_s, 3), "unit": self._unit(i, "baro"),
                               "kind": "excluded", "stage": "estimator",
                               "reason": f"baro residual beyond {self.tuning.k_residual:g}σ "
                                         f"{len(buf)} times in {self.tuning.baro_window_s:g} s: "
                                         "its gain column zeroed"})
            if self.adaptive and hasattr(f, "r_scale") and g.name in f.r_scale:
                R = f.nominal_r(g.name)
                f.r_scale[g.name], div = adaptive_r(f.r_scale[g.name], g.innovation, g.S, R,
                                                    self.tuning)
                if div and not self._diverging[i].get(g.name):
                    ev.append({"t_s": round(t_s, 3), "unit": self._unit(i, g.name.split("_")[0]),
                               "kind": "detected", "stage": "adaptive_r",
                               "reason": f"{g.name} diverging: νᵀν > {self.tuning.diverge_gamma:g}"
                                         f" tr(S) with R at {self.tuning.adapt_max:g}× nominal"})
                self._diverging[i][g.name] = div
        return ev

    def set_vertical(self, i: int, t_s: float, has_altitude: bool) -> list[dict]:
        """Freeze (``has_altitude`` False) or release unit ``i``'s vertical channel; returns the
        ``reconfigured`` event of a change."""
        frozen = not has_altitude
        if frozen == self.vertical_frozen[i]:
            return []
        self.vertical_frozen[i] = frozen
        f = self.filters[i]
        if hasattr(f, "frozen"):
            f.frozen[:] = frozen_states(f.frozen.size, frozen)
        return [{"t_s": round(t_s, 3), "unit": self._unit(i, "ins"), "kind": "reconfigured",
                 "stage": "estimator",
                 "reason": ("vertical channel frozen and excluded: no altitude measurement"
                            if frozen else "vertical channel released: altitude measured")}]

    def mask(self, used: list[bool] | None = None) -> np.ndarray:
        """Comparison channels: the vertical ones out when a unit in use has it frozen."""
        live = range(len(self.filters)) if used is None else [i for i, u in enumerate(used) if u]
        return channel_mask(any(self.vertical_frozen[i] for i in live))


__all__ = ["FaultTolerantEstimator", "FdiTuning", "MAJORITY", "SensorComparator", "TwoStageFdi",
           "VERTICAL_CHANNELS", "VERTICAL_STATES", "adaptive_r", "channel_mask", "channel_sigmas",
           "unmodelled_variances",
           "declared_sensor_noise", "frozen_states", "majority", "pair_flags", "residual_ok"]
