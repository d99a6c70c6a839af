"""Scenario files (YAML): aircraft, initial condition, wind, duration and timed events.

Example::

    aircraft: "737"
    initial: {lat_deg: 47.0, lon_deg: 8.0, alt_m: 3000, tas_kmh: 400, heading_deg: 90}
    duration_s: 120
    wind: {from_deg: 270, speed_kt: 20}
    turbulence: {severity: light}
    events:
      - {t_s: 10, heading_deg: 180}
      - {t_s: 40, alt_ft: 11000}
      - {when: {alt_m_above: 3400}, tas_kmh: 450}

Speeds may be given in the user's unit (``tas_mps | tas_kmh | tas_kt | cas_mps | cas_kt``),
altitudes as ``alt_m | alt_ft``; everything is converted to SI on load. Validation errors name the
file and the field (``events.2.bank_deg``) and say why.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (BaseModel, ConfigDict, Field, ValidationError, field_validator,
                      model_validator)

from fms_testbed.config.aircraft import list_aircraft
from fms_testbed.config.navigation import NavigationBlock, with_default_source
from fms_testbed.core.errors import ConfigError
from fms_testbed.config.yamlfile import read_mapping, validation_message
from fms_testbed.core.units import FT_M, KMH_MPS, KT_MPS

_SPEED_KEYS = {"tas_mps": ("tas", 1.0), "tas_kmh": ("tas", KMH_MPS), "tas_kt": ("tas", KT_MPS),
               "cas_mps": ("cas", 1.0), "cas_kt": ("cas", KT_MPS), "cas_kmh": ("cas", KMH_MPS)}
_ALT_KEYS = {"alt_m": 1.0, "alt_ft": FT_M}


class _Strict(BaseModel):
    """Base of the scenario blocks: unknown keys, booleans given as numbers (``alt_m: true``),
    strings given as numbers, infinities and NaN are all errors."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


def _speed(values: dict, where: str, required: bool) -> tuple[str | None, float | None]:
    given = [k for k in _SPEED_KEYS if values.get(k) is not None]
    if len(given) > 1:
        raise ValueError(f"give one speed, not {' and '.join(given)}")
    if not given:
        if required:
            raise ValueError(f"{where} needs a speed: one of {', '.join(_SPEED_KEYS)}")
        return None, None
    kind, scale = _SPEED_KEYS[given[0]]
    return kind, float(values[given[0]]) * scale


def _alt(values: dict, where: str, required: bool) -> float | None:
    given = [k for k in _ALT_KEYS if values.get(k) is not None]
    if len(given) > 1:
        raise ValueError("give one altitude, alt_m or alt_ft")
    if not given:
        if required:
            raise ValueError(f"{where} needs an altitude: alt_m or alt_ft")
        return None
    return float(values[given[0]]) * _ALT_KEYS[given[0]]


Speed = Annotated[float, Field(gt=0, lt=1000)]
Alt = Annotated[float, Field(ge=-400, le=25000)]


class _AltSpeed(_Strict):
    """Altitude and speed keys in the user's unit (one of each at most)."""

    alt_m: Alt | None = None
    alt_ft: Annotated[float, Field(ge=-1300, le=82000)] | None = None
    tas_mps: Speed | None = None
    tas_kmh: Annotated[float, Field(gt=0, lt=3600)] | None = None
    tas_kt: Annotated[float, Field(gt=0, lt=2000)] | None = None
    cas_mps: Speed | None = None
    cas_kt: Annotated[float, Field(gt=0, lt=2000)] | None = None
    cas_kmh: Annotated[float, Field(gt=0, lt=3600)] | None = None

    _required = False

    @property
    def altitude_m(self) -> float | None:
        """Altitude, m (None if not given)."""
        return _alt(self.__dict__, self._where(), self._required)

    @property
    def speed(self) -> tuple[str | None, float | None]:
        """(``'tas'`` or ``'cas'``, speed in m/s), or (None, None) if not given."""
        return _speed(self.__dict__, self._where(), self._required)

    def _where(self) -> str:
        return type(self).__name__.lower()


class Initial(_AltSpeed):
    """Initial condition (trimmed straight and level); altitude and speed required."""

    lat_deg: Annotated[float, Field(ge=-89, le=89)] = 45.0
    lon_deg: Annotated[float, Field(ge=-180, le=360)] = 0.0
    heading_deg: Annotated[float, Field(ge=0, le=360)] = 0.0

    _required = True

    @model_validator(mode="after")
    def _check(self):
        _ = self.altitude_m, self.speed
        return self


class Wind(_Strict):
    """Steady wind: direction it blows from (true, deg) and speed."""

    from_deg: Annotated[float, Field(ge=0, le=360)]
    speed_mps: Annotated[float, Field(ge=0, le=100)] | None = None
    speed_kt: Annotated[float, Field(ge=0, le=200)] | None = None

    @model_validator(mode="after")
    def _one(self):
        if (self.speed_mps is None) == (self.speed_kt is None):
            raise ValueError("give the wind speed as exactly one of speed_mps or speed_kt")
        return self

    @property
    def speed_ms(self) -> float:
        """Wind speed, m/s."""
        return self.speed_mps if self.speed_mps is not None else self.speed_kt * KT_MPS


