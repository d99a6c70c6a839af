"""Sensor errors of a strapdown IMU, applied to error-free increments (the truth side).

Per axis (accelerometer triad, then gyro triad; body axes x forward, y right, z down), over an
increment of length Δt with error-free increments Δv, Δθ::

    Δṽ = Δv + b_a Δt + K_a Δv + Γ(Δv) β_a + n_v,    n_v ~ N(0, N_v² Δt)   (VRW N_v, m/s/√s)
    Δθ̃ = Δθ + b_g Δt + K_g Δθ + Γ(Δθ) β_g + n_θ,    n_θ ~ N(0, N_θ² Δt)   (ARW N_θ, rad/√s)
    b = b_on + b_gm + b_rw        turn-on constant + bias instability + bias random walk
    b_on ~ N(0, σ_on²) fixed;  b_gm' = -b_gm/τ + η (stationary σ_gm, first-order Gauss-Markov);
    b_rw' = η (density q_rw);  K = diag(k), k and β first-order Gauss-Markov or random constants
    Γ(v) β = (v_y β1 + v_z β2, v_x β3 + v_z β4, v_x β5 + v_y β6)   (misalignment/non-orthogonality)

then quantised to the output LSB with the residue carried to the next sample (an integrating
output: the sum of the outputs never drifts from the sum of the inputs by more than one LSB).
These are the sensor equations of the 33-state model (Babich 2017 eq. 5.1-5.6,
:mod:`fms_testbed.sensors.sins.model`): the same Γ, the same state order, so one realisation can
be handed to the linear model (``layout_33``).

The slow states (b_gm, b_rw, k, β) advance once per navigation step with their exact
discretisation x ← a x + s N (a = e^{-Δt/τ}, s = σ √(1 - a²); random walk a = 1, s = √(q Δt));
within the step's frames they are constant (their change over 0.1 s is far below the white noise
of one frame). Parameters come from an IMU preset (:mod:`fms_testbed.sensors.sins.presets`): from
its :class:`~fms_testbed.sensors.sins.presets.ImuSpec` where it has one (the turn-on value and the
in-run instability then stay apart: a constant plus a stationary Gauss-Markov), else from its
:class:`~fms_testbed.sensors.sins.presets.ImuModel` (the 33-state arrays as they are).

State of one unit (:data:`N_ERR` floats): 0:6 b_on, 6:12 b_gm, 12:18 b_rw, 18:24 k, 24:36 β
(accelerometer before gyro in each group; SI: m/s², rad/s, dimensionless, rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numba import njit

from fms_testbed.core.units import DEG_RAD, DPH_RPS, G0_MPS2
from fms_testbed.sensors.sins.presets import ImuModel, ImuSpec, load_imu, load_imu_spec

N_ERR = 36
"""Error states per unit."""
N_SLOW = 30
"""States 6..35, advanced once per navigation step."""
_ON, _GM, _RW, _SF, _MIS = 0, 6, 12, 18, 24


@dataclass(frozen=True)
class ImuErrorParams:
    """Declared errors of one IMU, SI, 1σ; accelerometer (m/s², m/s) before gyro (rad/s, rad).

    Attributes
    ----------
    name : preset name
    on_sd : (6,) turn-on (run-to-run) bias σ
    gm_sd, gm_tau_s : (6,) bias-instability σ and correlation time, s (inf: none)
    rw_psd : (6,) bias random-walk density, unit²/s
    sf_sd, sf_tau_s : (6,) scale-factor σ (dimensionless) and correlation time (inf: constant)
    mis_sd, mis_tau_s : (12,) misalignment σ (rad) and correlation time (inf: constant)
    white_psd : (6,) VRW² (m²/s³) and ARW² (rad²/s): the white-noise densities
    lsb : (6,) output quantum of Δv (m/s) and Δθ (rad) (0: none)
    """

    name: str
    on_sd: np.ndarray
    gm_sd: np.ndarray
    gm_tau_s: np.ndarray
    rw_psd: np.ndarray
    sf_sd: np.ndarray
    sf_tau_s: np.ndarray
    mis_sd: np.ndarray
    mis_tau_s: np.ndarray
    white_psd: np.ndarray
    lsb: np.ndarray

    @classmethod
    def from_spec(cls, spec: ImuSpec) -> "ImuErrorParams":
        """From a preset file's :class:`ImuSpec` (datasheet units; 1σ)."""
        g, a = spec.gyro, spec.accelerometer
        ug = 1e-6 * G0_MPS2
        inf = math.inf

        def pair(av, gv):
            return np.array([av] * 3 + [gv] * 3, float)

        def tau(t):
            return inf if t is None else float(t)

        gm_a = a.bias_instability_ug * ug if a.bias_correlation_time_s else 0.0
        gm_g = g.bias_instability_deg_per_h * DPH_RPS if g.bias_correlation_time_s else 0.0
        return cls(
            spec.name, pair(a.bias_turn_on_ug * ug, g.bias_turn_on_deg_per_h * DPH_RPS),
            pair(gm_a, gm_g), pair(tau(a.bias_correlation_time_s), tau(g.bias_correlation_time_s)),
            pair((a.bias_rate_random_walk_ug_per_sqrt_s * ug) ** 2,
                 (g.bias_rate_random_walk_deg_per_h_per_sqrt_h * DPH_RPS / 60.0) ** 2),
            pair(a.scale_factor_ppm * 1e-6, g.scale_factor_ppm * 1e-6),
            pair(tau(a.scale_factor_correlation_time_s), tau(g.scale_factor_correlation_time_s)),
            np.array([a.misalignment_mrad * 1e-3] * 6 + [g.misalignment_mrad * 1e-3] * 6),
            np.array([tau(a.misalignment_correlation_time_s)] * 6
                     + [tau(g.misalignment_correlation_time_s)] * 6),
            pair((a.vrw_mps_per_sqrt_h / 60.0) ** 2, (g.arw_deg_per_sqrt_h * DEG_RAD / 60.0) ** 2),
            pair(a.quantization_mps, g.quantization_rad))

    @classmethod
    def from_model(cls, m: ImuModel) -> "ImuErrorParams":
        """From the 33-state arrays (decay, q, p0 of states 9..32): a decaying state is a
        Gauss-Markov of its σ, a non-decaying one a constant of σ² = p0 plus a random walk of
        density q; no quantisation."""
        d, q, p0 = m.decay_rps, m.q_psd[9:], m.p0_var[9:]
        gm = d[:6] > 0
        with np.errstate(divide="ignore"):
            tau = np.where(d > 0, 1.0 / np.where(d > 0, d, 1.0), math.inf)
        sd = np.sqrt(p0)
        return cls(m.name, np.where(gm, 0.0, sd[:6]), np.where(gm, sd[:6], 0.0), tau[:6].copy(),
                   np.where(gm, 0.0, q[:6]), sd[6:12], tau[6:12].copy(), sd[12:], tau[12:].copy(),
                   m.q_psd[3:9].copy(), np.zeros(6))

    def step_coefficients(self, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(a, s), each (30,): the slow states' exact discretisation x ← a x + s N over ``dt_s``
        (s): Gauss-Markov a = e^{-Δt/τ}, s = σ √(1 - a²); random walk a = 1, s = √(q Δt);
        random constant a = 1, s = 0."""
        sd = np.concatenate([self.gm_sd, np.zeros(6), self.sf_sd, self.mis_sd])
        tau = np.concatenate([self.gm_tau_s, np.full(6, math.inf), self.sf_tau_s, self.mis_tau_s])
        a = np.exp(-dt_s / tau)
        s = sd * np.sqrt(-np.expm1(-2.0 * dt_s / tau))
        s[6:12] = np.sqrt(self.rw_psd * dt_s)
        return a, s

    def initial_sd(self) -> np.ndarray:
        """(36,) σ of every state at turn-on (b_rw starts at 0)."""
        return np.concatenate([self.on_sd, self.gm_sd, np.zeros(6), self.sf_sd, self.mis_sd])


def imu_error_params(imu: str | Path | dict | ImuSpec | ImuModel) -> ImuErrorParams:
    """The :class:`ImuErrorParams` of ``imu``: a preset name, YAML path, mapping, spec or model.

    A MEMS gyro preset with compensation stages (``"STIM210+compensated"``) has only the
    33-state arrays and goes through :meth:`ImuErrorParams.from_model`.
    """
    if isinstance(imu, ImuSpec):
        return ImuErrorParams.from_spec(imu)
    if isinstance(imu, ImuModel):
        return ImuErrorParams.from_model(imu)
    from fms_testbed.sensors.mems.equivalent import parse_mems_request

    if isinstance(imu, (str, dict)) and parse_mems_request(imu) is not None:
        return ImuErrorParams.from_model(load_imu(imu))
    return ImuErrorParams.from_spec(load_imu_spec(imu))


def layout_33(e: np.ndarray) -> np.ndarray:
    """(24,) the sensor part of a 33-state vector (states 9..32: b_a, b_g, k_a, k_g, β_a, β_g)
    from one unit's error state ``e`` (36,): the bias is the sum of its three parts."""
    return np.concatenate([e[_ON:_ON + 6] + e[_GM:_GM + 6] + e[_RW:_RW + 6], e[_SF:]])


@njit(cache=True, inline="always")
def _gamma(v, b0, b1, b2, b3, b4, b5):
    """Γ(v) β of eq. 5.1 for β = (b0..b5)."""
    return (v[1] * b0 + v[2] * b1, v[0] * b2 + v[2] * b3, v[0] * b4 + v[1] * b5)


@njit(cache=True, inline="always")
def quantise(x, lsb, res):
    """(output, residue): the multiple of ``lsb`` nearest to x + res and what is left over for
    the next sample; (x, res) unchanged when lsb is 0."""
    if lsb > 0.0:
        t = x + res
        y = lsb * math.floor(t / lsb + 0.5)
        return y, t - y
    return x, res


@njit(cache=True, inline="always")
def measure(e, dth, dv, dt, white_sd, z):
    """One unit's measured increments (Δθ̃ rad, Δṽ m/s) before quantisation, from the
    error-free ones (module docstring): e (36,) its error state, white_sd (6,) the white-noise
    σ per increment, z (6,) standard normals."""
    ga = _gamma(dv, e[24], e[25], e[26], e[27], e[28], e[29])
    gg = _gamma(dth, e[30], e[31], e[32], e[33], e[34], e[35])
    mv0 = dv[0] + (e[0] + e[6] + e[12]) * dt + e[18] * dv[0] + ga[0] + white_sd[0] * z[0]
    mv1 = dv[1] + (e[1] + e[7] + e[13]) * dt + e[19] * dv[1] + ga[1] + white_sd[1] * z[1]
    mv2 = dv[2] + (e[2] + e[8] + e[14]) * dt + e[20] * dv[2] + ga[2] + white_sd[2] * z[2]
    mt0 = dth[0] + (e[3] + e[9] + e[15]) * dt + e[21] * dth[0] + gg[0] + white_sd[3] * z[3]
    mt1 = dth[1] + (e[4] + e[10] + e[16]) * dt + e[22] * dth[1] + gg[1] + white_sd[4] * z[4]
    mt2 = dth[2] + (e[5] + e[11] + e[17]) * dt + e[23] * dth[2] + gg[2] + white_sd[5] * z[5]
    return (mt0, mt1, mt2), (mv0, mv1, mv2)


ROW_E, ROW_A, ROW_S, ROW_WSD, ROW_LSB, ROW_RES, N_ROW = 0, 36, 66, 96, 102, 108, 114
"""A unit's sensor row as one array (what a compiled caller packs per unit): the error state
(36), the slow states' one-step a and s (30 each), white σ per increment (6), quanta (6),
quantisation residues (6)."""


@njit(cache=True, inline="always")
def measure_row(u, dth, dv, dt, z, k):
    """:func:`measure` then :func:`quantise` per channel for a unit whose sensor row (layout
    :data:`ROW_E`..) is ``u``; z (m, 6) standard normals, row k used (accelerometer channels
    0..2, gyro 3..5; the residues in ``u`` updated)."""
    e = u
    ga = _gamma(dv, e[24], e[25], e[26], e[27], e[28], e[29])
    gg = _gamma(dth, e[30], e[31], e[32], e[33], e[34], e[35])
    out = (dv[0] + (e[0] + e[6] + e[12]) * dt + e[18] * dv[0] + ga[0],
           dv[1] + (e[1] + e[7] + e[13]) * dt + e[19] * dv[1] + ga[1],
           dv[2] + (e[2] + e[8] + e[14]) * dt + e[20] * dv[2] + ga[2],
           dth[0] + (e[3] + e[9] + e[15]) * dt + e[21] * dth[0] + gg[0],
           dth[1] + (e[4] + e[10] + e[16]) * dt + e[22] * dth[1] + gg[1],
           dth[2] + (e[5] + e[11] + e[17]) * dt + e[23] * dth[2] + gg[2])
    y0, u[ROW_RES] = quantise(out[0] + u[ROW_WSD] * z[k, 0], u[ROW_LSB], u[ROW_RES])
    y1, u[ROW_RES + 1] = quantise(out[1] + u[ROW_WSD + 1] * z[k, 1], u[ROW_LSB + 1],
                                  u[ROW_RES + 1])
    y2, u[ROW_RES + 2] = quantise(out[2] + u[ROW_WSD + 2] * z[k, 2], u[ROW_LSB + 2],
                                  u[ROW_RES + 2])
    y3, u[ROW_RES + 3] = quantise(out[3] + u[ROW_WSD + 3] * z[k, 3], u[ROW_LSB + 3],
                                  u[ROW_RES + 3])
    y4, u[ROW_RES + 4] = quantise(out[4] + u[ROW_WSD + 4] * z[k, 4], u[ROW_LSB + 4],
                                  u[ROW_RES + 4])
    y5, u[ROW_RES + 5] = quantise(out[5] + u[ROW_WSD + 5] * z[k, 5], u[ROW_LSB + 5],
                                  u[ROW_RES + 5])
    return (y3, y4, y5), (y0, y1, y2)


@njit(cache=True, inline="always")
def measure_quantised(e, dth, dv, dt, white_sd, z, lsb, res):
    """:func:`measure` then :func:`quantise` per channel (lsb (6,) quanta, res (6,) residues,
    updated; accelerometer channels 0..2, gyro 3..5)."""
    th, v = measure(e, dth, dv, dt, white_sd, z)
    t0, res[3] = quantise(th[0], lsb[3], res[3])
    t1, res[4] = quantise(th[1], lsb[4], res[4])
    t2, res[5] = quantise(th[2], lsb[5], res[5])
    v0, res[0] = quantise(v[0], lsb[0], res[0])
    v1, res[1] = quantise(v[1], lsb[1], res[1])
    v2, res[2] = quantise(v[2], lsb[2], res[2])
    return (t0, t1, t2), (v0, v1, v2)


@njit(cache=True)
def advance_slow(E, a, s, z):
    """Advance every unit's slow states over one navigation step: E[i, 6:36] ← a[i] E[i, 6:36]
    + s[i] z[i] (E (n, ≥36), a and s (n, 30), z (n, 30) standard normals)."""
    for i in range(E.shape[0]):
        for k in range(N_SLOW):
            E[i, 6 + k] = a[i, k] * E[i, 6 + k] + s[i, k] * z[i, k]


class ImuErrors:
    """The error states of N IMUs of one model, with the methods the truth-side faults use.

    Parameters
    ----------
    params : one :class:`ImuErrorParams` per unit
    seeds : one seed per unit (:func:`fms_testbed.navigation.ins_bank.derive_seeds`); each
        unit draws its turn-on values, its slow-state noise and its white noise from three
        independent streams spawned from its seed
    """

    def __init__(self, params: list[ImuErrorParams], seeds: list[int]):
        if len(params) != len(seeds):
            raise ValueError("one seed per IMU")
        self.params = list(params)
        streams = [np.random.SeedSequence(int(s)).spawn(3) for s in seeds]
        self.rng_white = [np.random.default_rng(c[1]) for c in streams]
        self.rng_slow = [np.random.default_rng(c[2]) for c in streams]
        self.E = np.array([p.initial_sd() * np.random.default_rng(c[0]).standard_normal(N_ERR)
                           for p, c in zip(self.params, streams)])
        self.res = np.zeros((len(params), 6))          # quantisation residues
        self.lsb = np.array([p.lsb for p in self.params])
        self._noise_scale = np.ones((len(params), N_SLOW))   # a drift_scale fault raises it
        self._coef: tuple | None = None
        self._white: tuple | None = None
        self.version = 0              # raised whenever a parameter or a noise scale changes

    def __len__(self) -> int:
        return len(self.params)

    def coefficients(self, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(a, s) of the slow states for a step of ``dt_s`` (s), (n, 30) each; cached while
        ``dt_s`` does not change."""
        c = self._coef
        if c is None or abs(c[0] - dt_s) > 1e-12 * dt_s:
            ab = [p.step_coefficients(dt_s) for p in self.params]
            a = np.array([x[0] for x in ab])
            s = np.array([x[1] for x in ab]) * self._noise_scale
            self._coef = c = (dt_s, a, s)
        return c[1], c[2]

    def white_sd(self, frame_dt_s: float) -> np.ndarray:
        """(n, 6) σ of the white noise on one increment of ``frame_dt_s`` (s): √(N² Δt); cached
        while ``frame_dt_s`` does not change."""
        w = self._white
        if w is None or abs(w[0] - frame_dt_s) > 1e-12 * frame_dt_s:
            psd = np.array([p.white_psd for p in self.params])
            self._white = w = (frame_dt_s, np.sqrt(psd * frame_dt_s))
        return w[1]

    def pack_rows(self, U: np.ndarray, step_s: float, frame_s: float) -> None:
        """Write the slow states' one-step a and s for a step of ``step_s`` (s), the white σ
        per increment of ``frame_s`` (s) and the quanta into the sensor rows ``U`` (n,
        :data:`N_ROW`; the layout of :data:`ROW_E`); the error states and residues are left."""
        a, s = self.coefficients(step_s)
        U[:, ROW_A:ROW_S] = a
        U[:, ROW_S:ROW_WSD] = s
        U[:, ROW_WSD:ROW_LSB] = self.white_sd(frame_s)
        U[:, ROW_LSB:ROW_RES] = self.lsb

    # -- truth-side faults (fms_testbed.navigation.faults kinds) -------------------------------
    def step_bias(self, unit: int, sensor: str, axis: int, size: float) -> None:
        """Step unit ``unit``'s bias on ``axis`` (0 x, 1 y, 2 z) by ``size`` (m/s² for
        ``sensor="accel"``, rad/s for ``"gyro"``) from now on."""
        k = {"accel": 0, "gyro": 3}[sensor] + int(axis)
        self.E[unit, _ON + k] += float(size)

    def scale_gyro_drift(self, unit: int, factor: float) -> np.ndarray:
        """Make unit ``unit``'s gyro drift ``factor`` × its declared value: an excess constant
        drift (factor - 1) × the declared σ on every axis (turn-on and instability together) and
        the instability and random-walk noise × factor; returns the excess, rad/s (3,)."""
        p = self.params[unit]
        sigma = np.sqrt(p.on_sd[3:] ** 2 + p.gm_sd[3:] ** 2)
        excess = (float(factor) - 1.0) * sigma
        self.E[unit, _ON + 3:_ON + 6] += excess
        for k in (_GM - 6 + 3, _RW - 6 + 3):            # gyro columns of the slow block
            self._noise_scale[unit, k:k + 3] *= float(factor)
        self._coef = None
        self.version += 1
        return excess

    def make_deterministic(self) -> None:
        """Freeze every unit's realisation from now on: the in-run bias parts fold into the
        turn-on constants, and there is no white noise, no slow-state noise or decay, and no
        quantisation (for comparisons with the same realisation in another model)."""
        self.E[:, _ON:_ON + 6] += self.E[:, _GM:_GM + 6] + self.E[:, _RW:_RW + 6]
        self.E[:, _GM:_SF] = 0.0
        self.params = [replace(p, white_psd=np.zeros(6), lsb=np.zeros(6), gm_sd=np.zeros(6),
                               gm_tau_s=np.full(6, math.inf), rw_psd=np.zeros(6),
                               sf_tau_s=np.full(6, math.inf), mis_tau_s=np.full(12, math.inf))
                       for p in self.params]
        self.lsb[:] = 0.0
        self.res[:] = 0.0
        self._coef = self._white = None
        self.version += 1

    def values(self, unit: int) -> np.ndarray:
        """Unit ``unit``'s error state (36,), a copy (SI; see the module docstring)."""
        return self.E[unit].copy()

    def replace_params(self, unit: int, params: ImuErrorParams) -> None:
        """Use ``params`` for unit ``unit`` from now on (the states keep their values)."""
        self.params[unit] = params
        self.lsb[unit] = params.lsb
        self._coef = self._white = None
        self.version += 1


__all__ = ["ImuErrorParams", "ImuErrors", "imu_error_params", "layout_33", "measure",
           "measure_quantised", "measure_row", "quantise", "ROW_E", "ROW_A", "ROW_S", "ROW_WSD",
           "ROW_LSB", "ROW_RES", "N_ROW",
           "advance_slow", "N_ERR", "N_SLOW"]

