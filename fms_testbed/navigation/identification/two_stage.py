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

import numpy as np
from scipy.stats import chi2

from fms_testbed.navigation.identification.rules import (ESTIMATE_FAILED, PAIRS, UNIT_FAILED,
                                                         fuse, named_unit, pair_flags, ratio,
                                                         three_way, wrapped_difference)
from fms_testbed.navigation.identification.tuning import FdiTuning

_EPS_S = 1e-9

BY_TABLE, BY_INNOVATION = 1, 2
"""Reasons of an exclusion (:attr:`TwoStage.excluded_by`): stage 2's table on (Z_i, Ẑ, Ẑ_p),
or the unit's innovation test failing alone."""


def median_of_units(v: np.ndarray, live: np.ndarray) -> np.ndarray:
    """(R, C) median over the live units of ``v`` (R, U, C), per channel (two units: their
    mean; none: NaN)."""
    srt = np.sort(np.where(live[..., None], v, np.nan), axis=1)      # NaN last
    n = live.sum(axis=1)
    r = np.arange(v.shape[0])
    lo = np.clip((n - 1) // 2, 0, v.shape[1] - 1)
    hi = np.clip(n // 2, 0, v.shape[1] - 1)
    out = 0.5 * (srt[r, lo] + srt[r, hi])
    out[n == 0] = np.nan
    return out


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

    def innovation_fails(self, t_s: float) -> np.ndarray:
        """(R, U) bool: the windowed χ² test of each unit's innovations over ``window_s``
        fails at false-alarm probability ``alpha`` (Σ NIS > innovation_scale × χ²_{1−α}(Σ dof))."""
        buf = self._nis
        while buf and buf[0][0] < t_s - self.tuning.window_s:
            _, n, d = buf.pop(0)
            self._nis_sum -= n
            self._dof_sum -= d
        if not buf:
            self._nis_sum[:] = 0.0
            return np.zeros(self.used.shape, bool)
        q = np.full(self._dof_sum.shape, np.inf)
        for d in np.unique(self._dof_sum[self._dof_sum > 0]):
            if d not in self._isf:
                self._isf[d] = chi2.isf(self.tuning.alpha, int(d))
            q[self._dof_sum == d] = self._isf[d]
        r = self._nis_sum / q
        live = self.used & ~self.gnss_failed[:, None]
        np.maximum(self.stat_max[:, 3], np.where(live, r, 0.0).max(axis=1),
                   out=self.stat_max[:, 3])
        return r > self.tuning.innovation_scale

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
        """Both stages at ``t_s`` (s).

        Parameters
        ----------
        y : (R, U, C) the units' comparison vectors (position m, velocity m/s, attitude rad;
            channel 8 is the heading);  sig : (R, U, C) their σ
        nu_sensor : (R, 3) bool sensor-level pair verdicts (None: none)
        mask : (C,) bool channels compared (None: all)
        """
        self._clear_news()
        self._stage1(t_s, y, sig, nu_sensor, mask)
        surv = self.used & ~self.isolated
        zhat, shat = fuse(y, sig, surv)
        self._stage2(t_s, y, sig, zhat, shat, mask)
        self._innovation_stage(t_s)
        self._remember(t_s, zhat, shat, y)

    def _stage1(self, t_s, y, sig, nu_sensor, mask) -> None:
        tu, live = self.tuning, self.used
        raw = pair_flags(y, sig, tu.k_pair, live, mask)
        for a, b in PAIRS if self.track_stats else ():
            if b < self.n:
                r = np.where(live[:, a] & live[:, b],
                             ratio(y[:, a], y[:, b], sig[:, a], sig[:, b], mask), 0.0)
                np.maximum(self.stat_max[:, 0], r, out=self.stat_max[:, 0])
        self.flags = raw
        s = self._since
        s[raw & np.isnan(s)] = t_s
        s[~raw] = np.nan
        nu = raw & (t_s - s >= tu.persist_s - _EPS_S)
        if nu_sensor is not None:
            lp = np.zeros_like(raw)
            for p, (a, b) in enumerate(PAIRS):
                if b < self.n:
                    lp[:, p] = live[:, a] & live[:, b]
            nu |= np.asarray(nu_sensor, bool) & lp
        first = nu.any(axis=1) & np.isnan(self.t_detect_s)
        self.t_detect_s[first] = t_s
        self.new_detect = nu.any(axis=1) & ~self.nu.astype(bool).any(axis=1)
        self.nu = nu.astype(np.int64)
        named = named_unit(self.nu, live.sum(axis=1))
        r = np.nonzero(named >= 0)[0]
        new = r[~self.isolated[r, named[r]]]
        self.isolated[new, named[new]] = True
        self.new_isolate[new, named[new]] = True
        self.t_isolate_s[new, named[new]] = np.fmin(self.t_isolate_s[new, named[new]], t_s)

    def _prediction(self, t_s: float, y: np.ndarray):
        """Ẑ_p, σ_p from the estimate ``predict_s`` ago (None until there is one)."""
        h = self._hist
        while len(h) > 1 and h[1][0] <= t_s - self.tuning.predict_s + _EPS_S:
            h.pop(0)
        if not h or h[0][0] > t_s - self.tuning.predict_s + _EPS_S:
            return None
        _, z0, s0, y0, live0 = h[0]
        return z0 + median_of_units(wrapped_difference(y, y0), live0), s0

    def _stage2(self, t_s, y, sig, zhat, shat, mask) -> None:
        pred = self._prediction(t_s, y)
        if pred is None:
            self.verdict[:] = -1
            return
        zp, sp = pred
        ok = np.isfinite(zp).all(axis=1) & np.isfinite(zhat).all(axis=1)
        v = np.full(self.used.shape, -1, np.int64)
        if ok.any():
            v[ok] = three_way(y[ok], sig[ok], zhat[ok], shat[ok], zp[ok], sp[ok],
                              self.tuning.k_est, mask)
        v[~self.used] = -1
        self.verdict = v
        if self.track_stats:
            r = np.where(self.used & ok[:, None],
                         ratio(y, zhat[:, None], sig, shat[:, None], mask), 0.0)
            np.maximum(self.stat_max[:, 2], np.nan_to_num(r).max(axis=1),
                       out=self.stat_max[:, 2])
        bad = v == UNIT_FAILED
        s = self._s2_since
        s[bad & np.isnan(s)] = t_s
        s[~bad] = np.nan
        alone = bad & (bad.sum(axis=1, keepdims=True) == 1)
        ripe = alone & (t_s - s >= self.tuning.stage2_persist_s - _EPS_S)
        self._exclude(ripe, t_s, BY_TABLE)
        est = (v == ESTIMATE_FAILED).any(axis=1)
        self.new_estimate_failed = est & ~(self.t_estimate_failed_s == self._last_t)
        self.t_estimate_failed_s[est] = t_s
        if est.any():                         # the prediction restarts from the estimate
            for e in self._hist:
                e[1][est], e[3][est] = zhat[est], y[est]

    def _innovation_stage(self, t_s) -> None:
        if not self._nis:
            return
        fails = self.innovation_fails(t_s) & self.used
        n_live = self.used.sum(axis=1)
        gnss = ((fails | ~self.used).all(axis=1) & (n_live > 1) & ~self.flags.any(axis=1)
                & ~self.gnss_failed)
        self.gnss_failed |= gnss
        self.t_gnss_s[gnss] = t_s
        doubt = self.nu.any(axis=1) | (n_live < self.n) | (self.isolated & self.used).any(1)
        one = (fails.sum(axis=1) == 1) & (n_live > 1) & doubt & ~self.gnss_failed
        self._exclude(fails & one[:, None], t_s, BY_INNOVATION)

    def _exclude(self, which: np.ndarray, t_s: float, reason: int) -> None:
        which = which & self.used
        self.used &= ~which
        self.isolated &= ~which
        self.new_exclude |= which
        self.excluded_by[which] = reason
        self.t_exclude_s[which] = np.fmin(self.t_exclude_s[which], t_s)
        hit = which.any(axis=1)
        self.t_detect_s[hit] = np.fmin(self.t_detect_s[hit], t_s)     # detected by stage 2

    def _remember(self, t_s, zhat, shat, y) -> None:
        self._last_t = t_s
        self._hist.append((t_s, zhat, shat, np.array(y, float), self.used.copy()))

    _last_t = np.nan


__all__ = ["BY_INNOVATION", "BY_TABLE", "TwoStage", "median_of_units"]
