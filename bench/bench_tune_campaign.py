"""Campaign check of a tuned schedule: the same procedure sample flown with the file's gains and
with the tuned aircraft file, in wind and turbulence, and the shift of the error distributions.

    python bench/bench_tune_campaign.py --new RUN/aircraft.yaml [--old 737]
        [--airports KBFI KDLS ...] [--types STAR,APPROACH] [--limit N] [--workers 2] [--wind 270/30]
        [--turbulence moderate] --out DIR [--md]
    python bench/bench_tune_campaign.py --quick

Two regression campaigns over the same cases (embedded excerpt, ``--airports``, one condition
set: steady wind ``--wind`` and ``--turbulence``, truth navigation), one per aircraft file,
flown and compared by :func:`fms_testbed.cli.tune_envelope.campaign_check` (the code of
``tune --envelope --verify-campaign``); the flights are paired by (airport, type, procedure,
runway, transition, conditions). Written to ``DIR``: ``campaign-shift.md`` (per run: flights, status counts,
median and 90th percentile of ``fte_p95_m``, ``vpe_p95_m``, ``spd_err_p95_kt``, constraints
missed; per pair the median of the differences new − old) and ``campaign-shift.png`` (the
empirical distributions); ``--md`` also writes ``docs/results/tune_campaign.md`` and the figure
into ``docs/figures/tuning/``. ``--quick`` (``--new`` not needed): tunes the 737 on
``bench_tune.QUICK_GRID`` (no robustness set) into ``DIR/tune``, flies :data:`QUICK` with both
files into ``results/quick/tune_campaign`` and writes the page and the figure.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from bench_tune import write_quick_grid  # noqa: E402

PAGE = "tune_campaign.md"
QUICK = {"airports": ["KBFI"], "limit": 2}
"""The cases of a quick run: the first two of one airport's sample."""


def quick_schedule(folder: Path, workers: int) -> str:
    """Tune the 737 on ``bench_tune.QUICK_GRID`` without the robustness set into
    ``folder/tune``; the tuned aircraft file's path."""
    from fms_testbed.cli import main

    grid = write_quick_grid(folder)
    rc = main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid), "--no-robust",
               "--workers", str(workers), "--out", str(folder / "tune"), "--overwrite"])
    if rc not in (0, 1):
        raise SystemExit(f"tune --envelope for the quick schedule exited {rc}")
    return str(folder / "tune" / "aircraft.yaml")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--new", help="tuned aircraft file (tune --envelope's aircraft.yaml)")
    ap.add_argument("--old", default="737", help="aircraft with the file gains (name or file)")
    ap.add_argument("--airports", nargs="*", default=None)
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--types", default="STAR,APPROACH",
                    help="procedure types (descending profiles carry the vertical path error)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--wind", default="270/30", help="FROM_DEG/SPEED_KT")
    ap.add_argument("--turbulence", default="moderate", choices=("light", "moderate", "severe"))
    ap.add_argument("--out", help="output folder (quick: results/quick/tune_campaign)")
    ap.add_argument("--md", action="store_const", const=PAGE,
                    help=f"also write docs/results/{PAGE} and docs/figures/tuning/")
    report.add_quick(ap, "a 737 schedule tuned on three points, two cases of one airport")
    args = ap.parse_args()
    if args.quick:
        args.out = args.out or str(report.REPO / "results" / "quick" / "tune_campaign")
        args.airports, args.limit = args.airports or QUICK["airports"], QUICK["limit"]
        args.md = PAGE
    elif not (args.new and args.out):
        ap.error("--new and --out are required (or --quick)")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.new is None:
        args.new = quick_schedule(out, args.workers)
    from fms_testbed.cli.tune_envelope import campaign_check

    _, md = campaign_check(args.old, args.new, out, args.airports, args.limit, args.types,
                           args.workers, args.wind, args.turbulence)
    report.write(out / "campaign-shift.md", md)
    if args.md:
        import shutil

        report.write(args.md, md)
        fig = report.FIGURES / "tuning"
        fig.mkdir(parents=True, exist_ok=True)
        shutil.copy(out / "campaign-shift.png", fig / "campaign-shift.png")
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
