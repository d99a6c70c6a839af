"""Benchmark: the whole FAA CIFP parsed, built and monitored on one core, against a bare read.

    python bench/bench_procedures.py [--db FILE] [--aircraft 737] [--md procedures_timing.md]

Prints the wall-clock times of (1) a bare read of the file (read + split into lines), (2) the
indexed load plus parsing every procedure record, (3) building and monitoring every procedure
transition, and their ratios to the bare read, all measured in this one run; writes them as a
Markdown table to ``docs/results/procedures_timing.md`` (``--md ''``: do not).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.evaluation.check import check_airport, perf_for
from fms_testbed.procedures.database import load_database

DEFAULT = report.CIFP


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(DEFAULT), help="ARINC-424 file (default: FAA CIFP 2301)")
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--md", default="procedures_timing.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    args = ap.parse_args()
    if not Path(args.db).exists():
        raise SystemExit(f"{args.db}: no such ARINC-424 file (give --db)")
    perf = perf_for(args.aircraft)
    # warm the numba cache and imports outside the timed region
    check_airport(load_database(), "KDLS", perf)

    t0 = time.perf_counter()
    lines = Path(args.db).read_text(encoding="latin-1").splitlines()
    t_read = time.perf_counter() - t0

    t0 = time.perf_counter()
    db = load_database(args.db)
    n_seq = n_legs = 0
    for apt in db.airport_idents():
        seqs = db.sequences(apt)
        n_seq += len(seqs)
        n_legs += sum(len(s.legs) for s in seqs)
    t_parse = time.perf_counter() - t0

    t0 = time.perf_counter()
    status: dict[str, int] = {}
    for apt in db.airport_idents():
        for row in check_airport(db, apt, perf):
            status[row["status"]] = status.get(row["status"], 0) + 1
    t_build = time.perf_counter() - t0

    total = t_parse + t_build
    print(f"file: {args.db} ({len(lines)} lines, {n_seq} transitions, {n_legs} legs)")
    print(f"bare read            {t_read:7.2f} s   1.0x")
    print(f"load + parse         {t_parse:7.2f} s   {t_parse / t_read:6.1f}x bare read")
    print(f"build + monitor      {t_build:7.2f} s   {t_build / t_read:6.1f}x bare read "
          f"({1e3 * t_build / n_seq:.3f} ms per transition)")
    print(f"parse+build+monitor  {total:7.2f} s   {total / t_read:6.1f}x bare read "
          f"(goal <= 60 s on one core)")
    print("status: " + ", ".join(f"{k} {v}" for k, v in sorted(status.items())))
    name = Path(args.db).name
    report.write(args.md, report.table(
        ["stage", "time, s", "vs bare read"],
        [["bare read (read + split into lines)", f"{t_read:.2f}", "1.0×"],
         ["indexed load + parsing every procedure record", f"{t_parse:.2f}",
          f"{t_parse / t_read:.0f}×"],
         [f"build + monitor every transition ({1e3 * t_build / n_seq:.2f} ms each)",
          f"{t_build:.2f}", f"{t_build / t_read:.0f}×"],
         ["**total** (goal ≤ 60 s on one core)", f"**{total:.1f}**", f"{total / t_read:.0f}×"]]),
        note=f"`{name}`: {len(lines):,} lines, {n_seq:,} procedure transitions, {n_legs:,} legs; "
             f"aircraft {args.aircraft}, one core. Outcomes: "
             + ", ".join(f"{k} {v:,}" for k, v in sorted(status.items())) + ".")


if __name__ == "__main__":
    main()
