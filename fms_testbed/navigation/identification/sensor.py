"""Stage 1 at sensor level over arrays: a step in the difference of two units' raw IMU outputs.

For each pair and channel (3 accelerometers, 3 gyros) the mean difference over a short window
(``accel_window_s`` / ``gyro_window_s``) is compared with its mean over the ``reference_s``
before: Δ = mean_short − mean_ref, σ_Δ² = σ_sample² (1/N_short + 1/N_ref) + σ_k² |Δu|², with
σ_sample² the two units' white-noise variances per sample (VRW/ARW densities over the sample
interval) and the last term the declared scale-factor/misalignment variance of the pair
(σ_k², dimensionless) times the change of the measured specific force or rate between the
windows (a manoeuvre changes the difference of two healthy units by that much). ν_ij = 1 when
some |Δ| > k_sensor σ_Δ, tested once both windows are full; windows are counted in samples of
the interval ``dt_s``. The window statistic is the generalised likelihood-ratio test of a mean
shift of unknown size in a window (Basseville & Nikiforov 1993, § 2.4).

With ``sensor_test = "cusum"`` the statistic is instead Page's two-sided CUSUM of each sample
against the reference window's prediction of it (Basseville & Nikiforov § 2.2, the test
Lorden's bound T* is the delay of), for a design change Δ (``cusum_accel_mps2``,
``cusum_gyro_rps``). A manoeuvre changes the difference of two healthy units by c · u (c, per
axis: the two units' scale-factor and misalignment difference; u the measured force or rate):
not white noise but a bias held as long as the manoeuvre, which a CUSUM accumulates sample
after sample whatever variance it is given. The reference window therefore estimates c too —
the regression of the difference on u with the declared prior c ~ N(0, σ_k² I) (posterior
mean and covariance; ū, d̄ the window means, S_uu = Σ (u − ū)(u − ū)ᵀ, S_du = Σ (d − d̄)(u − ū)ᵀ)::

    A = S_uu + (σ_sample² / σ_k²) I,   ĉ = S_du A⁻¹,   P_c = σ_sample² A⁻¹
    e = x − d̄ − ĉ (u − ū),   b = κ √((u − ū)ᵀ P_c (u − ū))
    g± ← max(0, g± + Δ (±e − b − Δ/2) / σ_sample²),   ν_ij = 1 while some g > cusum_h

— what the window could not resolve of c (a manoeuvre it has not seen) is a bounded nuisance
bias: up to κ (``cusum_kappa``) of its posterior σ is taken off the excess before it
accumulates (the CUSUM of the least favourable bias inside that bound).

The reference lags the statistic by the short window only, so a step would enter the
regression (as d̄, or in a turn as ĉ · u) while the CUSUM is still accumulating it. While a
pair's g on some axis of a group exceeds ``cusum_freeze`` × ``cusum_h`` the pair keeps the
reference (d̄, ĉ, A⁻¹, ū) it had when it crossed that level; below it, the live reference is
used again.
"""

from __future__ import annotations

import numpy as np

from fms_testbed.navigation.identification.rules import PAIRS
from fms_testbed.navigation.identification.tuning import FdiTuning


class _Ring:
    """A running sum over the last ``n`` rows of shape ``shape``."""

    def __init__(self, n: int, shape: tuple):
        self.n, self.buf = n, np.zeros((n,) + shape)
        self.sum, self.i, self.count = np.zeros(shape), 0, 0

    def push(self, v: np.ndarray) -> None:
        """Add row ``v``, dropping the oldest once ``n`` are held."""
        if self.count == self.n:
            self.sum -= self.buf[self.i]
        else:
            self.count += 1
        self.buf[self.i] = v
        self.sum += v
        self.i = (self.i + 1) % self.n


