"""Vertical laws (altitude + speed) and their analysis.

Every law follows the runner's protocol: constructed as ``cls(aircraft_cfg)``, then
``engage(state, alt_cmd_m, tas_cmd_mps)`` once and ``update(dt_s, state, alt_cmd_m, tas_cmd_mps)
-> (nx_cmd, ny_cmd)`` (load factors in g) at the outer-loop rate.
"""

from __future__ import annotations

from typing import Protocol

from fms_testbed.core.state import AircraftState
from fms_testbed.control.baselines import SeparateChannelsLaw, TecsLaw
from fms_testbed.control.coupled_law import (CoupledLaw, CoupledLawParams, params_from_config,
                                             schedule_from_config)


class VerticalLaw(Protocol):
    """Interface of a vertical law (called by the runner at the outer-loop rate)."""

    def engage(self, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float) -> None:
        """Take over from the current state without a bump."""

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:
        """Return (nx_cmd, ny_cmd) in g for the inner loops."""


#: Name used in scenario files (``vertical_law:``) → class.
VERTICAL_LAWS: dict[str, type] = {
    "coupled": CoupledLaw,
    "pi": SeparateChannelsLaw,
    "tecs": TecsLaw,
}

LAW_CLIMB_FRACTION = 1.0
"""The coupled law's level-change rate is set to this fraction of the aircraft's sustained
climb rate (above the planned rate, so the law can catch up with the plan)."""


def procedure_law(cfg):
    """The coupled law for procedure flights: the aircraft's tuning with the level-change
    altitude-error limit raised so that its climb rate ``dH_limit / (2 ξ_H T_H)`` is
    LAW_CLIMB_FRACTION × ``limits.climb_rate_max_mps`` (never below the configured limit)."""
    g = cfg.coupled_law
    dh = max(g.dH_limit_m, LAW_CLIMB_FRACTION * cfg.limits.climb_rate_max_mps
             * 2.0 * g.xi_H * g.T_H_s)
    return CoupledLaw(params=params_from_config(cfg, dH_limit_m=dh),
                      schedule=schedule_from_config(cfg))



__all__ = ["procedure_law", "LAW_CLIMB_FRACTION", "VERTICAL_LAWS", "VerticalLaw", "CoupledLaw", "CoupledLawParams", "SeparateChannelsLaw",
           "TecsLaw", "params_from_config", "schedule_from_config"]
