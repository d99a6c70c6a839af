"""Seeded CLI fuzz over every command and subcommand: arguments drawn from the parser's own
definitions (options, choices, nargs, positionals) mixed with hostile values — 0, negative, NaN,
inf, 1e9, 2**70, empty, unicode, and paths that are files, symlinks, read-only or foreign
folders, another kind of run. Every run must end with a documented exit code (0, 1, 2; a 2
with one line on stderr), no traceback, no hang, and no output folder that looks complete when
the run did not succeed.

What is fuzzed is the command line up to the start of the work: the functions that fly,
simulate or fly a campaign are replaced by a sentinel (:class:`Work`) that ends the run where
the work would begin, so every run takes a fraction of a second and "validated before any work"
is what is checked (the work itself is tested by each command's own tests). The default suite
runs :data:`SMALL` runs; ``pytest -m slow`` runs :data:`LARGE`; every run is reproducible from
its seed (printed on failure). ``FUZZ_REPORT=FILE`` writes the counts as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import time
from collections import Counter
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from fms_testbed.cli import build_parser, main

SMALL = 60
LARGE = 600
RUN_LIMIT_S = 20.0
"""A run that takes longer is a hang (each one stops at the start of the work)."""


class Work(BaseException):
    """Raised where a command's work would begin (not an Exception: nothing catches it)."""


WORK = [   # a lazy re-export before its source: its saved value must be the real function
    ("fms_testbed.run", "run_scenario"), ("fms_testbed.run.api", "run_scenario"),
    ("fms_testbed.loop.flight.Flight", "__init__"),
    ("fms_testbed.campaign.runner", "run_local"), ("fms_testbed.campaign.runner", "run_dask"),
    ("fms_testbed.sensors.mems.static_test", "run_static_test"),
    ("fms_testbed.evaluation.montecarlo", "run_campaign"),
    ("fms_testbed.evaluation.check", "run_check"),
    ("fms_testbed.evaluation.law_comparison", "run_comparison"),
    ("fms_testbed.evaluation.law_tuning", "tune"),
    ("fms_testbed.evaluation.law_tuning", "identify_lags"),
    ("fms_testbed.sensors.sins.analysis", "covariance_run"),
    ("fms_testbed.sensors.sins.analysis", "montecarlo_run"),
]


def _stub(*args, **kwargs):
    raise Work


@pytest.fixture
def work_stubbed(monkeypatch):
    """Every work function replaced by :func:`_stub` for the test. The whole package is imported
    first, so no module imported during the fuzz keeps a stub under its own name afterwards."""
    import importlib
    import pkgutil

    import fms_testbed

    for m in pkgutil.walk_packages(fms_testbed.__path__, "fms_testbed."):
        if not m.name.endswith("__main__"):
            importlib.import_module(m.name)
    for name in getattr(fms_testbed, "__all__", ()):      # lazy exports resolved now
        getattr(fms_testbed, name)
    for mod, name in WORK:
        head, _, tail = mod.rpartition(".")
        try:
            target = importlib.import_module(mod)
        except ModuleNotFoundError:
            target = getattr(importlib.import_module(head), tail)
        monkeypatch.setattr(target, name, _stub)


def commands(parser=None, path=()):
    """(words, leaf parser) of every command and subcommand, from the parser's definitions."""
    parser = parser or build_parser()
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield list(path), parser
        return
    for s in subs:
        for name, sp in s.choices.items():
            yield from commands(sp, (*path, name))


HOSTILE = ["0", "-1", "-0.5", "nan", "inf", "-inf", "1e9", "1e-9", str(2 ** 70), "", " ",
           "Ω✈ü", "x" * 300, "../..", "1,2,", "270/", "tcp://", "\t"]


