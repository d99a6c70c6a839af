"""The interface of a bank of INS units, the one the INS/GNSS filter drives.

Two implementations: :class:`~fms_testbed.navigation.ins_bank.InsBank` (each unit truth ⊕ a
realisation of the linear 33-state error model) and
:class:`~fms_testbed.navigation.inertial.bank.StrapdownBank` (each unit a strapdown mechanisation
of its own IMU's measured increments). A filter written against :class:`InsBankLike` runs on
either.

Conventions (as in :mod:`fms_testbed.navigation.ins_filter`): navigation errors are *indicated
minus true*; δp in local ENU metres (E, N, U) of the aircraft's reference point, δV ENU m/s, ε
small rotations about E, N, U (rad) with C_B^N,ind = (I - [ε×]) C_B^N,true; sensor biases in
body axes (x forward, y right, z down): b_a m/s², b_g rad/s.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution


@runtime_checkable
class InsBankLike(Protocol):
    """N INS units on the truth side of a simulation (the filter sees only what they output)."""

    #: per-frame JSBSim samples the units' IMUs need (``(property, scale to SI)``; ``()``: none)
    frame_properties: tuple[tuple[str, float], ...]

    def __len__(self) -> int:  # pragma: no cover - protocol
        """Number of units."""

    def update(self, truth: AircraftState, frames: np.ndarray | None = None
               ) -> list[NavSolution]:  # pragma: no cover - protocol
        """Advance every unit to ``truth.t_s`` (s) and return each unit's indicated solution
        (lat/lon rad, alt m in the package's sea-level datum, V ENU m/s, Euler rad; a stuck
        unit repeats its frozen output). ``frames``: the JSBSim samples of
        :attr:`frame_properties` since the previous call (``(n_frames, n_props)``, SI; ``None``
        on the first call)."""

    def output(self, i: int, truth: AircraftState) -> NavSolution:  # pragma: no cover
        """Unit ``i``'s current indicated solution at ``truth.t_s`` (e.g. after a correction)."""

    def correct(self, i: int, dx: np.ndarray) -> None:  # pragma: no cover - protocol
        """Feed back a filter estimate ``dx`` (15,): δp ENU m, δV ENU m/s, ε E/N/U rad, b_a
        body m/s², b_g body rad/s (indicated minus true): the unit's position, velocity and
        attitude are corrected by it and its bias compensation grows by ``dx[9:15]``."""

    def take_fed_back(self) -> np.ndarray:  # pragma: no cover - protocol
        """(n, 15) the corrections fed back to each unit since the last call (then zeroed)."""

    def freeze(self, i: int, last: NavSolution) -> None:  # pragma: no cover - protocol
        """Unit ``i``'s output sticks at ``last`` from now on (a stuck-output fault)."""

    def errors(self, i: int) -> np.ndarray:  # pragma: no cover - protocol
        """Unit ``i``'s true errors (33,) at the last update, truth side (tests, logs): δp ENU
        m, δV ENU m/s, ε E/N/U rad, then the sensor errors in the 33-state layout (b_a m/s²,
        b_g rad/s — less the compensation fed back —, k_a, k_g, β_a rad, β_g rad)."""

    def measured(self, i: int) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - protocol
        """Unit ``i``'s compensated measured specific force (3,) m/s² and angular rate ω_ib (3,)
        rad/s in body axes, averaged over the last step: what the filter's F and Q are built
        from (never the truth)."""


__all__ = ["InsBankLike"]
