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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2

MAJORITY = {(1, 1, 0): 0, (1, 0, 1): 1, (0, 1, 1): 2}
"""Seed 001's table for three units: (ν12, ν13, ν23) → index of the failed unit."""

PAIRS = ((0, 1), (0, 2), (1, 2))


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
    d = np.sqrt(np.maximum(P.diagonal()[:9], 0.0))
    d[6] = d[7] = max(d[6], d[7])
    var_a, var_g = unmodelled_var
    if var_a > 0.0 or var_g > 0.0:
        rot2 = var_g * (roll_rad ** 2 + pitch_rad ** 2)
        d[6:8] = np.sqrt(d[6:8] ** 2 + var_a * load_factor ** 2 + rot2)
        d[8] = math.sqrt(d[8] ** 2 + rot2)
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
    m = np.ones(9, bool)
    if vertical_frozen:
        m[list(VERTICAL_CHANNELS)] = False
    return m


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
    m = np.ones(y.shape[1], bool) if mask is None else np.asarray(mask, bool)
    out = np.zeros(3, int)
    for k_, (a, b) in enumerate(PAIRS):
        if b < y.shape[0]:
            d = _diff(y[a], y[b])
            out[k_] = int((np.abs(d) > k * np.sqrt(sig[a] ** 2 + sig[b] ** 2))[m].any())
    return out


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
    """

    def __init__(self, n_units: int, tuning: FdiTuning = FdiTuning()):
        self.n, self.tuning = n_units, tuning
        self.state = FdiState([True] * n_units, nis=[[] for _ in range(n_units)])
        self.nu = (0, 0, 0)
        self._suspect: tuple[int, float] | None = None        # (unit, since t_s)

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
        return total > chi2.isf(self.tuning.alpha, dof)

    def pairwise(self, t_s: float, y: list[np.ndarray], sig: list[np.ndarray],
                 mask: np.ndarray | None = None) -> tuple:
        """Stage 1: (ν12, ν13, ν23) with persistence (pairs with a unit out of use read 0) over
        the channels in ``mask`` (:func:`channel_mask`)."""
        out = []
        flags = pair_flags(np.array(y), np.array(sig), self.tuning.k_pair, mask)
        for k, (a, b) in enumerate(PAIRS):
            if b >= self.n or not (self.state.used[a] and self.state.used[b]):
                out.append(0)
                continue
            if flags[k]:
                t0 = self.state.since.setdefault((a, b), t_s)
                out.append(int(t_s - t0 >= self.tuning.persist_s - 1e-9))
            else:
                self.state.since.pop((a, b), None)
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
             mask: np.ndarray | None = None) -> list[int]:
        """Majority voting: the units the majority table of this instant's output comparison
        (all units, no persistence, no sensor level, no estimator) does not flag."""
        if self.n != 3:
            return list(range(self.n))
        bad = majority(pair_flags(np.array(y), np.array(sig), self.tuning.k_pair, mask))
        return [i for i in range(self.n) if i != bad]


class _Ring:
    """Running sum over the last ``n`` samples of arrays of one shape."""

    def __init__(self, n: int, shape: tuple):
        self.buf = np.zeros((n,) + shape)
        self.sum = np.zeros(shape)
        self.i = self.count = 0

    def push(self, v: np.ndarray) -> None:
        n = self.buf.shape[0]
        if self.count == n:
            self.sum -= self.buf[self.i]
        else:
            self.count += 1
        self.buf[self.i] = v
        self.sum += v
        self.i = (self.i + 1) % n


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
        self.d_short, self.d_long, self.u_short, self.u_long = [], [], [], []
        for w in (tuning.accel_window_s, tuning.gyro_window_s):        # group 0 accel, 1 gyro
            ns = max(1, int(round(w / dt_s)))
            nl = ns + max(1, int(round(tuning.reference_s / dt_s)))
            self.n_short.append(ns)
            self.n_long.append(nl)
            self.d_short.append(_Ring(ns, (len(self.pairs), 3)))
            self.d_long.append(_Ring(nl, (len(self.pairs), 3)))
            self.u_short.append(_Ring(ns, (3,)))
            self.u_long.append(_Ring(nl, (3,)))
        self.last_z = np.zeros((len(self.pairs), 6))

    def update(self, t_s: float, errs: np.ndarray, f_mps2, w_rps) -> tuple:
        """Add the units' raw-output errors (n, 6) at ``t_s`` (s) with the measured specific
        force (3,) m/s² and rate (3,) rad/s; return (ν12, ν13, ν23)."""
        d = errs[self.ia] - errs[self.ib]
        bad = np.zeros(len(self.pairs), bool)
        for g, u in enumerate((np.asarray(f_mps2, float), np.asarray(w_rps, float))):
            cols = slice(3 * g, 3 * g + 3)
            ds, dl, us, ul = self.d_short[g], self.d_long[g], self.u_short[g], self.u_long[g]
            ds.push(d[:, cols])
            dl.push(d[:, cols])
            us.push(u)
            ul.push(u)
            if dl.count < self.n_long[g]:
                continue
            ns, nr = self.n_short[g], self.n_long[g] - self.n_short[g]
            delta = ds.sum / ns - (dl.sum - ds.sum) / nr
            du = us.sum / ns - (ul.sum - us.sum) / nr
            var = self.var[:, cols] * (1.0 / ns + 1.0 / nr) + self.sf[:, cols] * float(du @ du)
            z = delta / np.sqrt(var)
            self.last_z[:, cols] = z
            bad |= (np.abs(z) > self.tuning.k_sensor).any(axis=1)
        out = dict(zip(self.pairs, bad.astype(int).tolist()))
        return tuple(out.get(p, 0) for p in PAIRS)


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