class Turbulence(_Strict):
    """JSBSim MIL-F-8785C / MIL-HDBK-1797 (Tustin) turbulence; seeded by the run's seed."""

    severity: Literal["light", "moderate", "severe"] = "light"


class When(_Strict):
    """Condition that fires an event once: altitude crossing and/or time."""

    alt_m_above: float | None = None
    alt_m_below: float | None = None
    t_s_after: Annotated[float, Field(ge=0)] | None = None

    @model_validator(mode="after")
    def _some(self):
        if self.alt_m_above is None and self.alt_m_below is None and self.t_s_after is None:
            raise ValueError("'when' needs alt_m_above, alt_m_below or t_s_after")
        return self


class Event(_AltSpeed):
    """A target change at time ``t_s`` (or when ``when`` is met). Unset fields are unchanged."""

    t_s: Annotated[float, Field(ge=0)] | None = None
    when: When | None = None
    bank_deg: Annotated[float, Field(ge=-60, le=60)] | None = None
    heading_deg: Annotated[float, Field(ge=0, le=360)] | None = None
    nx: Annotated[float, Field(ge=-0.5, le=0.5)] | None = None
    ny: Annotated[float, Field(ge=-1.0, le=3.0)] | None = None
    throttle: Annotated[float, Field(ge=0, le=1)] | None = None

    @model_validator(mode="after")
    def _check(self):
        if (self.t_s is None) == (self.when is None):
            raise ValueError("an event needs exactly one of t_s or when")
        if self.bank_deg is not None and self.heading_deg is not None:
            raise ValueError("bank_deg and heading_deg in one event conflict")
        if self.nx is not None and self.throttle is not None:
            raise ValueError("nx and throttle in one event conflict")
        _ = self.altitude_m, self.speed
        targets = [k for k, v in self.__dict__.items() if v is not None and k not in ("t_s", "when")]
        if not targets:
            raise ValueError("an event must set at least one target")
        return self


class Scenario(_Strict):
    """A validated scenario (SI inside; see the module docstring for the file format)."""

    name: str = ""
    description: str = ""
    aircraft: str
    initial: Initial
    duration_s: Annotated[float, Field(gt=0, le=6 * 3600)]
    wind: Wind | None = None
    turbulence: Turbulence | None = None
    vertical_law: Literal["coupled", "pi", "tecs"] = "coupled"
    hold: bool = Field(False, description="engage the vertical law at t=0 holding the initial "
                                          "altitude and speed")
    outer_rate_hz: Annotated[float, Field(ge=5, le=120)] = Field(
        10.0, description="rate of navigation, guidance, heading hold and the vertical law, Hz")
    log_rate_hz: Annotated[float, Field(ge=1, le=120)] = Field(
        10.0, description="timeseries rate, Hz (at most the outer rate)")
    navigation: NavigationBlock | None = None
    rnp_nm: Annotated[float, Field(gt=0, le=30)] | None = Field(
        None, description="RNP for the navigation error of a flight without a procedure, NM "
                          "(default: 2 NM when the navigation source is not truth; a procedure "
                          "flight takes its RNP from the procedure)")
    procedure: dict[str, Any] | None = None
    events: list[Event] = Field(default_factory=list)
    source_file: str = ""

    @model_validator(mode="after")
    def _rates(self):
        if self.log_rate_hz > self.outer_rate_hz:
            raise ValueError(f"log_rate_hz {self.log_rate_hz:g} Hz is above outer_rate_hz "
                             f"{self.outer_rate_hz:g} Hz (a row is logged per outer step at most)")
        return self

    @field_validator("aircraft", mode="before")
    @classmethod
    def _name(cls, v):
        return str(v) if isinstance(v, int) and not isinstance(v, bool) else v  # aircraft: 737

    @field_validator("aircraft")
    @classmethod
    def _known(cls, v: str) -> str:
        if Path(v).suffix in (".yaml", ".yml"):
            return v
        known = list_aircraft()
        if v not in known:
            raise ValueError(f"unknown aircraft '{v}' (shipped: {', '.join(known)})")
        return v

    @field_validator("navigation", mode="before")
    @classmethod
    def _nav_default(cls, v):
        return with_default_source(v)

    @property
    def navigation_spec(self) -> dict[str, Any]:
        """The navigation block as the source's mapping (keys that were given, and ``source``)."""
        if self.navigation is None:
            return {"source": "truth"}
        return self.navigation.model_dump(exclude_unset=True) | {"source": self.navigation.source}


def parse_scenario(raw: Any, source: str = "<scenario>") -> Scenario:
    """Validate a scenario mapping; raise :class:`ConfigError` naming ``source`` and the field."""
    if not isinstance(raw, dict):
        raise ConfigError(f"{source}: expected a mapping at the top level")
    raw = dict(raw)
    raw.setdefault("source_file", source)
    try:
        return Scenario.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(validation_message(source, err)) from None


def load_scenario(path: str | Path, overrides: dict | None = None) -> Scenario:
    """Read and validate a scenario YAML file (``overrides`` are merged in before validation)."""
    path = Path(path)
    raw = read_mapping(path, "scenario file")
    raw.setdefault("name", path.stem)
    if overrides:
        raw.update(overrides)
    return parse_scenario(raw, str(path))
