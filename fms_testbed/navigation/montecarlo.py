"""Monte-Carlo engine of the three-INS / GNSS / baro navigation: R realisations at once, as numpy
arrays over realisations (``fms-testbed montecarlo``).

What one realisation is — the same models as the per-flight source
(:class:`~.ins_gnss.InsGnssNavigation` with ``n_ins: 3``), in the error domain:

* three INS units: the 33-state SINS error model (free vertical channel, stationary alignment,
  x_k = Φ x + S N_k, :mod:`fms_testbed.navigation.sins`), fed back by their filters;
* the GNSS receiver (:mod:`fms_testbed.sensors.gnss`: Markov position/velocity errors propagated
  exactly between epochs, white noise, latency, outages, ramps) and the baro
  (:mod:`fms_testbed.sensors.baro`: Markov bias + white noise);
* one error-state filter per unit (:mod:`.ins_filter`: 22 states, innovation gate, the
  delayed-measurement correction of :func:`~.kalman.correct_delayed` for GNSS, Joseph form for
  the baro, feedback of the INS block at every used fix);
* the raw IMU output errors and the two-stage identification
  (:class:`~.identification.two_stage.TwoStage` over all realisations at once — the same object
  the per-flight source holds with R = 1), the GNSS and baro checks of the different-type rules
  (every unit's innovations failing together names the GNSS; every unit's baro residual, the
  baro); the output is the mean of the units the identification keeps;
* the majority-voting baseline on the **raw** outputs: a copy of each unit's error without
  feedback (the free inertial solution), voted with table 1 at ε_N = k_pair √2 σ_free (σ_free
  from the declared model propagated along the route); its output is the mean of the voted
  units' corrected outputs (NSE histogram beside the identified output's).

Since the error model is linear, the measurements are differences of errors (z_p = δp_INS(t_m) -
δp_GNSS(t_m), z_v likewise, z_h = δh_INS - δh_baro) and no geodetic solution is formed.

Vectorisation (what differs from the per-flight source, and why it does not matter):

* Φ_k, S_k of the truth model depend only on the true trajectory and the IMU model: computed
  once per step for all 3 R units (the per-flight bank shares them between its units too).
* The filters' F is built at the **true** state, not at each unit's indicated state: the INS
  error (metres, milliradians) changes F by a relative 1e-5..1e-3 of entries that are
  themselves small (Coriolis, specific-force cross products) — far below what the covariance is
  sensitive to. Then Φ_k, Q_k are shared by all filters, and so is P as long as two filters took
  the same gate decisions: filters are kept in *covariance groups* (one P per group, split when a
  gate accepts a measurement for some members and rejects it for others), so a fault-free run
  carries about one P for all 3 R filters, exactly as R separate filters would.

Seeds: realisation i draws every random number from its own generator
``default_rng(SeedSequence([seed, i]))`` — its initial errors first, then blocks of
:data:`BLOCK_STEPS` steps of process, sensor and fix noise — so its numbers do not depend on how
many realisations run together (``chunk``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.navigation.fdi import channel_sigmas, unmodelled_variances
from fms_testbed.navigation.identification.rules import pair_flags, vote
from fms_testbed.navigation.identification.sensor import SensorPairTest
from fms_testbed.navigation.identification.two_stage import TwoStage
from fms_testbed.navigation.ins_filter import N_INS, InsGnssFilter, _filter_phi_q
from fms_testbed.navigation.montecarlo_model import (_NSE_EDGES_M, BLOCK_STEPS, FAULT_KINDS,
                                                     N_UNITS, McConfig, McFault, McResult,
                                                     percentile_from_hist, realisation_rng)
from fms_testbed.navigation.sins import _sins_step
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.analysis import SinsOptions, horizontal_radius, initial_map
from fms_testbed.sensors.sins.euler import eps_to_euler_errors
from fms_testbed.sensors.sins.presets import ImuModel, load_imu
from fms_testbed.sensors.sins.simulate import FACTOR_RTOL


def _group_update(P, gidx, xhat, z, Hm, R, q_lag, gate, allow=None):
    """One measurement group for all members (flattened realisation × unit) at once.

    Per covariance group g: C = (P_g - Q_lag) H_mᵀ, S = H_m C + R, K = C S⁻¹ (the
    delayed-measurement correction of :func:`~.kalman.correct_delayed`; Φ = I, Q_lag = 0 is the
    Joseph form); per member ν = z - H_m x̂, NIS = νᵀ S⁻¹ ν, gate |ν_i| ≤ gate √S_ii, and x̂ += K ν
    when it passes (and ``allow`` (M,), if given, is true). A group whose members disagree at
    the gate is split: the members that rejected keep the predicted P in a new group. Returns
    (P, gidx, NIS (M,), used (M,))."""
    G = P.shape[0]
    C = (P - q_lag) @ Hm.T                               # (G, n, m)
    S = Hm @ C + R
    S = 0.5 * (S + np.swapaxes(S, 1, 2))
    Si = np.linalg.inv(S)
    K = C @ Si                                           # (G, n, m)
    nu = z - xhat @ Hm.T                                 # (M, m)
    nis = np.einsum("mi,mij,mj->m", nu, Si[gidx], nu)
    sd = np.sqrt(np.diagonal(S, axis1=1, axis2=2))       # (G, m)
    ok = (np.abs(nu) <= gate * sd[gidx]).all(axis=1)
    if allow is not None:
        ok &= allow
    xhat[ok] += np.einsum("mij,mj->mi", K[gidx[ok]], nu[ok])
    KC = K @ np.swapaxes(C, 1, 2)
    Pn = P - KC - np.swapaxes(KC, 1, 2) + K @ S @ np.swapaxes(K, 1, 2)
    Pn = 0.5 * (Pn + np.swapaxes(Pn, 1, 2))
    n_ok = np.bincount(gidx[ok], minlength=G)
    n_all = np.bincount(gidx, minlength=G)
    out = np.where((n_ok > 0)[:, None, None], Pn, P)
    mixed = (n_ok > 0) & (n_ok < n_all)
    if mixed.any():
        new = np.cumsum(mixed) - 1 + G                   # new group of each mixed group
        move = ~ok & mixed[gidx]
        gidx = gidx.copy()
        gidx[move] = new[gidx[move]]
        out = np.concatenate([out, P[mixed]])
    return out, gidx, nis, ok


def _channel_update(P, gidx, xhat, z, Hm, R, q_lag, k, allow, hold_rows, hold_comp, no_alt):
    """Seed 001's fault-tolerant correction (eq. 8) for all members at once, per component.

    ν = z − H_m x̂; component i is used when |ν_i| ≤ k √S_ii (and ``allow`` (M,)): the gain
    K = C S⁻¹ of :func:`_group_update` has the columns of the failed components zeroed, and, for
    members with ``no_alt`` (M,) whose component ``hold_comp`` failed, the rows ``hold_rows``
    (n,) bool as well — those states keep their prediction (the vertical channel held). P is
    corrected with that gain in the Joseph form (P − K Cᵀ − C Kᵀ + K S Kᵀ, valid for any K);
    members of a covariance group that take different gains are split into groups. Returns
    (P, gidx, NIS over the used components (M,), their count (M,), used (M,))."""
    C = (P - q_lag) @ Hm.T
    S = Hm @ C + R
    S = 0.5 * (S + np.swapaxes(S, 1, 2))
    nu = z - xhat @ Hm.T
    sd = np.sqrt(np.diagonal(S, axis1=1, axis2=2))
    ok = (np.abs(nu) <= k * sd[gidx]) & allow[:, None]
    freeze = no_alt & ~ok[:, hold_comp]
    code = (ok * (1 << np.arange(ok.shape[1]))).sum(axis=1) * 2 + freeze
    keys, new_g = np.unique(np.stack([gidx, code], axis=1), axis=0, return_inverse=True)
    new_g = new_g.ravel()
    out = np.empty((keys.shape[0],) + P.shape[1:])
    nis = np.zeros(ok.shape[0])
    for j, (g, c) in enumerate(keys):
        use = np.array([(c >> (i + 1)) & 1 for i in range(ok.shape[1])], bool)
        K = np.zeros_like(C[g])
        if use.any():
            Si = np.linalg.inv(S[g][np.ix_(use, use)])
            K[:, use] = C[g][:, use] @ Si
        if c & 1:
            K[hold_rows] = 0.0
        KC = K @ C[g].T
        Pn = P[g] - KC - KC.T + K @ S[g] @ K.T
        out[j] = 0.5 * (Pn + Pn.T)
        mem = new_g == j
        xhat[mem] += nu[mem] @ K.T
        if use.any():
            nis[mem] = np.einsum("mi,ij,mj->m", nu[mem][:, use], Si, nu[mem][:, use])
    return out, new_g.astype(gidx.dtype), nis, ok.sum(axis=1), ok.any(axis=1)


def _compact(P, gidx):
    """Drop covariance groups without members."""
    keep, inv = np.unique(gidx, return_inverse=True)
    if keep.size == P.shape[0]:
        return P, gidx
    return P[keep], inv.astype(gidx.dtype)


NL = 33
"""States of the truth model per unit."""

_HOLD_VERTICAL = np.zeros(22, bool)
_HOLD_VERTICAL[[2, 5, 21]] = True
"""Filter states held when the vertical channel has no altitude measurement: δh, δV_U and the
baro bias (seed 001: ẑ_H and Ŵ_Z frozen)."""


class _Batch:
    """Run-time state of one batch of R realisations (truth, sensors, filters, decisions,
    statistics). Built by :meth:`MonteCarlo._start`, advanced by the engine's step functions."""

    def __init__(self, mc: "MonteCarlo", idx: np.ndarray):
        Rn, U, n, imu, cfg, f0 = idx.size, N_UNITS, mc.n, mc.imu, mc.cfg, mc.filt
        self.idx, self.Rn, self.M = idx, Rn, Rn * U
        self.rngs = [realisation_rng(mc.seed, i) for i in idx]
        s0 = mc.states[0]
        init = np.array([g.standard_normal(U * NL + 7) for g in self.rngs])
        A = initial_map(s0.lat_rad, (s0.roll_rad, s0.pitch_rad, s0.heading_rad), imu,
                        SinsOptions())
        z0 = init[:, :U * NL].reshape(Rn, U, NL) * np.sqrt(imu.p0_var)
        self.X = (z0 @ A.T).reshape(self.M, NL)
        self.X_free = self.X.copy()                      # no feedback: the raw outputs
        self.P_free = (A * imu.p0_var) @ A.T             # their declared covariance
        gs, bs = cfg.gnss, cfg.baro
        self.markov = gs.markov_sigma * init[:, U * NL:U * NL + 6]
        self.bias = bs.markov_sigma_m * init[:, U * NL + 6]
        f0.initialise(NavSolution(s0.t_s, s0.lat_rad, s0.lon_rad, s0.alt_m,
                                  np.asarray(s0.v_enu_mps), s0.roll_rad, s0.pitch_rad,
                                  s0.heading_rad, {}))
        self.P, self.gidx = f0.P[None].copy(), np.zeros(self.M, np.int64)
        self.xhat, self.comp = np.zeros((self.M, n)), np.zeros((self.M, 6))
        self.fdi = TwoStage(Rn, U, cfg.fdi, track_stats=True)
        self.sensor: SensorPairTest | None = None
        self.sd_sensor = None
        self.next_fix = self.next_baro = s0.t_s
        self.t_markov = self.t_bias = None
        self.queue: list = []                            # (t_m, t_deliv, zp, zv)
        self.lag: list = []
        self.last_used = np.full(Rn, -math.inf)
        nb = len(_NSE_EDGES_M) - 1
        self.hist_g, self.hist_c, self.hist_v = (np.zeros(nb, np.int64) for _ in range(3))
        self.nse_max, self.out_max = np.zeros(Rn), np.full(Rn, np.nan)
        self.anp_out_max = np.full(Rn, np.nan)
        self.o_samples = self.o_nse = self.o_anp = 0
        self.groups_max = 1
        self.sf_var = np.array([unmodelled_variances(imu)] * U)
        self.noise = np.empty((Rn, BLOCK_STEPS, K_ALL))
        self.fault_on = False
        self.baro_step_m = 0.0
        self.drift_unit, self.drift_factor = -1, 1.0
        self.vote_in = np.zeros((Rn, U))
        self.vote_n = 0

    def result(self, mc: "MonteCarlo", fault, wall_s: float) -> McResult:
        """The batch's :class:`McResult`."""
        st, f = mc.states, self.fdi
        return McResult(self.idx, f.t_detect_s, f.t_isolate_s, f.t_exclude_s, self.nse_max,
                        self.out_max, self.anp_out_max, self.hist_g, self.hist_c,
                        self.o_samples, self.o_nse, self.o_anp, st[-1].t_s - st[0].t_s,
                        wall_s, self.groups_max, fault, f.t_gnss_s, f.t_baro_s, self.hist_v,
                        self.vote_in / max(self.vote_n, 1), f.stat_max)


