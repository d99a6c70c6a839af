"""Seed 001's two-stage identification (:class:`~.fdi.TwoStageFdi`) on arrays of R realisations at
once, for the Monte-Carlo engine (:mod:`.montecarlo`).

:class:`~.fdi.TwoStageFdi` holds one realisation's state in Python lists and dicts, so it cannot run
over arrays; :class:`ArrayFdi` applies the same rules with the same tuning (:class:`~.fdi.FdiTuning`),
the same majority table (:data:`~.fdi.MAJORITY`, :data:`~.fdi.PAIRS`) and the same χ² quantile, on
(R, 3, 9) comparison vectors. Its single entry point :meth:`ArrayFdi.update` is the one place the
engine calls the decision logic; ``tests/navigation/test_array_fdi.py`` checks, realisation by
realisation, that it takes the decisions :class:`~.fdi.TwoStageFdi` takes on the same inputs.

Rules (per realisation, as :meth:`TwoStageFdi.update`): stage 1 ν_ij = 1 when some channel of
y_i - y_j exceeds k_pair √(σ_i² + σ_j²) for ``persist_s`` (or the sensor-level pair verdict, on
pairs of units in use); with three units in use the majority table names a suspect, excluded when
its innovation window fails the χ² test, when it disagrees with the mean of the others beyond
k_est √(σ_i² + σ̄²), or after ``isolate_s`` of being named; otherwise, when some ν is set or fewer
than three units are in use, a unit whose innovation window fails alone is excluded.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2

from fms_testbed.navigation.fdi import MAJORITY, PAIRS, FdiTuning

_SUSPECT = np.full(8, -1)
for _nu, _unit in MAJORITY.items():
    _SUSPECT[_nu[0] + 2 * _nu[1] + 4 * _nu[2]] = _unit


class ArrayFdi:
    """Two-stage identification of three units over R realisations.

    Parameters
    ----------
    n_real : R;  tuning : thresholds (those of :class:`~.fdi.TwoStageFdi`)

    Attributes
    ----------
    used : (R, 3) bool, units in use;  nu : (R, 3) int, current (ν12, ν13, ν23)
    t_detect_s, t_isolate_s, t_exclude_s : (R,), (R, 3), (R, 3) first detection / isolation /
        exclusion times, s (NaN: never)
    """

    n = 3

    def __init__(self, n_real: int, tuning: FdiTuning = FdiTuning()):
        self.tuning = tuning
        self.used = np.ones((n_real, 3), bool)
        self.nu = np.zeros((n_real, 3), np.int64)
        self._since = np.full((n_real, 3), np.nan)             # pair first disagreed, s
        self._suspect = np.full(n_real, -1)
        self._suspect_t = np.full(n_real, np.nan)
        self._nis: list[tuple[float, np.ndarray, int]] = []     # (t_s, NIS (R, 3), dim)
        self.t_detect_s = np.full(n_real, np.nan)
        self.t_isolate_s = np.full((n_real, 3), np.nan)
        self.t_exclude_s = np.full((n_real, 3), np.nan)

    def add_innovation(self, t_s: float, nis: np.ndarray, dim: int) -> None:
        """Record every realisation's and unit's NIS (R, 3) of a group of dimension ``dim``."""
        self._nis.append((t_s, nis, dim))

    def innovation_fails(self, t_s: float) -> np.ndarray:
        """(R, 3) bool: the windowed χ² test of each unit's innovations fails (stage 2)."""
        buf = self._nis
        while buf and buf[0][0] < t_s - self.tuning.window_s:
            buf.pop(0)
        if not buf:
            return np.zeros(self.used.shape, bool)
        total = sum(b[1] for b in buf)
        return total > chi2.isf(self.tuning.alpha, sum(b[2] for b in buf))

    def _prediction_fails(self, y: np.ndarray, sig: np.ndarray, used: np.ndarray) -> np.ndarray:
        """(r, 3) bool: unit i against the mean of the other units in ``used`` (stage 2)."""
        out = np.zeros(used.shape, bool)
        u = used.astype(float)
        for i in range(3):
            w = u.copy()
            w[:, i] = 0.0
            cnt = w.sum(axis=1)
            ok = cnt > 0
            c = np.where(ok, cnt, 1.0)[:, None]
            ym = np.einsum("rj,rjc->rc", w, y) / c
            sm2 = np.einsum("rj,rjc->rc", w, sig ** 2) / c
            d = y[:, i] - ym
            d[:, 8] = np.remainder(d[:, 8] + math.pi, 2 * math.pi) - math.pi
            out[:, i] = ok & (np.abs(d) > self.tuning.k_est * np.sqrt(sig[:, i] ** 2 + sm2)).any(1)
        return out

    def update(self, t_s: float, y: np.ndarray, sig: np.ndarray, nu_sensor: np.ndarray) -> None:
        """Both stages at ``t_s`` (s): ``y`` (R, 3, 9) comparison vectors (position m, velocity
        m/s, roll/pitch/heading rad, common offsets cancel), ``sig`` (R, 3, 9) their σ, and the
        sensor-level pair verdicts ``nu_sensor`` (R, 3); updates :attr:`used` and the times."""
        tu = self.tuning
        R = y.shape[0]
        nu_out = np.zeros((R, 3), np.int64)
        live_pair = np.zeros((R, 3), bool)
        for k, (a, b) in enumerate(PAIRS):
            live = self.used[:, a] & self.used[:, b]
            live_pair[:, k] = live
            d = y[:, a] - y[:, b]
            d[:, 8] = np.remainder(d[:, 8] + math.pi, 2 * math.pi) - math.pi
            bad = (np.abs(d) > tu.k_pair * np.sqrt(sig[:, a] ** 2 + sig[:, b] ** 2)).any(axis=1)
            s = self._since[:, k]
            start = live & bad & np.isnan(s)
            s[start] = t_s
            s[live & ~bad] = np.nan
            nu_out[:, k] = live & bad & (t_s - s >= tu.persist_s - 1e-9)
        nu = (nu_out.astype(bool) | (np.asarray(nu_sensor, bool) & live_pair)).astype(np.int64)
        newly = nu.any(axis=1) & ~self.nu.any(axis=1) & np.isnan(self.t_detect_s)
        self.t_detect_s[newly] = t_s
        self.nu = nu
        n_live = self.used.sum(axis=1)
        sus = np.where(n_live == 3, _SUSPECT[nu[:, 0] + 2 * nu[:, 1] + 4 * nu[:, 2]], -1)
        changed = (sus >= 0) & (sus != self._suspect)
        self._suspect_t[changed] = t_s
        self._suspect = sus
        self._suspect_t[sus < 0] = np.nan
        has = np.nonzero(sus >= 0)[0]
        innov = None
        if has.size or (nu.any(axis=1) | (n_live < 3)).any():
            innov = self.innovation_fails(t_s)
        if has.size:
            su = sus[has]
            iso = self.t_isolate_s[has, su]
            self.t_isolate_s[has, su] = np.where(np.isnan(iso), t_s, iso)
            pred = self._prediction_fails(y[has], sig[has], self.used[has])
            fail = innov[has, su] | pred[np.arange(has.size), su]
            timed = t_s - self._suspect_t[has] >= tu.isolate_s - 1e-9
            ex = fail | timed
            self._exclude(has[ex], su[ex], t_s)
        rest = np.nonzero((sus < 0) & (nu.any(axis=1) | (n_live < 3)))[0]
        if rest.size:
            fails = innov[rest] & self.used[rest]
            one = (fails.sum(axis=1) == 1) & (n_live[rest] > 1)
            self._exclude(rest[one], np.argmax(fails[one], axis=1), t_s)

    def _exclude(self, r: np.ndarray, unit: np.ndarray, t_s: float) -> None:
        self.used[r, unit] = False
        first = np.isnan(self.t_exclude_s[r, unit])
        self.t_exclude_s[r[first], unit[first]] = t_s


