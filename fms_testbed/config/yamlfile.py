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


MAX_YAML_BYTES = 10_000_000
"""Largest YAML file read, bytes (a scenario or aircraft file is a few KB)."""


def read_mapping(path: str | Path, what: str = "file") -> dict[str, Any]:
    """Read a YAML file whose top level is a mapping; raise :class:`ConfigError` otherwise.

    Parameters
    ----------
    path : the file
    what : what the file is, for the messages (``"scenario file"``, ``"aircraft file"``, …)
    """
    path = Path(path)
    try:
        if path.exists() and not path.is_dir() and not path.is_file():
            raise ConfigError(f"{path}: not a regular file (a device or a pipe?)")
        if path.is_file() and path.stat().st_size > MAX_YAML_BYTES:
            raise ConfigError(f"{path}: {path.stat().st_size} bytes is too large for a {what} "
                              f"(at most {MAX_YAML_BYTES} bytes)")
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text (byte {exc.start}: {exc.reason})") from None
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


_TAGGED_FIELDS = ("navigation", "wind")
"""Fields whose value is a discriminated union (pydantic adds the tag to the error location)."""


def validation_message(source: str, err) -> str:
    """One line from a pydantic ``ValidationError``: the first failing field and why."""
    e = err.errors()[0]
    parts = list(e["loc"])
    # a discriminated union (the navigation block) puts its tag into the location: drop it
    parts = [x for i, x in enumerate(parts)
             if not (i > 0 and parts[i - 1] in _TAGGED_FIELDS and isinstance(x, str))]
    loc = ".".join(str(x) for x in parts) or "<root>"
    msg = e["msg"].removeprefix("Value error, ")
    if e["type"] == "extra_forbidden":
        msg = "unknown field"
    more = f" (+{len(err.errors()) - 1} more)" if len(err.errors()) > 1 else ""
    return f"{source}: field '{loc}': {msg}{more}"
