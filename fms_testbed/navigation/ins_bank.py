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

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.presets import ImuModel


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

    def __len__(self) -> int:
        return len(self.units)

    def update(self, truth: AircraftState) -> list[NavSolution]:
        """Advance every unit to ``truth.t_s`` and return their outputs (indicated solutions)."""
        return [u.update(truth) for u in self.units]

    def output(self, i: int, truth: AircraftState) -> NavSolution:
        """Unit ``i``'s current output at ``truth`` (after a correction)."""
        return self.units[i].solution(truth)

    def correct(self, i: int, dx: np.ndarray) -> None:
        """Feed back a filter estimate: subtract ``dx`` (15,: δp m, δV m/s, ε rad, b_a m/s²,
        b_g rad/s) from unit ``i``'s error state."""
        self.units[i].x[:15] -= dx

    def errors(self, i: int) -> np.ndarray:
        """Unit ``i``'s true error state (33,), truth side (for tests and logs)."""
        return self.units[i].x


__all__ = ["InsBank", "derive_seeds"]
