"""Running scenarios: :func:`~fms_testbed.run.api.run_scenario` flies any scenario and returns
:class:`~fms_testbed.run.results.Results`."""

from fms_testbed.run.api import fly_procedure, load, results_of, run_scenario
from fms_testbed.run.results import Results, Summary

__all__ = ["Results", "Summary", "fly_procedure", "load", "results_of", "run_scenario"]