def _sandbox(root: Path, case) -> dict[str, Path]:
    """Paths a run may be given: a file, a symlink, an empty, read-only and foreign folder, a
    regression run and a montecarlo run (fresh for every run)."""
    root.mkdir()
    (root / "afile.txt").write_text("not a database\n")
    (root / "empty").mkdir()
    (root / "junk").mkdir()
    (root / "junk" / "thesis.tex").write_text("precious")
    ro = root / "readonly"
    ro.mkdir()
    ro.chmod(0o500)
    (root / "link").symlink_to(root / "empty", target_is_directory=True)
    reg = root / "regress"
    reg.mkdir()
    (reg / "run.json").write_text(json.dumps(case["run"]))
    (reg / "flights").mkdir()
    pq.write_table(case["plan"], reg / "plan.parquet")
    pq.write_table(case["part"], reg / "flights" / "part-1-1-x.parquet")
    mc = root / "mc"
    mc.mkdir()
    (mc / "run.json").write_text(json.dumps({"tool": "fms-testbed", "kind": "montecarlo"}))
    (mc / "timeseries.parquet").write_text("not parquet")
    (root / "bad.yaml").write_text("a: [1, 2\n")
    return {"file": root / "afile.txt", "empty": root / "empty", "junk": root / "junk",
            "readonly": ro, "link": root / "link", "regress": reg, "mc": mc,
            "missing": root / "nope" / "deeper", "new": root / "new-out",
            "yaml": root / "bad.yaml"}


def _value(rng: random.Random, action, paths: dict) -> str:
    pathish = any(k in (action.dest or "") for k in ("out", "db", "dir", "run", "file",
                                                      "scenario", "trajectory", "markdown",
                                                      "tolerance", "conditions", "others",
                                                      "profile", "imu", "aircraft"))
    r = rng.random()
    if action.choices and r < 0.6:
        return str(rng.choice(list(action.choices)))
    if pathish and r < 0.75:
        return str(rng.choice(list(paths.values())))
    if action.default not in (None, False, True, argparse.SUPPRESS) and r < 0.85:
        return str(action.default)
    return rng.choice(HOSTILE)


def random_argv(rng: random.Random, words: list[str], parser, paths: dict) -> list[str]:
    """A command line for ``words`` built from the parser's actions (module docstring)."""
    argv = list(words)
    for a in parser._actions:
        if isinstance(a, (argparse._HelpAction, argparse._VersionAction)):
            continue
        if not a.option_strings:                         # a positional
            n = 2 if a.nargs in ("+", "*") and rng.random() < 0.3 else 1
            argv += [_value(rng, a, paths) for _ in range(n)]
            continue
        if not (a.required or rng.random() < 0.35):
            continue
        opt = rng.choice(a.option_strings)
        if a.nargs == 0:
            argv.append(opt)
        else:
            n = rng.choice([1, 1, 2]) if a.nargs in ("+", "*") else 1
            argv += [opt] + [_value(rng, a, paths) for _ in range(n)]
    if rng.random() < 0.05:
        argv.append(rng.choice(["--no-such-option", "extra-word"]))
    return argv


def _run_jsons(root: Path) -> dict[Path, bytes]:
    out = {}
    for p in root.rglob("run.json"):
        try:
            out[p] = p.read_bytes()
        except OSError:
            pass
    return out


def _looks_complete(data: bytes) -> bool:
    try:
        info = json.loads(data)
    except ValueError:
        return False
    return isinstance(info, dict) and info.get("status", "complete") != "running"


