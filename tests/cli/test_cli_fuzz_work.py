"""Seeded fuzz of every command with its real work: each command line is a fast valid base of
the command with one option set to a hostile value (:data:`HOSTILE` or a sandbox path: a file,
a symlink, a read-only, foreign or missing folder, another kind of run), run as a subprocess
(``python -m fms_testbed``) with a timeout and nothing stubbed.

Every run must end within :data:`RUN_TIMEOUT_S` (never a hang) with exit 0, 1 or 2, no
traceback on stderr, a 2 with exactly one line on stderr, and leave the sandbox's other runs
whole (the regression run's part file and ``run.json``, the montecarlo run's ``run.json``, a
foreign folder's file) unless the line names that run with ``--overwrite``.

The draw: run ``k`` fuzzes command ``k mod C`` (C the parser's commands, in the parser's order),
``random.Random(k)`` picks the option and the value — so every command gets ``N / C`` runs and
any run is reproduced from its seed (printed on failure). The default suite checks the draw and
runs :data:`QUICK_SEEDS`; ``pytest -m slow`` runs ``FUZZ_WORK_N`` runs (default 3 per command)
from seed ``FUZZ_WORK_SEED0`` (default 0) over ``FUZZ_WORK_JOBS`` processes (default 2);
``FUZZ_WORK_REPORT=FILE`` writes the counts.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from pathlib import Path

import pytest

from fms_testbed.cli import build_parser
from test_cli_fuzz import HOSTILE, _sandbox, commands, regress_case  # noqa: F401 (fixture)

REPO = Path(__file__).resolve().parents[2]
RUN_TIMEOUT_S = 300.0
"""A run still going after this is a hang (a base line's own work takes well under a minute)."""
QUICK_SEEDS = (30,)
"""Run of the default suite (a regress run line refused before any work)."""

SHORT_SCENARIO = """name: fuzz-short
description: 737 level flight, one heading change
aircraft: "737"
initial: {lat_deg: 47.45, lon_deg: 8.55, alt_m: 3000, tas_kmh: 400, heading_deg: 90}
duration_s: 20
hold: true
events:
  - {t_s: 5, heading_deg: 120}
"""

STEP_SCENARIO = SHORT_SCENARIO.replace("name: fuzz-short", "name: fuzz-steps").replace(
    "one heading change", "one altitude step").replace(
    "  - {t_s: 5, heading_deg: 120}", "  - {t_s: 5, alt_m: 3050}")
"""The short flight with an altitude step instead of the turn (``compare`` measures steps)."""

BASES = {
    "run": ["run", "{scenario}", "--no-plots", "--out", "{new}"],
    "demo": ["demo", "--out", "{new}"],
    "inner": ["inner", "--aircraft", "737", "--out", "{new}"],
    "procedures build": ["procedures", "build", "--airport", "KBFI", "--out", "{new}"],
    "procedures check": ["procedures", "check", "--airports", "KBFI", "--no-progress", "--out",
                         "{new}"],
    "procedures list": ["procedures", "list", "--airport", "KBFI"],
    "fly": ["fly", "--scenario", "{scenario}", "--no-plots", "--out", "{new}"],
    "compare": ["compare", "{steps}", "--out", "{new}"],
    "analyse": ["analyse", "--aircraft", "737", "--out", "{new}"],
    "tune": ["tune", "--aircraft", "737", "--quick", "--out", "{new}"],
    "ins": ["ins", "straight", "--duration-s", "60", "--out", "{new}"],
    "imu-test": ["imu-test", "--duration-h", "0.02", "--out", "{new}"],
    "regress run": ["regress", "run", "--airports", "KBFI", "--limit", "1", "--no-progress",
                    "--out", "{new}"],
    "regress diff": ["regress", "diff", "{regress}", "{regress}"],
    "regress report": ["regress", "report", "{regress}"],
    "regress testdb": ["regress", "testdb", "--out", "{new}"],
    "montecarlo": ["montecarlo", "--runs", "2", "--duration-min", "1", "--fault-runs", "1",
                   "--out", "{new}"],
    "nav-replay": ["nav-replay", "--imu", "{file}", "--gnss", "{file}", "--init", "{file}",
                   "--out", "{new}"],
}
"""A fast valid line per command (``{name}``: a sandbox path); the fuzz changes one option."""


def _options(parser) -> list[argparse.Action]:
    return [a for a in parser._actions if a.option_strings and a.nargs != 0
            and not isinstance(a, argparse._HelpAction)]


@lru_cache(maxsize=1)
def _commands() -> list:
    return list(commands(build_parser()))


def draw(seed: int, paths: dict[str, Path]) -> tuple[str, list[str]]:
    """(command, argv) of fuzz run ``seed`` (module docstring)."""
    cmds = _commands()
    words, parser = cmds[seed % len(cmds)]
    name = " ".join(words)
    rng = random.Random(seed)
    fill = {k: str(v) for k, v in paths.items()}
    argv = [w.format(**fill) for w in BASES[name]]
    opts = _options(parser)
    action = rng.choice(opts)
    if rng.random() < 0.3:
        value = str(rng.choice(list(paths.values())))
    else:
        value = rng.choice(HOSTILE)
    flags = set(action.option_strings)
    for i, w in enumerate(argv):                 # replace the option's value if the base has it
        if w in flags:
            argv[i + 1] = value
            break
    else:
        argv += [action.option_strings[0], value]
    return name, argv


def _protected(paths: dict[str, Path]) -> dict[Path, bytes]:
    files = [paths["regress"] / "run.json", paths["regress"] / "flights" / "part-1-1-x.parquet",
             paths["mc"] / "run.json", paths["junk"] / "thesis.tex"]
    return {p: p.read_bytes() for p in files}


def one_run(seed: int, root: Path, case) -> tuple[str, str, str | None]:
    """Run fuzz line ``seed`` in its own sandbox: (command, outcome, failure or None)."""
    box = root / f"w{seed}"
    paths = _sandbox(box, case)
    (box / "short.yaml").write_text(SHORT_SCENARIO)
    paths["scenario"] = box / "short.yaml"
    (box / "steps.yaml").write_text(STEP_SCENARIO)
    paths["steps"] = box / "steps.yaml"
    name, argv = draw(seed, paths)
    before = _protected(paths)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO),
                                                       os.environ.get("PYTHONPATH", "")])}
    where = f"seed {seed}: {argv!r}"
    t0 = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "fms_testbed", *argv], cwd=box, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        _, err = proc.communicate(timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        paths["readonly"].chmod(0o700)
        return name, "hang", f"{where}: still running after {RUN_TIMEOUT_S:.0f} s"
    finally:
        wall = time.monotonic() - t0
    paths["readonly"].chmod(0o700)
    rc = proc.returncode
    fail = None
    if "Traceback" in err:
        fail = f"{where}: traceback\n{err[-1500:]}"
    elif rc not in (0, 1, 2):
        fail = f"{where}: exit {rc}\n{err[-800:]}"
    elif rc == 2 and len(err.strip().splitlines()) != 1:
        fail = f"{where}: exit 2 with {len(err.strip().splitlines())} lines\n{err[-800:]}"
    else:
        overwrite = "--overwrite" in argv
        for p, data in before.items():
            named = any(str(p).startswith(a) for a in argv if a.startswith(str(box)))
            if not (overwrite and named) and (not p.exists() or p.read_bytes() != data):
                fail = f"{where}: {p.relative_to(box)} changed or removed"
                break
    return name, f"rc{rc} ({wall:.0f} s)" if fail is None else "FAILED", fail


def fuzz(seeds, root: Path, case, jobs: int) -> tuple[Counter, list[str], Counter, float]:
    """Run the seeds over ``jobs`` processes: (outcomes, failures, runs per command, the
    longest run's wall time in s among those that ended)."""
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        results = list(pool.map(lambda s: one_run(s, root, case), seeds))
    outcomes = Counter(o.split(" ")[0] for _, o, _ in results)
    failures = [f for _, _, f in results if f]
    walls = [float(o.split("(")[1].split(" ")[0]) for _, o, _ in results if "(" in o]
    return outcomes, failures, Counter(n for n, _, _ in results), max(walls, default=0.0)


def test_every_command_has_a_base_and_each_line_changes_one_option(tmp_path):
    names = [" ".join(w) for w, _ in _commands()]
    assert set(names) == set(BASES), set(names) ^ set(BASES)
    paths = {k: tmp_path / k for k in ("file", "empty", "junk", "readonly", "link", "regress",
                                       "mc", "missing", "new", "yaml", "scenario", "steps")}
    drawn = Counter()
    for seed in range(3 * len(names)):
        name, argv = draw(seed, paths)
        drawn[name] += 1
        base = [w.format(**{k: str(v) for k, v in paths.items()}) for w in BASES[name]]
        changed = [i for i, (a, b) in enumerate(zip(argv, base)) if a != b]
        assert len(changed) <= 1 and len(argv) - len(base) in (0, 2), (seed, argv)
        assert argv != base, (seed, argv)
    assert set(drawn.values()) == {3}


def test_fuzz_work_quick(tmp_path, regress_case):
    outcomes, failures, by_cmd, _ = fuzz(QUICK_SEEDS, tmp_path, regress_case, 1)
    assert not failures, "\n".join(failures)
    assert set(by_cmd) == {"regress run"} and outcomes == {"rc2": 1}


@pytest.mark.slow
def test_fuzz_work(tmp_path, regress_case):
    n = int(os.environ.get("FUZZ_WORK_N", 3 * len(BASES)))
    jobs = int(os.environ.get("FUZZ_WORK_JOBS", 2))
    seed0 = int(os.environ.get("FUZZ_WORK_SEED0", 0))
    t0 = time.monotonic()
    outcomes, failures, by_cmd, longest_s = fuzz(range(seed0, seed0 + n), tmp_path,
                                                 regress_case, jobs)
    if os.environ.get("FUZZ_WORK_REPORT"):
        Path(os.environ["FUZZ_WORK_REPORT"]).write_text(json.dumps(
            {"runs": n, "seeds": [seed0, seed0 + n - 1], "jobs": jobs,
             "wall_s": round(time.monotonic() - t0), "longest_run_s": longest_s, **outcomes,
             "commands": by_cmd, "failures": failures}, indent=1))
    assert not failures, "\n".join(failures)