K_INS = N_UNITS * NL + N_UNITS * 6
"""Normal draws per step for the INS process noise and the raw-sensor white noise."""
K_ALL = K_INS + 6 + 6 + 1 + 1
"""... plus the GNSS Markov and white noise and the baro bias and white noise."""


def _propagate(mc: "MonteCarlo", b: _Batch, p: AircraftState, t_s: float, nz) -> None:
    """Truth errors (with and without feedback), the filters and the raw-output envelope from
    ``p`` to ``t_s``."""
    imu, f0, n = mc.imu, mc.filt, mc.n
    dt = t_s - p.t_s
    rpy = np.array([p.roll_rad, p.pitch_rad, p.heading_rad])
    w_eb = np.array([p.p_rps, p.q_rps, p.r_rps])
    v, fb = np.asarray(p.v_enu_mps, float), np.asarray(p.f_body_mps2, float)
    _, phi, L, status = _sins_step(np.zeros(NL), np.zeros(NL), p.lat_rad, p.alt_m, v, rpy,
                                   w_eb, fb, imu.decay_rps, imu.q_psd, 0.0, 0.0, dt, 1e-12,
                                   FACTOR_RTOL)
    if status:
        raise ConfigError(f"montecarlo: truth model discretisation failed at t = {p.t_s} s "
                          f"(status {status})")
    w = nz[:, :N_UNITS * NL].reshape(b.Rn, N_UNITS, NL)
    if b.drift_unit >= 0:
        w = w.copy()
        w[:, b.drift_unit, 12:15] *= b.drift_factor
    drive = w.reshape(b.M, NL) @ L.T
    b.X = b.X @ phi.T + drive
    b.X_free = b.X_free @ phi.T + drive
    b.P_free = phi @ b.P_free @ phi.T + L @ L.T
    phf, qkf, status = _filter_phi_q(n, p.lat_rad, p.alt_m, v, rpy, w_eb, fb, f0._decay24,
                                     f0.decay, f0._process_noise(p), dt, 1e-12)
    if status:
        raise ConfigError(f"montecarlo: filter discretisation failed at t = {p.t_s} s")
    b.xhat = b.xhat @ phf.T
    b.P = phf @ b.P @ phf.T + qkf
    b.P = 0.5 * (b.P + np.swapaxes(b.P, 1, 2))
    b.lag.append((p.t_s, phf, qkf))
    del b.lag[:-64]
    if b.sensor is None:
        q_w = imu.q_psd[3:9]
        b.sd_sensor = np.sqrt(q_w / dt)
        b.sensor = SensorPairTest(b.Rn, N_UNITS, np.array([q_w] * N_UNITS), dt, b.sf_var,
                                  mc.cfg.fdi)


