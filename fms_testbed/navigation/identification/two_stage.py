"""Seed 001's two-stage identification of U = 2 or 3 units in R realisations at once.

One step (:meth:`TwoStage.update`), all over arrays (R, U, C):

1. **Stage 1, pairwise.** ν_ij = 1 when some channel of the outputs y_i − y_j exceeds
   ε_N = k_pair √(σ_i² + σ_j²) for ``persist_s``, or when the sensor-level test
   (:class:`.sensor.SensorPairTest`) flags the pair. With three units in use table 1 names the
   failed unit: it is *isolated* — taken out of the output (and of the estimate below) at once.
2. **Stage 2, the estimator.** The survivors (units in use, not isolated) form the estimate
   Ẑ (:func:`.rules.fuse`); the prediction Ẑ_p is the estimate of ``predict_s`` ago advanced by
   the median change of the units' outputs since then (the motion all of them see; a median of
   three is not moved by one unit's step). Table 1 on (Z_i, Ẑ, Ẑ_p) with ε_K = k_est σ, for
   every unit in use — survivors and the isolated one alike: (1 1 0) for ``stage2_persist_s``,
   and for that unit alone, *excludes* it; (1 0 1) is the estimate failing against its own
   prediction (an event; the prediction restarts from the estimate). When stage 1 sees a
   disagreement it cannot resolve (two units, or every pair), or a unit is isolated, the units'
   own filter innovations are tested too (windowed χ² at ``alpha``): a unit failing alone is
   excluded.

An excluded unit leaves the comparisons, the estimate and the output for good; an isolated one
stays out of the output and is still compared.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2

from numba import njit

from fms_testbed.navigation.identification.rules import (_PAIR_A, _PAIR_B, ESTIMATE_FAILED,
                                                         HEADING,
                                                         UNIT_FAILED, _exceeds, _nan_max,
                                                         _wrap,
                                                         _ratio, _table1)
from fms_testbed.navigation.identification.tuning import FdiTuning

_EPS_S = 1e-9

BY_TABLE, BY_INNOVATION = 1, 2
"""Reasons of an exclusion (:attr:`TwoStage.excluded_by`): stage 2's table on (Z_i, Ẑ, Ẑ_p),
or the unit's innovation test failing alone."""


@njit(cache=True, error_model="numpy")
def _exclude_unit(r, u, t_s, reason, used, isolated, new_exclude, excluded_by, t_exclude_s,
                  t_detect_s) -> None:
    """Unit ``u`` of realisation ``r`` leaves for good at ``t_s`` (s) for ``reason``."""
    used[r, u] = False
    isolated[r, u] = False
    new_exclude[r, u] = True
    excluded_by[r, u] = reason
    t_exclude_s[r, u] = np.fmin(t_exclude_s[r, u], t_s)
    t_detect_s[r] = np.fmin(t_detect_s[r], t_s)                       # detected by stage 2


@njit(cache=True, error_model="numpy")
def _stage1(r, t_s, y, sig, nu_sensor, m, used, isolated, nu, flags, since, stat_max,
            t_detect_s, t_isolate_s, new_detect, new_isolate, track_stats, k_pair,
            persist_s) -> None:
    """Stage 1 of realisation ``r``: raw_ij = any_c |y_i − y_j| > k_pair √(σ_i² + σ_j²) over
    the live pair; ν_ij = raw_ij held ``persist_s``, or the sensor-level verdict; table 1 on ν
    with three live units names the unit isolated."""
    U = y.shape[1]
    n_live = 0
    for u in range(U):
        n_live += used[r, u]
    had_nu = nu[r, 0] != 0 or nu[r, 1] != 0 or nu[r, 2] != 0
    any_nu = False
    for p in range(3):
        a, b = _PAIR_A[p], _PAIR_B[p]
        pair = b < U and used[r, a] and used[r, b]
        raw = pair and _exceeds(y[r, a], y[r, b], sig[r, a], sig[r, b], k_pair, m)
        if track_stats and pair:
            stat_max[r, 0] = _nan_max(stat_max[r, 0],
                                      _ratio(y[r, a], y[r, b], sig[r, a], sig[r, b], m))
        flags[r, p] = raw
        if raw:
            if since[r, p] != since[r, p]:
                since[r, p] = t_s
        else:
            since[r, p] = math.nan
        v = raw and (t_s - since[r, p] >= persist_s - _EPS_S)
        v = v or (pair and nu_sensor[r, p])
        nu[r, p] = v
        any_nu = any_nu or v
    if any_nu and t_detect_s[r] != t_detect_s[r]:
        t_detect_s[r] = t_s
    new_detect[r] = any_nu and not had_nu
    named = _table1(nu[r, 0] != 0, nu[r, 1] != 0, nu[r, 2] != 0) if n_live == 3 else -1
    if named >= 0 and not isolated[r, named]:
        isolated[r, named] = True
        new_isolate[r, named] = True
        t_isolate_s[r, named] = np.fmin(t_isolate_s[r, named], t_s)


