"""Vertical laws (altitude + speed) and their analysis.

Every law follows the runner's protocol: constructed as ``cls(aircraft_cfg)``, then
``engage(state, alt_cmd_m, tas_cmd_mps)`` once and ``update(dt_s, state, alt_cmd_m, tas_cmd_mps)
-> (nx_cmd, ny_cmd)`` (load factors in g) at the outer-loop rate.
"""

from __future__ import annotations

from typing import Protocol

from ..state import AircraftState
from .baselines import SeparateChannelsLaw, TecsLaw
from .coupled_law import CoupledLaw, CoupledLawParams, params_from_config


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

__all__ = ["VERTICAL_LAWS", "VerticalLaw", "CoupledLaw", "CoupledLawParams", "SeparateChannelsLaw",
           "TecsLaw", "params_from_config"]
