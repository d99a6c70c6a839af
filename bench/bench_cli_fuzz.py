"""The seeded CLI fuzz at its large size (``tests/cli/test_cli_fuzz.py``, ``-m slow``): every
command and subcommand, arguments from the parser's definitions and hostile values, each run
ended where its work would begin. Writes ``docs/results/cli_fuzz.md``: the runs, their exit
codes, how many reached the work, the wall time, the runs per command, and every failure (none
is the goal: no traceback, exit codes 0/1/2, a 2 on one line, no hang, no folder that looks
complete when the run failed).

    python bench/bench_cli_fuzz.py [--md cli_fuzz.md] [--quick]

``--quick``: the default suite's small fuzz (``test_cli_fuzz_small``) instead of the large one.
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


def run_fuzz(quick: bool = False) -> dict:
    """Run the large fuzz test (``quick``: the small one) in a subprocess; its JSON report."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "fuzz.json"
        env = {**os.environ, "FUZZ_REPORT": str(out),
               "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
        res = subprocess.run([sys.executable, "-m", "pytest", "-q", *TESTS[quick]],
                             cwd=REPO, env=env, capture_output=True, text=True)
        if not out.exists():
            raise SystemExit(f"the fuzz wrote no report:\n{res.stdout[-2000:]}")
        return json.loads(out.read_text())


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
    args = ap.parse_args()
    r = run_fuzz(args.quick)
    refuse_degenerate({k: r.get(k, 0) for k in ("rc0", "rc1", "rc2", "work", "FAILED")},
                      what="cli fuzz", bad=("FAILED",))
    write(args.md, page(r))


if __name__ == "__main__":
    main()
