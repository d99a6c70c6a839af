"""Error analysis along a trajectory: covariance propagation and vectorised Monte-Carlo.

Covariance: P_k = Φ_k P_{k-1} Φ_kᵀ + Q_k (paper eq. 4.2). Monte-Carlo: X_k = Φ_k X_{k-1} + S_k N_k
with the realisations as the columns of X (numpy over realisations, eq. 6.11). Φ_k, Q_k come
from F at the true state at the start of each step (``fms_testbed.sensors.sins.model.build_F``).
Outputs are result objects with ``to_frame()``; plotting lives in :mod:`.plots`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from fms_testbed.core.earth import earth_rate_enu
from fms_testbed.core.errors import UserError
from fms_testbed.sensors.sins.discretize import METHODS, discretize, discretize_sins
from fms_testbed.sensors.sins.model import N_STATES, alignment_map, baro_gains, build_F, dcm_body_to_enu
from fms_testbed.sensors.sins.presets import ImuModel
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.simulate import factor_psd
from fms_testbed.sensors.sins.trajectory import Trajectory
from fms_testbed.sensors.sins.model import STATE_NAMES

VERTICAL_MODES = ("baro", "free")
ALIGNMENT_MODES = ("stationary", "none")


@dataclass(frozen=True)
class SinsOptions:
    """How the error model is run.

    method: ``picard`` (block-structured adaptive series), ``vanloan`` or ``trapezoid``
    tol: relative tolerance of the adaptive Picard order
    vertical: ``baro`` (vertical channel damped by a critically damped baro loop of time constant
        ``baro_tau_s``, s; the baro error itself is not modelled) or ``free`` (unstable, physics)
    alignment: ``stationary`` (initial attitude errors from a self-alignment at the start attitude
        and latitude, :func:`~.model.alignment_map`) or ``none`` (all initial errors independent)
    """

    method: str = "picard"
    tol: float = 1e-12
    vertical: str = "baro"
    baro_tau_s: float = 60.0
    alignment: str = "stationary"

    def __post_init__(self):
        if self.method not in METHODS:
            raise UserError(f"navigation.method: {self.method!r} is not one of {', '.join(METHODS)}")
        if self.vertical not in VERTICAL_MODES:
            raise UserError(f"navigation.vertical: {self.vertical!r} is not one of "
                            f"{', '.join(VERTICAL_MODES)}")
        if self.alignment not in ALIGNMENT_MODES:
            raise UserError(f"navigation.alignment: {self.alignment!r} is not one of "
                            f"{', '.join(ALIGNMENT_MODES)}")
        if not self.baro_tau_s > 0:
            raise UserError(f"navigation.baro_tau_s: must be > 0 s, got {self.baro_tau_s!r}")


def system_matrix(lat_rad, alt_m, v_enu_mps, rpy_rad, w_eb_b_rps, f_b_mps2, imu: ImuModel,
                  opts: SinsOptions) -> np.ndarray:
    """F (33×33) at one true state; ω_IB^B = ω_EB^B + C_N^B ω_IE^N (JSBSim p, q, r are Earth-relative)."""
    c_bn = dcm_body_to_enu(*rpy_rad)
    w_ib = np.asarray(w_eb_b_rps, float) + c_bn.T @ earth_rate_enu(lat_rad)
    k1, k2 = baro_gains(opts.baro_tau_s if opts.vertical == "baro" else None, lat_rad)
    return build_F(float(lat_rad), float(alt_m), np.asarray(v_enu_mps, float),
                   np.asarray(f_b_mps2, float), w_ib, c_bn, imu.decay_rps, k1, k2)


def step_discrete(F: np.ndarray, imu: ImuModel, dt_s: float, opts: SinsOptions):
    """(Φ, Q_k) for one step with the chosen method (Picard: block-structured kernel)."""
    if opts.method == "picard":
        return discretize_sins(F, imu.q_psd, dt_s, tol=opts.tol)
    return discretize(F, np.diag(imu.q_psd), dt_s, method=opts.method)


def initial_map(lat_rad: float, rpy_rad, imu: ImuModel, opts: SinsOptions) -> np.ndarray:
    """A with x0 = A z, z ~ N(0, diag(imu.p0_var)): identity, or the stationary alignment map."""
    if opts.alignment == "none":
        return np.eye(N_STATES)
    return alignment_map(float(lat_rad), dcm_body_to_enu(*rpy_rad), imu.decay_rps)


def _discrete_steps(traj: Trajectory, imu: ImuModel, opts: SinsOptions):
    """Yield (k, Φ_k, Q_k) for k = 1..n-1 with F at sample k-1."""
    for k in range(1, len(traj)):
        F = system_matrix(traj.lat_rad[k - 1], traj.alt_m[k - 1], traj.v_enu_mps[k - 1],
                          traj.rpy_rad[k - 1], traj.w_eb_b_rps[k - 1], traj.f_b_mps2[k - 1],
                          imu, opts)
        phi, qk = step_discrete(F, imu, traj.t_s[k] - traj.t_s[k - 1], opts)
        yield k, phi, qk


def horizontal_radius(p_ee, p_nn, p_en, prob: float = 0.95) -> float:
    """Radius (m) containing ``prob`` of a zero-mean 2-D Gaussian with covariance [[p_ee, p_en], [p_en, p_nn]] m².

    Exact: P(r) = (1/2π√(λ1λ2)) ∫_0^{2π} (1 - exp(-r² a(θ)/2)) / a(θ) dθ, a = cos²θ/λ1 + sin²θ/λ2,
    integrated with the periodic trapezoid rule and solved for r with Brent's method.
    """
    lam = np.linalg.eigvalsh(np.array([[p_ee, p_en], [p_en, p_nn]]))
    lam = np.maximum(lam, 0.0)
    if lam[1] <= 0:
        return 0.0
    if lam[0] <= lam[1] * 1e-12:                     # degenerate: 1-D Gaussian
        from scipy.stats import norm
        return float(norm.ppf(0.5 + prob / 2) * math.sqrt(lam[1]))
    th = np.linspace(0, 2 * np.pi, 256, endpoint=False)
    a = np.cos(th) ** 2 / lam[0] + np.sin(th) ** 2 / lam[1]
    c = 1.0 / (2 * np.pi * math.sqrt(lam[0] * lam[1])) * (2 * np.pi / th.size)

    def cdf(r):
        return c * np.sum((1 - np.exp(-r * r * a / 2)) / a) - prob

    hi = 5.0 * math.sqrt(lam[1])
    return float(brentq(cdf, 0.0, hi, xtol=1e-9 * hi))


@dataclass(frozen=True)
class CovarianceResult:
    """σ of every state vs time and the 95 % horizontal/vertical position error (m)."""

    t_s: np.ndarray
    sigma: np.ndarray                       # (n_t, 33) state units
    h95_m: np.ndarray
    v95_m: np.ndarray
    imu: str
    label: str = ""

    def to_frame(self) -> pd.DataFrame:
        """Columns t_s, h95_m, v95_m, sigma_<state> (state units)."""
        df = pd.DataFrame(self.sigma, columns=[f"sigma_{n}" for n in STATE_NAMES])
        df.insert(0, "v95_m", self.v95_m)
        df.insert(0, "h95_m", self.h95_m)
        df.insert(0, "t_s", self.t_s)
        return df


def covariance_run(traj: Trajectory, imu: ImuModel, opts: SinsOptions = SinsOptions(),
                   store_every_s: float = 1.0) -> CovarianceResult:
    """Propagate P along ``traj`` from P0 = A diag(imu.p0_var) Aᵀ (A: :func:`initial_map`);
    store every ``store_every_s`` s."""
    A = initial_map(traj.lat_rad[0], traj.rpy_rad[0], imu, opts)
    P = A @ np.diag(imu.p0_var) @ A.T
    t, sig, h95, v95 = [], [], [], []
    next_store = traj.t_s[0]

    def store(k):
        t.append(traj.t_s[k])
        sig.append(np.sqrt(np.maximum(np.diag(P), 0.0)))
        h95.append(horizontal_radius(P[0, 0], P[1, 1], P[0, 1]))
        v95.append(1.959963984540054 * math.sqrt(max(P[2, 2], 0.0)))

    store(0)
    next_store += store_every_s
    with single_thread_blas():
        for k, phi, qk in _discrete_steps(traj, imu, opts):
            P = phi @ P @ phi.T + qk
            if traj.t_s[k] >= next_store - 1e-9 or k == len(traj) - 1:
                P = 0.5 * (P + P.T)
                store(k)
                next_store += store_every_s
    return CovarianceResult(np.array(t), np.array(sig), np.array(h95), np.array(v95),
                            imu.name, traj.label)


@dataclass(frozen=True)
class MonteCarloResult:
    """Monte-Carlo statistics vs time.

    sigma: (n_t, 33) sample standard deviation; h95_m / v95_m: 95th percentile of the horizontal
    radial and absolute vertical position error, m; samples: (n_t, 33, n_keep) the first
    ``n_keep`` realisations (for plots).
    """

    t_s: np.ndarray
    sigma: np.ndarray
    h95_m: np.ndarray
    v95_m: np.ndarray
    samples: np.ndarray
    n_real: int
    seed: int
    imu: str
    label: str = ""
    extra: dict = field(default_factory=dict)

    def realisations_frame(self) -> pd.DataFrame:
        """Long table of the kept realisations: t_s, realisation, and the 9 navigation errors
        (dp_*_m, dv_*_mps, eps_*_rad)."""
        n_t, _, n_keep = self.samples.shape
        cols = {"t_s": np.repeat(self.t_s, n_keep),
                "realisation": np.tile(np.arange(n_keep), n_t)}
        for i, name in enumerate(STATE_NAMES[:9]):
            cols[name] = self.samples[:, i, :].reshape(-1)
        return pd.DataFrame(cols)

    def to_frame(self) -> pd.DataFrame:
        """Columns t_s, h95_m, v95_m, sigma_<state>."""
        df = pd.DataFrame(self.sigma, columns=[f"sigma_{n}" for n in STATE_NAMES])
        df.insert(0, "v95_m", self.v95_m)
        df.insert(0, "h95_m", self.h95_m)
        df.insert(0, "t_s", self.t_s)
        return df


def montecarlo_run(traj: Trajectory, imu: ImuModel, n_real: int = 1000, seed: int = 0,
                   opts: SinsOptions = SinsOptions(), store_every_s: float = 1.0,
                   n_keep: int = 20) -> MonteCarloResult:
    """Vectorised Monte-Carlo of ``n_real`` realisations along ``traj`` (reproducible from ``seed``).

    x_0 = A z, z ~ N(0, diag(imu.p0_var)) (A: :func:`initial_map`); each step X ← Φ X + S N,
    S Sᵀ = Q_k (:func:`factor_psd`).
    """
    if n_real < 2:
        raise UserError(f"Monte-Carlo needs at least 2 realisations, got {n_real}")
    rng = np.random.default_rng(seed)
    X = initial_map(traj.lat_rad[0], traj.rpy_rad[0], imu, opts) @ (
        np.sqrt(imu.p0_var)[:, None] * rng.standard_normal((N_STATES, n_real)))
    n_keep = min(n_keep, n_real)
    t, sig, h95, v95, keep = [], [], [], [], []
    next_store = traj.t_s[0]

    def store(k):
        t.append(traj.t_s[k])
        sig.append(X.std(axis=1, ddof=1))
        h = np.hypot(X[0], X[1])
        h95.append(np.percentile(h, 95))
        v95.append(np.percentile(np.abs(X[2]), 95))
        keep.append(X[:, :n_keep].copy())

    store(0)
    next_store += store_every_s
    with single_thread_blas():
        for k, phi, qk in _discrete_steps(traj, imu, opts):
            S = factor_psd(qk)
            X = phi @ X + S @ rng.standard_normal((S.shape[1], n_real))
            if traj.t_s[k] >= next_store - 1e-9 or k == len(traj) - 1:
                store(k)
                next_store += store_every_s
    return MonteCarloResult(np.array(t), np.array(sig), np.array(h95), np.array(v95),
                            np.array(keep), n_real, seed, imu.name, traj.label)


def error_table(result, every_s: float = 300.0) -> pd.DataFrame:
    """Table of the 95 % horizontal and vertical position error at every ``every_s`` s.

    Columns: t_min, h95_m, v95_m (from a :class:`CovarianceResult` or :class:`MonteCarloResult`).
    """
    t = result.t_s - result.t_s[0]
    marks = np.arange(0.0, t[-1] + 1e-9, every_s)
    if marks[-1] < t[-1] - 1e-9:
        marks = np.append(marks, t[-1])
    idx = np.searchsorted(t, marks - 1e-9)
    idx = np.minimum(idx, len(t) - 1)
    return pd.DataFrame({"t_min": t[idx] / 60.0, "h95_m": result.h95_m[idx],
                         "v95_m": result.v95_m[idx]})