def one_run(seed: int, root: Path, case, capsys, monkeypatch) -> tuple[str, str]:
    """Fuzz one command line; return its outcome ('rc0', 'rc1', 'rc2' or 'work') and
    command."""
    rng = random.Random(seed)
    cmds = list(commands())
    words, parser = cmds[rng.randrange(len(cmds))]
    box = root / f"s{seed}"
    paths = _sandbox(box, case)
    monkeypatch.chdir(box)
    argv = random_argv(rng, words, parser, paths)
    before = _run_jsons(box)
    t0 = time.monotonic()
    try:
        rc = main(argv)
        outcome = f"rc{rc}"
    except SystemExit as exc:                            # argparse: exit 2, one line
        rc, outcome = exc.code, f"rc{exc.code}"
    except Work:
        rc, outcome = None, "work"
    wall = time.monotonic() - t0
    err = capsys.readouterr().err
    where = f"seed {seed}: {argv!r}"
    assert "Traceback" not in err, f"{where}\n{err[-3000:]}"
    assert rc in (0, 1, 2, None), f"{where}: exit {rc}\n{err[-1000:]}"
    if rc == 2:
        assert len(err.strip().splitlines()) == 1, f"{where}\n{err}"
    assert wall < RUN_LIMIT_S, f"{where}: {wall:.1f} s"
    if rc != 0:
        for p, data in _run_jsons(box).items():
            if before.get(p) != data:
                assert not _looks_complete(data), f"{where}: {p} looks complete"
    if not ("--overwrite" in argv and str(paths["regress"]) in argv):
        assert (paths["regress"] / "flights" / "part-1-1-x.parquet").exists(), where
    assert (paths["junk"] / "thesis.tex").exists(), where
    paths["readonly"].chmod(0o700)
    return outcome, " ".join(words)


@pytest.fixture(scope="module")
def regress_case():
    """run.json, plan and one part of a one-case regression run (a real case's row)."""
    import pyarrow as pa

    from fms_testbed.campaign.audit import PLAN_COLUMNS, PLAN_SCHEMA
    from fms_testbed.campaign.cases import aircraft_files, enumerate_cases
    from fms_testbed.campaign.conditions import command_line_sets
    from fms_testbed.campaign.rows import failed_row, table
    from fms_testbed.procedures.index import load_index

    ix = load_index(None)
    c = enumerate_cases(ix, ["KBFI"], ["D"], aircraft_files(["737"]),
                        command_line_sets([None], [{"source": "truth"}]))[0]
    plan = pa.table({k: [str(getattr(c, k) if k != "conditions" else c.conditions.name)]
                     for k in PLAN_COLUMNS}, schema=PLAN_SCHEMA)
    run = {"tool": "fms-testbed", "kind": "regress-run", "status": "complete",
           "database": {"path": str(ix.path), "sha256": ix.sha256},
           "cases": {"count": 1, "set_sha256": "x"}, "sessions": []}
    return {"run": run, "plan": plan, "part": table([failed_row(c, "impossible", "fuzz")])}


def _fuzz(n: int, seed0: int, tmp_path, regress_case, capsys, monkeypatch) -> Counter:
    counts: Counter = Counter()
    by_cmd: Counter = Counter()
    t0 = time.monotonic()
    failures = []
    for seed in range(seed0, seed0 + n):
        try:
            outcome, cmd = one_run(seed, tmp_path, regress_case, capsys, monkeypatch)
        except AssertionError as exc:
            failures.append(str(exc).splitlines()[0][:400])
            outcome, cmd = "FAILED", "?"
        counts[outcome] += 1
        by_cmd[cmd] += 1
    counts["wall_s"] = round(time.monotonic() - t0)
    if os.environ.get("FUZZ_REPORT"):
        Path(os.environ["FUZZ_REPORT"]).write_text(json.dumps(
            {"runs": n, "seeds": [seed0, seed0 + n - 1], **counts, "commands": by_cmd,
             "failures": failures}, indent=1))
    assert not failures, "\n".join(failures)
    return counts


def test_every_command_is_reachable():
    words = {" ".join(w) for w, _ in commands()}
    assert {"fly", "imu-test", "montecarlo", "regress run", "regress diff", "regress report",
            "regress testdb", "run", "procedures check"} <= words


def test_cli_fuzz_small(tmp_path, regress_case, capsys, monkeypatch, work_stubbed):
    counts = _fuzz(SMALL, 0, tmp_path, regress_case, capsys, monkeypatch)
    assert counts["rc2"] > 0


@pytest.mark.slow
def test_cli_fuzz_large(tmp_path, regress_case, capsys, monkeypatch, work_stubbed):
    counts = _fuzz(LARGE, 10_000, tmp_path, regress_case, capsys, monkeypatch)
    assert counts["rc2"] > 0 and counts["work"] > 0