def _gnss_fix(mc: "MonteCarlo", b: _Batch, t: float, fx) -> None:
    """A GNSS fix taken at ``t`` (Markov exact between epochs, ramps, outlier bursts), queued
    for delivery after the latency unless in an outage."""
    gs = mc.cfg.gnss
    if t < b.next_fix - 1e-9:
        return
    if b.t_markov is not None:
        a = np.exp(-(t - b.t_markov) / gs.markov_tau_s)
        b.markov = a * b.markov + gs.markov_sigma * np.sqrt(1.0 - a * a) * fx[:, :6]
    b.t_markov = t
    white = np.array(gs.white_sigma, float) * np.ones(6)
    for o in gs.outliers:
        if t in o.during:
            white[:3] = np.hypot(white[:3], o.sigma_m)
    err = b.markov + white * fx[:, 6:12]
    for r in gs.ramps:
        err[:, :3] += r.offset_m(t)
    if not any(t in o for o in gs.outages):
        Xr = b.X.reshape(b.Rn, N_UNITS, NL)
        b.queue.append((t, t + gs.latency_s,
                        (Xr[:, :, 0:3] - err[:, None, :3]).reshape(b.M, 3),
                        (Xr[:, :, 3:6] - err[:, None, 3:6]).reshape(b.M, 3)))
    while b.next_fix <= t + 1e-9:
        b.next_fix += 1.0 / gs.rate_hz


