"""The numpy two-stage identification the compiled step replaced, kept as the straightforward
reference of the equivalence test: the rules as array expressions of
:mod:`fms_testbed.navigation.identification.rules` over (R, U, C), on the state of
:class:`~fms_testbed.navigation.identification.two_stage.TwoStage`."""

from __future__ import annotations

import numpy as np

from fms_testbed.navigation.identification.rules import (ESTIMATE_FAILED, PAIRS, UNIT_FAILED,
                                                         exceeds, fuse, named_unit, ratio,
                                                         three_way, wrapped_difference)
from fms_testbed.navigation.identification.two_stage import (_EPS_S, BY_INNOVATION, BY_TABLE,
                                                             TwoStage)

def pair_flags(y, sig, k, live=None, mask=None) -> np.ndarray:
    """(R, 3) bool (ν12, ν13, ν23) of one instant: :func:`exceeds` per pair of live units."""
    R, U = y.shape[:2]
    out = np.zeros((R, 3), bool)
    for p, (a, b) in enumerate(PAIRS):
        if b < U:
            out[:, p] = exceeds(y[:, a], y[:, b], sig[:, a], sig[:, b], k, mask)
            if live is not None:
                out[:, p] &= live[:, a] & live[:, b]
    return out


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


class TwoStageNumpy(TwoStage):
    """:class:`TwoStage` with :meth:`update` in numpy expressions (one call per rule)."""

    def update(self, t_s: float, y: np.ndarray, sig: np.ndarray,
               nu_sensor: np.ndarray | None = None, mask: np.ndarray | None = None) -> None:
        """Both stages at ``t_s`` (s), as :meth:`TwoStage.update` (same arguments)."""
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

    def _prediction_np(self, t_s: float, y: np.ndarray):
        """Ẑ_p, σ_p from the estimate ``predict_s`` ago (None until there is one)."""
        h = self._hist
        while len(h) > 1 and h[1][0] <= t_s - self.tuning.predict_s + _EPS_S:
            h.pop(0)
        if not h or h[0][0] > t_s - self.tuning.predict_s + _EPS_S:
            return None
        _, z0, s0, y0, live0 = h[0]
        return z0 + median_of_units(wrapped_difference(y, y0), live0), s0

    def _stage2(self, t_s, y, sig, zhat, shat, mask) -> None:
        pred = self._prediction_np(t_s, y)
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

    def innovation_fails(self, t_s: float) -> np.ndarray:
        """(R, U) bool: the windowed χ² test fails; records its statistic's maximum."""
        r = self._innovation_ratio(t_s)
        if r is None:
            return np.zeros(self.used.shape, bool)
        live = self.used & ~self.gnss_failed[:, None]
        np.maximum(self.stat_max[:, 3], np.where(live, r, 0.0).max(axis=1),
                   out=self.stat_max[:, 3])
        return r > self.tuning.innovation_scale


__all__ = ["TwoStageNumpy", "median_of_units"]
