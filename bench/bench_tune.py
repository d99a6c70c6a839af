"""Envelope tuning of the coupled law for the 737 and the Global 5000: goals, margins, timing.

    python bench/bench_tune.py [--aircraft 737 global5000] [--workers 2] [--md tune_envelope.md]

Runs ``fms-testbed tune --aircraft NAME --envelope --workers N`` on the default grid of each
aircraft (12 design points: 4 envelope points × 2 masses clean, 2 approach speeds × 2 masses),
times it, records the load average, and writes ``docs/results/<md>`` (per aircraft: the goal
lines, the smallest margins, the nonlinear cross deviations with the schedule and with the file
gains, the robustness minima per member, the wall time) and the figures into
``docs/figures/tuning/`` (``<aircraft>-nichols.png``, ``-bode-worst.png``, ``-steps.png``,
``-schedule.png``) and ``linear-vs-jsbsim-<aircraft>.png`` (``analyse --plant jsbsim``, whose
``analysis.md`` is kept beside the runs). The tuned aircraft files are kept in ``--keep`` (default
``results/bench-tune``) for ``bench_tune_campaign.py``.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import sys
import time
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]


def machine() -> str:
    import jsbsim
    import numpy

    return (f"{os.cpu_count()} cores, Python {platform.python_version()}, JSBSim "
            f"{jsbsim.__version__}, numpy {numpy.__version__}")


def one(name: str, workers: int, keep: Path) -> tuple[str, float, tuple]:
    """Tune one aircraft; return its markdown section, wall time (s) and load average."""
    from fms_testbed.cli import main
    from fms_testbed.cli.common import markdown_table
    from fms_testbed.cli.tune_envelope import goal_lines

    out = keep / name
    t0 = time.perf_counter()
    rc = main(["tune", "--aircraft", name, "--envelope", "--workers", str(workers), "--out",
               str(out), "--overwrite"])
    wall = time.perf_counter() - t0
    load = os.getloadavg()
    df = pd.read_csv(out / "points.csv")
    goals = "\n".join(f"- {'PASS' if ok else 'FAIL'}: {t}" for ok, t in goal_lines(df))
    cols = ["alt_m", "tas_mps", "mass_kg", "config", "gm_min_db", "pm_min_deg", "disk_margin",
            "max_dv_kmh", "max_dh_m", "old_max_dv_kmh", "old_max_dh_m", "robust_pm_mass_lo_deg",
            "robust_pm_mass_hi_deg", "robust_pm_cg_fwd_deg", "robust_pm_cg_aft_deg",
            "robust_pm_delay_deg"]
    fig = ROOT / "docs" / "figures" / "tuning"
    fig.mkdir(parents=True, exist_ok=True)
    for f in ("nichols", "bode-worst", "steps", "schedule"):
        shutil.copy(out / f"{f}.png", fig / f"{name}-{f}.png")
    md = (f"### {name}\n\n`fms-testbed tune --aircraft {name} --envelope --workers {workers}`: "
          f"{wall:.0f} s wall (exit {rc}), load average at the end {load[0]:.1f} / {load[1]:.1f} "
          f"/ {load[2]:.1f}.\n\n{goals}\n\n{markdown_table(df[[c for c in cols if c in df]])}\n")
    return md, wall, load


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--aircraft", nargs="+", default=["737", "global5000"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--md", default="tune_envelope.md")
    ap.add_argument("--keep", default=str(ROOT / "results" / "bench-tune"))
    args = ap.parse_args()
    keep = Path(args.keep)
    from fms_testbed.cli import main as cli

    for name in args.aircraft:         # the linearisation checked against the nonlinear model
        cli(["analyse", "--aircraft", name, "--plant", "jsbsim", "--out",
             str(keep / f"analyse-{name}"), "--overwrite"])
        fig = ROOT / "docs" / "figures" / "tuning"
        fig.mkdir(parents=True, exist_ok=True)
        shutil.copy(keep / f"analyse-{name}" / "linear-vs-jsbsim.png",
                    fig / f"linear-vs-jsbsim-{name}.png")
    parts, total = [], 0.0
    for name in args.aircraft:
        md, wall, _ = one(name, args.workers, keep)
        parts.append(md)
        total += wall
    head = ("<!-- written by python bench/bench_tune.py; rerun it to refresh, do not edit by hand -->"
            f"\n\nCommand: `python bench/bench_tune.py{' ' + ' '.join(sys.argv[1:]) if sys.argv[1:] else ''}`  \n"
            f"Machine: {machine()}; other sessions were running on the same cores (load average "
            f"in each section).\n\nColumns: margins are the smallest over the six broken loops "
            "(dB, deg, disk margin α) with the scheduled gains; `max_dv_kmh`/`max_dh_m` are the "
            "nonlinear JSBSim cross deviations (+100 m step, +10 % TAS step) with the schedule, "
            "`old_*` with the aircraft file's gains; `robust_pm_*` the smallest phase margin "
            "under mass −10 %/+10 %, CG 0.2 m forward/aft, 0.1 s delay at every actuator.\n\n"
            f"Both aircraft: {total:.0f} s wall.\n\n")
    (ROOT / "docs" / "results" / args.md).write_text(head + "\n".join(parts))
    print(head + "\n".join(parts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