def _deliver(mc: "MonteCarlo", b: _Batch, t: float) -> None:
    """The fixes due at ``t``: corrected at their time of validity for every filter (the
    realisations whose GNSS is named failed do not use them), then fed back."""
    f0, n = mc.filt, mc.n
    used_any = np.zeros(b.M, bool)
    allow = np.repeat(~b.fdi.gnss_failed, N_UNITS)
    while b.queue and b.queue[0][1] <= t + 1e-9:
        t_m, _, zp, zv = b.queue.pop(0)
        steps = [(ph, q) for t0, ph, q in b.lag if t0 >= t_m - 1e-9]
        if steps:
            phl, ql = steps[0]
            for ph, q in steps[1:]:
                phl, ql = ph @ phl, ph @ ql @ ph.T + q
            Hp = np.linalg.solve(phl.T, f0._H_pos.T).T
            Hv = np.linalg.solve(phl.T, f0._H_vel.T).T
        else:
            ql, Hp, Hv = np.zeros((n, n)), f0._H_pos, f0._H_vel
        for Hm, z, Rm in ((Hp, zp, f0._r_pos), (Hv, zv, f0._r_vel)):
            if mc.cfg.component_channels:
                b.P, b.gidx, nis, dof, ok = _channel_update(
                    b.P, b.gidx, b.xhat, z, Hm, Rm, ql, mc.cfg.fdi.k_residual, allow,
                    _HOLD_VERTICAL[:n], 2, np.repeat(b.fdi.baro_failed, N_UNITS))
            else:
                b.P, b.gidx, nis, ok = _group_update(b.P, b.gidx, b.xhat, z, Hm, Rm, ql,
                                                     mc.cfg.tuning.gate_sigma, allow)
                dof = np.where(allow, 3, 0)
            b.fdi.add_innovation(t, nis.reshape(b.Rn, N_UNITS), dof.reshape(b.Rn, N_UNITS))
            used_any |= ok
        b.last_used[used_any.reshape(b.Rn, N_UNITS).any(axis=1)] = t_m
    if used_any.any():
        dx = b.xhat[used_any, :N_INS]
        b.X[used_any, :N_INS] -= dx
        b.comp[used_any] += dx[:, 9:15]
        b.xhat[used_any, :N_INS] = 0.0


