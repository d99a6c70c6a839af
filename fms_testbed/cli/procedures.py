"""CLI: ``fms-testbed procedures build`` and ``fms-testbed procedures check``.

``build`` writes, per procedure transition, a GeoJSON FeatureCollection and a Fig.-2-style PNG
plus a one-line monitor outcome; a degraded transition (a rejected, duplicated or misplaced
record of its own) is refused with exit 2 unless ``--allow-degraded``. ``check`` runs the whole
database (or some airports) and writes ``procedures_check.parquet``/``.csv`` (one row per
transition), ``rejected_records.csv`` (file, line, columns, field, reason, record) and
``summary.json``.
"""

from __future__ import annotations

import math
from pathlib import Path

from fms_testbed.cli.procedures_list import register as register_list
from fms_testbed.cli.common import add_overwrite_option
from fms_testbed.core.errors import UserError
from fms_testbed.core.jsonio import dumps
from fms_testbed.run.outputs import OutputFolder
from fms_testbed.core.units import NM_M


def _perf(name: str):
    from fms_testbed.evaluation.check import perf_for
    return perf_for(name)


MANUAL_NM_MAX = 50.0
"""Largest --manual-nm, NM (as the scenario key ``procedure.manual_leg_nm``)."""


def _params(args):
    from fms_testbed.legs.model import BuildParams
    if not (math.isfinite(args.manual_nm) and 0.0 < args.manual_nm <= MANUAL_NM_MAX):
        raise UserError(f"--manual-nm must be a finite distance in (0, {MANUAL_NM_MAX:g}] NM, "
                        f"got {args.manual_nm!r}")
    return BuildParams(manual_leg_m=args.manual_nm * NM_M)


def cmd_build(args) -> int:
    """Build one airport's procedures (optionally one procedure/transition) to GeoJSON + PNG."""
    from fms_testbed.procedures.database import load_database
    from fms_testbed.viz.geojson import safe_name, write_geojson
    from fms_testbed.path.monitor import check_path
    from fms_testbed.viz.path import plot_path
    from fms_testbed.viz.figure import save
    from fms_testbed.path.segmentation import build_sequence
    from fms_testbed.core.geodesy import gravity_mps2

    from fms_testbed.procedures.integrity import refusal

    params = _params(args)
    db = load_database(args.db)
    perf = _perf(args.aircraft)
    seqs = db.select(args.airport.upper(), args.procedure, args.transition)
    degraded = [s for s in seqs if s.degraded]
    if degraded and not args.allow_degraded:
        more = f" ({len(degraded)} of {len(seqs)} transitions degraded)" if len(seqs) > 1 else ""
        raise UserError(refusal(degraded[0].name, degraded[0].defects) + more)
    out = Path(args.out)
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    apt = db.airports.get(args.airport.upper())
    g = gravity_mps2(apt.lat_deg if apt else 45.0)
    for seq in seqs:
        if not seq.legs:
            print(f"{seq.name}: degraded (no legs: every record rejected)")
            for d in seq.defects:
                print(f"    {d.finding}")
            continue
        path = check_path(build_sequence(db, seq, perf, params), perf, params, g)
        gj = write_geojson(path, tmp)
        png = save(plot_path(path), tmp / f"{safe_name(path)}.png") if path.segments else None
        status = f"degraded (monitor: {path.status})" if seq.degraded else path.status
        print(f"{path.name}: {status} ({len(path.legs)} legs, {len(path.segments)} "
              f"segments, {path.length_m() / NM_M:.1f} NM) -> {gj.name}"
              f"{', ' + png.name if png else ''}")
        for d in seq.defects:
            print(f"    {d.finding}")
        for f in path.findings:
            print(f"    leg {f.leg_index + 1}: {f.category}"
                  f"{' [' + f.branch + ']' if f.branch else ''}: {f.message}")
    for issue in db.issues[:20]:
        print(f"    rejected record: {issue}")
    if len(db.issues) > 20:
        print(f"    ... {len(db.issues) - 20} more rejected records")
    folder.commit()
    return 0


def cmd_check(args) -> int:
    """Check every procedure transition of a database; write the table and the summary."""
    import pandas as pd

    from fms_testbed.evaluation.check import ROW_COLUMNS, merge_airports, run_check
    from fms_testbed.procedures.fields import REJECTED_COLUMNS

    if args.workers < 1:
        raise UserError(f"--workers must be at least 1, got {args.workers}")
    params = _params(args)
    perf = _perf(args.aircraft)
    out = Path(args.out)
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    res = run_check(args.db, perf, merge_airports(args.airports), args.workers, params,
                    progress=not args.no_progress)
    rows, summary = res.rows, res.summary
    tmp = folder.open()
    df = pd.DataFrame(rows, columns=list(rows[0]) if rows else list(ROW_COLUMNS))
    df = df.drop(columns=["order"])
    df.to_parquet(tmp / "procedures_check.parquet", index=False)
    df.to_csv(tmp / "procedures_check.csv", index=False)
    pd.DataFrame([e.row() for e in res.rejected], columns=list(REJECTED_COLUMNS)).to_csv(
        tmp / "rejected_records.csv", index=False)
    (tmp / "summary.json").write_text(dumps(summary, indent=1))
    st = summary["by_status"]
    print(f"{summary['transitions']} procedure transitions from {summary['database']} "
          f"({summary['lines']} lines, {summary['parse_issues']} rejected records) in "
          f"{summary['elapsed_s']:.1f} s with {summary['workers']} worker(s)")
    print("  status: " + ", ".join(f"{k} {v}" for k, v in sorted(st.items()))
          + f"  -> ok or corrected {summary['ok_or_corrected_pct']:.2f}% of all transitions")
    print(f"  {summary['rejected_records']} rejected records -> "
          f"{tmp / 'rejected_records.csv'}; degraded transitions by defect: "
          f"{summary['degraded_by_defect'] or 'none'}; internal errors: "
          f"{summary['internal_errors']}")
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
    print(f"  class 3 (database coding) found: {summary['class3_transitions']} transitions; "
          f"coded numbers against the fixes by kind: {summary['class3_by_kind'] or 'none'}")
    print(f"  wrote {out / 'procedures_check.parquet'}, .csv and summary.json")
    folder.commit()
    return 0 if not math.isnan(summary["ok_or_corrected_pct"]) else 1


def register(subparsers) -> None:
    """Add ``procedures build`` and ``procedures check``."""
    p = subparsers.add_parser("procedures",
                              help="ARINC-424 procedures: list, build paths, check a database")
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
    b.add_argument("--allow-degraded", action="store_true",
                   help="build transitions with rejected, duplicated or misplaced records too "
                        "(refused by default, exit 2)")
    b.add_argument("--out", required=True, help="output folder")
    add_overwrite_option(b)
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
    add_overwrite_option(c)
    c.set_defaults(func=cmd_check)
    register_list(sub, common)
    p.set_defaults(func=lambda a: (p.print_help(), 2)[1])
