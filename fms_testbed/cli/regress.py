"""``fms-testbed regress``: procedure-database regression runs (``docs/regression.md``).

    fms-testbed regress run --db FILE [--airports ICAO …] [--sample-airports N --sample-seed S
        [--sample-min-transitions K]] [--types SID,STAR,APPROACH] [--aircraft 737,global5000 …]
        [--wind FROM_DEG/SPEED_KT …] [--isa-dev-c DEG_C …] [--nav truth|sins[:PRESET] …] [--imu PRESET]
        [--conditions FILE.yaml] [--combinations each|all] [--limit N] [--seed N]
        [--case-timeout S] [--keep timeseries,plots] [--phase test-db|integration]
        (--workers N | --scheduler tcp://HOST:PORT) --out DIR
    fms-testbed regress diff RUN_A RUN_B [--tolerance FILE.yaml] [--markdown FILE.md]
        [--across-conditions]
    fms-testbed regress report DIR [--worst N] [--with OTHER_DIR …]
    fms-testbed regress testdb --out FILE

``testdb`` writes the phase-1 test database (``procedures/testdb.py``: ~50 synthesised
procedures, every path terminator) and its manifest ``FILE.manifest.json``; ``regress run --db
FILE`` flies it (phase ``test database``, inferred from the manifest) and ``regress report``
checks the outcomes against the manifest.

``run`` exits 0 once every case is flown (whatever the flights' outcomes: they are the data;
``diff`` is the gate), 2 on a user error; re-running the same command resumes. ``diff`` exits 0
when nothing changed beyond tolerance, 1 otherwise. ``--missed`` flies the missed approach of
every approach case (part of each condition set: it enters the case id).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from fms_testbed.cli.common import (SEED, WIND_HELP, bounded_float, bounded_int, out_path,
                                    parse_isa_dev, parse_wind)

MAX_CASES = 10_000_000
"""Largest ``--limit``, cases."""
from fms_testbed.core.errors import UserError


def _split(values: list[str] | None) -> list[str]:
    """``['737,global5000', 'c172p']`` → ``['737', 'global5000', 'c172p']``."""
    return [v.strip() for item in values or [] for v in item.split(",") if v.strip()]


def _winds(values: list[str] | None) -> list[dict | None]:
    if not values:
        return [None]
    return [None if w.lower() == "calm" else parse_wind(w) for w in values]


def _navs(values: list[str] | None, imu: str | None) -> list[dict]:
    """Navigation blocks of ``--nav truth|SOURCE[:PRESET] ...`` (any registered source with an
    IMU: :data:`fms_testbed.navigation.SOURCES`)."""
    if not values:
        if imu:
            raise UserError("--imu is only used with a --nav source other than truth")
        return [{"source": "truth"}]
    out = []
    for v in values:
        name, _, preset = v.partition(":")
        if name == "truth" and not preset:
            out.append({"source": "truth"})
            continue
        from fms_testbed.navigation import SOURCES     # lazy: the registry imports the filters

        if name == "truth" or name not in SOURCES:
            raise UserError(f"--nav {v!r}: expected truth or SOURCE[:PRESET] with SOURCE one of "
                            f"{', '.join(k for k in SOURCES if k != 'truth')}")
        preset = preset or imu
        if not preset:
            raise UserError(f"--nav {v}: give the IMU preset ({name}:HG1700, or --imu PRESET)")
        out.append({"source": name, "imu": preset})
    return out


def config_from_args(args):
    """The :class:`~fms_testbed.campaign.runner.RunConfig` of ``regress run``'s options."""
    from fms_testbed.campaign.cases import parse_types
    from fms_testbed.campaign.conditions import command_line_sets, read_conditions
    from fms_testbed.campaign.runner import RunConfig

    if args.conditions:
        if args.wind or args.nav or args.imu or args.isa_dev_c or args.missed:
            raise UserError("--conditions FILE names the condition sets; --wind/--isa-dev-c/"
                            "--nav/--imu/--missed are not used with it ('missed: true' in a "
                            "set)")
        sets = read_conditions(args.conditions)
    else:
        navs = _navs(args.nav, args.imu)
        if getattr(args, "truth_model", None):
            navs = [n if n["source"] == "truth" else {**n, "truth_model": args.truth_model}
                    for n in navs]
        sets = command_line_sets(_winds(args.wind), navs,
                                 [parse_isa_dev(v) for v in args.isa_dev_c or []] or None,
                                 missed=args.missed)
    if args.sample_airports is None and (args.sample_seed is not None
                                         or args.sample_min_transitions is not None):
        raise UserError("--sample-seed/--sample-min-transitions need --sample-airports N")
    return RunConfig(
        out=out_path(args.out), conditions=sets, db=args.db, airports=args.airports,
        sample_airports=args.sample_airports, sample_seed=args.sample_seed or 0,
        sample_min_transitions=args.sample_min_transitions or 1,
        types=parse_types(args.types), aircraft=_split(args.aircraft) or ["737"],
        combinations=args.combinations, limit=args.limit, seed=args.seed,
        workers=args.workers or os.cpu_count() or 1, scheduler=args.scheduler,
        case_timeout_s=args.case_timeout, keep=tuple(_split([args.keep] if args.keep else [])),
        progress=False if args.no_progress else None, command=list(sys.argv), phase=args.phase,
        batch_rows=args.batch_rows, overwrite=args.overwrite)