def _baro(mc: "MonteCarlo", b: _Batch, t: float, fx) -> None:
    """The baro reading at ``t`` for every filter (not once the baro is named failed) and the
    channel test of each unit's residual."""
    bs, f0 = mc.cfg.baro, mc.filt
    if t < b.next_baro - 1e-9:
        return
    while b.next_baro <= t + 1e-9:
        b.next_baro += 1.0 / bs.rate_hz
    if b.t_bias is not None:
        a = math.exp(-(t - b.t_bias) / bs.markov_tau_s)
        b.bias = a * b.bias + bs.markov_sigma_m * math.sqrt(1.0 - a * a) * fx[:, 12]
    b.t_bias = t
    err = b.bias + bs.white_sigma_m * fx[:, 13] + b.baro_step_m
    zb = b.X[:, 2] - np.repeat(err, N_UNITS)
    allow = np.repeat(~b.fdi.baro_failed, N_UNITS)
    b.P, b.gidx, nis, _ = _group_update(b.P, b.gidx, b.xhat, zb[:, None], f0._H_baro,
                                        f0._r_baro, np.zeros((mc.n, mc.n)),
                                        mc.cfg.tuning.gate_sigma, allow)
    b.fdi.add_baro_test(t, (nis > mc.cfg.fdi.k_residual ** 2).reshape(b.Rn, N_UNITS))


