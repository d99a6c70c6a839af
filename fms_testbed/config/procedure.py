"""The scenario's ``procedure:`` block: which ARINC-424 procedure to fly and how to plan it."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictBool, ValidationError

from fms_testbed.core.errors import ConfigError


class ProcedureSpec(BaseModel):
    """The scenario's ``procedure:`` block (validated; aviation units only where the key says).

    Example::

        procedure: {db: embedded, airport: KSEA, procedure: ISBRG1, runway: RW34R}
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    db: str = Field("embedded", description="ARINC-424 file, or 'embedded' for procedures/")
    airport: Annotated[str, Field(min_length=3, max_length=4)]
    procedure: Annotated[str, Field(min_length=1, max_length=6)]
    transition: str | None = Field(None, description="en-route (SID/STAR) or approach transition")
    runway: str | None = Field(None, description="runway, e.g. 34R or RW34R (SID/STAR)")
    rnp_nm: Annotated[float, Field(gt=0, le=10)] | None = Field(
        None, description="RNP value used where the record codes none, NM")
    manual_leg_nm: Annotated[float, Field(gt=0, le=50)] = Field(
        5.0, description="distance flown on FM/VM/HM legs (vectors), NM")
    climb_gradient: Annotated[float, Field(gt=0.02, lt=0.3)] | None = Field(
        None, description="planned climb gradient (default: the aircraft's capability)")
    climb_top_ft: Annotated[float, Field(ge=1000, le=45000)] = Field(
        15000.0, description="SID/missed-approach climbs stop here (raised to the highest "
                             "'at or above' constraint when that is higher), ft")
    allow_degraded: StrictBool = Field(
        False, description="build and fly a procedure with a rejected, duplicated or misplaced "
                           "record of its own (refused by default); what is in doubt is "
                           "listed with the built path")
    missed: StrictBool = Field(
        False, description="approaches: go around at the missed-approach point and fly the "
                           "missed approach to its holding fix and one holding circuit "
                           "(default: the flight ends at the MAP)")
    start_alt_ft: Annotated[float, Field(ge=-1000, le=45000)] | None = Field(
        None, description="start altitude, ft (default: the build's planned start; a SID "
                          "that starts at a fix starts at that fix's 'at or above' altitude)")
    start: Literal["airborne", "takeoff"] = Field(
        "airborne", description="SIDs: 'airborne' at the departure end of the runway (35 ft), "
                                "or 'takeoff' from rest on the runway threshold (the aircraft "
                                "file's takeoff settings)")


def parse_procedure(raw, source: str = "<scenario>") -> ProcedureSpec:
    """Validate a ``procedure:`` mapping; :class:`ConfigError` names the file and field."""
    if not isinstance(raw, dict):
        raise ConfigError(f"{source}: field 'procedure': expected a mapping")
    try:
        return ProcedureSpec.model_validate(raw)
    except ValidationError as err:
        e = err.errors()[0]
        loc = ".".join(str(x) for x in e["loc"])
        msg = "unknown field" if e["type"] == "extra_forbidden" else e["msg"]
        raise ConfigError(f"{source}: field 'procedure.{loc}': {msg}") from None
