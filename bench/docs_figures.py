"""Regenerate the figures in ``docs/figures/`` that come from the CLI, each from the command
that makes it (nothing drawn by hand, nothing kept from an older version of the code).

    python bench/docs_figures.py [--only NAME ...] [--list]

Each entry of :data:`FIGURES` is (figure in ``docs/figures``, the ``fms-testbed`` command, the
PNG that command writes into its ``--out`` folder). The command runs into a temporary folder
and the PNG is copied into place; a command that fails stops the script with its output (exit
1) and leaves the old figure where it was.

The other figures have their own scripts: ``navigation/flight_test_attitude.png``
(``bench/flight_test_attitude.py``), ``navigation/ins_drift_x2.png`` / ``ins_drift_x10.png``
(``bench/plot_refdesc.py``), ``fly/takeoff_start.png`` (``bench/takeoff_start.py``),
``regression/*`` (``bench/integration_page.py``, from the two integration runs).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FIG = report.FIGURES
SCN = ROOT / "scenarios"

FIGURES: list[tuple[str, list[str], str]] = [
    ("fly/demo-sid-track.png", ["demo"], "procedure_track.png"),
    ("fly/demo-sid-vertical.png", ["demo"], "procedure_vertical.png"),
    ("fly/demo-sid-errors.png", ["demo"], "procedure_errors.png"),
    ("procedures/pafa-rf.png", ["procedures", "build", "--airport", "PAFA", "--procedure",
                                "H02LZ", "--transition", "GLDHL"], "PAFA_APP_H02LZ_GLDHL.png"),
    ("procedures/pabe-missed.png", ["procedures", "build", "--airport", "PABE", "--procedure",
                                    "I19RZ", "--transition", ""], "PABE_APP_I19RZ.png"),
    ("sins/hg9900-p95.png", ["ins", "synthetic:straight", "--imu", "HG9900",
                             "--table-every-s", "900"], "ins_p95.png"),
    ("coupled-law/paper-fig2.png", ["compare", str(SCN / "paper-fig2.yaml"), "--paper-plot"],
     "paper-fig2-paper-fig2.png"),
    ("coupled-law/altitude-step-comparison.png",
     ["compare", str(SCN / "coupled-altitude-step.yaml")],
     "coupled-altitude-step-comparison.png"),
    ("coupled-law/bode.png", ["analyse", "--aircraft", "737"], "bode.png"),
    ("coupled-law/tuned-vs-linear-737.png", ["tune", "--aircraft", "737", "--max-evals", "30"],
     "tuned-vs-linear.png"),
]
"""(figure, command, the PNG the command writes)."""


def regenerate(only: set[str] | None = None) -> int:
    """Run the commands (each once, shared by the figures it makes) and copy the PNGs;
    returns the number of figures written."""
    runs: dict[tuple[str, ...], Path] = {}
    n = 0
    with tempfile.TemporaryDirectory(prefix="docs-figures-") as tmp:
        for dest, cmd, png in FIGURES:
            if only and dest not in only and Path(dest).stem not in only:
                continue
            key = tuple(cmd)
            if key not in runs:
                out = Path(tmp) / f"run{len(runs)}"
                t0 = time.perf_counter()
                p = subprocess.run([sys.executable, "-m", "fms_testbed", *cmd, "--out", str(out)],
                                   capture_output=True, text=True, cwd=tmp)
                # compare exits 1 when a goal fails: its figures are still the measurement
                if p.returncode not in (0, 1) or not out.exists():
                    sys.stderr.write(f"fms-testbed {' '.join(cmd)} failed "
                                     f"(exit {p.returncode}):\n{p.stdout[-2000:]}"
                                     f"{p.stderr[-2000:]}")
                    raise SystemExit(1)
                print(f"fms-testbed {' '.join(cmd)}: {time.perf_counter() - t0:.0f} s")
                runs[key] = out
            src = runs[key] / png
            if not src.exists():
                sys.stderr.write(f"{' '.join(cmd)} wrote no {png} (has: "
                                 f"{', '.join(sorted(x.name for x in runs[key].iterdir()))})\n")
                raise SystemExit(1)
            (FIG / dest).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, FIG / dest)
            print(f"  -> docs/figures/{dest}")
            n += 1
    return n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", help="figures to make (path under docs/figures or stem)")
    ap.add_argument("--list", action="store_true", help="list the figures and their commands")
    report.add_quick(ap, "the two `procedures build` figures only")
    a = ap.parse_args()
    if a.quick:
        a.only = ["pafa-rf", "pabe-missed"]
    if a.list:
        for dest, cmd, png in FIGURES:
            print(f"{dest}: fms-testbed {' '.join(cmd)} --out DIR  ({png})")
        return
    n = regenerate(set(a.only) if a.only else None)
    print(f"{n} figures written")


if __name__ == "__main__":
    main()
