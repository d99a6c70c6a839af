"""Every public function of the listed modules documents each of its parameters, and every public
class and function has a docstring (the python-control ``docstrings_test`` idea, reduced to names
— and, unlike it, able to fail). A module joins the list once its docstrings are complete."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = [
    # the coupled law and its studies
    "control.coupled_law", "control.baselines", "control.pointmass", "control.linear",
    "control.metrics", "evaluation.law_tuning", "evaluation.law_comparison", "viz.control",
    # envelope tuning
    "sim.linearise", "control.loops", "control.schedule", "evaluation.envelope_points",
    "evaluation.envelope_tuning", "evaluation.linear_check", "viz.tuning", "cli.tune_envelope",
    # MEMS gyro drift
    "sensors.mems.preset", "sensors.mems.temperature", "sensors.mems.model",
    "sensors.mems.compensation", "sensors.mems.allan", "sensors.mems.static_test",
    "sensors.mems.reproduction", "sensors.mems.equivalent", "viz.mems",
    # the run path and its contracts
    "core.contracts", "core.earth", "core.processes", "evaluation.outcome", "run.results",
    "run.outputs", "navigation.truth", "sim.divergence", "viz.figure",
    # regression runs
    "procedures.index", "campaign.cases", "campaign.conditions", "campaign.rows",
    "campaign.worker", "campaign.executors", "campaign.store", "campaign.runner",
    "campaign.diff", "campaign.report", "campaign.figures", "cli.regress",
    "procedures.testdb", "campaign.manifest", "campaign.audit", "evaluation.navigation_truth",
    # the strapdown IMU and INS
    "sensors.imu.kinematics", "sensors.imu.synthesis", "sensors.imu.errors",
    "navigation.bank", "navigation.inertial.strapdown", "navigation.inertial.alignment",
    "navigation.inertial.bank", "navigation.inertial.twin",
    "loop.flight", "loop.log", "loop.phases", "loop.record", "loop.steps", "loop.takeoff",
    "guidance.fms", "guidance.locate", "guidance.sequencing", "guidance.conditions",
    "guidance.replan", "guidance.vnav", "guidance.step_log", "guidance.profile_kernel",
    "guidance.speed_plan", "guidance.active_path", "run.summary", "run.schemas", "run.api",
    "evaluation.records", "evaluation.flight_errors", "evaluation.threshold",
    # fault identification
    "navigation.identification.rules", "navigation.identification.sensor",
    "navigation.identification.two_stage", "navigation.identification.tuning",
    "navigation.fdi", "evaluation.detection_limit",
]
#: Parameter names that are self-explanatory in a CLI handler (argparse namespace, sub-parsers).
CLI_NAMES = ("args", "sub", "subparsers", "res")


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
                if p not in doc and p not in CLI_NAMES:
                    missing.append(f"{fname}: parameter {p!r} undocumented")
    assert not missing, "\n".join(missing)
