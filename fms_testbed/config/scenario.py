"""Scenario files (YAML): aircraft, initial condition, wind, duration and timed events.

Example::

    aircraft: "737"
    initial: {lat_deg: 47.0, lon_deg: 8.0, alt_m: 3000, tas_kmh: 400, heading_deg: 90}
    duration_s: 120
    wind: {from_deg: 270, speed_kt: 20}       # or a profile over altitude, see WindLayer
    atmosphere: {isa_dev_c: 15}               # a day 15 °C warmer than the ISA
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
from typing import Annotated, Any, Literal, Union

from pydantic import (BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError,
                      field_validator, model_validator)

from fms_testbed.config.aircraft import list_aircraft
from fms_testbed.config.navigation import NavigationBlock, with_default_source
from fms_testbed.core.errors import ConfigError
from fms_testbed.config.yamlfile import read_mapping, validation_message
from fms_testbed.core.units import FT_M, KMH_MPS, KT_MPS
from fms_testbed.core.wind import WindProfile

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

    alt_m: Alt | None = Field(None, description="altitude above mean sea level, m")
    alt_ft: Annotated[float, Field(ge=-1300, le=82000)] | None = Field(
        None, description="altitude above mean sea level, ft")
    tas_mps: Speed | None = Field(None, description="true airspeed, m/s")
    tas_kmh: Annotated[float, Field(gt=0, lt=3600)] | None = Field(
        None, description="true airspeed, km/h")
    tas_kt: Annotated[float, Field(gt=0, lt=2000)] | None = Field(
        None, description="true airspeed, kt")
    cas_mps: Speed | None = Field(None, description="calibrated airspeed, m/s")
    cas_kt: Annotated[float, Field(gt=0, lt=2000)] | None = Field(
        None, description="calibrated airspeed, kt")
    cas_kmh: Annotated[float, Field(gt=0, lt=3600)] | None = Field(
        None, description="calibrated airspeed, km/h")

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

    lat_deg: Annotated[float, Field(ge=-89, le=89)] = Field(
        45.0, description="geodetic latitude (WGS-84), deg")
    lon_deg: Annotated[float, Field(ge=-180, le=360)] = Field(0.0, description="longitude, deg")
    heading_deg: Annotated[float, Field(ge=0, le=360)] = Field(
        0.0, description="true heading, deg")

    _required = True

    @model_validator(mode="after")
    def _check(self):
        _ = self.altitude_m, self.speed
        return self


class Wind(_Strict):
    """Steady wind: direction it blows from (true, deg) and speed."""

    from_deg: Annotated[float, Field(ge=0, le=360)] = Field(
        description="direction the wind blows from, deg true")
    speed_mps: Annotated[float, Field(ge=0, le=100)] | None = Field(
        None, description="wind speed, m/s (or speed_kt)")
    speed_kt: Annotated[float, Field(ge=0, le=200)] | None = Field(
        None, description="wind speed, kt (or speed_mps)")

    @model_validator(mode="after")
    def _one(self):
        if (self.speed_mps is None) == (self.speed_kt is None):
            raise ValueError("give the wind speed as exactly one of speed_mps or speed_kt")
        return self

    @property
    def speed_ms(self) -> float:
        """Wind speed, m/s."""
        return self.speed_mps if self.speed_mps is not None else self.speed_kt * KT_MPS


class WindLayer(Wind):
    """One layer of a wind profile: the wind at an altitude (``alt_m`` or ``alt_ft``). The
    profile interpolates the wind vector linearly in altitude between layers and holds the end
    layers' beyond them (:class:`~fms_testbed.core.wind.WindProfile`)."""

    alt_m: Alt | None = Field(None, description="layer altitude above mean sea level, m")
    alt_ft: Annotated[float, Field(ge=-1300, le=82000)] | None = Field(
        None, description="layer altitude above mean sea level, ft")

    @property
    def altitude_m(self) -> float:
        """Layer altitude, m."""
        return _alt(self.__dict__, "wind layer", True)

    @model_validator(mode="after")
    def _has_alt(self):
        _ = self.altitude_m
        return self


