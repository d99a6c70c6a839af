"""The run record: :class:`Summary`, what ``summary.json`` holds, as typed frozen dataclasses, and
its JSON Schema (:func:`summary_schema`, shipped as
``fms_testbed/data/schemas/summary.schema.json``, :mod:`fms_testbed.run.schemas`).

Blocks and their producers:

* the flight loop's part (:class:`~fms_testbed.loop.record.FlightRecord`): scenario, aircraft,
  seeds, durations, ``trim``, ``metrics``, ``takeoff``;
* ``procedure`` (:class:`ProcedureInfo`, here), ``errors``, ``rnp``, ``constraints``,
  ``sequencing`` (:mod:`fms_testbed.evaluation.flight_errors`), ``threshold``
  (:mod:`fms_testbed.evaluation.threshold`), ``guidance_events``;
* ``navigation`` (:class:`NavigationBlock`, from :func:`fms_testbed.navigation.monitor.monitor_flight`)
  and ``attitude_reference`` (:class:`AttitudeReferenceBlock`);
* ``status``, ``reason`` and ``outcome`` (:func:`fms_testbed.evaluation.outcome.decide`, the one
  place the status is decided);
* ``plots`` and ``tracks``: the files :meth:`~fms_testbed.run.results.Results.save` wrote.

Blocks a flight does not have are left out of the JSON (a flight without a procedure has no
``procedure``, ``errors`` …). Units are in every name; degrees, feet and knots appear only where
the name says so (the constraint and threshold records are read as a chart is).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

from pydantic import TypeAdapter

from fms_testbed.core.contracts import OMIT_NONE, RecordView, record_dict
from fms_testbed.core.jsonio import dumps
from fms_testbed.evaluation.outcome import Decision
from fms_testbed.evaluation.records import (STRICT, ConstraintCheck, FlightErrors, Outcome,
                                            RnpContainment, Sequencing, ThresholdCrossing)
from fms_testbed.loop.record import FlightRecord
from fms_testbed.run.schemas import DRAFT


def _opt():
    return field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class ProcedureInfo(RecordView):
    """The procedure flown: its name, airport, type (SID, STAR, APPROACH), ident and
    transition, the start kind, the leg codes, length (NM), the monitor's status, the
    navigation source, the monitor's findings and, for a degraded procedure, its record
    defects ('file:line: field: reason')."""

    __pydantic_config__ = STRICT
    name: str
    airport: str
    type: str | None
    procedure: str
    transition: str
    start: str | None
    legs: list[str]
    length_nm: float
    monitor_status: str
    navigation: str
    findings: list[str]
    degraded: list[str]


@dataclass(frozen=True)
class GuidanceEvent(RecordView):
    """What guidance and the configuration did at ``t_s`` (s): ``kind`` 'leg' (a leg entered,
    its ``code``), 'condition', 'rebuild', 'abort' (with a ``detail``) on whole-procedure leg
    ``leg``; 'config' (flaps, gear, go-around: the ``detail``)."""

    __pydantic_config__ = STRICT
    t_s: float
    kind: str
    leg: int | None = _opt()
    code: str | None = _opt()
    detail: str | None = _opt()


@dataclass(frozen=True)
class NavigationEvent(RecordView):
    """What the navigation system reported at ``t_s`` (s): the ``unit`` (insN, gnss, baro,
    fms), the ``kind`` (detected, isolated, excluded, reconfigured, fault_injected, alert), the
    ``stage`` that decided it and why."""

    __pydantic_config__ = STRICT
    t_s: float
    unit: str
    kind: str
    stage: str
    reason: str


@dataclass(frozen=True)
class RnpAlert(RecordView):
    """The on-board RNP alert (ANP > RNP): raised, first time (s), the times to alert (s), the
    persistence (s), the largest ANP (m)."""

    __pydantic_config__ = STRICT
    raised: bool
    first_t_s: float | None
    time_to_alert_s: list[float]
    delay_s: float
    anp_max_m: float | None


@dataclass(frozen=True)
class NavigationBlock(RecordView):
    """The navigation monitoring of a flight: the RNP alert (None: no ANP logged), the 95th
    percentile of the horizontal NSE per output (m) and the events."""

    __pydantic_config__ = STRICT
    events: list[NavigationEvent]
    rnp_alert: RnpAlert | None = _opt()
    nse95_m: dict[str, float] | None = _opt()
    truth_model: str | None = _opt()
    """The INS units' truth side, ``strapdown`` or ``linear`` (None: no INS units)."""


