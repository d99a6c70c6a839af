"""The run-ending checks of a flight: non-finite state, ground contact, stall, overspeed, upset.

A flight that trips one ends with status ``diverged`` and the reason (with the time); it never
hangs or raises.
"""

from __future__ import annotations

import math

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import KT_MPS

UPSET_ROLL_DEG = 75.0
"""|roll| above this ends the flight as an upset, deg."""
UPSET_PITCH_DEG = 45.0
"""|pitch| above this ends the flight as an upset, deg."""


class Divergence:
    """The run-ending checks, with the aircraft's limits converted once (SI, rad)."""

    def __init__(self, cfg: AircraftConfig):
        lim = cfg.limits
        self.stall_alpha_deg = lim.stall_alpha_deg
        self.stall_rad = math.radians(lim.stall_alpha_deg)
        self.cas_max_mps = lim.cas_max_mps
        self.mach_max = lim.mach_max
        self.roll_max_rad, self.pitch_max_rad = math.radians(UPSET_ROLL_DEG), math.radians(UPSET_PITCH_DEG)

    def __call__(self, s: AircraftState, wow: float) -> str | None:
        """None while the flight is sound, else the reason it must end."""
        if not math.isfinite(s.alt_m + s.tas_mps + s.roll_rad + s.pitch_rad + s.alpha_rad + s.ny):
            return "non-finite state (JSBSim diverged)"
        if s.agl_m < 1.0 or wow > 0.5:
            return f"ground contact at t={s.t_s:.1f} s"
        if s.alpha_rad > self.stall_rad:
            return (f"stall: alpha {math.degrees(s.alpha_rad):.1f} deg > {self.stall_alpha_deg} deg "
                    f"at t={s.t_s:.1f} s")
        if s.cas_mps > self.cas_max_mps * 1.1:
            return (f"overspeed: CAS {s.cas_mps / KT_MPS:.0f} kt > 1.1 x VMO "
                    f"{self.cas_max_mps / KT_MPS:.0f} kt at t={s.t_s:.1f} s")
        if s.mach > self.mach_max + 0.05:
            return f"overspeed: Mach {s.mach:.3f} > MMO + 0.05 at t={s.t_s:.1f} s"
        if abs(s.roll_rad) > self.roll_max_rad or abs(s.pitch_rad) > self.pitch_max_rad:
            return (f"upset: roll {math.degrees(s.roll_rad):.0f} deg, "
                    f"pitch {math.degrees(s.pitch_rad):.0f} deg")
        return None