def _wind_kind(v: Any) -> str:
    return "profile" if isinstance(v, list) else "constant"


def _layers_increase(layers: list[WindLayer]) -> list[WindLayer]:
    if not layers:
        raise ValueError("a wind profile needs at least one layer")
    alts = [lay.altitude_m for lay in layers]
    for k in range(1, len(alts)):
        if alts[k] <= alts[k - 1]:
            raise ValueError(f"wind layer {k} altitude {alts[k]:.0f} m is not above layer "
                             f"{k - 1}'s {alts[k - 1]:.0f} m (give the layers bottom up)")
    return layers


WindSpec = Annotated[Union[Annotated[Wind, Tag("constant")],
                           Annotated[list[WindLayer], Tag("profile")]],
                     Discriminator(_wind_kind)]
"""A scenario wind: one steady wind (a mapping) or a profile (a list of :class:`WindLayer`)."""


def wind_profile(wind: Wind | list[WindLayer] | None) -> WindProfile | None:
    """A validated scenario wind (constant or layers) as a :class:`WindProfile` (SI), None for
    none."""
    if wind is None:
        return None
    if isinstance(wind, Wind):
        return WindProfile.constant(wind.speed_ms, wind.from_deg)
    return WindProfile.from_layers([(lay.altitude_m, lay.from_deg, lay.speed_ms)
                                    for lay in _layers_increase(list(wind))])


class Atmosphere(_Strict):
    """The day's atmosphere: the ISA with a temperature deviation (same at every altitude;
    pressure hydrostatic from the standard sea-level pressure, :mod:`fms_testbed.core.atmosphere`)."""

    isa_dev_c: Annotated[float, Field(ge=-60, le=60)] = Field(
        0.0, description="temperature deviation from the ISA, °C (= K)")


class Forecast(_Strict):
    """The conditions the path is planned for when they differ from the actual ones (a
    forecast): a wind (constant or profile) and an ISA deviation. Absent keys: the actual
    conditions. In flight the measured conditions are compared with these and the rest of the
    procedure is rebuilt when they differ too much (:mod:`fms_testbed.guidance.replan`)."""

    wind: WindSpec | None = Field(None, description="planned wind (default: the actual one)")
    calm: bool = Field(False, description="plan for calm air (whatever the actual wind)")
    isa_dev_c: Annotated[float, Field(ge=-60, le=60)] | None = Field(
        None, description="planned ISA deviation, °C (default: the actual one)")

    @field_validator("wind")
    @classmethod
    def _wind_layers(cls, v):
        return _layers_increase(v) if isinstance(v, list) else v

    @model_validator(mode="after")
    def _calm_or_wind(self):
        if self.calm and self.wind is not None:
            raise ValueError("forecast: give calm: true or a wind, not both")
        return self


class Turbulence(_Strict):
    """JSBSim MIL-F-8785C / MIL-HDBK-1797 (Tustin) turbulence; seeded by the run's seed."""

    severity: Literal["light", "moderate", "severe"] = Field(
        "light", description="MIL-HDBK-1797 severity (wind at 20 ft 25 / 50 / 75 kt)")


class AirDataBlock(_Strict):
    """The air-data computer's errors (:mod:`fms_testbed.sensors.air_data`); without this block
    it reports the truth."""

    errors: Literal["none", "typical"] = Field(
        "none", description="none (the truth) or typical (a transport aircraft's calibrated "
                            "air data: static-source residual, transducers, temperature probe, "
                            "vanes, pneumatic lags; seeded realisation)")
    seed: Annotated[int, Field(ge=0)] | None = Field(
        None, description="seed of the realisation (default: the run's seed)")


class When(_Strict):
    """Condition that fires an event once: altitude crossing and/or time."""

    alt_m_above: float | None = Field(None, description="fires once the altitude is above, m")
    alt_m_below: float | None = Field(None, description="fires once the altitude is below, m")
    t_s_after: Annotated[float, Field(ge=0)] | None = Field(
        None, description="and only after this time, s")

    @model_validator(mode="after")
    def _some(self):
        if self.alt_m_above is None and self.alt_m_below is None and self.t_s_after is None:
            raise ValueError("'when' needs alt_m_above, alt_m_below or t_s_after")
        return self


