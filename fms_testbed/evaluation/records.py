"""The evaluation's blocks of the run record (``summary.json``): flight errors, RNP containment,
constraint compliance, sequencing, the threshold crossing and the outcome. Frozen dataclasses,
units in every name; the producers are :mod:`.flight_errors`, :mod:`.threshold` and
:mod:`.outcome`, the assembly :class:`fms_testbed.run.summary.Summary`.

Every record forbids keys it does not declare (``extra='forbid'`` for the schema generator and
the validator), so the published JSON Schema is the whole record; each reads as its JSON form
too (``record["key"]``, :class:`~fms_testbed.core.contracts.RecordView`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pydantic import ConfigDict

from fms_testbed.core.contracts import OMIT_NONE, RecordView

STRICT = ConfigDict(extra="forbid")
"""Pydantic configuration of every run-record dataclass: undeclared keys are errors."""


def _opt():
    return field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class ErrorStat(RecordView):
    """95th percentile and maximum of an absolute error, m, over ``n`` samples (None: none)."""

    __pydantic_config__ = STRICT
    p95_m: float | None
    max_m: float | None
    n: int


@dataclass(frozen=True)
class ErrorParts(RecordView):
    """An error over the whole flight, on straight flight and in turns."""

    __pydantic_config__ = STRICT
    all: ErrorStat
    straight: ErrorStat
    turns: ErrorStat


@dataclass(frozen=True)
class LegErrors(RecordView):
    """One leg's errors (m; None where the leg has no such samples), its RNP (NM) and whether it
    is contained (TSE95 ≤ RNP and max TSE ≤ 2 × RNP; None: no defined path, or not flown)."""

    __pydantic_config__ = STRICT
    leg: int
    code: str
    fix: str
    samples: int
    fte95_m: float | None = None
    fte_max_m: float | None = None
    nse95_m: float | None = None
    nse_max_m: float | None = None
    pde95_m: float | None = None
    pde_max_m: float | None = None
    tse95_m: float | None = None
    tse_max_m: float | None = None
    rnp_nm: float | None = None
    rnp_contained: bool | None = None


@dataclass(frozen=True)
class FlightErrors(RecordView):
    """FTE, NSE, PDE and TSE statistics (:mod:`.flight_errors`), per leg, and the samples on the
    straight parts of heading legs left out of FTE and TSE."""

    __pydantic_config__ = STRICT
    fte: ErrorParts
    nse: ErrorParts
    pde: ErrorParts
    tse: ErrorParts
    per_leg: list[LegErrors]
    heading_leg_samples: int


@dataclass(frozen=True)
class RnpContainment(RecordView):
    """RNP containment over the legs flown: contained, the legs not contained (1-based), TSE95
    (m) and the smallest RNP flown (NM)."""

    __pydantic_config__ = STRICT
    contained: bool
    legs_not_contained: list[int]
    tse95_m: float | None
    min_rnp_nm: float | None


@dataclass(frozen=True)
class ConstraintCheck(RecordView):
    """One constrained fix: leg (1-based), code, fix, altitude descriptor; where it was checked,
    the true altitude (ft) and coded window (ft), the floor it was checked against (ft, a
    circling approach), the CAS (kt) and the speed limit; ``ok`` (None: nothing to check
    against) and why not (aviation units: this record is read as the chart is)."""

    __pydantic_config__ = STRICT
    leg: int
    code: str
    fix: str
    alt_desc: str
    where: str | None = _opt()
    alt_ft: int | None = _opt()
    window_ft: list[int | None] | None = _opt()
    floor_ft: int | None = _opt()
    cas_kt: float | None = _opt()
    speed_limit_kt: str | None = _opt()
    ok: bool | None = None
    why: str | None = _opt()


@dataclass(frozen=True)
class Sequencing(RecordView):
    """Legs of the procedure, legs entered, the 1-based legs skipped and entered twice, entered
    in order, and completed (flown to its end, not abandoned)."""

    __pydantic_config__ = STRICT
    legs: int
    legs_entered: int
    skipped: list[int]
    repeated: list[int]
    in_order: bool
    completed: bool


@dataclass(frozen=True)
class ThresholdChecks(RecordView):
    """The threshold-crossing checks (None: not checkable): CAS within the tolerance of Vapp,
    the path angle of the VPA, the height of the TCH, configured for landing."""

    __pydantic_config__ = STRICT
    cas: bool | None
    path_angle: bool | None
    height: bool | None
    configured: bool | None


@dataclass(frozen=True)
class ThresholdCrossing(RecordView):
    """An approach's threshold crossing (:mod:`.threshold`): the runway and what it codes (VPA
    deg, TCH ft), Vapp (kt); crossed or why not; where it was crossed (time s, extrapolated m
    past the last sample), CAS (kt) and its difference from Vapp, height (ft) and its
    difference from the TCH, γ and the fitted path angle (deg) and its difference from the
    VPA, the configuration (flap and gear positions, normalised), the checks and ``ok``."""

    __pydantic_config__ = STRICT
    runway: str
    map_is_threshold: bool
    vpa_deg: float | None
    tch_ft: float | None
    vapp_kt: float | None
    crossed: bool | None = None
    reason: str | None = None
    extrapolated_m: float | None = None
    t_s: float | None = None
    cas_kt: float | None = None
    cas_minus_vapp_kt: float | None = None
    height_ft: float | None = None
    height_minus_tch_ft: float | None = None
    gamma_deg: float | None = None
    path_angle_deg: float | None = None
    path_angle_minus_vpa_deg: float | None = None
    flap_pos_norm: float | None = None
    gear_pos_norm: float | None = None
    flaps_landing: bool | None = None
    gear_down: bool | None = None
    configured: bool | None = None
    checks: ThresholdChecks | None = None
    ok: bool | None = None


@dataclass(frozen=True)
class RecordsCheck(RecordView):
    """The procedure's own records: ok, defects of a degraded procedure."""

    __pydantic_config__ = STRICT
    ok: bool
    defects: int


