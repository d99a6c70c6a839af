"""Running scenarios: :func:`~fms_testbed.run.api.run_scenario` flies any scenario and returns
:class:`~fms_testbed.run.results.Results`.

The names are imported on first use, so ``fms_testbed.run.outputs`` (the output-folder checks
the CLI makes before any work) loads without the flight machinery.
"""

from __future__ import annotations

_NAMES = {"fly_procedure": "api", "load": "api", "results_of": "api", "run_scenario": "api",
          "Results": "results", "Summary": "summary"}


def __getattr__(name: str):
    if name in _NAMES:
        import importlib

        return getattr(importlib.import_module(f"fms_testbed.run.{_NAMES[name]}"), name)
    raise AttributeError(f"module 'fms_testbed.run' has no attribute {name!r}")


__all__ = sorted(_NAMES)
