"""Error analysis along a trajectory: covariance propagation and vectorised Monte-Carlo.

Covariance: P_k = Φ_k P_{k-1} Φ_kᵀ + Q_k (paper eq. 4.2). Monte-Carlo: X_k = Φ_k X_{k-1} + S_k N_k
with the realisations as the columns of X (numpy over realisations, eq. 6.11). Φ_k, Q_k come
from F at the true state at the start of each step (``fms_testbed.sensors.sins.model.build_F``).
Outputs are result objects with ``to_frame()``; plotting lives in :mod:`.plots`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import pandas as pd
from numba import njit
from scipy.special import ndtri

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


_GL_T, _GL_W = np.polynomial.legendre.leggauss(64)   # Gauss-Legendre nodes/weights on [-1, 1]
_TAIL_SIGMA = 10.0      # minor-axis integration stops at ±10 σ_min (the density is e^-50 there)


@njit(cache=True)
def _radius_cdf(r, s_major, s_minor):
    """(P, dP/dr) with P = P(x² + y² ≤ r²), x ~ N(0, s_major²), y ~ N(0, s_minor²) independent
    (r, s in m; dP/dr in 1/m).

    Integrated along the minor axis, P = ∫_{|y|<r} φ(y; s_minor) erf(√(r² - y²) / (√2 s_major)) dy,
    with y = r sin t (smooth integrand, no end-point singularity) over |y| ≤ min(r, 10 s_minor),
    64-point Gauss-Legendre in t; dP/dr = ∫ φ(r sin t; s_minor) √(2/π) / s_major
    · exp(-r² cos²t / (2 s_major²)) r dt on the same nodes.
    """
    a = math.asin(min(1.0, _TAIL_SIGMA * s_minor / r))
    c = r / (math.sqrt(2.0 * math.pi) * s_minor)
    k = r / (math.sqrt(2.0) * s_major)
    total = 0.0
    deriv = 0.0
    for i in range(_GL_T.size):
        t = a * _GL_T[i]
        st, ct = math.sin(t), math.cos(t)
        u = r * st / s_minor
        w = _GL_W[i] * math.exp(-0.5 * u * u)
        kc = k * ct
        total += w * math.erf(kc) * ct
        deriv += w * math.exp(-kc * kc)
    return total * a * c, deriv * a * c * (2.0 / math.sqrt(math.pi)) * k / r


@njit(cache=True)
def _radius_solve(s_major, s_minor, prob, lo, hi, rtol):
    """Root r of P(r) = prob in the bracket [lo, hi] (the 1-D and circular limits): Newton steps
    (safeguarded: bisection when a step leaves the bracket, which shrinks with every evaluation),
    started at lo + (hi - lo) q³ (q = s_minor/s_major: exact at q = 0 and q = 1, within 3 % of
    the root between)."""
    q = s_minor / s_major
    r = lo + (hi - lo) * q * q * q
    for _ in range(100):
        f, df = _radius_cdf(r, s_major, s_minor)
        f -= prob
        step = f / df if df > 0.0 else 0.0
        if abs(step) <= rtol * r and df > 0.0:
            return r - step
        if f > 0.0:
            hi = r
        else:
            lo = r
        r_new = r - step
        r = r_new if lo < r_new < hi else 0.5 * (lo + hi)
    return r


@lru_cache(maxsize=16)
def _radius_bracket(prob: float) -> tuple[float, float]:
    """(z, k): the radius lies in [z σ_max, k σ_max] — z for σ_min = 0 (1-D, two-sided normal
    quantile), k for σ_min = σ_max (circular, √(-2 ln(1 - prob)))."""
    return float(ndtri(0.5 + prob / 2.0)), math.sqrt(-2.0 * math.log1p(-prob))


def horizontal_radius(p_ee, p_nn, p_en, prob: float = 0.95) -> float:
    """Radius (m) containing ``prob`` of a zero-mean 2-D Gaussian with covariance [[p_ee, p_en], [p_en, p_nn]] m².

    Exact for every axis ratio: in the principal axes (σ_max ≥ σ_min, eigenvalues of the 2×2
    covariance), P(r) = ∫_{|y|<r} φ(y; σ_min) erf(√(r² - y²) / (√2 σ_max)) dy — the minor-axis
    coordinate y integrated against the exact 1-D probability along the major axis — with
    y = r sin t and 64-point Gauss-Legendre over |y| ≤ min(r, 10 σ_min) (the integrand is smooth
    in t and the node spacing follows σ_min, so an elongated ellipse is resolved as well as a
    circle), solved for r by regula falsi inside the bracket [z σ_max, √(-2 ln(1-prob)) σ_max]
    (z the two-sided normal quantile: the 1-D and the circular limits). Relative error < 1e-9
    at any σ_min/σ_max (tests/sensors/test_horizontal_radius.py); σ_min = 0 is the 1-D limit
    z σ_max exactly.

    Parameters
    ----------
    p_ee, p_nn, p_en : covariance entries E-E, N-N, E-N, m².
    prob : containment probability, 0 < prob < 1.

    Returns
    -------
    radius, m (0 for a zero covariance).
    """
    if not 0.0 < prob < 1.0:
        raise UserError(f"horizontal_radius: prob must be in (0, 1), got {prob!r}")
    half_tr = 0.5 * (p_ee + p_nn)
    disc = math.hypot(0.5 * (p_ee - p_nn), p_en)
    lam_max = half_tr + disc
    lam_min = max(half_tr - disc, 0.0)
    if not lam_max > 0.0:
        return 0.0
    s_major, s_minor = math.sqrt(lam_max), math.sqrt(lam_min)
    z, k = _radius_bracket(float(prob))
    if s_minor == 0.0:
        return z * s_major
    return float(_radius_solve(s_major, s_minor, float(prob), z * s_major, k * s_major, 1e-12))


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