class SensorPairTest:
    """The step test on the pairwise differences of U units' raw IMU output errors in R
    realisations.

    Parameters
    ----------
    n_real : R;  n_units : U (2 or 3)
    q_white : (U, 6) white-noise densities: accelerometer VRW² ((m/s²)²·s), gyro ARW² (rad²/s)
    dt_s : sample interval, s
    sf_var : (U, 2) declared scale-factor + 2 × misalignment variance (accelerometer, gyro)
    tuning : ``sensor_test``, ``k_sensor``, ``accel_window_s``, ``gyro_window_s``,
        ``reference_s``, ``cusum_h``, ``cusum_kappa``, ``cusum_accel_mps2``, ``cusum_gyro_rps``

    Attributes
    ----------
    last_z : (R, pairs, 6) the last test statistics Δ / σ_Δ, or the CUSUM max(g+, g-) (0
        before the windows are full)
    """

    def __init__(self, n_real: int, n_units: int, q_white: np.ndarray, dt_s: float,
                 sf_var: np.ndarray, tuning: FdiTuning = FdiTuning()):
        self.tuning, self.n = tuning, n_units
        self.pairs = [p for p in PAIRS if p[1] < n_units]
        self.ia = [p[0] for p in self.pairs]
        self.ib = [p[1] for p in self.pairs]
        q, sf = np.asarray(q_white, float), np.asarray(sf_var, float)
        self.var = (q[self.ia] + q[self.ib]) / dt_s                      # (pairs, 6)
        self.sf = np.repeat(sf[self.ia] + sf[self.ib], 3, axis=1)        # (pairs, 6)
        P = len(self.pairs)
        self.groups = []
        for w in (tuning.accel_window_s, tuning.gyro_window_s):
            ns = max(1, int(round(w / dt_s)))
            nl = ns + max(1, int(round(tuning.reference_s / dt_s)))
            self.groups.append((_Ring(ns, (n_real, P, 3)), _Ring(nl, (n_real, P, 3)),
                                _Ring(ns, (3,)), _Ring(nl, (3,))))
        # the CUSUM's regression sums: u uᵀ (shared) and d uᵀ per realisation, pair and axis
        self.moments = ([(_Ring(g[0].n, (3, 3)), _Ring(g[1].n, (3, 3)),
                          _Ring(g[0].n, (n_real, P, 3, 3)), _Ring(g[1].n, (n_real, P, 3, 3)))
                         for g in self.groups] if tuning.sensor_test == "cusum" else [])
        self.last_z = np.zeros((n_real, P, 6))
        self.g = np.zeros((2, n_real, P, 6))                           # CUSUM g+, g-
        self.frozen: dict = {}            # per group: the reference (d̄, ĉ, A⁻¹, ū) in use
        self.design = np.repeat([tuning.cusum_accel_mps2, tuning.cusum_gyro_rps], 3)

    def update(self, errs: np.ndarray, f_mps2, w_rps) -> np.ndarray:
        """Add the raw output errors ``errs`` (R, U, 6: accelerometer m/s², gyro rad/s) with the
        measured specific force (3,) m/s² and rate (3,) rad/s; return (R, 3) bool
        (ν12, ν13, ν23), 0 for pairs beyond U."""
        errs = np.asarray(errs, float)
        if errs.ndim != 3 or errs.shape[1] < self.n or errs.shape[2] < 6:
            raise ValueError(f"sensor errors of shape {errs.shape}, not (R, {self.n}, 6)")
        d = errs[:, self.ia] - errs[:, self.ib]                          # (R, pairs, 6)
        bad = np.zeros(d.shape[:2], bool)
        for g, u in enumerate((np.asarray(f_mps2, float), np.asarray(w_rps, float))):
            short, long_, us, ul = self.groups[g]
            cols = slice(3 * g, 3 * g + 3)
            for ring, v in ((short, d[:, :, cols]), (long_, d[:, :, cols]), (us, u), (ul, u)):
                ring.push(v)
            if self.moments:
                uus, uul, dus, dul = self.moments[g]
                uu, du_ = np.outer(u, u), d[:, :, cols, None] * u
                for ring, v in ((uus, uu), (uul, uu), (dus, du_), (dul, du_)):
                    ring.push(v)
            if long_.count < long_.n:
                continue
            if self.tuning.sensor_test == "cusum":
                bad |= self._cusum(g, d[:, :, cols], u, short, long_, us, ul)
                continue
            ns, nr = short.n, long_.n - short.n
            delta = short.sum / ns - (long_.sum - short.sum) / nr
            du = us.sum / ns - (ul.sum - us.sum) / nr
            var = self.var[:, cols] * (1.0 / ns + 1.0 / nr) + self.sf[:, cols] * float(du @ du)
            z = delta / np.sqrt(var)
            self.last_z[:, :, cols] = z
            bad |= (np.abs(z) > self.tuning.k_sensor).any(axis=2)
        return self._by_pair(bad)

    def _cusum(self, g: int, x, u, short, long_, us, ul) -> np.ndarray:
        """One CUSUM step of group ``g`` (0 accelerometers, 1 gyros) on the samples ``x``
        (R, pairs, 3) against the reference window's prediction; (R, pairs) bool alarms."""
        cols = slice(3 * g, 3 * g + 3)
        uus, uul, dus, dul = self.moments[g]
        nr = long_.n - short.n
        d_bar = (long_.sum - short.sum) / nr                             # (R, P, 3)
        u_bar = (ul.sum - us.sum) / nr                                   # (3,)
        Suu = (uul.sum - uus.sum) - nr * np.outer(u_bar, u_bar)
        Sdu = (dul.sum - dus.sum) - nr * d_bar[..., None] * u_bar        # (R, P, 3, 3)
        var = self.var[:, cols]                                          # (P, 3)
        lam = var / np.maximum(self.sf[:, cols], 1e-30)
        Ainv = np.linalg.inv(Suu + lam[..., None, None] * np.eye(3))     # (P, 3, 3, 3)
        c_hat = np.einsum("rpaj,pajk->rpak", Sdu, Ainv)
        gp, gm = self.g[0][..., cols], self.g[1][..., cols]
        # a pair whose CUSUM is above the freeze level keeps the reference it had before
        live = np.maximum(gp, gm).max(axis=2) <= self.tuning.cusum_freeze * self.tuning.cusum_h
        R = x.shape[0]
        if g not in self.frozen:
            self.frozen[g] = (np.broadcast_to(d_bar, (R,) + d_bar.shape[1:]).copy(),
                              c_hat.copy(),
                              np.broadcast_to(Ainv, (R,) + Ainv.shape).copy(),
                              np.broadcast_to(u_bar, (R, len(self.pairs), 3)).copy())
        fd, fc, fA, fu = self.frozen[g]
        fd[live], fc[live], fu[live] = d_bar[live], c_hat[live], u_bar
        fA[live] = np.broadcast_to(Ainv, (R,) + Ainv.shape)[live]
        du = u - fu                                                      # (R, P, 3)
        mu = fd + np.einsum("rpaj,rpj->rpa", fc, du)
        b = self.tuning.cusum_kappa * np.sqrt(np.maximum(
            var * np.einsum("rpj,rpajk,rpk->rpa", du, fA, du), 0.0))
        dd = self.design[cols]
        e = x - mu
        np.maximum(gp + dd * (e - b - 0.5 * dd) / var, 0.0, out=gp)
        np.maximum(gm + dd * (-e - b - 0.5 * dd) / var, 0.0, out=gm)
        stat = np.maximum(gp, gm)
        self.g[0][..., cols], self.g[1][..., cols] = gp, gm
        self.last_z[:, :, cols] = stat
        return (stat > self.tuning.cusum_h).any(axis=2)

    def _by_pair(self, bad: np.ndarray) -> np.ndarray:
        """(R, pairs) → (R, 3) in the order of :data:`.rules.PAIRS`."""
        out = np.zeros((bad.shape[0], 3), bool)
        for p, pair in enumerate(self.pairs):
            out[:, PAIRS.index(pair)] = bad[:, p]
        return out


__all__ = ["SensorPairTest"]