def cmd_run(args) -> int:
    """Plan, fly (resuming) and summarise a regression run."""
    from fms_testbed.campaign.runner import run_campaign

    info = run_campaign(config_from_args(args))
    s = info["sessions"][-1]
    c = info["cases"]
    print(f"{c['count']} cases ({c['procedures']} procedures at {c['airports']} airports) in "
          f"{args.out}: {s['cases_flown']} flown now, {s['cases_skipped']} already done; "
          f"{s['elapsed_s']:.0f} s" + (f", {s['flights_per_hour']} flights/h"
                                       if s["flights_per_hour"] else ""))
    print("  status: " + ", ".join(f"{k} {v}" for k, v in info["counts"].items()))
    if s["sum_loop_wall_s"]:
        over = 100.0 * (s["sum_wall_s"] - s["sum_loop_wall_s"]) / s["sum_loop_wall_s"]
        print(f"  per-case overhead (wall_s - loop_wall_s) / loop_wall_s: {over:.1f} %")
    if s.get("quarantined"):
        print(f"  {len(s['quarantined'])} damaged part file(s) moved to {args.out}/quarantine, "
              "their cases flown again")
    if info["status"] != "complete":
        print("  not every case is written: run the same command again to resume")
    return 0


def markdown_target(path: str, runs: list[str]) -> Path:
    """The ``--markdown`` file, checked before the diff: not a folder, its folder exists and is
    writable, and not inside either run folder compared (an input is never written).

    Parameters
    ----------
    path : the ``--markdown`` value; runs : the run folders compared
    """
    out = Path(path)
    if not path.strip():
        raise UserError("--markdown '': give a file name")
    if out.is_dir():
        raise UserError(f"--markdown {path}: is a folder; give the Markdown file to write")
    if out.is_symlink():
        raise UserError(f"--markdown {path}: is a symbolic link; give the real file")
    target = out.absolute().resolve()
    for r in runs:
        if target.is_relative_to(Path(r).absolute().resolve()):
            raise UserError(f"--markdown {path}: lies inside the run folder {r} that is "
                            "compared; write it elsewhere (an input is never written)")
    parent = target.parent
    if not parent.is_dir():
        raise UserError(f"--markdown {path}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise UserError(f"--markdown {path}: cannot write in {parent} (permission denied)")
    return out


def cmd_diff(args) -> int:
    """Compare two runs; exit 1 when something changed beyond tolerance."""
    from fms_testbed.campaign.diff import diff_runs, read_tolerances

    md = markdown_target(args.markdown, [args.run_a, args.run_b]) if args.markdown is not None \
        else None
    tol = read_tolerances(args.tolerance) if args.tolerance else None
    res = diff_runs(args.run_a, args.run_b, tol, args.across_conditions)
    print(res.text())
    if md is not None:
        tmp = md.with_name(f".{md.name}.tmp")
        try:
            tmp.write_text(res.markdown())
            tmp.replace(md)
        except OSError as exc:
            tmp.unlink(missing_ok=True)
            raise UserError(f"--markdown {md}: cannot write: {exc.strerror or exc}") from None
        print(f"  Markdown summary: {args.markdown}")
    return 0 if res.clean else 1


def cmd_report(args) -> int:
    """Write DIR/report.html; print its status counted from the data."""
    from fms_testbed.campaign.report import write_report

    if args.worst < 0:
        raise UserError(f"--worst {args.worst}: must be >= 0")
    path, line = write_report(args.dir, worst=args.worst, others=args.others or [],
                              refly=not args.no_refly)
    print(f"wrote {path}\n  {line}")
    return 0


def cmd_testdb(args) -> int:
    """Write the test database and its manifest."""
    from fms_testbed.procedures.testdb import PROCEDURES, write_testdb

    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out {out}: is a folder; give the database file to write")
    if not out.parent.is_dir():
        raise UserError(f"--out {out}: folder {out.parent} does not exist")
    db, man = write_testdb(out)
    kinds = {k: sum(1 for p in PROCEDURES if p.expect.kind == k) for k in ("fly", "refuse",
                                                                          "flag")}
    print(f"wrote {db} ({len(PROCEDURES)} procedures: {kinds['fly']} valid, "
          f"{kinds['refuse'] + kinds['flag']} miscoded) and {man}")
    print(f"  fly it: fms-testbed regress run --db {db} --workers 1 --out DIR; then "
          "fms-testbed regress report DIR")
    return 0


def _add_run(rs) -> None:
    """``regress run``'s options."""
    r = rs.add_parser("run", help="fly every procedure of a database (resumable)")
    r.add_argument("--db", help="ARINC-424 file (default: the embedded excerpt)")
    r.add_argument("--airports", nargs="+", metavar="ICAO", help="airports (default: all)")
    r.add_argument("--sample-airports", type=bounded_int(1, 100_000), metavar="N",
                   help="fly a seeded sample of N airports (of --airports, or of all)")
    r.add_argument("--sample-seed", type=SEED, metavar="S", help="seed of the sample (default 0)")
    r.add_argument("--sample-min-transitions", type=bounded_int(1, 10_000), metavar="K",
                   help="sample only airports with ≥ K transitions of the --types (default 1)")
    r.add_argument("--types", help="SID,STAR,APPROACH (default all three)")
    r.add_argument("--aircraft", nargs="+", help="aircraft names or files, e.g. 737,global5000 "
                                                 "(default 737)")
    r.add_argument("--wind", nargs="+", metavar="FROM/SPEED",
                   help=WIND_HELP + "; several give several condition sets; 'calm' for none")
    r.add_argument("--isa-dev-c", nargs="+", metavar="DEG_C",
                   help="ISA temperature deviations, °C (several give several condition sets; "
                        "default 0)")
    r.add_argument("--nav", nargs="+", metavar="SOURCE",
                   help="navigation sources: truth or SOURCE[:PRESET], e.g. sins:HG1700, "
                        "ins_gnss:STIM300 (default truth)")
    r.add_argument("--imu", help="IMU preset for --nav sins")
    from fms_testbed.cli.run import add_truth_model_option
    add_truth_model_option(r)
    r.add_argument("--conditions", metavar="FILE.yaml",
                   help="condition sets from a YAML file (instead of --wind/--isa-dev-c/--nav)")
    r.add_argument("--missed", action="store_true",
                   help="approach cases fly their missed approach (go-around at the MAP, "
                        "one holding circuit)")
    r.add_argument("--combinations", choices=("each", "all"), default="each",
                   help="each: fewest sequences flying every transition once (default); all: "
                        "every runway × en-route/approach transition")
    r.add_argument("--limit", type=bounded_int(1, MAX_CASES), metavar="N", help="fly only the first N cases")
    r.add_argument("--seed", type=SEED, default=0, help="campaign seed (default 0)")
    ex = r.add_mutually_exclusive_group()
    ex.add_argument("--workers", type=bounded_int(1, 1024), metavar="N",
                    help="local worker processes (default: the number of CPUs)")
    ex.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                    help="an existing dask.distributed scheduler (workers with --nthreads 1)")
    r.add_argument("--case-timeout", type=bounded_float(0.0, 7 * 86400.0, "s", lo_open=True), metavar="S",
                   help="wall-time limit of one case, s")
    r.add_argument("--keep", help="per-case artefacts to keep: timeseries,plots (in DIR/cases)")
    r.add_argument("--phase", choices=("test-db", "integration"),
                   help="Danilin phase of the run for the report (default: test-db when the "
                        "database has a test-database manifest, else inferred from the size)")
    r.add_argument("--batch-rows", type=bounded_int(1, 100_000), default=64, metavar="N",
                   help="rows per Parquet part file at most (default 64; a part is also "
                        "written every 15 s)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    r.add_argument("--out", required=True, help="campaign folder (resumed when it holds one)")
    r.add_argument("--overwrite", action="store_true",
                   help="replace an --out folder holding another kind of run, other files or a "
                        "run of other cases (never an input)")
    r.set_defaults(func=cmd_run)


def register(sub) -> None:
    """Add ``regress run|diff|report|testdb``."""
    p = sub.add_parser("regress", help="procedure-database regression runs: run, diff, report")
    rs = p.add_subparsers(dest="regress_command", metavar="SUBCOMMAND")
    _add_run(rs)

    d = rs.add_parser("diff", help="compare two runs (exit 1 when something changed)")
    d.add_argument("run_a", help="campaign folder A (the reference)")
    d.add_argument("run_b", help="campaign folder B")
    d.add_argument("--tolerance", metavar="FILE.yaml", help="per-column tolerances")
    d.add_argument("--markdown", metavar="FILE.md", help="also write the summary as Markdown")
    d.add_argument("--across-conditions", action="store_true",
                   help="match cases without their condition set (e.g. calm run vs wind run)")
    d.set_defaults(func=cmd_diff)

    q = rs.add_parser("report", help="write DIR/report.html (self-contained)")
    q.add_argument("dir", help="campaign folder")
    q.add_argument("--worst", type=bounded_int(0, 1000), default=6, help="worst cases drawn (default 6)")
    q.add_argument("--with", dest="others", nargs="+", metavar="DIR",
                   help="other runs for the phase table (e.g. the test-database phase)")
    q.add_argument("--no-refly", action="store_true",
                   help="do not re-fly worst cases whose timeseries were not kept")
    q.set_defaults(func=cmd_report)

    t = rs.add_parser("testdb", help="write the phase-1 test database and its manifest")
    t.add_argument("--out", required=True, metavar="FILE",
                   help="database file to write (the manifest goes to FILE.manifest.json)")
    t.set_defaults(func=cmd_testdb)

    def _help(args) -> int:
        p.print_help()
        return 2

    p.set_defaults(func=_help)