FAULT_KINDS = {
    "gyro_bias_step": "ins", "accel_bias_step": "ins", "drift_scale": "ins", "stuck": "ins",
    "gnss_outliers": "gnss", "gnss_ramp": "gnss", "gnss_outage": "gnss", "baro_failure": "baro"}
"""Injectable navigation faults and the unit kind each applies to."""


class Fault(_Strict):
    """A navigation fault injected when its event fires (navigation source ``ins_gnss``).

    INS (``unit: ins1``..``ins3``): ``gyro_bias_step`` (``axis``, ``size_dph``),
    ``accel_bias_step`` (``axis``, ``size_ug``), ``drift_scale`` (``factor``: the gyro drift
    becomes ``factor`` × its declared value), ``stuck`` (output frozen). GNSS (``unit: gnss``):
    ``gnss_outliers`` (``sigma_m``, ``duration_s``), ``gnss_ramp`` (``rate_mps`` E, N, U),
    ``gnss_outage`` (``duration_s``). Baro (``unit: baro``): ``baro_failure`` (stuck port).
    """

    unit: str = Field(description="ins1, ins2, ins3, gnss or baro")
    kind: Literal["gyro_bias_step", "accel_bias_step", "drift_scale", "stuck", "gnss_outliers",
                  "gnss_ramp", "gnss_outage", "baro_failure"] = Field(description="fault kind")
    axis: Literal["x", "y", "z"] | None = Field(None, description="body axis (bias steps)")
    size_dph: Annotated[float, Field(ge=-3.6e5, le=3.6e5)] | None = Field(
        None, description="gyro bias step, deg/h")
    size_ug: Annotated[float, Field(ge=-1e6, le=1e6)] | None = Field(
        None, description="accelerometer bias step, µg")
    factor: Annotated[float, Field(gt=0, le=100)] | None = Field(
        None, description="drift scale factor (drift_scale)")
    sigma_m: Annotated[float, Field(gt=0, le=1e5)] | None = Field(
        None, description="outlier σ per axis, m (gnss_outliers)")
    rate_mps: Annotated[list[Annotated[float, Field(ge=-100, le=100)]],
                        Field(min_length=3, max_length=3)] | None = Field(
        None, description="ramp rate E, N, U, m/s (gnss_ramp)")
    duration_s: Annotated[float, Field(gt=0)] | None = Field(
        None, description="how long it lasts, s (gnss_outliers, gnss_outage; default: to the end)")

    @model_validator(mode="after")
    def _fits(self):
        want = FAULT_KINDS[self.kind]
        ok_unit = (self.unit in ("ins1", "ins2", "ins3") if want == "ins" else self.unit == want)
        if not ok_unit:
            raise ValueError(f"fault {self.kind} applies to "
                             f"{'ins1..ins3' if want == 'ins' else want}, not {self.unit!r}")
        need = {"gyro_bias_step": ("axis", "size_dph"), "accel_bias_step": ("axis", "size_ug"),
                "drift_scale": ("factor",), "gnss_outliers": ("sigma_m",),
                "gnss_ramp": ("rate_mps",)}.get(self.kind, ())
        missing = [k for k in need if getattr(self, k) is None]
        if missing:
            raise ValueError(f"fault {self.kind} needs {', '.join(missing)}")
        return self


