"""Interfaces between the layers: what a navigation source, a guidance and a vertical law look
like to the flight loop. Plain Protocols and dataclasses; units in every name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from fms_testbed.core.state import AircraftState, NavSolution


class NavigationSource(Protocol):
    """A navigation source: called once per navigation step with the true state (the truth side
    gives it what its sensors would measure) and returns what the navigation system believes.

    Sensors that sample faster than the navigation step (an IMU at the JSBSim frame rate) name
    the JSBSim properties they read in :attr:`frame_properties`; the flight loop then reads them
    after every JSBSim frame of the step and hands them to :meth:`update` as ``frames``.
    """

    #: ``(property, scale to SI)`` pairs sampled after every JSBSim frame; ``()``: none
    frame_properties: tuple[tuple[str, float], ...]

    def update(self, truth: AircraftState, frames: np.ndarray | None = None
               ) -> NavSolution:  # pragma: no cover - protocol
        """Return the navigation solution at ``truth.t_s``.

        ``frames``: shape ``(n_frames, len(frame_properties))``, the samples (SI) taken after
        each JSBSim frame since the previous call, the last row at ``truth.t_s``; ``None`` on
        the first call and when :attr:`frame_properties` is empty."""


@dataclass
class GuidanceOutput:
    """What a path guidance returns each outer step.

    Attributes
    ----------
    bank_rad : bank-angle command, rad (None: leave the lateral channel alone)
    alt_m : altitude target for the vertical law, m (None: unchanged)
    tas_mps : true-airspeed target for the vertical law, m/s (None: unchanged)
    done : True once the path has been flown to its end
    log : extra timeseries columns for this step (names with units)
    """

    bank_rad: float | None = None
    alt_m: float | None = None
    tas_mps: float | None = None
    done: bool = False
    log: dict[str, float] = field(default_factory=dict)


class Guidance(Protocol):
    """Lateral/vertical guidance flying on the navigation solution, called at the outer rate."""

    def update(self, dt_s: float, nav: NavSolution, truth: AircraftState
               ) -> GuidanceOutput:  # pragma: no cover - protocol
        """Return the commands for the next ``dt_s`` seconds."""


class VerticalLaw(Protocol):
    """A vertical law (altitude + speed), called by the flight loop at the outer-loop rate."""

    def engage(self, state: AircraftState, alt_cmd_m: float,
               tas_cmd_mps: float) -> None:  # pragma: no cover - protocol
        """Take over from the current state without a bump."""

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:  # pragma: no cover - protocol
        """Return (nx_cmd, ny_cmd) in g for the inner loops (ny in the vertical plane)."""