def _comparison(e: np.ndarray, s: AircraftState) -> np.ndarray:
    """(R, 3, 9) comparison vectors of navigation errors ``e`` (R, 3, 9: δp m, δV m/s, ε rad):
    position and velocity, then roll, pitch, heading errors (rad) at the true attitude."""
    dr, dp, dh = eps_to_euler_errors(e[..., 6], e[..., 7], e[..., 8], s.pitch_rad,
                                     s.heading_rad)
    return np.concatenate([e[..., :6], np.stack([dr, dp, dh], axis=-1)], axis=-1)


def _identify(mc: "MonteCarlo", b: _Batch, s: AircraftState, nz) -> np.ndarray:
    """Both stages on the corrected outputs and the raw sensor outputs; returns the corrected
    navigation errors (R, 3, 9)."""
    e = (b.X[:, :9] - b.xhat[:, :9]).reshape(b.Rn, N_UNITS, 9)
    y = _comparison(e, s)
    # the units' attitude: the truth's (their errors, < 0.1°, change σ by < 1e-3)
    n_load = float(np.linalg.norm(s.f_body_mps2)) / G0_MPS2
    sig_g = np.array([channel_sigmas(Pg, (b.sf_var[0, 0], b.sf_var[0, 1]), s.roll_rad,
                                     s.pitch_rad, n_load) for Pg in b.P])
    sig = sig_g[b.gidx].reshape(b.Rn, N_UNITS, 9)
    nu_s = None
    if b.sensor is not None:
        w = np.array([s.p_rps, s.q_rps, s.r_rps])
        f = np.asarray(s.f_body_mps2, float)
        errs = _sensor_errors(b.X.reshape(b.Rn, N_UNITS, NL), b.comp.reshape(b.Rn, N_UNITS, 6),
                              f, w, b.sd_sensor, nz[:, N_UNITS * NL:K_INS].reshape(b.Rn,
                                                                                 N_UNITS, 6))
        nu_s = b.sensor.update(errs, f, w)
        np.maximum(b.fdi.stat_max[:, 1], np.abs(b.sensor.last_z).max(axis=(1, 2)),
                   out=b.fdi.stat_max[:, 1])
    b.fdi.update(s.t_s, y, sig, nu_s)
    return e


def _vote_raw(mc: "MonteCarlo", b: _Batch, s: AircraftState, e: np.ndarray) -> np.ndarray:
    """The majority-voting baseline: table 1 of this instant on the raw (free inertial)
    outputs at ε_N = k_pair √2 σ_free; returns (R, 3) bool, the units voted in."""
    raw = _comparison(b.X_free[:, :9].reshape(b.Rn, N_UNITS, 9), s)
    d = np.sqrt(np.maximum(np.diag(b.P_free)[:9], 0.0))
    d[6] = d[7] = max(d[6], d[7])
    sig = np.broadcast_to(d, raw.shape)
    voted = vote(pair_flags(raw, sig, mc.cfg.fdi.k_pair), N_UNITS)
    if b.fault_on or mc._fault is None:
        b.vote_in += voted
        b.vote_n += 1
    eh = (e[..., :2] * voted[..., None]).sum(axis=1) / voted.sum(axis=1)[:, None]
    b.hist_v += np.histogram(np.hypot(eh[:, 0], eh[:, 1]), _NSE_EDGES_M)[0]
    return voted


