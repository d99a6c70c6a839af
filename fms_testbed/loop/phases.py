"""The phases of a flight, each a set of steps of the one flight loop (:mod:`.flight`).

Every outer step the loop calls, in this order, the active phase's

``check(s, raw)`` → ``wind(s)`` → (navigation, air data, events, guidance) →
``after_guidance(s, gout)`` → ``command(s, nav, air, gout)`` → (log) → ``advance()``

``after_guidance`` returns the phase that flies the rest of the step (the takeoff hands over
to the airborne phase there). The phases:

* :class:`AirbornePhase` — the normal flight: heading hold or bank hold or the guidance's bank
  (:class:`~.steps.LateralStep`), the vertical law or the direct load-factor targets
  (:class:`~.steps.VerticalStep`), flaps and gear (:class:`~.steps.ConfigStep`: the approach
  schedule, and from the go-around — the guidance's missed approach — the retraction schedule);
* :class:`~.takeoff.TakeoffPhase` — the takeoff roll, rotation and initial climb of a SID started
  on the runway, then the handover to the airborne phase.

:class:`LoopParts` holds what every phase shares (one lateral step, one wind ramp, one frame
sampler, the targets), so a phase change keeps their state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from fms_testbed.core.contracts import GuidanceOutput
from fms_testbed.core.state import AirData, AircraftState, NavSolution
from fms_testbed.loop.steps import (ConfigStep, FrameSampling, LateralStep, Targets,
                                    VerticalStep, WindRamp)
from fms_testbed.sim.divergence import Divergence
from fms_testbed.sim.jsbsim_core import RAW

_NAN = math.nan
_WOW = RAW["wow"]


@dataclass
class LoopParts:
    """What the phases of one flight share.

    Attributes
    ----------
    cfg : the aircraft configuration; aircraft : its :class:`~fms_testbed.sim.jsbsim_core.JSBSimAircraft`
    targets : the flight's :class:`~.steps.Targets`; lateral : its :class:`~.steps.LateralStep`
    wind : its :class:`~.steps.WindRamp`; sampling : its :class:`~.steps.FrameSampling`
    n_frames : JSBSim frames per outer step; dt_outer_s : outer-loop period, s
    events : the guidance's event list the configuration changes go to (None: kept apart)
    """

    cfg: object
    aircraft: object
    targets: Targets
    lateral: LateralStep
    wind: WindRamp
    sampling: FrameSampling
    n_frames: int
    dt_outer_s: float
    events: list | None = None


class AirbornePhase:
    """The airborne flight (module docstring).

    Parameters
    ----------
    parts : the shared parts; vertical : the :class:`~.steps.VerticalStep`
    config : flaps and gear (:class:`~.steps.ConfigStep`; None: an aircraft without approach
        settings, or a flight without guidance)
    go_around : returns True once the guidance flies a missed approach
    """

    name = "airborne"
    fires_events = True
    always_guided = True
    hands_over = False

    def __init__(self, parts: LoopParts, vertical: VerticalStep, config: ConfigStep | None,
                 go_around: Callable[[], bool]):
        self.parts, self.vertical, self.config, self.go_around = parts, vertical, config, go_around
        self.divergence = Divergence(parts.cfg)
        self.tg, self.lateral, self.wind_ramp = parts.targets, parts.lateral, parts.wind
        self.run, self.n_frames = parts.sampling.run, parts.n_frames

    def check(self, s: AircraftState, raw: list[float]) -> str | None:
        """Why the flight must end now (:class:`~fms_testbed.sim.divergence.Divergence`)."""
        return self.divergence(s, raw[_WOW])

    def wind(self, s: AircraftState) -> None:
        """The wind ramp and profile (:class:`~.steps.WindRamp`)."""
        self.wind_ramp.step(s.t_s, s.alt_m)

    def guided(self, s: AircraftState) -> bool:
        """The guidance flies every airborne step."""
        return True

    def after_guidance(self, s: AircraftState, gout: GuidanceOutput | None) -> "AirbornePhase":
        """The airborne phase goes on."""
        return self

    def command(self, s: AircraftState, nav: NavSolution, air: AirData,
                gout: GuidanceOutput | None) -> tuple:
        """Lateral, vertical and configuration commands sent for this step; return them with
        the navigation solution for the log (:data:`~fms_testbed.core.timeseries.LOG_FIELDS`:
        bank rad, heading target rad, n_x g, n_y g, throttle, altitude m, TAS m/s, navigation
        latitude, longitude rad, altitude m, heading, roll, pitch rad; NaN where inactive)."""
        tg = self.tg
        bank = self.lateral(tg, nav, gout is not None)
        nx, ny, alt, tas = self.vertical(s, air, tg, bank)
        if self.config is not None:
            self.config(s, tg, self.go_around())
        hdg, thr = tg.heading_rad, tg.throttle
        return (bank, _NAN if hdg is None else hdg, nx, ny, _NAN if thr is None else thr, alt,
                tas, nav.lat_rad, nav.lon_rad, nav.alt_m, nav.heading_rad, nav.roll_rad,
                nav.pitch_rad)

    def advance(self) -> str:
        """Run the JSBSim frames to the next outer step; '' or why the flight must end."""
        return "" if self.run(self.n_frames) else "JSBSim stopped"


__all__ = ["AirbornePhase", "LoopParts"]
