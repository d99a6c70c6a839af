"""``fms-testbed montecarlo``: Monte-Carlo statistics of the three-INS / GNSS / baro navigation and
its two-stage fault identification, vectorised over realisations.

    fms-testbed montecarlo [--runs 1000] [--duration-min 60] [--profile turns|straight|manoeuvres
        | --trajectory RUN_DIR] [--imu STIM300] [--outage START_S:END_S ...]
        [--fault KIND:AXIS:SIZE[,SIZE...] ...] [--fault-runs 50] [--fault-at-s 200]
        [--fault-duration-min 10] [--rnp-nm 0.3] [--seed 0] [--chunk 250] [--workers 1] --out DIR

Fault kinds: ``gyro_bias_step`` (sizes deg/h) and ``accel_bias_step`` (sizes µg), on INS 2.
Writes into ``--out``: ``montecarlo.csv`` and ``montecarlo.md`` (one row per phase: false
exclusions and their 95 % upper rate bound, detection / missed-detection rates, times to detect,
isolate and exclude, NSE95 with and without GNSS, RNP containment in outages),
``realisations.csv`` (per realisation and phase: detection/isolation/exclusion times, NSE max),
``summary.json`` and ``montecarlo.png``. Each realisation's seed is derived from ``--seed`` and its
index, so the numbers do not depend on ``--chunk`` or ``--workers`` (beyond round-off). Exit 0; 2 on a user error.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

from fms_testbed.cli.common import (SEED, add_overwrite_option, bounded_float, bounded_int,
                                    markdown_table, out_path)
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import NM_M


def _outages(texts):
    from fms_testbed.sensors.gnss import Interval

    out = []
    for t in texts or []:
        try:
            a, b = (float(x) for x in t.split(":"))
        except ValueError:
            raise UserError(f"--outage {t!r}: expected START_S:END_S, e.g. 1800:1920") from None
        if not b > a >= 0:
            raise UserError(f"--outage {t!r}: needs 0 <= START_S < END_S")
        out.append(Interval(a, b))
    return tuple(out)


def _faults(texts, t_s: float):
    from fms_testbed.core.errors import ConfigError
    from fms_testbed.navigation.montecarlo import McFault

    out = []
    for t in texts or []:
        parts = t.split(":")
        if len(parts) != 3:
            raise UserError(f"--fault {t!r}: expected KIND:AXIS:SIZE[,SIZE...], e.g. "
                            "gyro_bias_step:z:2.5,20")
        try:
            sizes = [float(x) for x in parts[2].split(",")]
        except ValueError:
            raise UserError(f"--fault {t!r}: sizes must be numbers") from None
        if not all(math.isfinite(s) for s in sizes):
            raise UserError(f"--fault {t!r}: sizes must be finite numbers (a NaN or infinite "
                            "bias is not a fault size)")
        for s in sizes:
            try:
                out.append(McFault(parts[0], s, t_s, 1, parts[1]))
            except ConfigError as exc:
                raise UserError(f"--fault {t!r}: {exc}") from None
    return out


WALL_S_PER_REALISATION_S = 1.0e-3
"""Wall time per simulated second of one realisation on one worker, s (the estimate's rate)."""
MAX_ESTIMATE_H = 24.0
"""A run estimated to take longer (wall time, h) is refused before any work."""
MAX_DURATION_MIN = 1440.0
"""Longest realisation, min (a day)."""


def estimate_wall_s(runs: int, duration_s: float, n_faults: int, fault_runs: int,
                    fault_duration_s: float, workers: int) -> float:
    """Estimated wall time of a run, s: realisation-seconds × :data:`WALL_S_PER_REALISATION_S`
    over the workers.

    Parameters
    ----------
    runs, duration_s : fault-free realisations and their length, s
    n_faults, fault_runs, fault_duration_s : fault phases, realisations per phase, length, s
    workers : processes
    """
    work_s = runs * duration_s + n_faults * fault_runs * fault_duration_s
    return work_s * WALL_S_PER_REALISATION_S / max(1, workers)


def _check(args):
    """Every option checked before any work; the outages, faults and the output folder."""
    from fms_testbed.run.outputs import OutputFolder
    from fms_testbed.sensors.sins.presets import load_imu

    load_imu(args.imu)                                   # unknown preset: one-line error
    outages = _outages(args.outage)
    faults = _faults(args.fault, args.fault_at_s)
    if args.runs == 0 and not faults:
        raise UserError("nothing to run: --runs 0 and no --fault")
    est = estimate_wall_s(args.runs, args.duration_min * 60.0, len(faults), args.fault_runs,
                          args.fault_duration_min * 60.0, args.workers)
    if est > MAX_ESTIMATE_H * 3600.0:
        raise UserError(f"--runs {args.runs} x --duration-min {args.duration_min:g} (and the "
                        f"fault phases): estimated {est / 3600.0:.0f} h of wall time on "
                        f"{args.workers} worker(s), beyond the limit of {MAX_ESTIMATE_H:g} h; "
                        "fewer or shorter realisations, or more --workers")
    if est > 60.0:
        print(f"montecarlo: estimated {est / 60.0:.0f} min of wall time", file=sys.stderr)
    folder = OutputFolder(out_path(args.out), getattr(args, "overwrite", False), "montecarlo",
                          [args.trajectory] if args.trajectory else [])
    return outages, faults, folder


def _states(args, dur: float, fdur: float):
    from fms_testbed.evaluation.montecarlo import flown_states, synthetic_states

    if args.trajectory:
        return (flown_states(args.trajectory, duration_s=dur),
                flown_states(args.trajectory, duration_s=fdur),
                f"flown trajectory {args.trajectory}")
    return (synthetic_states(args.profile, dur), synthetic_states(args.profile, fdur),
            f"synthetic profile {args.profile}")


def _per_realisation(rep) -> list[dict]:
    per = []
    for label, r in rep.phases.items():
        for j in range(r.index.size):
            per.append({"phase": label, "realisation": int(r.index[j]),
                        "t_detect_s": r.t_detect_s[j],
                        **{f"t_isolate_ins{u + 1}_s": r.t_isolate_s[j, u] for u in range(3)},
                        **{f"t_exclude_ins{u + 1}_s": r.t_exclude_s[j, u] for u in range(3)},
                        "nse_max_m": r.nse_max_m[j], "nse_outage_max_m": r.nse_outage_max_m[j]})
    return per


def _write(folder, rep, args, cfg, where: str, outages, wall: float) -> list[dict]:
    import pandas as pd

    from fms_testbed.viz.figure import save
    from fms_testbed.viz.montecarlo import plot_montecarlo

    df = rep.to_pandas()
    rows = [{k: (None if isinstance(v, float) and math.isnan(v) else v)
             for k, v in rep.row(label).items()} for label in rep.phases]
    try:
        with folder as tmp:
            df.to_csv(tmp / "montecarlo.csv", index=False, float_format="%.6g")
            pd.DataFrame(_per_realisation(rep)).to_csv(tmp / "realisations.csv", index=False,
                                                       float_format="%.6g")
            (tmp / "montecarlo.md").write_text(markdown_table(df.round(4)) + "\n")
            save(plot_montecarlo(rep), tmp / "montecarlo.png")
            summary = {"seed": args.seed, "imu": args.imu, "trajectory": where,
                       "rnp_m": cfg.rnp_m, "outages_s": [[o.start_s, o.end_s] for o in outages],
                       "wall_time_s": round(wall, 1), "phases": rows,
                       "outputs": ["montecarlo.csv", "montecarlo.md", "realisations.csv",
                                   "summary.json", "montecarlo.png"]}
            (tmp / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
            folder.set_run_info(command=["fms-testbed", *sys.argv[1:]], seed=args.seed)
    except OSError as exc:
        raise UserError(f"--out {args.out}: cannot write the outputs: "
                        f"{exc.strerror or exc}") from None
    return rows


def _print(rows: list[dict], args, where: str, wall: float) -> None:
    from fms_testbed.evaluation.montecarlo import rate_upper_95

    print(f"montecarlo: {where}, {args.imu} x3, seed {args.seed}, {wall:.0f} s wall")
    for row in rows:
        if "false_exclusions" in row:
            k, h = row["false_exclusions"], row["hours"]
            print(f"  fault-free: {row['runs']} runs x {row['duration_s'] / 60:.0f} min: "
                  f"{k} false exclusions, rate <= {rate_upper_95(k, h):.2e} /h (95 %), "
                  f"{row['false_detections']} stage-1 detections; NSE95 {row['nse95_gnss_m']:.2f} m"
                  f" with GNSS, {row['nse95_coast_m']:.2f} m coasting")
        else:
            fmt = lambda v: "-" if v is None else f"{v:.1f}"  # noqa: E731
            print(f"  {row['phase']}: excluded {100 * row['excluded_frac']:.0f} %, missed "
                  f"{100 * row['missed_detection_rate']:.0f} %, wrong {row['wrong_exclusions']}, "
                  f"median time to detect {fmt(row['ttd_median_s'])} s, to exclude "
                  f"{fmt(row['tte_median_s'])} s")
    print(f"  outputs in {args.out}")


def cmd_montecarlo(args) -> int:
    """Run the phases, write the tables, the per-realisation CSV, the summary and the plot."""
    from fms_testbed.evaluation.montecarlo import run_campaign
    from fms_testbed.navigation.montecarlo import McConfig
    from fms_testbed.sensors.gnss import GnssSpec

    outages, faults, folder = _check(args)
    dur, fdur = args.duration_min * 60.0, args.fault_duration_min * 60.0
    states, fstates, where = _states(args, dur, fdur)
    if faults and fstates[-1].t_s - fstates[0].t_s <= args.fault_at_s:
        raise UserError(f"--fault-at-s {args.fault_at_s:g} s is past the end of the fault runs "
                        f"({fstates[-1].t_s - fstates[0].t_s:.0f} s)")
    cfg = McConfig(imu=args.imu, gnss=GnssSpec(outages=outages), rnp_m=args.rnp_nm * NM_M)
    t0 = time.perf_counter()
    last = [0.0]

    def progress(k, n):
        if sys.stderr.isatty() and time.perf_counter() - last[0] > 5:
            last[0] = time.perf_counter()
            print(f"\r  step {k}/{n}", end="", file=sys.stderr, flush=True)

    rep = run_campaign(states, cfg, args.seed, args.runs, faults, fstates, args.fault_runs,
                       args.chunk, progress, args.workers)
    wall = time.perf_counter() - t0
    rows = _write(folder, rep, args, cfg, where, outages, wall)
    if sys.stderr.isatty():
        print("", file=sys.stderr)
    _print(rows, args, where, wall)
    return 0


def register(sub) -> None:
    """Add ``montecarlo`` to the CLI."""
    from fms_testbed.evaluation.montecarlo import SYNTHETIC

    p = sub.add_parser("montecarlo", help="Monte-Carlo statistics of the three-INS navigation "
                                          "and its fault identification")
    p.add_argument("--runs", type=bounded_int(0, 1_000_000), default=1000,
                   help="fault-free realisations (default 1000; 0: fault phases only)")
    p.add_argument("--duration-min", default=60.0,
                   type=bounded_float(0.0, MAX_DURATION_MIN, "min", lo_open=True),
                   help="length of a fault-free realisation, min (default 60)")
    p.add_argument("--profile", default="manoeuvres", choices=SYNTHETIC,
                   help="built-in synthetic trajectory (default manoeuvres)")
    p.add_argument("--trajectory", metavar="RUN_DIR",
                   help="fly a run's timeseries instead of a synthetic profile")
    p.add_argument("--imu", default="STIM300", help="IMU preset of the three units "
                                                    "(default STIM300)")
    p.add_argument("--outage", action="append", metavar="START_S:END_S",
                   help="GNSS outage in every realisation, s (repeatable)")
    p.add_argument("--fault", action="append", metavar="KIND:AXIS:SIZE[,SIZE]",
                   help="fault phase(s) on INS 2: gyro_bias_step (deg/h) or accel_bias_step "
                        "(ug), e.g. gyro_bias_step:z:2.5,20,50 (repeatable)")
    p.add_argument("--fault-runs", type=bounded_int(1, 100_000), default=50,
                   help="realisations per fault phase (default 50)")
    p.add_argument("--fault-at-s", type=bounded_float(0.0, MAX_DURATION_MIN * 60.0, "s"),
                   default=200.0,
                   help="fault time after the start, s (default 200)")
    p.add_argument("--fault-duration-min", default=10.0,
                   type=bounded_float(0.0, MAX_DURATION_MIN, "min", lo_open=True),
                   help="length of a fault realisation, min (default 10)")
    p.add_argument("--rnp-nm", type=bounded_float(0.0, 30.0, "NM", lo_open=True), default=0.3,
                   help="RNP of the containment statistics, NM (default 0.3)")
    p.add_argument("--seed", type=SEED, default=0, help="run seed (default 0)")
    p.add_argument("--chunk", type=bounded_int(1, 100_000), default=250,
                   help="realisations computed together (memory; the numbers do not depend on "
                        "it; default 250)")
    p.add_argument("--workers", type=bounded_int(1, 256), default=1,
                   help="processes running chunks in parallel (default 1; the numbers do not "
                        "depend on it)")
    p.add_argument("--out", required=True, help="output folder")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_montecarlo)
