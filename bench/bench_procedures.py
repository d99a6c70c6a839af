"""Benchmark: the whole FAA CIFP parsed, built and monitored, against a bare read, and the
whole-cycle ``procedures check`` with 2 workers (the goal: ≤ 15 s wall).

    python bench/bench_procedures.py [--db FILE] [--aircraft 737] [--workers 2]
                                     [--airports A B ...] [--md procedures_timing.md] [--quick]

Prints the wall-clock times of (1) a bare read of the file (read + split into lines), (2) the
load through the database index, (3) every airport's procedure transitions taken from it
(parsed when the index was written), (4) building and monitoring every procedure transition
on one core — wall and CPU time each — then (5)
the wall time of ``fms-testbed procedures check --workers N`` (a subprocess: imports, the
index load in every worker and the tables written included), all measured in this one run;
writes them as a Markdown table to ``docs/results/procedures_timing.md`` (``--md ''``: do
not). ``--airports``: only those; ``--quick``: only ``bench_check.QUICK_AIRPORTS``. A run whose transitions are all impossible, or
none, writes nothing (``report.refuse_degenerate``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from bench_check import QUICK_AIRPORTS  # noqa: E402

from fms_testbed.evaluation.check import check_airport, perf_for  # noqa: E402
from fms_testbed.procedures.database import load_database  # noqa: E402
from fms_testbed.procedures.index import load_index  # noqa: E402

DEFAULT = report.CIFP


def _stages(db_path: str, airports, perf) -> dict:
    """Times (s) and counts of the one-core stages (module docstring)."""
    out = {}
    t0 = time.perf_counter()
    out["lines"] = len(Path(db_path).read_text(encoding="latin-1").splitlines())
    out["read"] = time.perf_counter() - t0
    load_index(db_path)                       # the index written once, outside the timing
    t0, c0 = time.perf_counter(), time.process_time()
    db = load_index(db_path).db
    out["load"], out["load_cpu"] = time.perf_counter() - t0, time.process_time() - c0
    todo = airports or db.airport_idents()
    t0, c0 = time.perf_counter(), time.process_time()
    seqs = [s for apt in todo for s in db.sequences(apt)]
    out["parse"], out["parse_cpu"] = time.perf_counter() - t0, time.process_time() - c0
    out["n_seq"], out["n_legs"] = len(seqs), sum(len(s.legs) for s in seqs)
    t0, c0 = time.perf_counter(), time.process_time()
    status: dict[str, int] = {}
    for apt in todo:
        for row in check_airport(db, apt, perf):
            status[row["status"]] = status.get(row["status"], 0) + 1
    out["build"], out["build_cpu"] = time.perf_counter() - t0, time.process_time() - c0
    out["status"] = status
    return out


def _check_wall(db_path: str, aircraft: str, workers: int, airports
                ) -> tuple[float, float, dict]:
    """Wall time (s) of ``procedures check`` with ``workers``, the CPU time (user + system,
    s) of it and its workers, and its summary."""
    import json
    import resource
    import tempfile

    def children_cpu() -> float:
        ru = resource.getrusage(resource.RUSAGE_CHILDREN)
        return ru.ru_utime + ru.ru_stime

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "check"
        argv = ["procedures", "check", "--db", db_path, "--aircraft", aircraft, "--workers",
                str(workers), "--no-progress", "--out", str(out)]
        c0 = children_cpu()
        _, wall, _ = report.run_cli(argv + (["--airports", *airports] if airports else []),
                                    expect=out / "summary.json")
        return wall, children_cpu() - c0, json.loads((out / "summary.json").read_text())


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(DEFAULT), help="ARINC-424 file (default: FAA CIFP 2301)")
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--airports", nargs="*", default=None, help="only these airports")
    ap.add_argument("--md", default="procedures_timing.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "the airports " + " ".join(QUICK_AIRPORTS) + " only")
    args = ap.parse_args(argv)
    if args.quick and not args.airports:
        args.airports = QUICK_AIRPORTS
    if not Path(args.db).exists():
        raise SystemExit(f"{args.db}: no such ARINC-424 file (give --db)")
    perf = perf_for(args.aircraft)
    # warm the numba cache and imports outside the timed region
    check_airport(load_database(), "KDLS", perf)
    st = _stages(args.db, args.airports, perf)
    report.refuse_degenerate(st["status"], what="build + monitor")
    load0 = os.getloadavg()[0]
    wall, cpu, summary = _check_wall(args.db, args.aircraft, args.workers, args.airports)
    report.refuse_degenerate(summary["by_status"], headline=wall, what="procedures check")
    t_read, one = st["read"], st["load"] + st["parse"] + st["build"]
    one_cpu = st["load_cpu"] + st["parse_cpu"] + st["build_cpu"]
    print(f"file: {args.db} ({st['lines']} lines, {st['n_seq']} transitions, "
          f"{st['n_legs']} legs)")
    for name, t in (("bare read", t_read), ("index load", st["load"]), ("parse", st["parse"]),
                    ("build + monitor", st["build"]), ("one core, total", one),
                    (f"procedures check, {args.workers} workers (wall)", wall)):
        print(f"{name:32s} {t:7.2f} s   {t / t_read:6.1f}x bare read")
    print("status: " + ", ".join(f"{k} {v}" for k, v in sorted(st["status"].items())))
    name = Path(args.db).name
    rows = [["bare read (read + split into lines)", f"{t_read:.2f}", "—"],
            ["load through the index", f"{st['load']:.2f}", f"{st['load_cpu']:.2f}"],
            ["every airport's procedures from the index (parsed when it was written)",
             f"{st['parse']:.2f}", f"{st['parse_cpu']:.2f}"],
            [f"build + monitor every transition, one core "
             f"({1e3 * st['build_cpu'] / max(st['n_seq'], 1):.2f} ms CPU each)",
             f"{st['build']:.2f}", f"{st['build_cpu']:.2f}"],
            ["one core, total", f"{one:.1f}", f"{one_cpu:.1f}"],
            [f"**`procedures check --workers {args.workers}`** (goal ≤ 15 s wall; CPU of "
             f"it and its workers)", f"**{wall:.1f}**", f"{cpu:.1f}"],
            [f"the same, the least wall it can take on {args.workers} idle cores "
             f"(CPU / {args.workers})", "", f"{cpu / args.workers:.1f}"]]
    report.write(args.md, report.table(["stage", "wall, s", "CPU, s"], rows),
                 note=f"`{name}`{' (airports: ' + ' '.join(args.airports) + ')' if args.airports else ''}: "
                      f"{st['lines']:,} lines, {st['n_seq']:,} procedure transitions, "
                      f"{st['n_legs']:,} legs; aircraft {args.aircraft}. Outcomes: "
                      + ", ".join(f"{k} {v:,}" for k, v in sorted(st["status"].items()))
                      + f". Load average before the check: {load0:.1f} on {os.cpu_count()} "
                        "cores shared with other work: wall times move with the load, CPU "
                        "times much less.")


if __name__ == "__main__":
    main()
