"""Condition sets of a campaign: the "current conditions" a procedure is flown in (Danilin's
first error class is the errors they cause).

A condition set is a name, a steady wind, a turbulence level and a navigation source — the
scenario keys ``wind``, ``turbulence`` and ``navigation``, validated by the scenario's own
models. The sets come from the command line (the product of ``--wind`` × ``--nav``) or from a
YAML file (``--conditions FILE``)::

    conditions:
      - name: calm
      - name: west-30
        wind: {from_deg: 270, speed_kt: 30}
      - name: hg1700
        navigation: {source: sins, imu: HG1700}
        turbulence: {severity: light}

Keys the flight stack cannot honour yet (``isa_dev_c``, ``missed``) are refused in one line,
never ignored; so is any other unknown key. Names must be unique: with the procedure and the
aircraft they are how two runs' cases are matched (``regress diff``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import TypeAdapter, ValidationError

from fms_testbed.config.navigation import NavigationBlock, with_default_source
from fms_testbed.config.scenario import Turbulence, Wind
from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.core.units import KT_MPS

NOT_YET = {
    "isa_dev_c": "ISA temperature deviation is not modelled by the flight stack yet (JSBSim "
                 "flies ISA); it comes with the ISA-deviation issue",
    "missed": "missed approaches are not flown yet (an approach ends at the MAP); they come "
              "with the missed-approach issue",
}
"""Condition keys that are refused (with why) until the flight stack honours them."""

_KEYS = ("name", "wind", "turbulence", "navigation")
_NAV = TypeAdapter(NavigationBlock)


@dataclass(frozen=True)
class Conditions:
    """One condition set (scenario keys, validated).

    Attributes
    ----------
    name : unique label, e.g. 'calm', 'wind 270/30kt', 'sins HG1700'
    wind : scenario ``wind`` mapping (``from_deg`` deg true, ``speed_kt`` kt or ``speed_mps``
        m/s) or None for calm air
    turbulence : scenario ``turbulence`` mapping or None
    navigation : scenario ``navigation`` mapping (``source`` and its keys)
    """

    name: str
    wind: dict | None = None
    turbulence: dict | None = None
    navigation: dict = field(default_factory=lambda: {"source": "truth"})

    def overrides(self) -> dict[str, Any]:
        """The scenario keys of this set."""
        out: dict[str, Any] = {"navigation": dict(self.navigation)}
        if self.wind is not None:
            out["wind"] = dict(self.wind)
        if self.turbulence is not None:
            out["turbulence"] = dict(self.turbulence)
        return out

    def canonical(self) -> str:
        """Canonical JSON of the set (sorted keys): what the case id hashes."""
        return json.dumps({"name": self.name, **self.overrides()}, sort_keys=True,
                          separators=(",", ":"))

    @property
    def wind_speed_mps(self) -> float:
        """Steady wind speed, m/s (0 for calm air)."""
        if self.wind is None:
            return 0.0
        w = self.wind
        return float(w["speed_mps"]) if w.get("speed_mps") is not None \
            else float(w["speed_kt"]) * KT_MPS

    @property
    def nominal(self) -> bool:
        """Calm air, no turbulence, navigation = truth: failures here are not caused by the
        current conditions (Danilin's class 1 cannot apply)."""
        return (self.wind_speed_mps == 0.0 and self.turbulence is None
                and self.navigation.get("source", "truth") == "truth")


def _check_block(where: str, key: str, value, model) -> dict:
    """A wind/turbulence/navigation block checked by the scenario's model; the mapping as the
    scenario takes it (navigation: the keys given, with ``source``)."""
    try:
        if model is _NAV:
            _NAV.validate_python(with_default_source(value))
            return dict(with_default_source(value))
        return model.model_validate(value).model_dump(exclude_none=True)
    except ValidationError as err:
        e = err.errors()[0]
        loc = ".".join(str(x) for x in (key, *e["loc"]))
        msg = "unknown field" if e["type"] == "extra_forbidden" else e["msg"]
        raise ConfigError(f"{where}: field '{loc}': {msg}") from None


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
    wind = _check_block(where, "wind", raw["wind"], Wind) if raw.get("wind") is not None else None
    turb = (_check_block(where, "turbulence", raw["turbulence"], Turbulence)
            if raw.get("turbulence") is not None else None)
    nav = _check_block(where, "navigation", raw.get("navigation") or {"source": "truth"}, _NAV)
    name = raw.get("name")
    if name is None:
        name = default_name(wind, turb, nav)
    if not isinstance(name, str) or not name.strip():
        raise ConfigError(f"{where}: field 'name': expected a non-empty text")
    return Conditions(name.strip(), wind, turb, nav)


def default_name(wind: dict | None, turbulence: dict | None, navigation: dict) -> str:
    """'calm', 'wind 270/30kt', '... turbulence light', '... sins HG1700'.

    Parameters
    ----------
    wind, turbulence, navigation : the set's validated scenario blocks (None: absent)
    """
    parts = []
    if wind is None:
        parts.append("calm")
    else:
        spd = (f"{wind['speed_kt']:g}kt" if wind.get("speed_kt") is not None
               else f"{wind['speed_mps']:g}mps")
        parts.append(f"wind {wind['from_deg']:g}/{spd}")
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


def command_line_sets(winds: list[dict | None], navs: list[dict]) -> list[Conditions]:
    """The product of the ``--wind`` values and the ``--nav`` blocks, winds varying slowest.

    Parameters
    ----------
    winds : scenario wind mappings (None: calm air)
    navs : scenario navigation mappings
    """
    sets = [make_conditions({"wind": w, "navigation": n}, "--wind/--nav")
            for w in winds for n in navs]
    return _unique(sets, "--wind/--nav")


__all__ = ["NOT_YET", "Conditions", "check_sources", "command_line_sets", "default_name",
           "make_conditions", "read_conditions"]
