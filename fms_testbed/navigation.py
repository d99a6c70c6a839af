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


_NO_ERRORS: dict[str, float] = {}  # shared; nobody writes into a solution's errors


class TruthNavigation:
    """Navigation solution equal to truth (no navigation-system error)."""

    def update(self, truth: AircraftState) -> NavSolution:
        """Return the truth as the navigation solution."""
        return NavSolution(truth.t_s, truth.lat_rad, truth.lon_rad, truth.alt_m, truth.v_enu_mps,
                           truth.roll_rad, truth.pitch_rad, truth.heading_rad, _NO_ERRORS)


def make_source(spec: dict | None, seed: int | None = None) -> NavigationSource:
    """Build a navigation source from a scenario's ``navigation`` block (``None``: truth)."""
    if not spec or spec.get("source", "truth") == "truth":
        return TruthNavigation()
    if spec["source"] == "sins":
        from .sins.navigation import SinsNavigation  # provided by the SINS module

        return SinsNavigation.from_spec(spec, seed=seed)
    raise ValueError(f"unknown navigation source {spec['source']!r}")
