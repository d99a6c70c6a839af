"""Every public function and class of the MEMS package (and its plots and command) has a
docstring, and every function parameter is named in it."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = ["sensors.mems.preset", "sensors.mems.temperature", "sensors.mems.model",
           "sensors.mems.compensation", "sensors.mems.allan", "sensors.mems.static_test",
           "sensors.mems.reproduction", "sensors.mems.equivalent", "viz.mems", "cli.imu_test"]


@pytest.mark.parametrize("name", MODULES)
def test_public_functions_document_every_parameter(name):
    mod = importlib.import_module(f"fms_testbed.{name}")
    assert (mod.__doc__ or "").strip(), f"{name}: no module docstring"
    missing = []
    for fname, obj in vars(mod).items():
        if fname.startswith("_") or not callable(obj) or getattr(obj, "__module__", "") != mod.__name__:
            continue
        doc = inspect.getdoc(obj) or ""
        if not doc:
            missing.append(f"{fname}: no docstring")
            continue
        if inspect.isfunction(obj):
            for p in inspect.signature(obj).parameters:
                if p not in doc and p not in ("res", "args", "sub"):
                    missing.append(f"{fname}: parameter {p!r} undocumented")
    assert not missing, "\n".join(missing)
