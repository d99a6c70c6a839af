"""The seeded CLI fuzz at its large size (``tests/cli/test_cli_fuzz.py``, ``-m slow``): every
command and subcommand, arguments from the parser's definitions and hostile values, each run
ended where its work would begin. Writes ``docs/results/cli_fuzz.md``: the runs, their exit
codes, how many reached the work, the wall time, the runs per command, and every failure (none
is the goal: no traceback, exit codes 0/1/2, a 2 on one line, no hang, no folder that looks
complete when the run failed).

    python bench/bench_cli_fuzz.py [--md cli_fuzz.md] [--quick]
    python bench/bench_cli_fuzz.py --work [--runs 500] [--seed0 0] [--jobs 2]
    python bench/bench_cli_fuzz.py --work --from A.json B.json

``--quick``: the default suite's small fuzz (``test_cli_fuzz_small``) instead of the large one.
``--work``: the fuzz with the commands' real work (``tests/cli/test_cli_fuzz_work.py``, nothing
stubbed, a subprocess per run with its 300 s timeout) into ``cli_fuzz_work.md``; ``--from``
joins the reports of runs over disjoint seed ranges (``FUZZ_WORK_REPORT`` of the slow test)
instead of running it.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from report import REPO, refuse_degenerate, table, write  # noqa: E402

TESTS = {False: ("-m", "slow", "tests/cli/test_cli_fuzz.py::test_cli_fuzz_large"),
         True: ("tests/cli/test_cli_fuzz.py::test_cli_fuzz_small",)}
"""The pytest arguments of the large fuzz and of the small one (``--quick``)."""


WORK_TEST = ("-m", "slow", "-n", "0", "tests/cli/test_cli_fuzz_work.py::test_fuzz_work")
"""The pytest arguments of the fuzz with real work (one process: the test runs its own jobs)."""


def run_fuzz(quick: bool = False, work: dict | None = None) -> dict:
    """Run the large fuzz test (``quick``: the small one; ``work``: the fuzz with real work,
    ``{"runs", "seed0", "jobs"}``) in a subprocess; its JSON report."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "fuzz.json"
        env = {**os.environ, "FUZZ_REPORT": str(out), "FUZZ_WORK_REPORT": str(out),
               "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
        args = TESTS[quick]
        if work is not None:
            args = WORK_TEST
            env.update(FUZZ_WORK_N=str(work["runs"]), FUZZ_WORK_SEED0=str(work["seed0"]),
                       FUZZ_WORK_JOBS=str(work["jobs"]))
        res = subprocess.run([sys.executable, "-m", "pytest", "-q", *args],
                             cwd=REPO, env=env, capture_output=True, text=True)
        if not out.exists():
            raise SystemExit(f"the fuzz wrote no report:\n{res.stdout[-2000:]}")
        return json.loads(out.read_text())


def join(reports: list[dict]) -> dict:
    """One report of fuzz runs over disjoint seed ranges: counts summed, seeds as ranges."""
    ranges = sorted(tuple(r["seeds"]) for r in reports)
    for (_, hi), (lo, _) in zip(ranges, ranges[1:]):
        if lo <= hi:
            raise SystemExit(f"the reports' seed ranges overlap: {ranges}")
    out: dict = {"runs": sum(r["runs"] for r in reports), "ranges": ranges,
                 "seeds": [ranges[0][0], ranges[-1][1]], "failures": [], "commands": {},
                 "wall_s": sum(r["wall_s"] for r in reports),
                 "longest_run_s": max(r.get("longest_run_s", 0.0) for r in reports)}
    for r in reports:
        for k in ("rc0", "rc1", "rc2", "work", "hang", "FAILED"):
            out[k] = out.get(k, 0) + r.get(k, 0)
        for k, v in r["commands"].items():
            out["commands"][k] = out["commands"].get(k, 0) + v
        out["failures"] += r["failures"]
    return out


def work_page(r: dict) -> str:
    """The results page of the fuzz with real work (one or joined reports)."""
    ranges = ", ".join(f"{a}-{b}" for a, b in r.get("ranges", [tuple(r["seeds"])]))
    rows = [("runs (seeds)", f"{r['runs']} ({ranges})"),
            ("exit 2 (refused, one line)", r.get("rc2", 0)), ("exit 0", r.get("rc0", 0)),
            ("exit 1", r.get("rc1", 0)), ("hangs (over 300 s)", r.get("hang", 0)),
            ("failures (traceback, other exit, 2 lines, hang, another run damaged)",
             f"**{r.get('FAILED', 0) + r.get('hang', 0)}**"),
            ("longest run, s", f"{r.get('longest_run_s', 0):.0f}"),
            ("wall time, s (sum over the reports)", r["wall_s"])]
    body = [table(("quantity", "measured"), rows), "",
            "Runs per command: " + ", ".join(f"`{k}` {v}" for k, v in
                                              sorted(r["commands"].items()))]
    if r.get("failures"):
        body += ["", "Failures:", ""] + [f"- `{f.splitlines()[0]}`" for f in r["failures"]]
    return "\n".join(body)


def page(r: dict) -> str:
    """The results page of one fuzz report."""
    n = r["runs"]
    rows = [("runs (seeds)", f"{n} ({r['seeds'][0]}-{r['seeds'][1]})"),
            ("exit 2 (refused, one line)", r.get("rc2", 0)), ("exit 0", r.get("rc0", 0)),
            ("exit 1", r.get("rc1", 0)), ("reached the start of the work", r.get("work", 0)),
            ("failures (traceback, other exit, 2 lines, hang, complete-looking folder)",
             f"**{r.get('FAILED', 0)}**"),
            ("wall time, s", r["wall_s"])]
    body = [table(("quantity", "measured"), rows), "",
            "Runs per command: " + ", ".join(f"`{k}` {v}" for k, v in
                                              sorted(r["commands"].items()) if k != "?")]
    if r.get("failures"):
        body += ["", "Failures:", ""] + [f"- `{f}`" for f in r["failures"]]
    return "\n".join(body)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--md", default="cli_fuzz.md", help="results file (default cli_fuzz.md)")
    report.add_quick(ap, "the small fuzz of the default suite")
    ap.add_argument("--work", action="store_true",
                    help="the fuzz with the commands' real work (cli_fuzz_work.md)")
    ap.add_argument("--runs", type=int, default=500, help="with --work: fuzz lines (500)")
    ap.add_argument("--seed0", type=int, default=0, help="with --work: first seed (0)")
    ap.add_argument("--jobs", type=int, default=2, help="with --work: parallel runs (2)")
    ap.add_argument("--from", dest="reports", nargs="+", metavar="REPORT.json",
                    help="with --work: join these reports instead of running the fuzz")
    args = ap.parse_args()
    if args.work:
        if args.quick:
            args.runs = 18
        r = (join([json.loads(Path(f).read_text()) for f in args.reports]) if args.reports
             else run_fuzz(work={"runs": args.runs, "seed0": args.seed0, "jobs": args.jobs}))
        md = "cli_fuzz_work.md" if args.md == "cli_fuzz.md" else args.md
        write(md, work_page(r))
        if r.get("FAILED", 0) or r.get("hang", 0):
            raise SystemExit(f"{r.get('FAILED', 0)} failed fuzz runs (listed in {md})")
        return
    r = run_fuzz(args.quick)
    refuse_degenerate({k: r.get(k, 0) for k in ("rc0", "rc1", "rc2", "work", "FAILED")},
                      what="cli fuzz", bad=("FAILED",))
    write(args.md, page(r))


if __name__ == "__main__":
    main()
