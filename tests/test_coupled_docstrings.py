"""Every public function of the coupled-law package documents each of its parameters
(the python-control ``docstrings_test`` idea, reduced to names)."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = ["control.coupled_law", "control.baselines", "control.pointmass", "control.linear",
           "control.metrics", "evaluation.law_tuning", "evaluation.law_comparison", "viz.control"]


@pytest.mark.parametrize("name", MODULES)
def test_public_functions_document_every_parameter(name):
    mod = importlib.import_module(f"fms_testbed.{name}")
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
                if p not in doc:
                    missing.append(f"{fname}: parameter {p!r} undocumented")
    assert not missing, "\n".join(missing)