@dataclass(frozen=True)
class EnvelopeCheck(RecordView):
    """The aircraft's envelope: ok, each limit passed with its first time and extreme value."""

    __pydantic_config__ = STRICT
    ok: bool
    violations: list[str]


@dataclass(frozen=True)
class RnpCheck(RecordView):
    """RNP containment of a procedure flight: ok, the legs not contained (1-based)."""

    __pydantic_config__ = STRICT
    ok: bool
    legs_not_contained: list[int]


@dataclass(frozen=True)
class NavigationCheck(RecordView):
    """NSE containment seen from truth (:mod:`.navigation_truth`): the smallest RNP in force
    (NM), NSE95 and max NSE (m), contained (None: no samples)."""

    __pydantic_config__ = STRICT
    rnp_nm: float
    nse95_m: float | None
    nse_max_m: float | None
    contained: bool | None


@dataclass(frozen=True)
class MissedAlert(RecordView):
    """The navigation error went past the RNP in force at ``t_s`` (s; ``nse_m`` m against
    ``rnp_nm`` NM) with the on-board RNP alert silent; ``alert_t_s``: when it was raised later
    (None: never)."""

    __pydantic_config__ = STRICT
    t_s: float
    nse_m: float
    rnp_nm: float
    alert_t_s: float | None


@dataclass(frozen=True)
class AlertCheck(RecordView):
    """The on-board RNP alert: ok (never raised), the first time it was raised, s."""

    __pydantic_config__ = STRICT
    ok: bool
    first_t_s: float


@dataclass(frozen=True)
class ConstraintsCheck(RecordView):
    """Coded constraints: ok, how many were checked and missed."""

    __pydantic_config__ = STRICT
    ok: bool
    checked: int
    missed: int


@dataclass(frozen=True)
class Checks(RecordView):
    """Every check's verdict (None: the check does not apply to the flight)."""

    __pydantic_config__ = STRICT
    records: RecordsCheck
    envelope: EnvelopeCheck
    rnp: RnpCheck | None = _opt()
    navigation: NavigationCheck | None = _opt()
    rnp_alert: AlertCheck | None = _opt()
    missed_alert: MissedAlert | None = _opt()
    constraints: ConstraintsCheck | None = _opt()


@dataclass(frozen=True)
class Outcome(RecordView):
    """The flight's outcome (:func:`.outcome.decide`): its status, the statuses that apply
    (most severe first) and every check."""

    __pydantic_config__ = STRICT
    status: str
    failed: list[str]
    checks: Checks


__all__ = ["AlertCheck", "Checks", "ConstraintCheck", "ConstraintsCheck", "EnvelopeCheck",
           "ErrorParts", "ErrorStat", "FlightErrors", "LegErrors", "MissedAlert", "NavigationCheck",
           "Outcome",
           "RecordsCheck", "RnpCheck", "RnpContainment", "STRICT", "Sequencing",
           "ThresholdChecks", "ThresholdCrossing"]
