"""CLI: ``fms-testbed procedures build`` and ``fms-testbed procedures check``.

``build`` writes, per procedure transition, a GeoJSON FeatureCollection and a Fig.-2-style PNG
plus a one-line monitor outcome; ``check`` runs the whole database (or some airports) and writes
``procedures_check.parquet``/``.csv`` (one row per transition) and ``summary.json``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from fms_testbed.core.errors import UserError


def _perf(name: str):
    from fms_testbed.evaluation.check import perf_for
    return perf_for(name)


def _params(args):
    from fms_testbed.legs.model import BuildParams
    return BuildParams(manual_leg_m=args.manual_nm * 1852.0)


def cmd_build(args) -> int:
    """Build one airport's procedures (optionally one procedure/transition) to GeoJSON + PNG."""
    from fms_testbed.procedures.database import load_database
    from fms_testbed.viz.geojson import safe_name, write_geojson
    from fms_testbed.path.monitor import check_path
    from fms_testbed.viz.path import plot_path
    from fms_testbed.path.segmentation import build_sequence
    from fms_testbed.core.geodesy import gravity_mps2

    db = load_database(args.db)
    perf = _perf(args.aircraft)
    params = _params(args)
    seqs = db.select(args.airport.upper(), args.procedure, args.transition)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    apt = db.airports.get(args.airport.upper())
    g = gravity_mps2(apt.lat_deg if apt else 45.0)
    for seq in seqs:
        path = check_path(build_sequence(db, seq, perf, params), perf, params, g)
        gj = write_geojson(path, out)
        png = plot_path(path, out / f"{safe_name(path)}.png") if path.segments else None
        print(f"{path.name}: {path.status} ({len(path.legs)} legs, {len(path.segments)} "
              f"segments, {path.length_m() / 1852:.1f} NM) -> {gj.name}"
              f"{', ' + png.name if png else ''}")
        for f in path.findings:
            print(f"    leg {f.leg_index + 1}: {f.category}"
                  f"{' [' + f.branch + ']' if f.branch else ''}: {f.message}")
    for issue in db.issues[:20]:
        print(f"    rejected record: {issue}")
    return 0


def cmd_check(args) -> int:
    """Check every procedure transition of a database; write the table and the summary."""
    import pandas as pd

    from fms_testbed.evaluation.check import check_database

    perf = _perf(args.aircraft)
    airports = [a.upper() for a in args.airports] if args.airports else None
    if args.workers < 1:
        raise UserError(f"--workers must be at least 1, got {args.workers}")
    rows, summary = check_database(args.db, perf, airports, args.workers, _params(args),
                                   progress=not args.no_progress)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(rows).drop(columns=["order"])
    df.to_parquet(out / "procedures_check.parquet", index=False)
    df.to_csv(out / "procedures_check.csv", index=False)
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=float))
    st = summary["by_status"]
    print(f"{summary['transitions']} procedure transitions from {summary['database']} "
          f"({summary['lines']} lines, {summary['parse_issues']} rejected records) in "
          f"{summary['elapsed_s']:.1f} s with {summary['workers']} worker(s)")
    print("  status: " + ", ".join(f"{k} {v}" for k, v in sorted(st.items()))
          + f"  -> ok or corrected {summary['ok_or_corrected_pct']:.2f}%")
    print("  leg types (coded/built): " + ", ".join(
        f"{pt} {v['coded']}/{v['built']}" for pt, v in summary["by_leg_type"].items()
        if v["coded"]))
    if summary["leg_types_present_not_built"]:
        print("  leg types never built: " + ", ".join(summary["leg_types_present_not_built"]))
    print(f"  invariants: max gap {summary['max_gap_m']:.3f} m, max fix excess "
          f"{summary['max_fix_excess_m']:.3f} m, max RF radius error "
          f"{summary['max_rf_radius_err_nm']:.4f} NM, turn mismatches "
          f"{summary['turn_mismatches']}")
    print(f"  corrections by branch: {summary['branches']}; flags: {summary['flags']}")
    print(f"  wrote {out / 'procedures_check.parquet'}, .csv and summary.json")
    return 0 if not math.isnan(summary["ok_or_corrected_pct"]) else 1


def register(subparsers) -> None:
    """Add ``procedures build`` and ``procedures check``."""
    p = subparsers.add_parser("procedures", help="ARINC-424 procedures: build paths, check a database")
    sub = p.add_subparsers(dest="procedures_command", metavar="SUBCOMMAND")
    common = dict(default=None, help="ARINC-424 file (default: the embedded excerpt "
                                     "procedures/cifp_excerpt.dat)")
    b = sub.add_parser("build", help="build procedure paths to GeoJSON and PNG")
    b.add_argument("--db", **common)
    b.add_argument("--airport", required=True, help="ICAO airport ident, e.g. KJFK")
    b.add_argument("--procedure", default=None, help="procedure ident, e.g. DEEZZ5 or I04L")
    b.add_argument("--transition", default=None,
                   help="transition ident (e.g. RW04B; '' for the common route)")
    b.add_argument("--aircraft", default="737", help="aircraft name or YAML (default 737)")
    b.add_argument("--manual-nm", type=float, default=5.0,
                   help="distance flown on FM/VM legs, NM (default 5)")
    b.add_argument("--out", required=True, help="output folder")
    b.set_defaults(func=cmd_build)
    c = sub.add_parser("check", help="build and monitor every procedure transition")
    c.add_argument("--db", **common)
    c.add_argument("--airports", nargs="*", default=None, help="only these airports")
    c.add_argument("--workers", type=int, default=1, help="processes (default 1)")
    c.add_argument("--aircraft", default="737", help="aircraft name or YAML (default 737)")
    c.add_argument("--manual-nm", type=float, default=5.0,
                   help="distance flown on FM/VM legs, NM (default 5)")
    c.add_argument("--no-progress", action="store_true", help="no progress bar")
    c.add_argument("--out", required=True, help="output folder")
    c.set_defaults(func=cmd_check)
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])
