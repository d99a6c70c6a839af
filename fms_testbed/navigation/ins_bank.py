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

from dataclasses import replace

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.presets import ImuModel


def _gamma(v: np.ndarray) -> np.ndarray:
    """Γ (3×6) of the misalignment model: rows [v_y v_z 0 0 0 0], [0 0 v_x v_z 0 0],
    [0 0 0 0 v_x v_y] (paper eq. 5.1)."""
    return np.array([[v[1], v[2], 0, 0, 0, 0], [0, 0, v[0], v[2], 0, 0], [0, 0, 0, 0, v[0], v[1]]])


def derive_seeds(seed: int, n: int) -> list[int]:
    """``n`` independent 32-bit seeds derived from ``seed`` (numpy ``SeedSequence.spawn``)."""
    return [int(c.generate_state(1)[0]) for c in np.random.SeedSequence(int(seed)).spawn(n)]


class InsBank:
    """INS units with independent error realisations.

    Parameters
    ----------
    imus : one declared IMU model per unit
    seeds : one seed per unit (:func:`derive_seeds`)
    method : discretisation of the truth error model (``picard`` or ``vanloan``)
    """

    def __init__(self, imus: list[ImuModel], seeds: list[int], method: str = "picard"):
        if len(imus) != len(seeds):
            raise ValueError("one seed per INS unit")
        opts = SinsOptions(method=method, vertical="free")
        self.units = [SinsNavigation(imu, seed=s, opts=opts) for imu, s in zip(imus, seeds)]
        self.stuck: dict[int, NavSolution] = {}          # unit → its frozen output
        self.compensation = np.zeros((len(self.units), 6))  # bias compensation fed back so far
        self._rng = np.random.default_rng(np.random.SeedSequence(seeds).spawn(1)[0])

    def __len__(self) -> int:
        return len(self.units)

    def update(self, truth: AircraftState) -> list[NavSolution]:
        """Advance every unit to ``truth.t_s`` and return their outputs (indicated solutions); a
        stuck unit repeats its frozen output (time stamp advancing)."""
        out = [u.update(truth) for u in self.units]
        for i, held in self.stuck.items():
            out[i] = replace(held, t_s=truth.t_s)
        return out

    def output(self, i: int, truth: AircraftState) -> NavSolution:
        """Unit ``i``'s current output at ``truth`` (after a correction)."""
        if i in self.stuck:
            return replace(self.stuck[i], t_s=truth.t_s)
        return self.units[i].solution(truth)

    def correct(self, i: int, dx: np.ndarray) -> None:
        """Feed back a filter estimate: subtract ``dx`` (15,: δp m, δV m/s, ε rad, b_a m/s²,
        b_g rad/s) from unit ``i``'s error state."""
        self.units[i].x[:15] -= dx
        self.compensation[i] += dx[9:15]

    def sensor_errors(self, truth: AircraftState, dt_s: float) -> np.ndarray:
        """(n, 6) what each unit's IMU outputs minus the truth over the last ``dt_s`` (s): the
        accelerometer (m/s²) and gyro (rad/s) errors of the error model (paper eq. 5.1-5.6:
        bias + scale factor + misalignment at the true specific force and rate; the bias is
        the sensor's own, the error state's residual plus the compensation fed back), plus white
        noise of the unit's VRW/ARW averaged over ``dt_s`` (drawn from the bank's own stream:
        the same density as the noise inside the error model, not the same numbers)."""
        f = np.asarray(truth.f_body_mps2, float)
        w = np.array([truth.p_rps, truth.q_rps, truth.r_rps])
        gf, gw = _gamma(f), _gamma(w)
        out = np.empty((len(self.units), 6))
        for i, u in enumerate(self.units):
            x = u.x
            b = x[9:15] + self.compensation[i]       # the sensor's bias, not the residual
            out[i, :3] = b[:3] + x[15:18] * f + gf @ x[21:27]
            out[i, 3:] = b[3:] + x[18:21] * w + gw @ x[27:33]
            out[i] += np.sqrt(u.imu.q_psd[3:9] / dt_s) * self._rng.standard_normal(6)
        return out

    def freeze(self, i: int, last: NavSolution) -> None:
        """Unit ``i``'s output sticks at ``last`` from now on (a stuck-output fault)."""
        self.stuck[i] = last

    def errors(self, i: int) -> np.ndarray:
        """Unit ``i``'s true error state (33,), truth side (for tests and logs)."""
        return self.units[i].x


__all__ = ["InsBank", "derive_seeds"]
