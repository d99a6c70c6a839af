"""N independent INS units on the truth side: each is truth ⊕ its own realisation of the
33-state SINS error model (:class:`~fms_testbed.navigation.sins.SinsNavigation`, free vertical
channel: the integrated filter, not a baro loop, damps it), with seeds derived from one run seed.

Seed derivation: :func:`derive_seeds` spawns independent streams with numpy's ``SeedSequence``
(``SeedSequence(seed).spawn(n)``), so the units, the GNSS receiver and the baro of a run never
share random numbers, and adding a unit does not change the others' realisations.

Feedback: :meth:`InsBank.correct` subtracts a filter's estimate of position, velocity, attitude
and sensor-bias errors from a unit's error state — what correcting the mechanisation and the
bias compensation does to the error (the error model is linear, so the two are the same).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numba import njit

from fms_testbed.core.earth import OMEGA_IE_RPS
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.sins import SinsNavigation, _c_bn, output_solution, outputs
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.presets import ImuModel


@njit(cache=True)
def _advance(phi, x, L, noise):
    """x_k = Φ x_{k-1} + S N_k (paper eq. 6.11), the same expression as the SINS kernel's."""
    return phi @ x + L @ noise


@njit(cache=True)
def _advance_many(phi, X, L, N):
    """:func:`_advance` for k units sharing (Φ, S): X (k, 33), N (k, 33) their noise."""
    out = np.empty_like(X)
    for i in range(X.shape[0]):
        out[i] = phi @ X[i] + L @ N[i]
    return out


@njit(cache=True)
def _sensor_errors(X, comp, f, w, sd, z):
    """(n, 6) raw IMU output errors of n units (see :meth:`InsBank.sensor_errors`): X (n, 33)
    error states, comp (n, 6) compensation fed back, f (3,) m/s², w (3,) rad/s, sd (n, 6) white
    σ per sample, z (n, 6) standard normals."""
    n = X.shape[0]
    out = np.empty((n, 6))
    for i in range(n):
        x = X[i]
        # Γ(v) m (paper eq. 5.1): rows [v_y v_z 0 0 0 0], [0 0 v_x v_z 0 0], [0 0 0 0 v_x v_y]
        ga = (f[1] * x[21] + f[2] * x[22], f[0] * x[23] + f[2] * x[24],
              f[0] * x[25] + f[1] * x[26])
        gw = (w[1] * x[27] + w[2] * x[28], w[0] * x[29] + w[2] * x[30],
              w[0] * x[31] + w[1] * x[32])
        for a in range(3):
            out[i, a] = (x[9 + a] + comp[i, a]) + x[15 + a] * f[a] + ga[a]
            out[i, 3 + a] = (x[12 + a] + comp[i, 3 + a]) + x[18 + a] * w[a] + gw[a]
        for c in range(6):
            out[i, c] += sd[i, c] * z[i, c]
    return out


def derive_seeds(seed: int, n: int) -> list[int]:
    """``n`` independent 32-bit seeds derived from ``seed`` (numpy ``SeedSequence.spawn``)."""
    return [int(c.generate_state(1)[0]) for c in np.random.SeedSequence(int(seed)).spawn(n)]


_NOISE_BLOCK = 100
"""Steps of raw-sensor white noise drawn at once."""


