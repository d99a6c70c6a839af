"""The shape of the code: no module over :data:`MODULE_MAX_LINES` lines, no class with more than
:data:`CLASS_MAX_METHODS` methods, no function over :data:`FUNCTION_MAX_LINES` lines — checked
on the modules listed in :data:`CHECKED` (the lanes reshaped so far; extend the list as the
others are), and the package-wide count of long functions held at :data:`LONG_FUNCTIONS_MAX`.

A function's length is its lines from the ``def`` to its last line, docstring included; a
class's methods are the functions defined in its body (properties included)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "fms_testbed"
MODULE_MAX_LINES = 600
CLASS_MAX_METHODS = 15
FUNCTION_MAX_LINES = 60
LONG_FUNCTIONS_MAX = 12
"""Functions over :data:`FUNCTION_MAX_LINES` lines allowed in the whole package (the goal)."""

CHECKED = (
    "loop/", "guidance/active_path.py", "guidance/conditions.py", "guidance/fms.py",
    "guidance/geometry.py", "guidance/locate.py", "guidance/replan.py",
    "guidance/sequencing.py", "guidance/speed_plan.py", "guidance/step_log.py",
    "guidance/vertical.py", "guidance/vnav.py", "run/", "evaluation/outcome.py",
    "evaluation/records.py", "evaluation/flight_errors.py", "evaluation/threshold.py",
    "core/contracts.py", "core/state.py", "navigation/__init__.py", "sensors/sins/", "viz/",
    "navigation/identification/", "navigation/fdi.py", "navigation/montecarlo.py",
    "navigation/montecarlo_model.py", "evaluation/montecarlo.py", "evaluation/detection_limit.py",
    "navigation/reference_description.py", "navigation/reference_kernels.py",
    "campaign/", "evaluation/navigation_truth.py", "cli/regress.py", "cli/fly.py",
    "cli/imu_test.py", "cli/montecarlo.py", "cli/common.py",
    "control/", "sim/linearise.py", "sim/inner_loops.py", "sim/jsbsim_core.py",
    "evaluation/envelope_points.py", "evaluation/envelope_tuning.py",
    "evaluation/linear_check.py", "evaluation/law_tuning.py", "cli/coupled.py", "cli/inner.py",
    "cli/tune_envelope.py",
    "navigation/ins_filter.py", "navigation/prediction.py", "navigation/measurements.py",
    "navigation/replay.py", "navigation/replay_io.py", "navigation/recording.py",
    "navigation/strapdown_sins.py", "cli/nav_replay.py", "viz/replay.py",
    "evaluation/campaign_shift.py", "guidance/vertical_schedule.py", "path/departure.py",
)
"""Modules (or folders, ending in '/') whose shape is enforced, relative to the package."""


def _modules(prefixes=("",)) -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py")
                  if any(str(p.relative_to(PACKAGE)).startswith(x) for x in prefixes))


def shape(path: Path) -> tuple[int, list[tuple[str, int]], list[tuple[str, int]]]:
    """(module lines, [(class, methods)], [(function, lines)]) of one module."""
    text = path.read_text()
    tree = ast.parse(text)
    classes, functions = [], []
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef):
            n = sum(isinstance(b, (ast.FunctionDef, ast.AsyncFunctionDef)) for b in node.body)
            classes.append((node.name, n))
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            functions.append((node.name, node.end_lineno - node.lineno + 1))
    return len(text.splitlines()), classes, functions


@pytest.mark.parametrize("path", _modules(CHECKED), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_checked_module_shape(path):
    lines, classes, functions = shape(path)
    assert lines <= MODULE_MAX_LINES, f"{lines} lines"
    big = [c for c in classes if c[1] > CLASS_MAX_METHODS]
    assert not big, f"classes with more than {CLASS_MAX_METHODS} methods: {big}"
    long = [f for f in functions if f[1] > FUNCTION_MAX_LINES]
    assert not long, f"functions over {FUNCTION_MAX_LINES} lines: {long}"


def long_functions() -> list[tuple[str, str, int]]:
    """Every function of the package over :data:`FUNCTION_MAX_LINES` lines: (module, name, lines)."""
    out = []
    for p in _modules():
        for name, n in shape(p)[2]:
            if n > FUNCTION_MAX_LINES:
                out.append((str(p.relative_to(PACKAGE)), name, n))
    return out


def test_package_long_functions_within_the_goal():
    long = long_functions()
    assert len(long) <= LONG_FUNCTIONS_MAX, sorted(long, key=lambda f: -f[2])


def test_package_modules_and_classes_within_the_goal():
    big = []
    for p in _modules():
        lines, classes, _ = shape(p)
        name = str(p.relative_to(PACKAGE))
        if lines > MODULE_MAX_LINES:
            big.append((name, f"{lines} lines"))
        big += [(name, f"class {c} has {n} methods") for c, n in classes if n > CLASS_MAX_METHODS]
    assert not big, big
