"""Navigation sources: what guidance flies on.

A source turns the true state into a :class:`~fms_testbed.state.NavSolution`. ``TruthNavigation``
passes truth through; the SINS source (``fms_testbed.sins``) adds the error model's errors.
A new source implements ``update(truth) -> NavSolution`` and is registered in :func:`make_source`.
"""

from __future__ import annotations

from typing import Protocol

from .state import AircraftState, NavSolution


class NavigationSource(Protocol):
    """Interface: called once per navigation step with the true state."""

    def update(self, truth: AircraftState) -> NavSolution:  # pragma: no cover - protocol
        ...


class TruthNavigation:
    """Navigation solution equal to truth (no navigation-system error)."""

    def update(self, truth: AircraftState) -> NavSolution:
        """Return the truth as the navigation solution."""
        return NavSolution(
            t_s=truth.t_s, lat_rad=truth.lat_rad, lon_rad=truth.lon_rad, alt_m=truth.alt_m,
            v_enu_mps=truth.v_enu_mps, roll_rad=truth.roll_rad, pitch_rad=truth.pitch_rad,
            heading_rad=truth.heading_rad,
        )


def make_source(spec: dict | None, seed: int | None = None) -> NavigationSource:
    """Build a navigation source from a scenario's ``navigation`` block (``None``: truth)."""
    if not spec or spec.get("source", "truth") == "truth":
        return TruthNavigation()
    if spec["source"] == "sins":
        from .sins.navigation import SinsNavigation  # provided by the SINS module

        return SinsNavigation.from_spec(spec, seed=seed)
    raise ValueError(f"unknown navigation source {spec['source']!r}")
