"""Strict JSON for every file the testbed writes: non-finite numbers become ``null`` (JSON has no
NaN or Infinity), numpy scalars and arrays become numbers and lists, paths become strings; any
other object is an error (a bug to fix, never silently stringified)."""

from __future__ import annotations

import json
import math
from pathlib import PurePath
from typing import Any


def to_json_value(x: Any) -> Any:
    """``x`` as plain JSON data (dicts, lists, str, int, float, bool, None)."""
    if isinstance(x, bool) or x is None or isinstance(x, (str, int)):
        return x
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {str(k): to_json_value(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [to_json_value(v) for v in x]
    if isinstance(x, PurePath):
        return str(x)
    if hasattr(x, "tolist"):                       # numpy scalars and arrays
        return to_json_value(x.tolist())
    raise TypeError(f"not JSON data: {type(x).__name__}")


def dumps(obj: Any, indent: int | None = 2) -> str:
    """Strict JSON text of ``obj`` (see the module docstring), with a final newline."""
    return json.dumps(to_json_value(obj), indent=indent, allow_nan=False) + "\n"


__all__ = ["dumps", "to_json_value"]