class ArraySensorComparator:
    """:class:`~.fdi.SensorComparator` on R realisations: the step test on the pairwise
    differences of the units' raw IMU output errors, same windows, variances and threshold.

    Parameters
    ----------
    n_real : R;  q_white : (3, 6) white-noise densities;  dt_s : sample interval, s
    sf_var : (3, 2) declared scale-factor + 2 × misalignment variances;  tuning : thresholds
    """

    def __init__(self, n_real: int, q_white: np.ndarray, dt_s: float, sf_var: np.ndarray,
                 tuning: FdiTuning = FdiTuning()):
        self.tuning = tuning
        ia = [p[0] for p in PAIRS]
        ib = [p[1] for p in PAIRS]
        self.ia, self.ib = ia, ib
        q = np.asarray(q_white, float)
        sf = np.asarray(sf_var, float)
        self.var = (q[ia] + q[ib]) / dt_s                              # (3 pairs, 6)
        self.sf = np.repeat(sf[ia] + sf[ib], 3, axis=1)
        self.groups = []
        for w in (tuning.accel_window_s, tuning.gyro_window_s):
            ns = max(1, int(round(w / dt_s)))
            nl = ns + max(1, int(round(tuning.reference_s / dt_s)))
            self.groups.append({"ns": ns, "nl": nl, "count": 0, "i_s": 0, "i_l": 0,
                                "ds": np.zeros((ns, n_real, 3, 3)), "dl": np.zeros((nl, n_real, 3, 3)),
                                "sds": np.zeros((n_real, 3, 3)), "sdl": np.zeros((n_real, 3, 3)),
                                "us": np.zeros((ns, 3)), "ul": np.zeros((nl, 3)),
                                "sus": np.zeros(3), "sul": np.zeros(3), "cs": 0})

    @staticmethod
    def _push(buf, s, i, count, v):
        n = buf.shape[0]
        if count == n:
            s -= buf[i]
        buf[i] = v
        s += v
        return (i + 1) % n

    def update(self, errs: np.ndarray, f_mps2, w_rps) -> np.ndarray:
        """Add the errors (R, 3, 6) with the measured specific force (3,) and rate (3,);
        return the pair verdicts (R, 3)."""
        d = errs[:, self.ia] - errs[:, self.ib]
        bad = np.zeros(d.shape[:2], bool)
        for g, u in enumerate((np.asarray(f_mps2, float), np.asarray(w_rps, float))):
            G = self.groups[g]
            cols = slice(3 * g, 3 * g + 3)
            ns, nl = G["ns"], G["nl"]
            dv = d[:, :, cols]
            G["i_s"] = self._push(G["ds"], G["sds"], G["i_s"], min(G["count"], ns), dv)
            G["i_l"] = self._push(G["dl"], G["sdl"], G["i_l"], G["count"], dv)
            self._push(G["us"], G["sus"], (G["i_s"] - 1) % ns, min(G["count"], ns), u)
            self._push(G["ul"], G["sul"], (G["i_l"] - 1) % nl, G["count"], u)
            G["count"] = min(G["count"] + 1, nl)
            if G["count"] < nl:
                continue
            nr = nl - ns
            delta = G["sds"] / ns - (G["sdl"] - G["sds"]) / nr
            du = G["sus"] / ns - (G["sul"] - G["sus"]) / nr
            var = self.var[:, cols] * (1.0 / ns + 1.0 / nr) + self.sf[:, cols] * float(du @ du)
            bad |= (np.abs(delta / np.sqrt(var)) > self.tuning.k_sensor).any(axis=2)
        return bad.astype(np.int64)


__all__ = ["ArrayFdi", "ArraySensorComparator"]
