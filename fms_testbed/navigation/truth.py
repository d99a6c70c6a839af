"""The truth source: the navigation solution equals the true state (no navigation error)."""

from __future__ import annotations

from fms_testbed.core.contracts import NavigationSourceBase
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AircraftState, NavSolution

_NO_ERRORS: dict[str, float] = {}  # shared; nobody writes into a solution's errors


class TruthNavigation(NavigationSourceBase):
    """Navigation solution equal to truth (no navigation-system error)."""

    #: per-frame JSBSim samples the truth side needs (none: it reads the outer-step state)
    frame_properties: tuple[tuple[str, float], ...] = ()

    @classmethod
    def from_spec(cls, spec: dict, seed: int | None = None) -> "TruthNavigation":
        """Build from a scenario's ``navigation:`` block (``{source: truth}``: no other key)."""
        extra = sorted(set(spec) - {"source"})
        if extra:
            raise ConfigError(f"field 'navigation.{extra[0]}': unknown field for source truth")
        return cls()

    def update(self, truth: AircraftState, frames=None) -> NavSolution:
        """Return the truth as the navigation solution."""
        return NavSolution(truth.t_s, truth.lat_rad, truth.lon_rad, truth.alt_m, truth.v_enu_mps,
                           truth.roll_rad, truth.pitch_rad, truth.heading_rad, _NO_ERRORS)
