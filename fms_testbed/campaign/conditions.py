"""Condition sets of a campaign: the "current conditions" a procedure is flown in (Danilin's
first error class is the errors they cause).

A condition set is a name, a wind (steady, or a profile over altitude), an ISA temperature
deviation, a turbulence level and a navigation source — the scenario keys ``wind``,
``atmosphere.isa_dev_c``, ``turbulence`` and ``navigation``, validated by the scenario's own
models. The sets come from the command line (the product of ``--wind`` × ``--isa-dev-c`` ×
``--nav``) or from a YAML file (``--conditions FILE``)::

    conditions:
      - name: calm
      - name: west-30
        wind: {from_deg: 270, speed_kt: 30}
      - name: hg1700
        navigation: {source: sins, imu: HG1700}
        turbulence: {severity: light}
      - name: hot-shear
        isa_dev_c: 20
        wind: [{alt_ft: 0, from_deg: 250, speed_kt: 10}, {alt_ft: 10000, from_deg: 280, speed_kt: 50}]

``missed: true`` flies the missed approach of every approach case of the set (go-around at
the MAP, the missed-approach legs and one holding circuit; SID and STAR cases fly as without
it); it is part of the set's canonical form, so it enters the case id. Keys the flight stack
cannot honour yet (:data:`NOT_YET`, none now) are refused in one line, never ignored; so is
any other unknown key. Names must be unique: with the procedure and the
aircraft they are how two runs' cases are matched (``regress diff``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import TypeAdapter, ValidationError

from fms_testbed.config.navigation import NavigationBlock, with_default_source
from fms_testbed.config.scenario import Atmosphere, Turbulence, WindSpec, wind_profile
from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.core.units import KT_MPS

NOT_YET: dict[str, str] = {}
"""Condition keys that are refused (with why) until the flight stack honours them."""

_KEYS = ("name", "wind", "isa_dev_c", "turbulence", "navigation", "missed")
_NAV = TypeAdapter(NavigationBlock)
_WIND = TypeAdapter(WindSpec)


@dataclass(frozen=True)
class Conditions:
    """One condition set (scenario keys, validated).

    Attributes
    ----------
    name : unique label, e.g. 'calm', 'wind 270/30kt', 'sins HG1700'
    wind : scenario ``wind`` mapping (``from_deg`` deg true, ``speed_kt`` kt or ``speed_mps``
        m/s), a list of such layers with ``alt_m``/``alt_ft`` (a profile), or None for calm air
    turbulence : scenario ``turbulence`` mapping or None
    navigation : scenario ``navigation`` mapping (``source`` and its keys)
    isa_dev_c : temperature deviation from the ISA, °C (scenario ``atmosphere.isa_dev_c``)
    missed : approaches fly their missed approach (``procedure.missed``)
    """

    name: str
    wind: dict | list | None = None
    turbulence: dict | None = None
    navigation: dict = field(default_factory=lambda: {"source": "truth"})
    isa_dev_c: float = 0.0
    missed: bool = False

    def overrides(self) -> dict[str, Any]:
        """The scenario keys of this set."""
        out: dict[str, Any] = {"navigation": dict(self.navigation)}
        if self.wind is not None:
            out["wind"] = ([dict(x) for x in self.wind] if isinstance(self.wind, list)
                           else dict(self.wind))
        if self.isa_dev_c:   # absent at ISA: the case ids of ISA sets are unchanged
            out["atmosphere"] = {"isa_dev_c": self.isa_dev_c}
        if self.turbulence is not None:
            out["turbulence"] = dict(self.turbulence)
        return out

    def canonical(self) -> str:
        """Canonical JSON of the set (sorted keys): what the case id hashes."""
        extra = {"missed": True} if self.missed else {}   # absent: ids of other sets unchanged
        return json.dumps({"name": self.name, **self.overrides(), **extra}, sort_keys=True,
                          separators=(",", ":"))

    @property
    def wind_speed_mps(self) -> float:
        """Wind speed, m/s (0 for calm air; a profile: its strongest layer's)."""
        if self.wind is None:
            return 0.0
        layers = self.wind if isinstance(self.wind, list) else [self.wind]
        return max(float(w["speed_mps"]) if w.get("speed_mps") is not None
                   else float(w["speed_kt"]) * KT_MPS for w in layers)

    @property
    def nominal(self) -> bool:
        """Calm air, no turbulence, navigation = truth: failures here are not caused by the
        current conditions (Danilin's class 1 cannot apply)."""
        return (self.wind_speed_mps == 0.0 and self.turbulence is None and self.isa_dev_c == 0.0
                and self.navigation.get("source", "truth") == "truth")


def _check_block(where: str, key: str, value, model) -> dict:
    """A wind/turbulence/navigation block checked by the scenario's model; the mapping as the
    scenario takes it (navigation: the keys given, with ``source``)."""
    try:
        if model is _NAV:
            _NAV.validate_python(with_default_source(value))
            return dict(with_default_source(value))
        if model is _WIND:
            got = _WIND.validate_python(value)
            wind_profile(got)   # layer order
            return ([x.model_dump(exclude_none=True) for x in got] if isinstance(got, list)
                    else got.model_dump(exclude_none=True))
        return model.model_validate(value).model_dump(exclude_none=True)
    except ValidationError as err:
        e = err.errors()[0]
        # the wind union's tag ('constant' / 'profile') is no field of the file
        parts = [x for i, x in enumerate(e["loc"])
                 if not (model is _WIND and i == 0 and x in ("constant", "profile"))]
        loc = ".".join(str(x) for x in (key, *parts))
        msg = "unknown field" if e["type"] == "extra_forbidden" else e["msg"]
        raise ConfigError(f"{where}: field '{loc}': {msg}") from None
    except ValueError as err:
        raise ConfigError(f"{where}: field '{key}': {err}") from None


def make_conditions(raw: dict, where: str) -> Conditions:
    """Validate one condition-set mapping (module docstring); :class:`ConfigError` naming
    ``where`` and the field.

    Parameters
    ----------
    raw : the mapping (``name``, ``wind``, ``turbulence``, ``navigation``)
    where : what to name in an error (file and list position, or the options)
    """
    if not isinstance(raw, dict):
        raise ConfigError(f"{where}: expected a mapping with name/wind/turbulence/navigation")
    for k in raw:
        if k in NOT_YET:
            raise ConfigError(f"{where}: field '{k}': {NOT_YET[k]}")
        if k not in _KEYS:
            raise ConfigError(f"{where}: field '{k}': unknown field (known: {', '.join(_KEYS)})")
    wind = _check_block(where, "wind", raw["wind"], _WIND) if raw.get("wind") is not None else None
    dev = 0.0
    if raw.get("isa_dev_c") is not None:
        dev = float(_check_block(where, "isa_dev_c", {"isa_dev_c": raw["isa_dev_c"]},
                                 Atmosphere).get("isa_dev_c", 0.0))
    turb = (_check_block(where, "turbulence", raw["turbulence"], Turbulence)
            if raw.get("turbulence") is not None else None)
    nav = _check_block(where, "navigation", raw.get("navigation") or {"source": "truth"}, _NAV)
    name = raw.get("name")
    if name is None:
        name = default_name(wind, turb, nav, dev)
    if not isinstance(name, str) or not name.strip():
        raise ConfigError(f"{where}: field 'name': expected a non-empty text")
    missed = raw.get("missed", False)
    if not isinstance(missed, bool):
        raise ConfigError(f"{where}: field 'missed': expected true or false")
    if missed and raw.get("name") is None:
        name += " missed"
    return Conditions(name.strip(), wind, turb, nav, dev, missed)


def default_name(wind: dict | list | None, turbulence: dict | None, navigation: dict,
                 isa_dev_c: float = 0.0) -> str:
    """'calm', 'wind 270/30kt', 'wind profile 3 layers', '... ISA+15', '... turbulence light',
    '... sins HG1700'.

    Parameters
    ----------
    wind, turbulence, navigation : the set's validated scenario blocks (None: absent)
    isa_dev_c : the set's ISA deviation, °C (named when not 0)
    """
    parts = []
    if wind is None:
        parts.append("calm")
    elif isinstance(wind, list):
        parts.append(f"wind profile {len(wind)} layers")
    else:
        spd = (f"{wind['speed_kt']:g}kt" if wind.get("speed_kt") is not None
               else f"{wind['speed_mps']:g}mps")
        parts.append(f"wind {wind['from_deg']:g}/{spd}")
    if isa_dev_c:
        parts.append(f"ISA{isa_dev_c:+g}")
    if turbulence is not None:
        parts.append(f"turbulence {turbulence.get('severity', 'light')}")
    if navigation.get("source", "truth") != "truth":
        imu = navigation.get("imu")
        parts.append(f"{navigation['source']} {imu if isinstance(imu, str) else 'imu'}")
    return " ".join(parts)


def check_sources(sets: list[Conditions]) -> None:
    """Build each distinct navigation source once (an unknown IMU preset is refused before any
    flight, naming the condition set).

    Parameters
    ----------
    sets : the condition sets
    """
    from fms_testbed.navigation import make_source

    seen = set()
    for c in sets:
        key = json.dumps(c.navigation, sort_keys=True)
        if key in seen:
            continue
        seen.add(key)
        try:
            make_source(c.navigation, seed=0)
        except UserError as exc:
            raise ConfigError(f"condition set {c.name!r}: {exc}") from None


def _unique(sets: list[Conditions], where: str) -> list[Conditions]:
    names = [c.name for c in sets]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ConfigError(f"{where}: condition set names must be unique; repeated: "
                          f"{', '.join(dup)}")
    return sets


def read_conditions(path: str | Path) -> list[Conditions]:
    """The condition sets of a YAML file (module docstring).

    Parameters
    ----------
    path : the file
    """
    path = Path(path)
    raw = read_mapping(path, "conditions file")
    extra = sorted(set(raw) - {"conditions"})
    if extra:
        raise ConfigError(f"{path}: field '{extra[0]}': unknown field (the file holds "
                          "'conditions:', a list of condition sets)")
    items = raw.get("conditions")
    if not isinstance(items, list) or not items:
        raise ConfigError(f"{path}: field 'conditions': expected a non-empty list of "
                          "condition sets")
    sets = [make_conditions(c, f"{path}: conditions[{i}]") for i, c in enumerate(items)]
    return _unique(sets, str(path))


def command_line_sets(winds: list[dict | None], navs: list[dict],
                      isa_devs: list[float] | None = None,
                      missed: bool = False) -> list[Conditions]:
    """The product of the ``--wind`` values, the ``--isa-dev-c`` values and the ``--nav``
    blocks, winds varying slowest.

    Parameters
    ----------
    winds : scenario wind mappings (None: calm air)
    navs : scenario navigation mappings
    isa_devs : ISA deviations, °C (default: the ISA only)
    missed : every set flies the missed approaches (``--missed``)
    """
    sets = [make_conditions({"wind": w, "isa_dev_c": d, "navigation": n, "missed": missed},
                            "--wind/--isa-dev-c/--nav")
            for w in winds for d in (isa_devs or [0.0]) for n in navs]
    return _unique(sets, "--wind/--isa-dev-c/--nav")


__all__ = ["NOT_YET", "Conditions", "check_sources", "command_line_sets", "default_name",
           "make_conditions", "read_conditions"]