class Event(_AltSpeed):
    """A target change at time ``t_s`` (or when ``when`` is met). Unset fields are unchanged."""

    t_s: Annotated[float, Field(ge=0)] | None = Field(None, description="time it fires, s")
    when: When | None = Field(None, description="condition it fires on (instead of t_s)")
    bank_deg: Annotated[float, Field(ge=-60, le=60)] | None = Field(
        None, description="bank-hold target, deg (right wing down positive)")
    heading_deg: Annotated[float, Field(ge=0, le=360)] | None = Field(
        None, description="heading-hold target, deg true (on the navigation heading)")
    nx: Annotated[float, Field(ge=-0.5, le=0.5)] | None = Field(
        None, description="tangential load-factor target for the n_x loop, g")
    ny: Annotated[float, Field(ge=-1.0, le=3.0)] | None = Field(
        None, description="normal (lift-axis) load-factor target, g")
    throttle: Annotated[float, Field(ge=0, le=1)] | None = Field(
        None, description="direct throttle 0..1 (disengages the n_x loop)")
    fault: Fault | None = Field(None, description="navigation fault injected when it fires")

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

    name: str = Field("", description="run name (default: the file's stem)")
    description: str = Field("", description="free text")
    aircraft: str = Field(description="a shipped aircraft (737, global5000, c172p) or a path to "
                                      "an aircraft YAML file")
    initial: Initial = Field(description="initial condition, trimmed straight and level (a "
                                         "procedure flight defaults it to the path start)")
    duration_s: Annotated[float, Field(gt=0, le=6 * 3600)] = Field(
        description="simulated time to fly, s (a procedure flight ends when guidance completes)")
    wind: WindSpec | None = Field(
        None, description="steady wind (mapping) or a profile over altitude (list of layers "
                          "with alt_m|alt_ft), ramped in over 20 s after trim")
    atmosphere: Atmosphere | None = Field(
        None, description="the day's atmosphere (ISA deviation); default the ISA")
    forecast: Forecast | None = Field(
        None, description="conditions the path is planned for, when not the actual ones")
    turbulence: Turbulence | None = Field(None, description="JSBSim turbulence after trim")
    vertical_law: Literal["coupled", "pi", "tecs"] = Field(
        "coupled", description="law for altitude/speed targets: the coupled thrust/elevator law "
                               "(Kulikov), separate PI channels, or TECS")
    hold: bool = Field(False, description="engage the vertical law at t=0 holding the initial "
                                          "altitude and speed")
    outer_rate_hz: Annotated[float, Field(ge=5, le=120)] = Field(
        10.0, description="rate of navigation, guidance, heading hold and the vertical law, Hz")
    log_rate_hz: Annotated[float, Field(ge=1, le=120)] = Field(
        10.0, description="timeseries rate, Hz (at most the outer rate)")
    navigation: NavigationBlock | None = None
    air_data: AirDataBlock | None = Field(
        None, description="air-data computer errors (default: none, the computer reports the "
                          "truth)")
    rnp_nm: Annotated[float, Field(gt=0, le=30)] | None = Field(
        None, description="RNP for the navigation error of a flight without a procedure, NM "
                          "(default: 2 NM when the navigation source is not truth; a procedure "
                          "flight takes its RNP from the procedure)")
    procedure: dict[str, Any] | None = Field(
        None, description="the ARINC-424 procedure to fly (see the procedure block)")
    events: list[Event] = Field(default_factory=list, description="target changes, in order")
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

    @field_validator("wind")
    @classmethod
    def _wind_layers(cls, v):
        return _layers_increase(v) if isinstance(v, list) else v

    @property
    def isa_dev_c(self) -> float:
        """The actual temperature deviation from the ISA, K (0 without an atmosphere block)."""
        return self.atmosphere.isa_dev_c if self.atmosphere is not None else 0.0

    @property
    def wind_profile(self) -> WindProfile | None:
        """The actual wind as a :class:`~fms_testbed.core.wind.WindProfile`, None for calm."""
        return wind_profile(self.wind)

    @property
    def planned_wind_profile(self) -> WindProfile | None:
        """The wind the path is planned for: the forecast's, else the actual one."""
        f = self.forecast
        if f is not None and f.calm:
            return None
        if f is not None and f.wind is not None:
            return wind_profile(f.wind)
        return self.wind_profile

    @property
    def planned_isa_dev_c(self) -> float:
        """The ISA deviation the path is planned for, K: the forecast's, else the actual."""
        f = self.forecast
        return f.isa_dev_c if f is not None and f.isa_dev_c is not None else self.isa_dev_c

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