def _output(mc: "MonteCarlo", b: _Batch, s: AircraftState, e: np.ndarray) -> None:
    """The output (mean of the units the identification keeps; the smallest position trace
    when it keeps none) and its statistics."""
    t, gs, P = s.t_s, mc.cfg.gnss, b.P
    used = b.fdi.output_units
    valid = used.any(axis=1)
    g2 = b.gidx.reshape(b.Rn, N_UNITS)
    tr = np.trace(P[:, :3, :3], axis1=1, axis2=2)[g2]
    pick = np.where(valid[:, None], used,
                    np.arange(N_UNITS)[None] == np.argmin(tr, 1)[:, None])
    cnt = pick.sum(axis=1)
    eh = (e[..., :2] * pick[..., None]).sum(axis=1) / cnt[:, None]
    nse = np.hypot(eh[:, 0], eh[:, 1])
    np.maximum(b.nse_max, nse, out=b.nse_max)
    coast = t - b.last_used > 2.0 / gs.rate_hz + gs.latency_s + 1e-6
    b.hist_g += np.histogram(nse[~coast], _NSE_EDGES_M)[0]
    b.hist_c += np.histogram(nse[coast], _NSE_EDGES_M)[0]
    if any(t in o for o in gs.outages):
        ph = np.stack([P[:, 0, 0], P[:, 1, 1], P[:, 0, 1]], axis=1)[g2]     # (R, U, 3)
        pm = (ph * pick[..., None]).sum(axis=1) / cnt[:, None]
        uniq, inv = np.unique(pm, axis=0, return_inverse=True)
        anp = np.array([horizontal_radius(*row) for row in uniq])[inv.ravel()]
        b.out_max = np.fmax(b.out_max, nse)
        b.anp_out_max = np.fmax(b.anp_out_max, anp)
        b.o_samples += b.Rn
        b.o_nse += int((nse <= mc.cfg.rnp_m).sum())
        b.o_anp += int((anp <= mc.cfg.rnp_m).sum())


def _inject(mc: "MonteCarlo", b: _Batch, t: float, fault: McFault) -> None:
    """The fault at its time (detection times then count from it)."""
    Xr = b.X.reshape(b.Rn, N_UNITS, NL)
    Xf = b.X_free.reshape(b.Rn, N_UNITS, NL)
    if fault.kind in ("gyro_bias_step", "accel_bias_step"):
        j, d = fault.delta()
        Xr[:, fault.unit, j] += d
        Xf[:, fault.unit, j] += d
    elif fault.kind == "gyro_drift_scale":
        excess = (fault.size - 1.0) * np.sqrt(mc.imu.p0_var[12:15])
        Xr[:, fault.unit, 12:15] += excess
        Xf[:, fault.unit, 12:15] += excess
        b.drift_unit, b.drift_factor = fault.unit, float(fault.size)
    else:                                                    # baro_step
        b.baro_step_m = float(fault.size)
    b.fdi.t_detect_s[:] = np.nan
    b.fault_on = True


class MonteCarlo:
    """R realisations of the three-INS navigation along one true trajectory.

    Parameters
    ----------
    states : the true trajectory (:class:`~fms_testbed.core.state.AircraftState`, uniform step)
    cfg : the models;  seed : the run seed
    """

    def __init__(self, states: list[AircraftState], cfg: McConfig = McConfig(), seed: int = 0):
        if len(states) < 2:
            raise ConfigError("montecarlo: the trajectory needs at least 2 samples")
        self.states, self.cfg, self.seed = states, cfg, int(seed)
        self.imu: ImuModel = load_imu(cfg.imu)
        self.filt = InsGnssFilter(self.imu, cfg.gnss, cfg.baro, cfg.tuning)
        self.n = self.filt.n
        self._fault: McFault | None = None

    def run(self, indices, fault: McFault | None = None, progress=None, probe=None) -> McResult:
        """Run realisations ``indices`` (their seeds: :func:`realisation_rng`) together, on one
        BLAS thread (OpenBLAS threads make these small products many times slower on a busy
        machine: :mod:`fms_testbed.sensors.sins._blas`). ``probe(t_s, X (R, 3, 33), x̂ (R, 3, n),
        P (G, n, n), group (R, 3))``, if given, sees the truth errors and the filters after every
        step (tests)."""
        with single_thread_blas():
            return self._run(indices, fault, progress, probe)

    def _run(self, indices, fault, progress, probe) -> McResult:
        t_wall = time.perf_counter()
        self._fault = fault
        b = _Batch(self, np.asarray(indices, int))
        st = self.states
        for k, s in enumerate(st):
            self._step(b, k, s, fault)
            if probe is not None:
                probe(s.t_s, b.X.reshape(b.Rn, N_UNITS, NL), b.xhat.reshape(b.Rn, N_UNITS,
                                                                            self.n),
                      b.P, b.gidx.reshape(b.Rn, N_UNITS))
            if progress is not None and k % 1000 == 0:
                progress(k, len(st))
        return b.result(self, fault, time.perf_counter() - t_wall)

    def _step(self, b: _Batch, k: int, s: AircraftState, fault: McFault | None) -> None:
        """One sample of the trajectory: propagate, sensors, corrections, decisions, output."""
        t = s.t_s
        if k % BLOCK_STEPS == 0:
            for r, g in enumerate(b.rngs):
                g.standard_normal(out=b.noise[r])
        nz = b.noise[:, k % BLOCK_STEPS]
        if k > 0:
            _propagate(self, b, self.states[k - 1], t, nz)
        fx = nz[:, K_INS:]
        _gnss_fix(self, b, t, fx)
        _deliver(self, b, t)
        _baro(self, b, t, fx)
        b.P, b.gidx = _compact(b.P, b.gidx)
        b.groups_max = max(b.groups_max, b.P.shape[0])
        e = _identify(self, b, s, nz)
        _vote_raw(self, b, s, e)
        _output(self, b, s, e)
        if fault is not None and not b.fault_on and t >= fault.t_s - 1e-9:
            _inject(self, b, t, fault)


