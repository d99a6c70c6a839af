"""Writing a benchmark's figures as a Markdown table into ``docs/results/`` (included by the docs).

Every measured figure in the documentation comes from one of these files, and each file says
the command that wrote it and the machine it ran on (cores and CPU model, no date): rerun the
command to refresh it. Ratios are measured interleaved within one run, so they stay comparable
on a shared machine; absolute times move with the load.
"""

from __future__ import annotations

import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterable, Sequence

REPO = Path(__file__).resolve().parents[1]
#: where the pages go: ``docs/results/``, or the folder in ``$FMS_BENCH_RESULTS`` (the quick-mode
#: test points it at a temporary folder, so a quick run never overwrites a published page)
RESULTS = Path(os.environ.get("FMS_BENCH_RESULTS") or REPO / "docs" / "results")
#: where the reference figures go: ``docs/figures/``, or ``$FMS_BENCH_FIGURES``
FIGURES = Path(os.environ.get("FMS_BENCH_FIGURES") or REPO / "docs" / "figures")
#: the FAA CIFP beside the repository (``../shared/data/cifp``); every CIFP bench defaults to it
CIFP = REPO.parent / "shared" / "data" / "cifp" / "FAACIFP18_230126"


def add_quick(ap, what: str) -> None:
    """Add ``--quick`` to a bench's parser: the smallest run that exercises every code path of
    the bench and writes its page(s) (``what``: what the quick run does, for the help text).
    Quick figures are not the published ones: run it with ``$FMS_BENCH_RESULTS`` pointing
    elsewhere (``tests/bench/test_benches_quick.py`` does)."""
    ap.add_argument("--quick", action="store_true",
                    help=f"quick mode, a smoke run of the bench: {what}")


def machine() -> str:
    """Cores, CPU model and the versions that matter, without a date."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    bits = [f"{os.cpu_count()} cores ({model})", f"Python {platform.python_version()}"]
    try:
        import jsbsim

        bits.append(f"JSBSim {jsbsim.__version__}")
    except ImportError:
        pass
    import numpy

    bits.append(f"numpy {numpy.__version__}")
    return ", ".join(bits)


def command() -> str:
    """The command line that ran this script, relative to the repository."""
    script = Path(sys.argv[0]).resolve()
    try:
        script = script.relative_to(REPO)
    except ValueError:
        pass
    return " ".join(["python", str(script), *map(shlex.quote, sys.argv[1:])])


def table(header: Sequence[str], rows: Iterable[Sequence]) -> str:
    """A Markdown table (cells are str()-ed; pipes escaped)."""
    def cell(v) -> str:
        return str(v).replace("|", "\\|")

    out = ["| " + " | ".join(map(cell, header)) + " |",
           "|" + "---|" * len(header)]
    out += ["| " + " | ".join(map(cell, r)) + " |" for r in rows]
    return "\n".join(out)


class DegenerateRun(SystemExit):
    """A bench run whose outcome cannot be published (:func:`refuse_degenerate`)."""


def refuse_degenerate(outcomes=None, headline: float | None = None, what: str = "run",
                      bad: Sequence[str] = ("impossible", "error", "timeout",
                                            "internal-error")) -> None:
    """The one guard of every bench: stop (exit with the reason, no page written) when the run
    is degenerate — no outcome at all (no transitions, no flights), every outcome a failure
    (``bad``: everything ``impossible``), or a headline figure that is NaN or infinite.

    Parameters
    ----------
    outcomes : mapping outcome → count (statuses of the transitions or flights), or None
    headline : the figure the page leads with (a ratio, a time, a rate), or None
    what : what ran, for the message
    bad : the outcomes that count as failures
    """
    import math

    if outcomes is not None:
        n = sum(outcomes.values())
        if n == 0:
            raise DegenerateRun(f"{what}: no outcome at all (nothing ran): no page written")
        if sum(v for k, v in outcomes.items() if k in bad) == n:
            raise DegenerateRun(f"{what}: every one of its {n} outcomes is a failure "
                                f"({dict(outcomes)}): no page written")
    if headline is not None and not math.isfinite(headline):
        raise DegenerateRun(f"{what}: the headline figure is {headline}: no page written")


def _nan_cells(body: str) -> list[str]:
    """Table rows of ``body`` with a cell that is NaN (a figure that was not measured)."""
    out = []
    for line in body.splitlines():
        if line.startswith("|"):
            cells = [c.strip().strip("*").lower() for c in line.strip("|").split("|")]
            if any(c in ("nan", "nan %", "nan s", "nan x", "nan ×") or c.startswith("nan ")
                   for c in cells):
                out.append(line)
    return out


def write(name: str | Path | None, body: str, note: str = "") -> Path | None:
    """Write ``docs/results/NAME`` (or the given path): provenance lines, then ``body``.

    ``name`` None or empty: write nothing (``--md ''`` on a bench's command line). A body
    with a NaN figure in a table is refused (:class:`DegenerateRun`): every bench writes
    through here, so none publishes a figure it did not measure.
    """
    if not name:
        return None
    bad = _nan_cells(body)
    if bad:
        raise DegenerateRun(f"{name}: {len(bad)} table row(s) with a NaN figure, e.g. "
                            f"{bad[0][:120]!r}: no page written")
    path = Path(name)
    if not path.is_absolute() and path.parent == Path("."):
        path = RESULTS / path
    path.parent.mkdir(parents=True, exist_ok=True)
    head = (f"<!-- written by {command()}; rerun it to refresh, do not edit by hand -->\n\n"
            f"Command: `{command()}`  \nMachine: {machine()}.\n\n")
    path.write_text(head + (note.strip() + "\n\n" if note else "") + body.strip() + "\n")
    print(f"table written to {path}")
    return path


def run_cli(argv: Sequence[str], expect: Path | None = None, ok_codes=(0,)) -> tuple[int, float, str]:
    """Run ``fms-testbed ARGV`` (this Python's package); return (exit code, wall s, stdout).

    Stops the bench with the command's stderr when the exit code is not in ``ok_codes`` or the
    file ``expect`` was not written (a crash exits 1 too, like a failed goal).
    """
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "fms_testbed.cli", *argv],
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode not in ok_codes or (expect is not None and not Path(expect).exists()):
        raise SystemExit(f"fms-testbed {' '.join(argv)} failed ({proc.returncode}):\n"
                         f"{proc.stderr[-2000:]}")
    return proc.returncode, wall, proc.stdout
