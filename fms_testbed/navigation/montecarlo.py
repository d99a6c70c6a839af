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
* the raw IMU output errors and the two-stage identification (:mod:`.array_fdi`, the rules and
  tuning of :class:`~.fdi.TwoStageFdi`); the output is the mean of the units in use.

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
from dataclasses import dataclass, field

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.navigation.array_fdi import ArrayFdi, ArraySensorComparator
from fms_testbed.navigation.fdi import FdiTuning, channel_sigmas, unmodelled_variances
from fms_testbed.navigation.ins_filter import (N_INS, FilterTuning, InsGnssFilter,
                                               _filter_phi_q)
from fms_testbed.navigation.sins import _sins_step
from fms_testbed.sensors.baro import BaroSpec
from fms_testbed.sensors.gnss import GnssSpec
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.analysis import SinsOptions, horizontal_radius, initial_map
from fms_testbed.sensors.sins.euler import eps_to_euler_errors
from fms_testbed.sensors.sins.presets import ImuModel, load_imu
from fms_testbed.sensors.sins.simulate import FACTOR_RTOL

BLOCK_STEPS = 100
"""Steps of noise a realisation draws per call of its generator (fixed: part of the stream)."""

N_UNITS = 3
_AXIS = {"x": 0, "y": 1, "z": 2}
_NSE_EDGES_M = np.concatenate([[0.0], np.logspace(-3, 5, 1601)])
"""Histogram bin edges of the horizontal NSE, m (0.5 % wide bins from 1 mm to 100 km)."""

FAULT_KINDS = ("gyro_bias_step", "accel_bias_step")


@dataclass(frozen=True)
class McFault:
    """A fault injected on the truth side of unit ``unit`` (0..2) at ``t_s``: ``kind``
    ``gyro_bias_step`` (``size`` deg/h) or ``accel_bias_step`` (``size`` µg) on ``axis``."""

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
        return f"{self.kind} {self.axis} {self.size:g} {'deg/h' if 'gyro' in self.kind else 'ug'}"

    def delta(self) -> tuple[int, float]:
        """(state index, step in state units: rad/s or m/s²)."""
        if self.kind == "gyro_bias_step":
            return 12 + _AXIS[self.axis], self.size * DPH_RPS
        return 9 + _AXIS[self.axis], self.size * 1e-6 * G0_MPS2


@dataclass(frozen=True)
class McConfig:
    """The models of a Monte-Carlo run (SI).

    imu : IMU preset of the three units;  gnss, baro : sensor models (``gnss.outages`` are the
    outages of every realisation);  tuning, fdi : filter and identification settings
    rnp_m : RNP for the containment statistics, m
    """

    imu: str = "STIM300"
    gnss: GnssSpec = GnssSpec()
    baro: BaroSpec = BaroSpec()
    tuning: FilterTuning = FilterTuning()
    fdi: FdiTuning = FdiTuning()
    rnp_m: float = 555.6


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
    wall_s : wall time of the batch, s;  n_cov_groups_max : most covariance groups held at once
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
    extra: dict = field(default_factory=dict)

    @staticmethod
    def concat(parts: list["McResult"]) -> "McResult":
        """Join batches of the same configuration (histograms and counts summed)."""
        a = parts[0]
        cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
        return McResult(cat("index"), cat("t_detect_s"), cat("t_isolate_s"), cat("t_exclude_s"),
                        cat("nse_max_m"), cat("nse_outage_max_m"), cat("anp_max_outage_m"),
                        sum(p.hist_gnss for p in parts), sum(p.hist_coast for p in parts),
                        sum(p.outage_samples for p in parts), sum(p.outage_nse_in for p in parts),
                        sum(p.outage_anp_in for p in parts), a.duration_s,
                        sum(p.wall_s for p in parts), max(p.n_cov_groups_max for p in parts),
                        a.fault)


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


def _group_update(P, gidx, xhat, z, Hm, R, q_lag, gate):
    """One measurement group for all members (flattened realisation × unit) at once.

    Per covariance group g: C = (P_g - Q_lag) H_mᵀ, S = H_m C + R, K = C S⁻¹ (the
    delayed-measurement correction of :func:`~.kalman.correct_delayed`; Φ = I, Q_lag = 0 is the
    Joseph form); per member ν = z - H_m x̂, NIS = νᵀ S⁻¹ ν, gate |ν_i| ≤ gate √S_ii, and x̂ += K ν
    when it passes. A group whose members disagree at the gate is split: the members that
    rejected keep the predicted P in a new group. Returns (P, gidx, NIS (M,), used (M,))."""
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


