"""Fly a procedure scenario with the in-flight rebuild on changed conditions switched on or off
(the conditions benches compare the two)."""

from __future__ import annotations

import fms_testbed.guidance.replan as replan
from fms_testbed.guidance.conditions import ConditionMonitor, ConditionThresholds
from fms_testbed.loop.procedure import prepare
from fms_testbed.run import fly_procedure


def fly(raw: dict, db, rebuild: bool = True):
    """(Results, built procedure) of scenario mapping ``raw`` on database ``db``; with
    ``rebuild`` False the condition monitor's thresholds are infinite (no rebuild for a
    measured wind or temperature)."""
    scn, spec, fp, d = prepare(raw, db=db)
    th = ConditionThresholds() if rebuild else ConditionThresholds(wind_err_mps=1e9,
                                                                   isa_dev_err_c=1e9)
    orig = replan.ConditionMonitor
    replan.ConditionMonitor = lambda thresholds=None: ConditionMonitor(th)
    try:
        return fly_procedure(scn, spec, fp, d, progress=False, plots=False), fp
    finally:
        replan.ConditionMonitor = orig
