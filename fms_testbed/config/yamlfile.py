"""Reading user YAML files (aircraft, scenarios, IMU presets) with one-line errors.

Every loader reads through :func:`read_mapping` and reports pydantic validation errors through
:func:`validation_message`, so a bad file always says ``FILE[: line L, column C]: reason`` or
``FILE: field 'a.b.0.c': reason``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from fms_testbed.core.errors import ConfigError


def read_mapping(path: str | Path, what: str = "file") -> dict[str, Any]:
    """Read a YAML file whose top level is a mapping; raise :class:`ConfigError` otherwise.

    Parameters
    ----------
    path : the file
    what : what the file is, for the messages (``"scenario file"``, ``"aircraft file"``, …)
    """
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a folder, not a {what}") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read {what}: {exc.strerror}") from None
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}:" if mark else ""
        raise ConfigError(f"{path}:{where} invalid YAML: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(raw, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level")
    return raw


def validation_message(source: str, err) -> str:
    """One line from a pydantic ``ValidationError``: the first failing field and why."""
    e = err.errors()[0]
    loc = ".".join(str(x) for x in e["loc"]) or "<root>"
    msg = e["msg"].removeprefix("Value error, ")
    if e["type"] == "extra_forbidden":
        msg = "unknown field"
    more = f" (+{len(err.errors()) - 1} more)" if len(err.errors()) > 1 else ""
    return f"{source}: field '{loc}': {msg}{more}"