@njit(cache=True, error_model="numpy")
def _estimate(r, y, sig, used, isolated, zhat, shat) -> None:
    """The estimate of realisation ``r`` over the survivors S (in use, not isolated):
    Ẑ = y_0 + Σ_S σ⁻² ⊙ wrap(y_i − y_0) / Σ_S σ⁻², σ_Ẑ = (Σ_S σ⁻²)^-½."""
    U, C = y.shape[1], y.shape[2]
    for c in range(C):
        tot, acc = 0.0, 0.0
        for u in range(U):
            inv = 1.0 / (sig[r, u, c] * sig[r, u, c]) if used[r, u] and not isolated[r, u] \
                else 0.0
            d = y[r, u, c] - y[r, 0, c]
            if c == HEADING:
                d = _wrap(d)
            tot += inv
            acc += inv * d
        zhat[r, c] = y[r, 0, c] + acc / tot
        shat[r, c] = 1.0 / math.sqrt(tot)


@njit(cache=True, error_model="numpy")
def _prediction(r, y, z0, y0, live0, zhat, med, zp) -> bool:
    """Ẑ_p of realisation ``r`` into ``zp``: Ẑ₀ + median over ``live0`` of wrap(y − y₀); True
    when Ẑ_p and Ẑ are finite in every component."""
    U, C = y.shape[1], y.shape[2]
    ok = True
    for c in range(C):
        k = 0
        for u in range(U):
            if live0[r, u]:
                d = y[r, u, c] - y0[r, u, c]
                if c == HEADING:
                    d = _wrap(d)
                med[k] = d
                k += 1
        if k == 0:
            zp[c] = math.nan
        else:
            srt = np.sort(med[:k])                  # NaN last, as numpy sorts
            zp[c] = z0[r, c] + 0.5 * (srt[(k - 1) // 2] + srt[k // 2])
        if not (np.isfinite(zp[c]) and np.isfinite(zhat[r, c])):
            ok = False
    return ok


@njit(cache=True, error_model="numpy")
def _stage2_statistic(r, y, sig, m, used, ok, zhat, shat, stat_max) -> None:
    """Calibration record of realisation ``r``: the largest |Z_i − Ẑ|/σ over the units in use."""
    U = y.shape[1]
    top = 0.0
    for u in range(U):
        q = 0.0
        if used[r, u] and ok:
            q = _ratio(y[r, u], zhat[r], sig[r, u], shat[r], m)
            if q != q:
                q = 0.0
            elif q == math.inf:
                q = 1.7976931348623157e308
        top = _nan_max(top, q) if u > 0 else q
    stat_max[r, 2] = _nan_max(stat_max[r, 2], top)


@njit(cache=True, error_model="numpy")
def _stage2(r, t_s, y, sig, m, s0, used, isolated, verdict, s2_since, stat_max, t_detect_s,
            t_exclude_s, t_estimate_failed_s, excluded_by, new_exclude, new_estimate_failed,
            zhat, shat, last_t_s, track_stats, k_est, stage2_persist_s, ok, zp) -> bool:
    """Stage 2 of realisation ``r``: table 1 on (Z_i, Ẑ, Ẑ_p) at ``k_est`` for each unit in use;
    (1 1 0) alone for ``stage2_persist_s`` excludes. Returns: the estimate failed (1 0 1)."""
    U = y.shape[1]
    sp = s0[r]
    n_bad, est = 0, False
    for u in range(U):
        v = -1
        if ok and used[r, u]:
            v = _table1(_exceeds(y[r, u], zhat[r], sig[r, u], shat[r], k_est, m),
                        _exceeds(y[r, u], zp, sig[r, u], sp, k_est, m),
                        _exceeds(zhat[r], zp, shat[r], sp, k_est, m))
        verdict[r, u] = v
        n_bad += v == UNIT_FAILED
        est = est or v == ESTIMATE_FAILED
    if track_stats:
        _stage2_statistic(r, y, sig, m, used, ok, zhat, shat, stat_max)
    for u in range(U):
        bad = verdict[r, u] == UNIT_FAILED
        if bad:
            if s2_since[r, u] != s2_since[r, u]:
                s2_since[r, u] = t_s
        else:
            s2_since[r, u] = math.nan
        if (bad and n_bad == 1 and t_s - s2_since[r, u] >= stage2_persist_s - _EPS_S
                and used[r, u]):
            _exclude_unit(r, u, t_s, BY_TABLE, used, isolated, new_exclude,
                          excluded_by, t_exclude_s, t_detect_s)
    new_estimate_failed[r] = est and not (t_estimate_failed_s[r] == last_t_s)
    if est:
        t_estimate_failed_s[r] = t_s
    return est


@njit(cache=True, error_model="numpy")
def _innovation_stage(r, t_s, r_innov, used, isolated, nu, flags, gnss_failed, t_gnss_s,
                      stat_max, t_detect_s, t_exclude_s, excluded_by, new_exclude,
                      innovation_scale) -> None:
    """Innovation stage of realisation ``r``: ``r_innov`` (R, U) Σ NIS / χ²_{1−α} >
    ``innovation_scale``; every unit in use failing with no output disagreement names the
    GNSS, one failing alone under doubt is excluded."""
    U = r_innov.shape[1]
    top = 0.0
    for u in range(U):
        q = r_innov[r, u] if used[r, u] and not gnss_failed[r] else 0.0
        top = _nan_max(top, q) if u > 0 else q
    stat_max[r, 3] = _nan_max(stat_max[r, 3], top)
    n_live, n_fail, all_fail = 0, 0, True
    for u in range(U):
        f = r_innov[r, u] > innovation_scale and used[r, u]
        n_live += used[r, u]
        n_fail += f
        all_fail = all_fail and (f or not used[r, u])
    if (all_fail and n_live > 1 and not (flags[r, 0] or flags[r, 1] or flags[r, 2])
            and not gnss_failed[r]):
        gnss_failed[r] = True
        t_gnss_s[r] = t_s
    doubt = nu[r, 0] != 0 or nu[r, 1] != 0 or nu[r, 2] != 0 or n_live < U
    for u in range(U):
        doubt = doubt or (isolated[r, u] and used[r, u])
    if n_fail == 1 and n_live > 1 and doubt and not gnss_failed[r]:
        for u in range(U):
            if r_innov[r, u] > innovation_scale and used[r, u]:
                _exclude_unit(r, u, t_s, BY_INNOVATION, used, isolated, new_exclude,
                              excluded_by, t_exclude_s, t_detect_s)


@njit(cache=True, error_model="numpy")
def _step(t_s, y, sig, nu_sensor, mask, have_pred, z0, s0, y0, live0, have_innov, r_innov,
          used, isolated, nu, flags, verdict, since, s2_since, gnss_failed, t_gnss_s,
          stat_max, t_detect_s, t_isolate_s, t_exclude_s, t_estimate_failed_s, excluded_by,
          new_detect, new_isolate, new_exclude, new_estimate_failed, zhat, shat, last_t_s,
          track_stats, k_pair, k_est, persist_s, stage2_persist_s, innovation_scale) -> bool:
    """Both stages of :class:`TwoStage` at ``t_s`` (s) for every realisation r (the module
    docstring's rules; state arrays updated in place, ``zhat``/``shat`` (R, C) written):
    :func:`_stage1`, :func:`_estimate`, the prediction (when ``have_pred``) and
    :func:`_stage2`, :func:`_innovation_stage` (when ``have_innov``).

    Returns
    -------
    bool : some realisation's estimate failed against its prediction (1 0 1).
    """
    R, U, C = y.shape
    any_est = False
    med = np.empty(U)
    zp = np.empty(C)
    for r in range(R):
        m = mask[r]
        for u in range(U):
            new_isolate[r, u] = False
            new_exclude[r, u] = False
        new_estimate_failed[r] = False
        _stage1(r, t_s, y, sig, nu_sensor, m, used, isolated, nu, flags, since, stat_max,
                t_detect_s, t_isolate_s, new_detect, new_isolate, track_stats, k_pair,
                persist_s)
        _estimate(r, y, sig, used, isolated, zhat, shat)
        if not have_pred:
            for u in range(U):
                verdict[r, u] = -1
        else:
            ok = _prediction(r, y, z0, y0, live0, zhat, med, zp)
            if _stage2(r, t_s, y, sig, m, s0, used, isolated, verdict, s2_since, stat_max,
                       t_detect_s, t_exclude_s, t_estimate_failed_s, excluded_by,
                       new_exclude, new_estimate_failed, zhat, shat, last_t_s, track_stats,
                       k_est, stage2_persist_s, ok, zp):
                any_est = True
        if have_innov:
            _innovation_stage(r, t_s, r_innov, used, isolated, nu, flags, gnss_failed,
                              t_gnss_s, stat_max, t_detect_s, t_exclude_s, excluded_by,
                              new_exclude, innovation_scale)
    return any_est


class TwoStage:
    """Two-stage identification state and rules over R realisations of U units.

    Parameters
    ----------
    n_real : R;  n_units : U (2 or 3);  tuning : thresholds
    track_stats : keep :attr:`stat_max` (the statistics' maxima, for calibration)

    Attributes
    ----------
    used : (R, U) bool, not excluded;  isolated : (R, U) bool, named by stage 1 (out of the
        output, still compared);  nu : (R, 3) int (ν12, ν13, ν23) of the last update, with
        persistence and the sensor level;  flags : (R, 3) bool, the output comparison of that
        instant without persistence
    gnss_failed, baro_failed : (R,) bool, the GNSS / baro named failed (latched)
    t_gnss_s, t_baro_s : (R,) when, s (NaN: never)
    stat_max : (R, 4) the largest statistic so far, in units of its threshold's σ: stage-1
        output pairs, (unused here: the sensor level, filled by the consumer), stage 2
        |Z_i − Ẑ| of the units in use, innovation window Σ NIS / χ²_{1−α}
    t_detect_s, t_isolate_s, t_exclude_s : (R,), (R, U), (R, U) first detection (stage 1, or
        a stage-2 exclusion),
        isolation and exclusion times, s (NaN: never);  t_estimate_failed_s : (R,) last time
        the estimate failed against its prediction, s
    verdict : (R, U) int, stage 2's table of the last update (:func:`.rules.three_way`)
    new_detect, new_isolate, new_exclude, new_estimate_failed : what the last update changed
    excluded_by : (R, U) int, reason of each exclusion (:data:`BY_TABLE`, :data:`BY_INNOVATION`)
    """

    def __init__(self, n_real: int, n_units: int, tuning: FdiTuning = FdiTuning(),
                 track_stats: bool = False):
        R, U = n_real, n_units
        self.track_stats = bool(track_stats)
        self.n_real, self.n, self.tuning = R, U, tuning
        self.used = np.ones((R, U), bool)
        self.isolated = np.zeros((R, U), bool)
        self.nu = np.zeros((R, 3), np.int64)
        self.flags = np.zeros((R, 3), bool)
        self.verdict = np.full((R, U), -1, np.int64)
        self._since = np.full((R, 3), np.nan)
        self._s2_since = np.full((R, U), np.nan)
        self._hist: list[tuple] = []            # (t_s, Ẑ, σ_Ẑ, y, live) of recent steps
        self._nis: list[tuple] = []             # (t_s, NIS (R, U), dof (R, U))
        self._nis_sum = np.zeros((R, U))
        self._dof_sum = np.zeros((R, U), np.int64)
        self._baro: list[tuple] = []            # (t_s, failed (R, U))
        self._baro_sum = np.zeros((R, U), np.int64)
        self.gnss_failed = np.zeros(R, bool)
        self.baro_failed = np.zeros(R, bool)
        self.t_gnss_s = np.full(R, np.nan)
        self.t_baro_s = np.full(R, np.nan)
        self.stat_max = np.zeros((R, 4))
        self._isf: dict = {}
        self.t_detect_s = np.full(R, np.nan)
        self.t_isolate_s = np.full((R, U), np.nan)
        self.t_exclude_s = np.full((R, U), np.nan)
        self.t_estimate_failed_s = np.full(R, np.nan)
        self.excluded_by = np.zeros((R, U), np.int64)
        self._clear_news()

    def _clear_news(self) -> None:
        R, U = self.used.shape
        self.new_detect = np.zeros(R, bool)
        self.new_isolate = np.zeros((R, U), bool)
        self.new_exclude = np.zeros((R, U), bool)
        self.new_estimate_failed = np.zeros(R, bool)

    @property
    def output_units(self) -> np.ndarray:
        """(R, U) bool: the units the output uses (in use and not isolated)."""
        return self.used & ~self.isolated

    def add_innovation(self, t_s: float, nis: np.ndarray, dof: np.ndarray) -> None:
        """Record the units' GNSS innovation statistics: NIS (R, U) of groups of ``dof``
        (R, U) components (0 where a unit had none) at ``t_s`` (s)."""
        e = (t_s, np.asarray(nis, float), np.asarray(dof, np.int64))
        self._nis.append(e)
        self._nis_sum += e[1]
        self._dof_sum += e[2]

    def add_baro_test(self, t_s: float, failed: np.ndarray) -> None:
        """Record the units' baro channel tests at ``t_s`` (s): ``failed`` (R, U) bool where
        |ν| > k_residual √S. Every unit in use failing ``baro_fails`` times within
        ``baro_window_s`` names the baro failed (the different-type pair baro vs INS altitude,
        for every unit at once)."""
        f = np.asarray(failed, bool)
        self._baro.append((t_s, f))
        self._baro_sum += f
        while self._baro and self._baro[0][0] < t_s - self.tuning.baro_window_s:
            self._baro_sum -= self._baro.pop(0)[1]
        many = self._baro_sum >= self.tuning.baro_fails
        allf = (many | ~self.used).all(axis=1) & self.used.any(axis=1) & ~self.baro_failed
        self.baro_failed |= allf
        self.t_baro_s[allf] = t_s

    def update(self, t_s: float, y: np.ndarray, sig: np.ndarray,
               nu_sensor: np.ndarray | None = None, mask: np.ndarray | None = None) -> None:
        """Both stages at ``t_s`` (s), in one compiled call (:func:`_step`) over all realisations.

        Parameters
        ----------
        y : (R, U, C) the units' comparison vectors (position m, velocity m/s, attitude rad;
            channel 8 is the heading);  sig : (R, U, C) their σ
        nu_sensor : (R, 3) bool sensor-level pair verdicts (None: none)
        mask : (C,) or (R, C) bool channels compared (None: all)
        """
        y = np.ascontiguousarray(y, dtype=float)
        sig = np.ascontiguousarray(sig, dtype=float)
        R, U, C = y.shape
        m = (np.ones((R, C), bool) if mask is None
             else np.ascontiguousarray(np.broadcast_to(np.asarray(mask, bool), (R, C))))
        nus = (np.zeros((R, 3), bool) if nu_sensor is None
               else np.ascontiguousarray(np.broadcast_to(np.asarray(nu_sensor, bool), (R, 3))))
        pred = self._prediction(t_s)
        have_pred = pred is not None
        if not have_pred:
            pred = (np.zeros((R, C)), np.zeros((R, C)), y, self.used)   # unread placeholders
        r_innov = self._innovation_ratio(t_s) if self._nis else None
        tu = self.tuning
        zhat, shat = np.empty((R, C)), np.empty((R, C))
        est = _step(float(t_s), y, sig, nus, m, have_pred, pred[0], pred[1], pred[2],
                    pred[3], r_innov is not None,
                    np.zeros((R, U)) if r_innov is None else r_innov,
                    self.used, self.isolated, self.nu, self.flags, self.verdict, self._since,
                    self._s2_since, self.gnss_failed, self.t_gnss_s, self.stat_max,
                    self.t_detect_s, self.t_isolate_s, self.t_exclude_s,
                    self.t_estimate_failed_s, self.excluded_by, self.new_detect,
                    self.new_isolate, self.new_exclude, self.new_estimate_failed, zhat, shat,
                    float(self._last_t), self.track_stats, tu.k_pair, tu.k_est, tu.persist_s,
                    tu.stage2_persist_s, tu.innovation_scale)
        if est:                               # the prediction restarts from the estimate
            e = (self.verdict == ESTIMATE_FAILED).any(axis=1)
            for h in self._hist:
                h[1][e], h[3][e] = zhat[e], y[e]
        self._remember(t_s, zhat, shat, y)

    def _prediction(self, t_s: float):
        """(Ẑ, σ_Ẑ, y, live) of the step ``predict_s`` ago, the start of the prediction Ẑ_p
        (None until there is one)."""
        h = self._hist
        while len(h) > 1 and h[1][0] <= t_s - self.tuning.predict_s + _EPS_S:
            h.pop(0)
        if not h or h[0][0] > t_s - self.tuning.predict_s + _EPS_S:
            return None
        return h[0][1:]

    def _innovation_ratio(self, t_s: float) -> np.ndarray | None:
        """(R, U) Σ NIS / χ²_{1−α}(Σ dof) over the last ``window_s`` (0 where no dof; None when
        the window holds no innovation)."""
        buf = self._nis
        while buf and buf[0][0] < t_s - self.tuning.window_s:
            _, n, d = buf.pop(0)
            self._nis_sum -= n
            self._dof_sum -= d
        if not buf:
            self._nis_sum[:] = 0.0
            return None
        q = np.full(self._dof_sum.shape, np.inf)
        for d in np.unique(self._dof_sum[self._dof_sum > 0]):
            if d not in self._isf:
                self._isf[d] = chi2.isf(self.tuning.alpha, int(d))
            q[self._dof_sum == d] = self._isf[d]
        return self._nis_sum / q

    def innovation_fails(self, t_s: float) -> np.ndarray:
        """(R, U) bool: the windowed χ² test of each unit's innovations over ``window_s``
        fails at false-alarm probability ``alpha`` (Σ NIS > innovation_scale × χ²_{1−α}(Σ dof))."""
        r = self._innovation_ratio(t_s)
        if r is None:
            return np.zeros(self.used.shape, bool)
        return r > self.tuning.innovation_scale

    def _remember(self, t_s, zhat, shat, y) -> None:
        self._last_t = t_s
        self._hist.append((t_s, zhat, shat, np.array(y, float), self.used.copy()))

    _last_t = np.nan


__all__ = ["BY_INNOVATION", "BY_TABLE", "TwoStage"]