def _compact(P, gidx):
    """Drop covariance groups without members."""
    keep, inv = np.unique(gidx, return_inverse=True)
    if keep.size == P.shape[0]:
        return P, gidx
    return P[keep], inv.astype(gidx.dtype)


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

    # -- one batch -------------------------------------------------------------------------
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
        idx = np.asarray(indices, int)
        Rn, U, n, imu, cfg, f0 = idx.size, N_UNITS, self.n, self.imu, self.cfg, self.filt
        M = Rn * U
        rngs = [realisation_rng(self.seed, i) for i in idx]
        st = self.states
        s0 = st[0]
        # initial draws per realisation: 3 × 33 INS, 6 GNSS Markov, 1 baro bias
        init = np.array([g.standard_normal(U * 33 + 7) for g in rngs])
        A = initial_map(s0.lat_rad, (s0.roll_rad, s0.pitch_rad, s0.heading_rad), imu,
                        SinsOptions())
        z0 = init[:, :U * 33].reshape(Rn, U, 33) * np.sqrt(imu.p0_var)
        X = (z0 @ A.T).reshape(M, 33)
        gs, bs = cfg.gnss, cfg.baro
        gsig, gtau, gwhite = gs.markov_sigma, gs.markov_tau_s, gs.white_sigma
        markov = gsig * init[:, U * 33:U * 33 + 6]
        bias = bs.markov_sigma_m * init[:, U * 33 + 6]
        sol0 = NavSolution(s0.t_s, s0.lat_rad, s0.lon_rad, s0.alt_m, np.asarray(s0.v_enu_mps),
                           s0.roll_rad, s0.pitch_rad, s0.heading_rad, {})
        f0.initialise(sol0)
        P = f0.P[None].copy()
        gidx = np.zeros(M, np.int64)
        xhat = np.zeros((M, n))
        comp = np.zeros((M, 6))
        H_pos, H_vel, H_baro = f0._H_pos, f0._H_vel, f0._H_baro
        r_pos, r_vel, r_baro = f0._r_pos, f0._r_vel, f0._r_baro
        fdi = ArrayFdi(Rn, cfg.fdi)
        sd_sensor = None
        comparator = None
        # timing of GNSS epochs (from the first sample, every period) and baro readings
        period, lat_s = 1.0 / gs.rate_hz, gs.latency_s
        next_fix, next_baro, t_markov, t_bias = s0.t_s, s0.t_s, None, None
        queue: list[tuple[float, float, np.ndarray, np.ndarray]] = []   # (t_m, t_deliv, zp, zv)
        lag: list[tuple[float, np.ndarray, np.ndarray]] = []
        last_used = np.full(Rn, -math.inf)     # as the source's nav_mode: coasting until a fix
        hist_g = np.zeros(len(_NSE_EDGES_M) - 1, np.int64)
        hist_c = np.zeros_like(hist_g)
        nse_max = np.zeros(Rn)
        out_max = np.full(Rn, np.nan)
        anp_out_max = np.full(Rn, np.nan)
        o_samples = o_nse = o_anp = 0
        groups_max = 1
        q_w = imu.q_psd[3:9]
        sf_var = np.array([unmodelled_variances(imu)] * U)
        noise = None
        fault_done = fault is None
        NL = 33
        K_INS = U * NL + U * 6            # per step: INS process noise, raw-sensor white noise
        K_FIX = 6 + 6 + 1 + 1             # per step (used at epochs): Markov, white, baro ×2
        K = K_INS + K_FIX
        for k, s in enumerate(st):
            t = s.t_s
            b = k % BLOCK_STEPS
            if b == 0:
                if noise is None:
                    noise = np.empty((Rn, BLOCK_STEPS, K))
                for r, g in enumerate(rngs):
                    g.standard_normal(out=noise[r])
            nz = noise[:, b]                                    # (R, K)
            if k > 0:
                p = st[k - 1]
                dt = t - p.t_s
                rpy = np.array([p.roll_rad, p.pitch_rad, p.heading_rad])
                w_eb = np.array([p.p_rps, p.q_rps, p.r_rps])
                v = np.asarray(p.v_enu_mps, float)
                fb = np.asarray(p.f_body_mps2, float)
                _, phi, L, status = _sins_step(np.zeros(33), np.zeros(33), p.lat_rad, p.alt_m, v,
                                               rpy, w_eb, fb, imu.decay_rps, imu.q_psd, 0.0, 0.0,
                                               dt, 1e-12, FACTOR_RTOL)
                if status:
                    raise ConfigError(f"montecarlo: truth model discretisation failed at "
                                      f"t = {p.t_s} s (status {status})")
                X = X @ phi.T + nz[:, :U * NL].reshape(M, NL) @ L.T
                phf, qkf, status = _filter_phi_q(n, p.lat_rad, p.alt_m, v, rpy, w_eb, fb,
                                                 f0._decay24, f0.decay, f0._process_noise(p),
                                                 dt, 1e-12)
                if status:
                    raise ConfigError(f"montecarlo: filter discretisation failed at t = "
                                      f"{p.t_s} s")
                xhat = xhat @ phf.T
                P = phf @ P @ phf.T + qkf
                P = 0.5 * (P + np.swapaxes(P, 1, 2))
                lag.append((p.t_s, phf, qkf))
                del lag[:-64]
                if sd_sensor is None:
                    sd_sensor = np.sqrt(q_w / dt)
                    comparator = ArraySensorComparator(Rn, np.array([q_w] * U), dt, sf_var,
                                                       cfg.fdi)
            # GNSS fix taken at this sample (Markov exact between epochs), delivered later
            fx = nz[:, K_INS:]
            if t >= next_fix - 1e-9:
                if t_markov is not None:
                    a = np.exp(-(t - t_markov) / gtau)
                    markov = a * markov + gsig * np.sqrt(1.0 - a * a) * fx[:, :6]
                t_markov = t
                err = markov + gwhite * fx[:, 6:12]
                for r in gs.ramps:
                    err[:, :3] += r.offset_m(t)
                if not any(t in o for o in gs.outages):
                    Xr = X.reshape(Rn, U, 33)
                    queue.append((t, t + lat_s, (Xr[:, :, 0:3] - err[:, None, :3]).reshape(M, 3),
                                  (Xr[:, :, 3:6] - err[:, None, 3:6]).reshape(M, 3)))
                while next_fix <= t + 1e-9:
                    next_fix += period
            used_any = np.zeros(M, bool)
            while queue and queue[0][1] <= t + 1e-9:
                t_m, _, zp, zv = queue.pop(0)
                steps = [(ph, q) for t0, ph, q in lag if t0 >= t_m - 1e-9]
                if steps:
                    phl, ql = steps[0]
                    for ph, q in steps[1:]:
                        phl, ql = ph @ phl, ph @ ql @ ph.T + q
                    Hp = np.linalg.solve(phl.T, H_pos.T).T
                    Hv = np.linalg.solve(phl.T, H_vel.T).T
                else:
                    ql, Hp, Hv = np.zeros((n, n)), H_pos, H_vel
                for Hm, z, Rm in ((Hp, zp, r_pos), (Hv, zv, r_vel)):
                    P, gidx, nis, ok = _group_update(P, gidx, xhat, z, Hm, Rm, ql,
                                                     cfg.tuning.gate_sigma)
                    fdi.add_innovation(t, nis.reshape(Rn, U), 3)
                    used_any |= ok
                last_used[used_any.reshape(Rn, U).any(axis=1)] = t_m
            if used_any.any():
                dx = xhat[used_any, :N_INS]
                X[used_any, :N_INS] -= dx
                comp[used_any] += dx[:, 9:15]
                xhat[used_any, :N_INS] = 0.0
            # baro reading at this sample
            if t >= next_baro - 1e-9:
                while next_baro <= t + 1e-9:
                    next_baro += 1.0 / bs.rate_hz
                if t_bias is not None:
                    a = math.exp(-(t - t_bias) / bs.markov_tau_s)
                    bias = a * bias + bs.markov_sigma_m * math.sqrt(1.0 - a * a) * fx[:, 12]
                t_bias = t
                zb = X[:, 2] - np.repeat(bias + bs.white_sigma_m * fx[:, 13], U)
                P, gidx, _, _ = _group_update(P, gidx, xhat, zb[:, None], H_baro, r_baro,
                                              np.zeros((n, n)), cfg.tuning.gate_sigma)
            P, gidx = _compact(P, gidx)
            groups_max = max(groups_max, P.shape[0])
            # identification and output
            e = (X[:, :9] - xhat[:, :9]).reshape(Rn, U, 9)
            dr, dp, dh = eps_to_euler_errors(e[..., 6], e[..., 7], e[..., 8], s.pitch_rad,
                                             s.heading_rad)
            y = np.concatenate([e[..., :6], np.stack([dr, dp, dh], axis=-1)], axis=-1)
            # the units' attitude: the truth's (their errors, < 0.1°, change σ by < 1e-3)
            n_load = float(np.linalg.norm(s.f_body_mps2)) / G0_MPS2
            sig_g = np.array([channel_sigmas(Pg, (sf_var[0, 0], sf_var[0, 1]), s.roll_rad,
                                             s.pitch_rad, n_load) for Pg in P])
            sig = sig_g[gidx].reshape(Rn, U, 9)
            if comparator is not None:
                Xr = X.reshape(Rn, U, 33)
                w = np.array([s.p_rps, s.q_rps, s.r_rps])
                f = np.asarray(s.f_body_mps2, float)
                errs = _sensor_errors(Xr, comp.reshape(Rn, U, 6), f, w, sd_sensor,
                                      nz[:, U * NL:K_INS].reshape(Rn, U, 6))
                nu_s = comparator.update(errs, f, w)
            else:
                nu_s = np.zeros((Rn, 3), np.int64)
            fdi.update(t, y, sig, nu_s)
            used = fdi.used
            valid = used.any(axis=1)
            g2 = gidx.reshape(Rn, U)
            tr = np.trace(P[:, :3, :3], axis1=1, axis2=2)[g2]
            pick = np.where(valid[:, None], used, np.arange(U)[None] == np.argmin(tr, 1)[:, None])
            cnt = pick.sum(axis=1)
            eh = (e[..., :2] * pick[..., None]).sum(axis=1) / cnt[:, None]
            nse = np.hypot(eh[:, 0], eh[:, 1])
            np.maximum(nse_max, nse, out=nse_max)
            coast = t - last_used > 2.0 * period + lat_s + 1e-6
            hist_g += np.histogram(nse[~coast], _NSE_EDGES_M)[0]
            hist_c += np.histogram(nse[coast], _NSE_EDGES_M)[0]
            in_outage = any(t in o for o in gs.outages)
            if in_outage:
                ph = np.stack([P[:, 0, 0], P[:, 1, 1], P[:, 0, 1]], axis=1)[g2]   # (R, U, 3)
                pm = (ph * pick[..., None]).sum(axis=1) / cnt[:, None]
                uniq, inv = np.unique(pm, axis=0, return_inverse=True)
                anp = np.array([horizontal_radius(*row) for row in uniq])[inv.ravel()]
                out_max = np.fmax(out_max, nse)
                anp_out_max = np.fmax(anp_out_max, anp)
                o_samples += Rn
                o_nse += int((nse <= cfg.rnp_m).sum())
                o_anp += int((anp <= cfg.rnp_m).sum())
            if not fault_done and t >= fault.t_s - 1e-9:
                j, d = fault.delta()
                X.reshape(Rn, U, 33)[:, fault.unit, j] += d
                fdi.t_detect_s[:] = np.nan           # detection times count from the fault
                fault_done = True
            if probe is not None:
                probe(t, X.reshape(Rn, U, 33), xhat.reshape(Rn, U, n), P, gidx.reshape(Rn, U))
            if progress is not None and k % 1000 == 0:
                progress(k, len(st))
        return McResult(idx, fdi.t_detect_s, fdi.t_isolate_s, fdi.t_exclude_s, nse_max, out_max,
                        anp_out_max, hist_g, hist_c, o_samples, o_nse, o_anp,
                        st[-1].t_s - s0.t_s, time.perf_counter() - t_wall, groups_max, fault)


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