@dataclass(frozen=True)
class AttitudeAngle(RecordView):
    """One angle of the flight-test attitude reference (deg): the injected error and the
    estimation error at ``at_s``, the largest error after it, the filter's σ there, the largest
    error/σ after it, the goal, whether it is met and inside 3σ, and since when within the
    goal (s; None: never)."""

    __pydantic_config__ = STRICT
    injected_at_s_deg: float
    err_at_s_deg: float
    max_abs_err_after_deg: float
    sigma_at_s_deg: float
    max_err_over_sigma_after: float
    goal_deg: float
    meets_goal: bool
    inside_3sigma: bool
    within_goal_from_s: float | None


@dataclass(frozen=True)
class AttitudeReferenceBlock(RecordView):
    """The flight-test attitude-reference estimation judged from ``at_s`` (s) against the goal
    per angle (deg)."""

    __pydantic_config__ = STRICT
    at_s: float
    goal_deg: dict[str, float]
    angles: dict[str, AttitudeAngle]
    meets_goal: bool
    inside_3sigma: bool
    reason: str | None = _opt()


@dataclass(frozen=True)
class Summary(FlightRecord):
    """The record of one flight (module docstring): ``summary.json`` as typed fields — the
    flight loop's record (:class:`~fms_testbed.loop.record.FlightRecord`, its ``status`` and
    ``reason`` those :func:`~fms_testbed.evaluation.outcome.decide` gave) and the blocks below.

    ``summary["key"]`` reads the JSON form (:class:`~fms_testbed.core.contracts.RecordView`);
    :meth:`to_json` writes it.
    """

    __pydantic_config__ = STRICT
    procedure: ProcedureInfo | None = _opt()
    errors: FlightErrors | None = _opt()
    rnp: RnpContainment | None = _opt()
    constraints: list[ConstraintCheck] | None = _opt()
    constraints_met: bool | None = _opt()
    sequencing: Sequencing | None = _opt()
    threshold: ThresholdCrossing | None = _opt()
    guidance_events: list[GuidanceEvent] | None = _opt()
    navigation: NavigationBlock | None = _opt()
    attitude_reference: AttitudeReferenceBlock | None = _opt()
    outcome: Outcome | None = _opt()
    plots: list[str] | None = _opt()
    tracks: list[str] | None = _opt()

    @property
    def ok(self) -> bool:
        """True only for status ``ok``."""
        return self.status == "ok"

    def to_json(self) -> str:
        """Strict JSON (non-finite numbers as null), indented."""
        return dumps(self.to_dict())

    def with_outputs(self, plots: list[str] | None, tracks: list[str] | None) -> "Summary":
        """This record with the output files written beside it."""
        return replace(self, plots=plots, tracks=tracks)


def assemble(record: FlightRecord, decision: Decision, **blocks: Any) -> Summary:
    """The :class:`Summary` of a flight from the loop's record, the decision (status, reason,
    outcome) and the other blocks (typed records, or mappings in their JSON form from the
    layers that write them: ``navigation``, ``attitude_reference``, ``guidance_events``; None:
    the flight has no such block). The whole is validated against the types: a block with a key
    the record does not declare is an error."""
    data = record_dict(record)
    data.update(status=decision.status, reason=decision.reason)
    for k, v in blocks.items():
        if v is not None:
            data[k] = record_dict(v)
    data["outcome"] = record_dict(decision.outcome)
    return _adapter().validate_python(data)


@lru_cache(maxsize=1)
def _adapter() -> TypeAdapter:
    return TypeAdapter(Summary)


def summary_schema() -> dict:
    """The JSON Schema of ``summary.json``, generated from the :class:`Summary` types."""
    schema = _adapter().json_schema(mode="serialization")
    schema["$schema"] = DRAFT
    schema["title"] = "fms-testbed summary.json"
    return schema


__all__ = ["AttitudeAngle", "AttitudeReferenceBlock", "GuidanceEvent", "NavigationBlock",
           "NavigationEvent", "ProcedureInfo", "RnpAlert", "Summary", "assemble",
           "summary_schema"]
