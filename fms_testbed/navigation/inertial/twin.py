"""The linear 33-state model with a strapdown unit's own error realisation: the fast mode
checked against the nonlinear mechanisation on the same trajectory.

:func:`linear_twin` returns a :class:`~fms_testbed.navigation.sins.SinsNavigation` whose state
starts at the unit's true errors (navigation errors after its alignment, its sensor errors in
the 33-state layout) and whose process noise and sensor decay are zero: with the unit's IMU made
deterministic (:meth:`~fms_testbed.sensors.imu.errors.ImuErrors.make_deterministic`) both models
then carry the same constant sensor errors, and what differs is the error propagation itself —
the linearisation (second-order terms: the velocity error's (C_ind - C_true) f expands to
-ε × f + ½ ε × (ε × f) + ..., a relative ½|ε| for an attitude error ε) and the 10-Hz zero-order
hold of F against the strapdown's exact 120-Hz dynamics.
"""

from __future__ import annotations

import numpy as np

from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.sensors.sins.analysis import SinsOptions
from fms_testbed.sensors.sins.model import N_STATES
from fms_testbed.sensors.sins.presets import ImuModel


def linear_twin(bank, unit: int) -> SinsNavigation:
    """A noise-free 33-state model starting at ``bank.errors(unit)`` (call it after the bank's
    first update; free vertical channel, no alignment mapping: the errors are the unit's own).

    Parameters
    ----------
    bank : a :class:`~fms_testbed.navigation.inertial.bank.StrapdownBank` after its first update
    unit : which unit
    """
    model = ImuModel("twin", "", np.zeros(24), np.zeros(N_STATES), np.zeros(N_STATES))
    twin = SinsNavigation(model, seed=0, opts=SinsOptions(vertical="free", alignment="none"))
    twin._z0 = bank.errors(unit).copy()
    twin.x = twin._z0.copy()
    return twin


__all__ = ["linear_twin"]
