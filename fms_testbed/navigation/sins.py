"""SINS navigation source: truth ⊕ the 33-state error model, one step per navigation update.

Scenario block (``navigation:``)::

    source: sins
    truth_model: linear     # linear (this class) | strapdown (.strapdown_sins)
    imu: STIM300            # preset name (imu/*.yaml), a .yaml path, or an inline mapping
    seed: 7                 # optional; otherwise the run seed
    method: picard          # picard | vanloan | trapezoid
    dt_s: 0.1               # nominal navigation step, s (the step actually used is Δt of truth)
    vertical: baro          # baro (damped, default) | free (unstable vertical channel)
    baro_tau_s: 60          # baro loop time constant, s
    tol: 1.0e-12            # adaptive Picard tolerance
    alignment: stationary   # stationary (self-alignment at the start attitude) | none
    matrices_dt_s: 0        # reuse Φ_k, S_k for this long (s) before rebuilding F; 0 = every step
    matrices_rotation_deg: 1.0e9   # ... and only while the body has turned less than this, deg

Each :meth:`SinsNavigation.update` builds F at the previous true state, discretises over the
elapsed Δt, propagates x_k = Φ x_{k-1} + S N_k (paper eq. 6.11) and returns truth ⊕ errors.
With ``matrices_dt_s > 0`` the last Φ_k, S_k are reused (same Δt) until that much time has
passed, or the body has turned ``matrices_rotation_deg`` (∫|ω| dt) since they were built: the
propagation then costs two 33×33 products per step, at the price of holding F (attitude,
specific force, rates) constant over that interval — the rotation limit keeps the hold to
straight flight, where F hardly changes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit

import fms_testbed.core.earth as _earth
import fms_testbed.sensors.sins as _sins_pkg
from fms_testbed.core.contracts import NavigationSourceBase
from fms_testbed.core._numba_cache import invalidate_if_sources_changed

# this module's kernel inlines the SINS package's kernels and the Earth model's: clear its cache
# when any of them changes
invalidate_if_sources_changed(Path(__file__).parent, also_hash=(Path(_sins_pkg.__file__).parent,
                                                                 Path(_earth.__file__)))

from fms_testbed.core.earth import OMEGA_IE_RPS, radii_and_derivatives, radii_m
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.euler import eps_to_euler_errors_scalar
from fms_testbed.sensors.sins.discretize import (PICARD_MAX_ORDER, PICARD_MAX_RATE_DT, DiscretisationError,
                         _picard_sins, discretize)
from fms_testbed.sensors.sins.model import baro_gains, build_F
from fms_testbed.sensors.sins.presets import ImuModel, load_imu
from fms_testbed.sensors.sins.simulate import FACTOR_RTOL, IndefiniteCovarianceError, _psd_cholesky
from fms_testbed.sensors.sins._blas import single_thread_blas
from fms_testbed.sensors.sins.analysis import system_matrix, initial_map

SPEC_KEYS = {"source", "imu", "seed", "method", "dt_s", "vertical", "baro_tau_s", "tol",
             "matrices_dt_s", "matrices_rotation_deg", "alignment", "truth_model"}
NOISE_BLOCK = 256   # navigation steps of process noise drawn at once


@njit(cache=True)
def _c_bn(roll, pitch, heading):
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    ch, sh = math.cos(heading), math.sin(heading)
    c = np.empty((3, 3))
    c[0, 0] = cp * sh
    c[0, 1] = sr * sp * sh + cr * ch
    c[0, 2] = cr * sp * sh - sr * ch
    c[1, 0] = cp * ch
    c[1, 1] = sr * sp * ch - cr * sh
    c[1, 2] = cr * sp * ch + sr * sh
    c[2, 0] = sp
    c[2, 1] = -sr * cp
    c[2, 2] = -cr * cp
    return c


@njit(cache=True)
def _sins_step(x, noise, lat, alt, v, rpy, w_eb, f_b, decay, q_diag, k1, k2, dt, tol, rtol):
    """Fused kernel: F at the true state → Picard (Φ, Q_k) → S → (Φ x + S N, Φ, S, status);
    status 0 ok, 1 Picard range, 2 no convergence, 3 indefinite Q_k."""
    c = _c_bn(rpy[0], rpy[1], rpy[2])
    w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    w_ib = w_eb + c.T @ w_ie
    F = build_F(lat, alt, v, f_b, w_ib, c, decay, k1, k2)
    rate = 0.0
    for i in range(F.shape[0]):
        rate = max(rate, abs(F[i, i]))
    empty = np.zeros((0, 0))
    if rate * dt > PICARD_MAX_RATE_DT:
        return x, empty, empty, 1
    phi, qk, _, ok = _picard_sins(F, q_diag, dt, tol, PICARD_MAX_ORDER)
    if not ok:
        return x, empty, empty, 2
    L, bad = _psd_cholesky(qk, rtol)
    if bad >= 0:
        return x, empty, empty, 3
    return phi @ x + L @ noise, phi, L, 0


@njit(cache=True)
def _outputs_many(X, lat, lon, alt, v_enu, roll, pitch, heading):
    """Indicated outputs of k units at one true state: truth ⊕ error (X (k, ≥9): δp ENU m, δV
    m/s, ε rad); Euler errors by paper eq. 6.10 (the scalar form of
    euler.eps_to_euler_errors). Returns (k, 9) [lat rad, lon rad, alt m, V E N U m/s, roll,
    pitch, heading rad]."""
    k = X.shape[0]
    out = np.empty((k, 9))
    rm, rn, _, _ = radii_and_derivatives(lat)
    cl = math.cos(lat)
    for i in range(k):
        d_roll, d_pitch, d_head = eps_to_euler_errors_scalar(X[i, 6], X[i, 7], X[i, 8], pitch,
                                                             heading)
        out[i, 0] = lat + X[i, 1] / (rm + alt)
        out[i, 1] = lon + X[i, 0] / ((rn + alt) * cl)
        out[i, 2] = alt + X[i, 2]
        for j in range(3):
            out[i, 3 + j] = v_enu[j] + X[i, 3 + j]
        out[i, 6] = roll + d_roll
        out[i, 7] = pitch + d_pitch
        out[i, 8] = (heading + d_head) % (2.0 * math.pi)
    return out


def outputs(X: np.ndarray, truth: AircraftState) -> np.ndarray:
    """(k, 9) indicated outputs [lat rad, lon rad, alt m, V E N U m/s, roll, pitch, heading
    rad] of k error states X (k, ≥9) at the true state (:func:`_outputs_many`)."""
    return _outputs_many(X, truth.lat_rad, truth.lon_rad, truth.alt_m,
                         np.asarray(truth.v_enu_mps, float), truth.roll_rad, truth.pitch_rad,
                         truth.heading_rad)


def output_solution(t_s: float, o: np.ndarray, errors: dict | None = None) -> NavSolution:
    """A :class:`NavSolution` from one row of :func:`outputs`."""
    return NavSolution(t_s, o[0], o[1], o[2], o[3:6], o[6], o[7], o[8],
                       {} if errors is None else errors)


class SinsNavigation(NavigationSourceBase):
    """Navigation source with SINS errors; see the module docstring for the scenario keys."""

    #: per-frame JSBSim samples the truth side needs (none: it reads the outer-step state)
    frame_properties: tuple[tuple[str, float], ...] = ()
    #: the truth side: truth ⊕ the linear error model
    truth_model = "linear"

    def __init__(self, imu: ImuModel, seed: int = 0, opts: SinsOptions = SinsOptions(),
                 dt_s: float = 0.1, matrices_dt_s: float = 0.0,
                 matrices_rotation_deg: float = 1e9):
        self.imu = imu
        self.opts = opts
        self.dt_s = float(dt_s)
        self.matrices_dt_s = float(matrices_dt_s)
        self.matrices_rotation_rad = math.radians(matrices_rotation_deg)
        self._turned_rad = 0.0      # ∫|ω| dt since the held matrices were built
        self.seed = int(seed)
        self.rng = np.random.default_rng(self.seed)
        self._z0 = np.sqrt(imu.p0_var) * self.rng.standard_normal(imu.p0_var.size)
        # process noise drawn NOISE_BLOCK steps at a time: numpy's Generator fills a block in
        # the order of successive draws, so the numbers are those of one draw per step
        self._noise = np.empty((0, imu.p0_var.size))
        self._noise_i = 0
        self.x = self._z0.copy()          # mapped through the alignment at the first update
        self._prev: AircraftState | None = None
        self._gains: tuple[float, float] | None = None       # baro gains, set at the first step
        self._held = None                                    # (t_built_s, dt_s, Φ, S)
        self.last_matrices = None                            # (prev state, dt_s, Φ, S) of the last step

    @classmethod
    def from_spec(cls, spec: dict, seed: int | None = None) -> "SinsNavigation":
        """Build from a scenario's ``navigation`` mapping (``spec['seed']`` wins over ``seed``).

        Raises
        ------
        ConfigError : unknown key, missing ``imu``, or a bad value (named ``navigation.<key>``).
        """
        if not isinstance(spec, dict):
            raise ConfigError(f"navigation: expected a mapping, got {type(spec).__name__}")
        unknown = sorted(set(spec) - SPEC_KEYS)
        if unknown:
            raise ConfigError(f"navigation.{unknown[0]}: unknown key; allowed: "
                              f"{', '.join(sorted(SPEC_KEYS))}")
        truth_model = spec.get("truth_model", "linear")
        if truth_model not in ("linear", "strapdown"):
            raise ConfigError(f"navigation.truth_model: strapdown or linear, got {truth_model!r}")
        if truth_model == "strapdown":
            from fms_testbed.navigation.strapdown_sins import StrapdownSinsNavigation
            return StrapdownSinsNavigation.from_spec(spec, seed)
        if "imu" not in spec:
            raise ConfigError("navigation.imu: missing (a preset name, a .yaml path or a mapping)")
        imu = load_imu(spec["imu"])
        try:
            opts = SinsOptions(method=str(spec.get("method", "picard")),
                               tol=float(spec.get("tol", 1e-12)),
                               vertical=str(spec.get("vertical", "baro")),
                               baro_tau_s=float(spec.get("baro_tau_s", 60.0)),
                               alignment=str(spec.get("alignment", "stationary")))
            dt_s = float(spec.get("dt_s", 0.1))
            matrices_dt_s = float(spec.get("matrices_dt_s", 0.0))
            matrices_rotation_deg = float(spec.get("matrices_rotation_deg", 1e9))
            sd = spec.get("seed", seed)
            sd = 0 if sd is None else int(sd)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"navigation: bad value: {exc}") from None
        if not dt_s > 0:
            raise ConfigError(f"navigation.dt_s: must be > 0 s, got {dt_s}")
        if matrices_dt_s < 0:
            raise ConfigError(f"navigation.matrices_dt_s: must be >= 0 s, got {matrices_dt_s}")
        if not matrices_rotation_deg > 0:
            raise ConfigError("navigation.matrices_rotation_deg: must be > 0 deg, got "
                              f"{matrices_rotation_deg}")
        return cls(imu, seed=sd, opts=opts, dt_s=dt_s, matrices_dt_s=matrices_dt_s,
                   matrices_rotation_deg=matrices_rotation_deg)

    def _next_noise(self) -> np.ndarray:
        """This step's standard-normal process-noise vector (drawn NOISE_BLOCK steps at once)."""
        if self._noise_i >= len(self._noise):
            self._noise = self.rng.standard_normal((NOISE_BLOCK, self.x.size))
            self._noise_i = 0
        noise = self._noise[self._noise_i]
        self._noise_i += 1
        return noise

    def replace_imu(self, imu: ImuModel) -> None:
        """Replace the unit's IMU model from now on (a fault changing its errors); held
        matrices built with the old model are dropped."""
        self.imu = imu
        self._held = None

    def held_for(self, prev: AircraftState, dt: float) -> tuple[tuple | None, float]:
        """(the held (t_built_s, Δt, Φ, S) if they serve the step of ``dt`` (s) from ``prev``,
        else None; the rotation since they were built, rad, counting this step) — no side
        effect."""
        held = self._held
        if held is None:
            return None, 0.0
        turned = self._turned_rad + math.sqrt(prev.p_rps ** 2 + prev.q_rps ** 2
                                              + prev.r_rps ** 2) * dt
        ok = (abs(held[1] - dt) <= 1e-6 * dt and prev.t_s - held[0] < self.matrices_dt_s - 1e-9
              and turned < self.matrices_rotation_rad)
        return (held if ok else None), turned

    def _propagate(self, prev: AircraftState, dt: float) -> None:
        noise = self._next_noise()
        held, self._turned_rad = self.held_for(prev, dt)
        if held is not None:
            self.x = held[2] @ self.x + held[3] @ noise
            return
        o = self.opts
        if self._gains is None:
            self._gains = baro_gains(o.baro_tau_s if o.vertical == "baro" else None,
                                     prev.lat_rad)
        k1, k2 = self._gains
        rpy = np.array([prev.roll_rad, prev.pitch_rad, prev.heading_rad])
        w_eb = np.array([prev.p_rps, prev.q_rps, prev.r_rps])
        v = np.asarray(prev.v_enu_mps, float)
        f_b = np.asarray(prev.f_body_mps2, float)
        if o.method == "picard":
            x, phi, L, status = _sins_step(self.x, noise, prev.lat_rad, prev.alt_m, v, rpy, w_eb,
                                           f_b, self.imu.decay_rps, self.imu.q_psd, k1, k2, dt,
                                           o.tol, FACTOR_RTOL)
            if status == 1 or status == 2:
                raise DiscretisationError(
                    f"navigation: Picard series unsuitable at dt = {dt:g} s (Δt/τ > "
                    f"{PICARD_MAX_RATE_DT} or no convergence); set navigation.method: vanloan")
            if status == 3:
                raise IndefiniteCovarianceError(f"navigation: Q_k indefinite at t = {prev.t_s} s")
        else:
            F = system_matrix(prev.lat_rad, prev.alt_m, v, rpy, w_eb, f_b, self.imu, o)
            with single_thread_blas():
                phi, qk = discretize(F, np.diag(self.imu.q_psd), dt, method=o.method)
            L, bad = _psd_cholesky(np.ascontiguousarray(qk), FACTOR_RTOL)
            if bad >= 0:
                raise IndefiniteCovarianceError(f"navigation: Q_k indefinite at t = {prev.t_s} s "
                                                f"(method {o.method})")
            x = phi @ self.x + L @ noise
        self.x = x
        self.last_matrices = (prev, dt, phi, L)     # for units sharing this step (ins_bank)
        if self.matrices_dt_s > 0:
            self._held = (prev.t_s, dt, phi, L)
            self._turned_rad = 0.0

    def update(self, truth: AircraftState, frames=None) -> NavSolution:
        """Advance the error state to ``truth.t_s`` and return truth ⊕ errors."""
        self.advance(truth)
        return self.solution(truth)

    def advance(self, truth: AircraftState) -> None:
        """Advance the error state to ``truth.t_s`` (the first call maps the alignment errors).

        Raises
        ------
        UserError : time went backwards
        """
        prev = self._prev
        if prev is None:
            rpy = (truth.roll_rad, truth.pitch_rad, truth.heading_rad)
            self.x = initial_map(truth.lat_rad, rpy, self.imu, self.opts) @ self._z0
        else:
            dt = truth.t_s - prev.t_s
            if dt < 0:
                raise UserError(f"navigation: time went backwards ({prev.t_s} -> {truth.t_s} s)")
            if dt > 0:
                self._propagate(prev, dt)
        self._prev = truth

    def solution(self, truth: AircraftState, errors: bool = True) -> NavSolution:
        """Truth ⊕ the current error state (position, velocity, attitude, :func:`outputs`; with
        ``errors`` the errors dict for logs — an INS bank's units leave it empty)."""
        x = self.x
        o = outputs(x[None, :], truth)[0]
        if not errors:
            return output_solution(truth.t_s, o)
        e, n, u, ve, vn, vu, _, _, _, ba_x, _, _, bg_x, _, bg_z = x[:15].tolist()
        errs = {
            "nse_east_m": e, "nse_north_m": n, "nse_up_m": u,
            "ve_err_mps": ve, "vn_err_mps": vn, "vu_err_mps": vu,
            "att_err_roll_deg": math.degrees(o[6] - truth.roll_rad),
            "att_err_pitch_deg": math.degrees(o[7] - truth.pitch_rad),
            "att_err_heading_deg": math.degrees(math.remainder(o[8] - truth.heading_rad,
                                                               2 * math.pi)),
            "bias_accel_x_ug": ba_x / G0_MPS2 * 1e6,
            "bias_gyro_x_dph": bg_x / DPH_RPS, "bias_gyro_z_dph": bg_z / DPH_RPS,
        }
        return output_solution(truth.t_s, o, errs)