class InsBank:
    """INS units with independent error realisations.

    Parameters
    ----------
    imus : one declared IMU model per unit
    seeds : one seed per unit (:func:`derive_seeds`)
    method : discretisation of the truth error model (``picard`` or ``vanloan``)
    share : units with the same IMU model object share one step's (Φ_k, S_k): every unit's
        error model is built at the same true state, so the matrices are the same numbers;
        only x_k = Φ x + S N_k (own noise N_k) is per unit (False: each unit rebuilds them)
    matrices_dt_s, matrices_rotation_deg : each unit reuses its (Φ_k, S_k) this long (s) while
        the body turns less than this (deg) (:class:`~.sins.SinsNavigation`; 0: every step)
    """

    def __init__(self, imus: list[ImuModel], seeds: list[int], method: str = "picard",
                 share: bool = True, matrices_dt_s: float = 0.0,
                 matrices_rotation_deg: float = 1e9):
        if len(imus) != len(seeds):
            raise ValueError("one seed per INS unit")
        opts = SinsOptions(method=method, vertical="free")
        self.units = [SinsNavigation(imu, seed=s, opts=opts, matrices_dt_s=matrices_dt_s,
                                     matrices_rotation_deg=matrices_rotation_deg)
                      for imu, s in zip(imus, seeds)]
        self.stuck: dict[int, NavSolution] = {}          # unit → its frozen output
        self.compensation = np.zeros((len(self.units), 6))  # bias compensation fed back so far
        self.fed_back = np.zeros((len(self.units), 15))      # corrections since take_fed_back
        self._rng = np.random.default_rng(np.random.SeedSequence(seeds).spawn(1)[0])
        self.share = bool(share)
        # sensor noise drawn _NOISE_BLOCK steps at a time (numpy's Generator fills a block in
        # the order of successive draws: the numbers of one draw per step)
        self._noise = np.empty((0, len(self.units), 6))
        self._noise_i = 0
        self._sd: tuple | None = None      # (dt_s, white σ per sample, the IMU models)

    def __len__(self) -> int:
        return len(self.units)

    def _advance_held(self, truth: AircraftState) -> bool:
        """Advance every unit in one compiled call when they all reuse the same held (Φ_k, S_k)
        over this step (the shared discretisation, held in straight flight); False (nothing
        done) otherwise."""
        u0 = self.units[0]
        prev = u0._prev
        if not self.share or prev is None or u0._held is None:
            return False
        dt = truth.t_s - prev.t_s
        if dt <= 0:
            return False
        held, turned = u0.held_for(prev, dt)
        if held is None or any(u._prev is not prev or u._held is not held or u.imu is not u0.imu
                               for u in self.units[1:]):
            return False
        X = _advance_many(held[2], np.array([u.x for u in self.units]), held[3],
                          np.array([u._next_noise() for u in self.units]))
        for i, u in enumerate(self.units):
            u.x = X[i]
            u._turned_rad = turned          # the same rates: the same rotation for every unit
            u._prev = truth
        return True

    #: per-frame JSBSim samples the units need (none: the error model reads the outer-step state)
    frame_properties: tuple[tuple[str, float], ...] = ()

    def update(self, truth: AircraftState, frames=None) -> list[NavSolution]:
        """Advance every unit to ``truth.t_s`` and return their outputs (indicated solutions); a
        stuck unit repeats its frozen output (time stamp advancing). ``frames`` is not used
        (:class:`~fms_testbed.navigation.bank.InsBankLike`)."""
        if self._advance_held(truth):
            O = outputs(np.array([u.x[:9] for u in self.units]), truth)
            out = [output_solution(truth.t_s, o) for o in O]
            for i, held in self.stuck.items():
                out[i] = replace(held, t_s=truth.t_s)
            return out
        out = []
        lead = None                          # a unit that just built this step's matrices
        for u in self.units:
            prev = u._prev
            lm = lead.last_matrices if lead is not None else None
            if (lm is not None and prev is lm[0] and u.imu is lead.imu and u.opts == lead.opts
                    and u.matrices_dt_s == lead.matrices_dt_s
                    and u.matrices_rotation_rad == lead.matrices_rotation_rad
                    and truth.t_s - prev.t_s == lm[1]):
                u.x = _advance(lm[2], u.x, lm[3], u._next_noise())
                u._gains = lead._gains
                u._held, u._turned_rad = lead._held, lead._turned_rad   # hold them alike
                u._prev = truth
                out.append(u.solution(truth, errors=False))
                continue
            u.advance(truth)
            out.append(u.solution(truth, errors=False))
            lm = u.last_matrices
            lead = u if (self.share and prev is not None and lm is not None and lm[0] is prev
                         ) else None
        for i, held in self.stuck.items():
            out[i] = replace(held, t_s=truth.t_s)
        return out

    def output(self, i: int, truth: AircraftState) -> NavSolution:
        """Unit ``i``'s current output at ``truth`` (after a correction)."""
        if i in self.stuck:
            return replace(self.stuck[i], t_s=truth.t_s)
        return self.units[i].solution(truth, errors=False)

    def correct(self, i: int, dx: np.ndarray) -> None:
        """Feed back a filter estimate: subtract ``dx`` (15,: δp m, δV m/s, ε rad, b_a m/s²,
        b_g rad/s) from unit ``i``'s error state."""
        self.units[i].x[:15] -= dx
        self.compensation[i] += dx[9:15]
        self.fed_back[i] += dx

    def take_fed_back(self) -> np.ndarray:
        """(n, 15) the corrections fed back to each unit since the last call (δp m, δV m/s, ε
        rad, b_a m/s², b_g rad/s), then zeroed: what a free-running copy of each unit would not
        have had (:mod:`.reference_description`)."""
        out = self.fed_back.copy()
        self.fed_back[:] = 0.0
        return out

    def sensor_errors(self, truth: AircraftState, dt_s: float) -> np.ndarray:
        """(n, 6) what each unit's IMU outputs minus the truth over the last ``dt_s`` (s): the
        accelerometer (m/s²) and gyro (rad/s) errors of the error model (paper eq. 5.1-5.6:
        bias + scale factor + misalignment at the true specific force and rate; the bias is
        the sensor's own, the error state's residual plus the compensation fed back), plus white
        noise of the unit's VRW/ARW averaged over ``dt_s`` (drawn from the bank's own stream:
        the same density as the noise inside the error model, not the same numbers)."""
        f = np.asarray(truth.f_body_mps2, float)
        w = np.array([truth.p_rps, truth.q_rps, truth.r_rps])
        n = len(self.units)
        # the sensor's bias is the error state's residual plus the compensation fed back
        X = np.array([u.x for u in self.units])
        imus = [u.imu for u in self.units]       # a drift_scale fault replaces a model
        if (self._sd is None or abs(self._sd[0] - dt_s) > 1e-9 * dt_s
                or any(a is not b for a, b in zip(self._sd[2], imus))):
            self._sd = (dt_s, np.array([np.sqrt(u.imu.q_psd[3:9] / dt_s) for u in self.units]),
                        imus)
        if self._noise_i >= len(self._noise):
            self._noise = self._rng.standard_normal((_NOISE_BLOCK, n, 6))
            self._noise_i = 0
        noise = self._noise[self._noise_i]
        self._noise_i += 1
        return _sensor_errors(X, self.compensation, f, w, self._sd[1], noise)

    def measured(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Unit ``i``'s compensated measured specific force (3,) m/s² and angular rate ω_ib
        (3,) rad/s, body axes, at the last update's true state: the truth plus the unit's
        deterministic sensor errors less the compensation fed back (bias residual + scale
        factor + misalignment, paper eq. 5.1-5.6, :func:`_sensor_errors` without its white
        noise — the noise is drawn only by :meth:`sensor_errors`, whose stream this leaves
        untouched). The :class:`~fms_testbed.navigation.bank.InsBankLike` method."""
        truth = self.units[i]._prev
        f = np.asarray(truth.f_body_mps2, float)
        c = _c_bn(truth.roll_rad, truth.pitch_rad, truth.heading_rad)
        w_ie = np.array([0.0, OMEGA_IE_RPS * math.cos(truth.lat_rad),
                         OMEGA_IE_RPS * math.sin(truth.lat_rad)])
        w = np.array([truth.p_rps, truth.q_rps, truth.r_rps]) + c.T @ w_ie
        e = _sensor_errors(self.units[i].x[None, :], np.zeros((1, 6)), f, w, np.zeros((1, 6)),
                           np.zeros((1, 6)))[0]
        return f + e[:3], w + e[3:]

    def freeze(self, i: int, last: NavSolution) -> None:
        """Unit ``i``'s output sticks at ``last`` from now on (a stuck-output fault)."""
        self.stuck[i] = last

    def errors(self, i: int) -> np.ndarray:
        """Unit ``i``'s true error state (33,), truth side (for tests and logs)."""
        return self.units[i].x


__all__ = ["InsBank", "derive_seeds"]
