"""The whole-database check's figures, from ``fms-testbed procedures check`` itself.

Runs ``fms-testbed procedures check --db FILE --no-progress --out TMP`` and writes its
``summary.json`` (counts by status, leg types coded/built, invariants, corrections by branch,
flags) and the list of impossible transitions with their reasons from ``procedures_check.csv``
as Markdown to ``docs/results/cifp_check.md``.

    python bench/bench_check.py [--db FILE] [--aircraft 737] [--workers 1] [--md cifp_check.md]
                                [--airports A B ...] [--quick]

``--db`` defaults to the FAA CIFP beside the repository (``../shared/data/cifp/FAACIFP18_230126``).
``--quick``: only the airports of :data:`QUICK_AIRPORTS` (unless ``--airports`` is given).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

QUICK_AIRPORTS = ["KDLS", "KAUS"]
"""The airports of a quick run (``--quick``): two fields of the FAA cycle, a few hundred
transitions between them."""


def markdown(summary: dict, table: pd.DataFrame, cmd: str, wall_s: float) -> str:
    """The check's summary and its impossible transitions as Markdown."""
    st = summary["by_status"]
    n = summary["transitions"]
    rows = [["lines", f"{summary['lines']:,}"],
            ["rejected records", f"{summary['parse_issues']:,}"],
            ["procedure transitions", f"{n:,}"]]
    rows += [[status, f"{count:,}"] for status, count in sorted(st.items())]
    rows += [["ok or corrected", f"**{summary['ok_or_corrected_pct']:.2f} %**"],
             ["largest gap between consecutive segments", f"{summary['max_gap_m']:.3f} m"],
             ["largest excess over a fix's allowance (≤ 0: every fix within its allowance)",
              f"{summary['max_fix_excess_m']:.3f} m"],
             ["largest RF radius error vs coded", f"{summary['max_rf_radius_err_nm']:.3f} NM"],
             ["turns against the coded direction", f"{summary['turn_mismatches']}"],
             ["leg types present but never built",
              ", ".join(summary["leg_types_present_not_built"]) or "none"],
             ["class 3 (database coding) found", f"{summary['class3_transitions']:,}"],
             ["highest planned altitude, TAS",
              f"{table['max_plan_alt_ft'].max():,.0f} ft, {table['max_plan_tas_kt'].max():.0f} kt"],
             *path_rows(table),
             ["wall time, workers", f"{wall_s:.1f} s, {summary['workers']}"]]
    legs = [[pt, f"{v['coded']:,}", f"{v['built']:,}"]
            for pt, v in summary["by_leg_type"].items() if v["coded"]]
    absent = [pt for pt, v in summary["by_leg_type"].items() if not v["coded"]]
    branches = [[b, f"{c:,}"] for b, c in sorted(summary["branches"].items())]
    flags = [[f, f"{c:,}"] for f, c in sorted(summary["flags"].items())]
    imp = table[table["status"] == "impossible"]
    imp_rows = [[f"{r.airport} {r.type} {r.procedure} {r.transition or '(common)'}",
                 str(r.findings).split(";")[-1].strip()] for r in imp.itertuples()]
    out = [report.table(["metric", "result"], rows), "",
           "**Leg types, coded / built** (built: in transitions that are not impossible"
           + (f"; never coded in this database: {', '.join(absent)}" if absent else "") + ")\n",
           report.table(["leg type", "coded", "built"], legs), "",
           "**Corrections by monitor branch**\n", report.table(["branch", "transitions"], branches),
           "", "**Flags**\n", report.table(["flag", "transitions"], flags), "",
           f"**Impossible transitions ({len(imp)})**, each with its last finding\n",
           report.table(["transition", "reason"], imp_rows)]
    return "\n".join(out)


def path_rows(table: pd.DataFrame) -> list[list[str]]:
    """Counts from the findings: CF legs off their coded course in transitions that are not
    impossible, CF legs whose course cannot be flown, CF courses joined at the minimum speed,
    holds built off their coded distance/time by more than the tolerance."""
    f = table["findings"].astype(str)
    live = table["status"] != "impossible"
    off = f.str.contains(r"CF \S* built \d+° off", regex=True)
    return [["CF legs built > 20° off their coded course (transitions not impossible)",
             f"{int((off & live).sum())}"],
            ["CF legs whose coded course cannot be flown (impossible, with the reason)",
             f"{int(f.str.count('the coded course cannot be flown').sum())}"],
            ["CF courses joined at the minimum speed (branch V,γ)",
             f"{int(f.str.count('joined at the minimum speed').sum())}"],
            ["holds built off their coded distance or time by > 0.1 NM",
             f"{int(f.str.count('hold_length:').sum())}"]]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(report.CIFP),
                    help="ARINC-424 file (default: the FAA CIFP beside the repository)")
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--airports", nargs="*", default=None, help="only these airports")
    ap.add_argument("--md", default="cifp_check.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "the airports " + " ".join(QUICK_AIRPORTS) + " only")
    args = ap.parse_args(argv)
    if args.quick and not args.airports:
        args.airports = QUICK_AIRPORTS
    if not Path(args.db).exists():
        raise SystemExit(f"{args.db}: no such ARINC-424 file (give --db)")
    with tempfile.TemporaryDirectory() as tmp:
        argv = ["procedures", "check", "--db", args.db, "--aircraft", args.aircraft,
                "--workers", str(args.workers), "--no-progress", "--out", tmp]
        if args.airports:
            argv += ["--airports", *args.airports]
        _, wall, stdout = report.run_cli(argv, expect=Path(tmp) / "summary.json")
        print(stdout)
        summary = json.loads((Path(tmp) / "summary.json").read_text())
        table = pd.read_csv(Path(tmp) / "procedures_check.csv", keep_default_na=False)
    report.refuse_degenerate(summary["by_status"], headline=summary["ok_or_corrected_pct"],
                             what="procedures check")
    some = f" --airports {' '.join(args.airports)}" if args.airports else ""
    cmd = (f"fms-testbed procedures check --db {Path(args.db).name} --aircraft {args.aircraft} "
           f"--workers {args.workers} --no-progress{some} --out DIR")
    report.write(args.md, markdown(summary, table, cmd, wall),
                 note=f"`{cmd}`: every procedure transition of "
                      + ("those airports" if args.airports else "the database")
                      + " built and monitored.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
