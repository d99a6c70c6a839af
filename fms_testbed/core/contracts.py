"""Interfaces between the layers: what a navigation source, a guidance and a vertical law look
like to the flight loop, and how a flight loop ends. Plain Protocols, small base classes that
give every optional member its default, and dataclasses; units in every name.

The flight loop calls only the members declared here — it never probes an object for an
attribute: a source or a guidance that does not need a member inherits its default from
:class:`NavigationSourceBase` / :class:`GuidanceBase`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Protocol, Sequence

import numpy as np

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.state import AirData, AircraftState, NavSolution


# ------------------------------------------------------------------------- navigation
class NavigationSource(Protocol):
    """A navigation source: called once per navigation step with the true state (the truth side
    gives it what its sensors would measure) and returns what the navigation system believes.

    Sensors that sample faster than the navigation step (an IMU at the JSBSim frame rate) name
    the JSBSim properties they read in :attr:`frame_properties`; the flight loop then reads them
    after every JSBSim frame of the step and hands them to :meth:`update` as ``frames``.
    """

    #: ``(property, scale to SI)`` pairs sampled after every JSBSim frame; ``()``: none
    frame_properties: tuple[tuple[str, float], ...]
    #: what the source reported (``t_s``, ``unit``, ``kind``, ``stage``, ``reason``), in order
    events: Sequence[dict]

    def update(self, truth: AircraftState, frames: np.ndarray | None = None
               ) -> NavSolution:  # pragma: no cover - protocol
        """Return the navigation solution at ``truth.t_s``.

        ``frames``: shape ``(n_frames, len(frame_properties))``, the samples (SI) taken after
        each JSBSim frame since the previous call, the last row at ``truth.t_s``; ``None`` on
        the first call and when :attr:`frame_properties` is empty."""

    def check_fault(self, fault: dict) -> None:  # pragma: no cover - protocol
        """Raise :class:`~fms_testbed.core.errors.ConfigError` when the scenario fault
        ``fault`` (``events[].fault`` as a mapping) cannot be injected into this source."""

    def inject(self, fault: dict, t_s: float) -> None:  # pragma: no cover - protocol
        """Inject the scenario fault ``fault`` at ``t_s`` (s) on the truth side."""


class NavigationSourceBase:
    """Defaults of the optional :class:`NavigationSource` members: no per-frame samples, no
    events, no faults (:meth:`check_fault` refuses every fault). A source subclasses it and
    overrides what it has."""

    frame_properties: tuple[tuple[str, float], ...] = ()
    events: Sequence[dict] = ()

    def update(self, truth: AircraftState, frames: np.ndarray | None = None
               ) -> NavSolution:  # pragma: no cover - abstract
        """Return the navigation solution at ``truth.t_s`` (:meth:`NavigationSource.update`)."""
        raise NotImplementedError

    def check_fault(self, fault: dict) -> None:
        """Refuse the fault: this source takes none."""
        raise ConfigError(f"events.fault needs a navigation source that takes faults "
                          f"(ins_gnss), not {type(self).__name__}")

    def inject(self, fault: dict, t_s: float) -> None:
        """Refuse the fault (:meth:`check_fault` runs before the flight, so this is a bug)."""
        self.check_fault(fault)


# ------------------------------------------------------------------------- guidance
@dataclass(slots=True)
class GuidanceOutput:
    """What a path guidance returns each outer step.

    Attributes
    ----------
    bank_rad : bank-angle command, rad (None: leave the lateral channel alone)
    alt_m : altitude target for the vertical law, m (None: unchanged)
    tas_mps : true-airspeed target for the vertical law, m/s (None: unchanged)
    done : True once the path has been flown to its end
    """

    bank_rad: float | None = None
    alt_m: float | None = None
    tas_mps: float | None = None
    done: bool = False


class Guidance(Protocol):
    """Lateral/vertical guidance flying on the navigation solution and the air data, called at
    the outer rate. It never sees the true state: the flight loop logs truth, guidance reads
    :class:`~fms_testbed.core.state.NavSolution` and :class:`~fms_testbed.core.state.AirData`.

    Logging: :attr:`log_columns` names the record :meth:`log_record` returns for the last
    :meth:`update` (the loop asks only on the steps it logs); :meth:`log_frame` turns the
    logged records into timeseries columns after the flight, with the true positions the loop
    logged (the columns that compare the path with the true position, such as TSE, are
    computed there, never in flight).
    """

    #: ``(column, description with unit)`` of the columns :meth:`log_frame` returns
    log_columns: tuple[tuple[str, str], ...]
    #: True once the path has been flown to its end (or abandoned: :attr:`abort_reason`)
    done: bool
    #: why guidance abandoned its path ('' when it did not)
    abort_reason: str
    #: what guidance did (``t_s``, ``kind``, ``leg``, ``detail`` or ``code``), in order
    events: list[dict]

    def update(self, dt_s: float, nav: NavSolution, air: AirData
               ) -> GuidanceOutput:  # pragma: no cover - protocol
        """Return the commands for the next ``dt_s`` seconds (s)."""

    @property
    def go_around_active(self) -> bool:  # pragma: no cover - protocol
        """True once a missed approach is flown (the configuration retracts)."""

    def set_mass(self, mass_kg: float) -> None:  # pragma: no cover - protocol
        """The gross weight (kg) the aircraft flies with (speeds scaled to it)."""

    def log_record(self) -> tuple:  # pragma: no cover - protocol
        """The log record of the last :meth:`update` (opaque; :meth:`log_frame` reads it)."""

    def log_frame(self, records: list[tuple], true_lat_rad: np.ndarray,
                  true_lon_rad: np.ndarray) -> dict[str, np.ndarray]:  # pragma: no cover
        """The :attr:`log_columns` of the logged ``records`` (one per row), given the true
        position of each row (rad)."""

    def position_text(self) -> str:  # pragma: no cover - protocol
        """Where on its path guidance is, for a reason ('leg 3 of 9'; '' when not known)."""


class GuidanceBase:
    """Defaults of the :class:`Guidance` members besides :meth:`~Guidance.update`: no log
    columns, never done by itself, no go-around, mass not used."""

    log_columns: tuple[tuple[str, str], ...] = ()
    done: bool = False
    abort_reason: str = ""

    def __init__(self) -> None:
        self.events: list[dict] = []

    def update(self, dt_s: float, nav: NavSolution, air: AirData
               ) -> GuidanceOutput:  # pragma: no cover - abstract
        """Return the commands for the next ``dt_s`` seconds (:meth:`Guidance.update`)."""
        raise NotImplementedError

    @property
    def go_around_active(self) -> bool:
        """Never: a guidance without a missed approach."""
        return False

    def set_mass(self, mass_kg: float) -> None:
        """Not used (kg)."""

    def log_record(self) -> tuple:
        """Nothing to log."""
        return ()

    def log_frame(self, records: list[tuple], true_lat_rad: np.ndarray,
                  true_lon_rad: np.ndarray) -> dict[str, np.ndarray]:
        """No columns."""
        return {}

    def position_text(self) -> str:
        """Not known."""
        return ""


# ------------------------------------------------------------------------- vertical law
class VerticalLaw(Protocol):
    """A vertical law (altitude + speed), called by the flight loop at the outer-loop rate."""

    def engage(self, state: AircraftState, alt_cmd_m: float,
               tas_cmd_mps: float) -> None:  # pragma: no cover - protocol
        """Take over from the current state without a bump."""

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:  # pragma: no cover - protocol
        """Return (nx_cmd, ny_cmd) in g for the inner loops (ny in the vertical plane)."""


# ------------------------------------------------------------------------- how a loop ends
ENDING_STATUS = {"in_flight": "ok", "duration": "ok", "guidance_complete": "ok",
                 "diverged": "diverged", "abandoned": "diverged", "incomplete": "incomplete",
                 "stopped": "timeout"}
"""Status of each way a flight loop can end, before the flight's checks
(:func:`fms_testbed.evaluation.outcome.decide` adds them)."""


@dataclass(frozen=True, slots=True)
class Ending:
    """How a flight loop ended (or that it has not: ``in_flight``).

    Attributes
    ----------
    kind : ``in_flight`` (stepped, not ended), ``duration`` (the scenario's duration flown),
        ``guidance_complete`` (the path flown to its end), ``diverged`` (the loop had to stop:
        non-finite state, ground contact, stall, overspeed, a failed takeoff, JSBSim stopped),
        ``abandoned`` (guidance gave up its path), ``incomplete`` (the duration ended before
        the path did), ``stopped`` (stopped from outside, e.g. a wall-time limit)
    reason : one line
    """

    kind: str
    reason: str

    @property
    def status(self) -> str:
        """The loop's status (:data:`ENDING_STATUS`)."""
        return ENDING_STATUS[self.kind]


# ------------------------------------------------------------------------- run records
OMIT_NONE = {"omit_none": True}
"""Metadata of a record field left out of the record's JSON form while it is None
(``dataclasses.field(default=None, metadata=OMIT_NONE)``)."""


def record_dict(obj: Any) -> Any:
    """The JSON form of a run record ``obj``: dataclasses as mappings in field order (fields
    marked :data:`OMIT_NONE` left out while None), lists, tuples and mappings converted item by
    item, numbers and strings as they are."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: record_dict(v) for f in dataclasses.fields(obj)
                if not ((v := getattr(obj, f.name)) is None and f.metadata.get("omit_none"))}
    if isinstance(obj, Mapping):
        return {k: record_dict(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [record_dict(v) for v in obj]
    return obj


class RecordView(Mapping):
    """A read-only mapping view of a frozen record dataclass: ``record["key"]`` reads its JSON
    form (:func:`record_dict`, nested blocks as plain mappings), as a ``summary.json`` reader
    would; the typed fields are the record's attributes."""

    @cached_property
    def _json(self) -> dict:
        return record_dict(self)

    def to_dict(self) -> dict:
        """The JSON form (a copy)."""
        return record_dict(self)

    def __getitem__(self, key: str) -> Any:
        return self._json[key]

    def __iter__(self):
        return iter(self._json)

    def __len__(self) -> int:
        return len(self._json)


__all__ = ["ENDING_STATUS", "Ending", "OMIT_NONE", "RecordView", "record_dict", "Guidance", "GuidanceBase", "GuidanceOutput",
           "NavigationSource", "NavigationSourceBase", "VerticalLaw"]
