"""Navigation sources: what guidance flies on.

A source turns the true state (and, on the truth side, its sensors' errors) into a
:class:`~fms_testbed.core.state.NavSolution`. Sources are registered by name in :data:`SOURCES`;
a scenario picks one with ``navigation: {source: NAME, ...}``. A new source is a subclass of
:class:`~fms_testbed.core.contracts.NavigationSourceBase` with ``from_spec(spec, seed)`` and
``update(truth, frames=None) -> NavSolution`` (and, where it has them, ``frame_properties``,
``events``, ``check_fault`` and ``inject``: the
:class:`~fms_testbed.core.contracts.NavigationSource` protocol), added to :data:`SOURCES` —
nothing else changes.
"""

from __future__ import annotations

from fms_testbed.core.contracts import NavigationSource
from fms_testbed.core.errors import ConfigError
from fms_testbed.navigation.attitude_reference import AttitudeReferenceNavigation
from fms_testbed.navigation.ins_gnss import InsGnssNavigation
from fms_testbed.navigation.sins import SinsNavigation
from fms_testbed.navigation.truth import TruthNavigation

#: Source name (``navigation.source`` in a scenario) → class with ``from_spec(spec, seed)``.
SOURCES: dict[str, type] = {
    "truth": TruthNavigation,
    "sins": SinsNavigation,
    "ins_gnss": InsGnssNavigation,
    "attitude_reference": AttitudeReferenceNavigation,
}


def make_source(spec: dict | None, seed: int | None = None) -> NavigationSource:
    """Build the navigation source a scenario's ``navigation`` block names (``None``: truth).

    Parameters
    ----------
    spec : the ``navigation:`` mapping (``source`` plus the source's own keys)
    seed : seed for the source's error realisation
    """
    spec = dict(spec or {})
    name = spec.get("source", "truth")
    if name not in SOURCES:
        raise ConfigError(f"field 'navigation.source': unknown source {name!r} "
                          f"(available: {', '.join(SOURCES)})")
    return SOURCES[name].from_spec(spec, seed=seed)


__all__ = ["SOURCES", "make_source", "NavigationSource", "TruthNavigation", "SinsNavigation",
           "InsGnssNavigation", "AttitudeReferenceNavigation"]
