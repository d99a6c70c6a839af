"""Campaign check of a tuned schedule: the same procedure sample flown with the file's gains and
with the tuned aircraft file, in wind and turbulence, and the shift of the error distributions.

    python bench/bench_tune_campaign.py --new RUN/aircraft.yaml [--old 737]
        [--airports KBFI KDLS ...] [--types STAR,APPROACH] [--limit N] [--workers 2] [--wind 270/30]
        [--turbulence moderate] --out DIR [--md]
    python bench/bench_tune_campaign.py --quick

Two ``fms-testbed regress run`` campaigns over the same cases (embedded excerpt, ``--airports``,
one condition set: steady wind ``--wind`` and ``--turbulence``, truth navigation), one per
aircraft file; the flights are paired by (airport, type, procedure, runway, transition,
conditions). Written to ``DIR``: ``campaign-shift.md`` (per run: flights, status counts,
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

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from bench_tune import write_quick_grid  # noqa: E402

PAGE = "tune_campaign.md"
QUICK = {"airports": ["KBFI"], "limit": 2}
"""The cases of a quick run: the first two of one airport's sample."""

KEY = ["airport", "type", "procedure", "runway", "transition", "conditions"]
METRICS = ("fte_p95_m", "vpe_p95_m", "spd_err_p95_kt")


def _run(aircraft: str, cond: Path, args, out: Path) -> pd.DataFrame:
    from fms_testbed.cli import main

    argv = ["regress", "run", "--aircraft", aircraft, "--conditions", str(cond),
            "--workers", str(args.workers), "--no-progress", "--out", str(out)]
    if args.airports:
        argv += ["--airports", *args.airports]
    if args.limit:
        argv += ["--limit", str(args.limit)]
    if args.types:
        argv += ["--types", args.types]
    rc = main(argv)
    if rc not in (0, 1):
        raise SystemExit(f"regress run for {aircraft} exited {rc}")
    return pd.read_parquet(out / "flights")


def summary(df: pd.DataFrame) -> dict:
    """Per-run figures: flights, ok, medians and p90 of the error metrics, constraints missed."""
    flown = df[df[list(METRICS)].notna().any(axis=1)]
    row = {"cases": len(df), "flown": len(flown), "ok": int((df.status == "ok").sum()),
           "constraints_checked": int(df.constraints_checked.fillna(0).sum()),
           "constraints_missed": int(df.constraints_missed.fillna(0).sum())}
    for m in METRICS:
        v = flown[m].dropna()
        row[f"{m} median"] = float(v.median()) if len(v) else np.nan
        row[f"{m} p90"] = float(v.quantile(0.9)) if len(v) else np.nan
    return row


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
    frm, spd = (float(x) for x in args.wind.split("/"))
    cond = out / "conditions.yaml"
    cond.write_text(f"conditions:\n  - name: wind-{frm:.0f}-{spd:.0f}kt-{args.turbulence}\n"
                    f"    wind: {{from_deg: {frm:g}, speed_kt: {spd:g}}}\n"
                    f"    turbulence: {{severity: {args.turbulence}}}\n")
    runs = {"file gains": _run(args.old, cond, args, out / "old"),
            "tuned schedule": _run(args.new, cond, args, out / "new")}
    table = pd.DataFrame({k: summary(v) for k, v in runs.items()})
    a, b = (runs[k].set_index(KEY) for k in ("file gains", "tuned schedule"))
    both = a.merge(b, left_index=True, right_index=True, suffixes=("_old", "_new"))
    diffs = {m: float((both[f"{m}_new"] - both[f"{m}_old"]).median()) for m in METRICS}
    from fms_testbed.cli.common import markdown_table
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.tuning import plot_campaign_shift

    md = (f"Aircraft: `{args.old}` (file gains) and `{args.new}` (tuned schedule). "
          f"Conditions: wind {args.wind} kt, {args.turbulence} turbulence; "
          f"{len(both)} paired flights.\n\n{markdown_table(table.reset_index())}\n\n"
          "Median of the paired differences (tuned − file gains): "
          + ", ".join(f"{m} {v:+.3g}" for m, v in diffs.items()) + "\n")
    report.write(out / "campaign-shift.md", md)
    if args.md:
        report.write(args.md, md)
        fig = report.FIGURES / "tuning"
        fig.mkdir(parents=True, exist_ok=True)
    save(plot_campaign_shift(runs, METRICS, f"{args.old}: file gains vs tuned schedule, wind "
                             f"{args.wind} kt, {args.turbulence} turbulence ({len(both)} paired "
                             "flights)"), out / "campaign-shift.png")
    if args.md:
        import shutil

        shutil.copy(out / "campaign-shift.png", fig / "campaign-shift.png")
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
