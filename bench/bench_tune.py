"""Envelope tuning of the coupled law for the 737 and the Global 5000: goals, margins, timing.

    python bench/bench_tune.py [--aircraft 737 global5000] [--workers 2] [--md tune_envelope.md]
                               [--grid FILE.yaml] [--keep DIR] [--quick]

Runs ``fms-testbed tune --aircraft NAME --envelope --workers N`` on the default grid of each
aircraft (12 design points: 4 envelope points × 2 masses clean, 2 approach speeds × 2 masses),
times it, records the load average, and writes ``docs/results/<md>`` (per aircraft: the goal
lines, the smallest margins, the nonlinear cross deviations with the schedule and with the file
gains, the robustness minima per member, the wall time) and the figures into
``docs/figures/tuning/`` (``<aircraft>-nichols.png``, ``-bode-worst.png``, ``-steps.png``,
``-schedule.png``) and ``linear-vs-jsbsim-<aircraft>.png`` (``analyse --plant jsbsim``, whose
``analysis.md`` is kept beside the runs). The tuned aircraft files are kept in ``--keep`` (default
``results/bench-tune``) for ``bench_tune_campaign.py``. ``--grid``: ``tune --envelope --grid``'s
design points instead of the default grid. ``--quick``: the 737 on the three points of
:data:`QUICK_GRID`, kept in ``results/quick/bench-tune``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import time
from pathlib import Path

import pandas as pd
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

ROOT = report.REPO
QUICK_GRID = [{"alt_m": 1000.0, "tas_mps": 105.0}, {"alt_m": 3000.0, "tas_mps": 111.1},
              {"alt_m": 6000.0, "tas_mps": 150.0}]
"""The design points of a quick run (m, m/s; the aircraft's loaded mass, clean): the fewest a
schedule can be fitted to."""


def write_quick_grid(folder: Path) -> Path:
    """Write :data:`QUICK_GRID` as a ``tune --envelope --grid`` file into ``folder``; its path."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "quick-grid.yaml"
    path.write_text(yaml.safe_dump({"points": QUICK_GRID}))
    return path


def one(name: str, workers: int, keep: Path, grid: str | None = None
        ) -> tuple[str, float, tuple]:
    """Tune one aircraft (on the design points of the file ``grid``, default grid if None);
    return its markdown section, wall time (s) and load average."""
    from fms_testbed.cli import main
    from fms_testbed.cli.common import markdown_table
    from fms_testbed.cli.tune_envelope import goal_lines

    out = keep / name
    t0 = time.perf_counter()
    rc = main(["tune", "--aircraft", name, "--envelope", "--workers", str(workers), "--out",
               str(out), "--overwrite", *(["--grid", grid] if grid else [])])
    wall = time.perf_counter() - t0
    load = os.getloadavg()
    df = pd.read_csv(out / "points.csv")
    goals = "\n".join(f"- {'PASS' if ok else 'FAIL'}: {t}" for ok, t in goal_lines(df))
    cols = ["alt_m", "tas_mps", "mass_kg", "config", "gm_min_db", "pm_min_deg", "disk_margin",
            "max_dv_kmh", "max_dh_m", "old_max_dv_kmh", "old_max_dh_m", "ps_max_mps",
            "ps_step_mps", "dv_energy_kmh", "robust_pm_mass_lo_deg",
            "robust_pm_mass_hi_deg", "robust_pm_cg_fwd_deg", "robust_pm_cg_aft_deg",
            "robust_pm_delay_deg"]
    fig = report.FIGURES / "tuning"
    fig.mkdir(parents=True, exist_ok=True)
    for f in ("nichols", "bode-worst", "steps", "schedule"):
        shutil.copy(out / f"{f}.png", fig / f"{name}-{f}.png")
    on = f" --grid {Path(grid).name}" if grid else ""
    md = (f"### {name}\n\n`fms-testbed tune --aircraft {name} --envelope{on} --workers {workers}`: "
          f"{wall:.0f} s wall (exit {rc}), load average at the end {load[0]:.1f} / {load[1]:.1f} "
          f"/ {load[2]:.1f}.\n\n{goals}\n\n{markdown_table(df[[c for c in cols if c in df]])}\n")
    return md, wall, load


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--aircraft", nargs="+", default=["737", "global5000"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--md", default="tune_envelope.md")
    ap.add_argument("--keep", default=None,
                    help="folder for the runs (default results/bench-tune, quick: "
                         "results/quick/bench-tune)")
    ap.add_argument("--grid", default=None, help="design points (tune --envelope --grid)")
    report.add_quick(ap, "the 737 on three design points")
    args = ap.parse_args()
    if args.quick:
        args.aircraft = ["737"]
    keep = Path(args.keep or ROOT / "results" / ("quick" if args.quick else "") / "bench-tune")
    if args.quick and not args.grid:
        args.grid = str(write_quick_grid(keep))
    from fms_testbed.cli import main as cli

    for name in args.aircraft:         # the linearisation checked against the nonlinear model
        cli(["analyse", "--aircraft", name, "--plant", "jsbsim", "--out",
             str(keep / f"analyse-{name}"), "--overwrite"])
        fig = report.FIGURES / "tuning"
        fig.mkdir(parents=True, exist_ok=True)
        shutil.copy(keep / f"analyse-{name}" / "linear-vs-jsbsim.png",
                    fig / f"linear-vs-jsbsim-{name}.png")
    parts, total = [], 0.0
    for name in args.aircraft:
        md, wall, _ = one(name, args.workers, keep, args.grid)
        parts.append(md)
        total += wall
    head = ("The cores may be shared with other work: the load average is in each section."
            "\n\nColumns: margins are the smallest over the six broken loops "
            "(dB, deg, disk margin α) with the scheduled gains; `max_dv_kmh`/`max_dh_m` are the "
            "nonlinear JSBSim cross deviations (+100 m step, +10 % TAS step) with the schedule, "
            "`old_*` with the aircraft file's gains; `robust_pm_*` the smallest phase margin "
            "under mass −10 %/+10 %, CG 0.2 m forward/aft, 0.1 s delay at every actuator.\n\n"
            f"{' and '.join(args.aircraft)}: {total:.0f} s wall.\n\n")
    print(head + "\n".join(parts))
    report.write(args.md, "\n".join(parts), note=head)
    return 0


if __name__ == "__main__":
    sys.exit(main())