def _sensor_errors(X, comp, f, w, sd, z):
    """(R, 3, 6) raw IMU output errors (as :meth:`~.ins_bank.InsBank.sensor_errors`): bias (the
    residual plus the compensation fed back) + scale factor + misalignment (paper eq. 5.1) at the
    true specific force ``f`` and rate ``w``, plus white noise ``sd`` × ``z``."""
    out = np.empty(X.shape[:2] + (6,))
    out[..., :3] = X[..., 9:12] + comp[..., :3] + X[..., 15:18] * f
    out[..., 3:] = X[..., 12:15] + comp[..., 3:] + X[..., 18:21] * w
    out[..., 0] += f[1] * X[..., 21] + f[2] * X[..., 22]
    out[..., 1] += f[0] * X[..., 23] + f[2] * X[..., 24]
    out[..., 2] += f[0] * X[..., 25] + f[1] * X[..., 26]
    out[..., 3] += w[1] * X[..., 27] + w[2] * X[..., 28]
    out[..., 4] += w[0] * X[..., 29] + w[2] * X[..., 30]
    out[..., 5] += w[0] * X[..., 31] + w[1] * X[..., 32]
    return out + sd * z


def _run_batch(job) -> McResult:
    mc, indices, fault = job
    return mc.run(indices, fault)


def _worker_init() -> None:
    """Workers die on SIGTERM (not the CLI's handler, inherited through fork)."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def run_chunks(mc: MonteCarlo, n_real: int, chunk: int, fault: McFault | None = None,
               first: int = 0, progress=None, workers: int = 1) -> McResult:
    """Realisations ``first`` .. ``first + n_real - 1`` in batches of ``chunk``, on ``workers``
    processes (same numbers for any ``chunk`` and ``workers``: each realisation's stream is its
    own)."""
    batches = [range(a, min(a + chunk, first + n_real)) for a in range(first, first + n_real, chunk)]
    if workers > 1 and len(batches) > 1:
        from concurrent.futures import ProcessPoolExecutor

        ex = ProcessPoolExecutor(max_workers=min(workers, len(batches)), initializer=_worker_init)
        try:
            parts = list(ex.map(_run_batch, [(mc, b, fault) for b in batches]))
        except BaseException:                # interrupted: stop the workers, do not wait
            for proc in list(getattr(ex, "_processes", {}).values()):
                proc.terminate()
            ex.shutdown(wait=False, cancel_futures=True)
            raise
        ex.shutdown()
    else:
        parts = [mc.run(b, fault, progress) for b in batches]
    return McResult.concat(parts)


__all__ = ["BLOCK_STEPS", "FAULT_KINDS", "McConfig", "McFault", "McResult", "MonteCarlo",
           "percentile_from_hist", "realisation_rng", "run_chunks"]
