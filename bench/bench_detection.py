"""Detection limits, threshold calibration and false alarms of the identification, on the
Monte-Carlo engine (the 33-state SINS error model as truth; docs/navigation.md, "Detection
limits").

    python bench/bench_detection.py table [--seeds 20] [--workers 2]      # writes the table
    python bench/bench_detection.py calibrate [--runs 200] [--seed 1000]  # fault-free maxima
    python bench/bench_detection.py false-alarms [--runs 1000] [--seed 2000] [--workers 2]
    python bench/bench_detection.py --quick                               # all three, small

``table``: each fault kind and size on INS 2 (GNSS and baro faults on those sensors) at
t = 200 s of the ``manoeuvres`` profile, ``--seeds`` realisations of seed 0: median and worst
time from the fault to the first detection and to the isolation of the right source, next to
T* (:mod:`fms_testbed.evaluation.detection_limit`) at the goal's false-alarm rate 3e-3/h;
writes ``docs/results/detection_limits.md``.

``calibrate``: one-hour fault-free realisations of ``--seed`` (the calibration set): the
largest statistic of each layer per hour, a Gumbel fit to those maxima, and the threshold that
fit exceeds once in 1/(3e-4) hours per layer; writes ``docs/results/fdi_calibration.md``.

``false-alarms``: one-hour fault-free realisations of ``--seed`` (disjoint from the calibration
streams: realisation i of seed s draws from SeedSequence([s, i])) with the default (calibrated)
tuning: every isolation, exclusion and GNSS/baro naming; writes
``docs/results/fdi_false_alarms.md``.

``--run-s`` (calibrate, false-alarms): realisations of that length instead of an hour (the
rates per hour become chances per realisation in proportion). ``--quick``: the three in turn at
the sizes of :data:`QUICK` (one fault of each source in the table, a few 300 s realisations in
the other two), every page written.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import chi2, gumbel_r

from fms_testbed.core.units import DPH_RPS, G0_MPS2
from fms_testbed.evaluation.detection_limit import (arl0_samples, cusum_mean_shift_s,
                                                    cusum_variance_s, ramp_s,
                                                    unit_against_others_sigma)
from fms_testbed.evaluation.montecarlo import synthetic_states
from fms_testbed.navigation.identification.tuning import FdiTuning
from fms_testbed.navigation.montecarlo import McConfig, McFault, McResult, MonteCarlo, run_chunks
from fms_testbed.sensors.gnss import GnssSpec, Interval, OutlierBurst, Ramp
from fms_testbed.sensors.sins.presets import load_imu

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

PAGES = ("fdi_calibration.md", "fdi_false_alarms.md", "detection_limits_without_drift.md",
         "detection_limits_drift.md", "detection_limits_cusum_step.md",
         "fdi_calibration_cusum.md", "fdi_false_alarms_cusum.md", "detection_limits_cusum_22.md",
         "detection_limits_cusum_50.md", "detection_limits_cusum_100.md")
"""The docs/results pages this bench writes (``--only 'gyro drift'`` with and without
``--exclude`` for the two detection-limit pages; ``--only 'gyro step' --sensor-test cusum`` for
the CUSUM comparison, ``--only 'x 22'`` (``'x 50'``, ``'x 100'``) with it for one row;
``calibrate`` and ``false-alarms`` with ``--sensor-test cusum`` for its
threshold and false alarms)."""
RATE_PER_H = 3e-3
"""The goal's false-alarm rate (zero in 1,000 one-hour flights: ≤ 3e-3/h at 95 %)."""
FAULT_AT_S = 200.0
DT_S = 0.1
QUICK = {"table": {"seeds": 2, "after_s": 60.0,
                   "rows": ("gyro step x 100 °/h", "GNSS ramp E 2 m/s", "baro step 20 m")},
         "calibrate": {"runs": 4, "chunk": 4, "run_s": 300.0},
         "false-alarms": {"runs": 2, "chunk": 1, "run_s": 300.0}}
"""``--quick``: seeds, rows (one fault on an INS, on GNSS, on baro) and simulated s after the
fault of the table; realisations, chunk and simulated s of each realisation of the calibration
and false-alarm sets."""
HOUR_S = 3600.0


def _span(run_s: float) -> str:
    """The length of a realisation, in words."""
    return "one hour" if run_s == HOUR_S else f"{run_s:g} s"


def _rows(imu):
    """(label, McFault or None, GNSS spec change or None, T* s, source, after_s)."""
    arw, vrw = math.sqrt(imu.q_psd[6]), math.sqrt(imu.q_psd[3])
    sg = unit_against_others_sigma(arw / math.sqrt(DT_S), 2)      # rad/s per sample
    sa = unit_against_others_sigma(vrw / math.sqrt(DT_S), 2)      # m/s² per sample
    a_ins = arl0_samples(RATE_PER_H, 3, DT_S)                     # three axes of a triad
    rows = []
    for d in (2.5, 5, 10, 22, 50, 100):
        rows.append((f"gyro step x {d:g} °/h", McFault("gyro_bias_step", d, FAULT_AT_S, 1, "x"),
                     None, cusum_mean_shift_s(d * DPH_RPS, sg, DT_S, a_ins), "ins2", 600.0))
    for mg in (0.75, 3.75, 10):
        rows.append((f"accel step x {mg:g} mg", McFault("accel_bias_step", mg * 1e3,
                                                        FAULT_AT_S, 1, "x"),
                     None, cusum_mean_shift_s(mg * 1e-3 * G0_MPS2, sa, DT_S, a_ins), "ins2",
                     600.0))
    sb = math.sqrt(imu.p0_var[12])
    for k in (2, 5, 10):
        rows.append((f"gyro drift ×{k}", McFault("gyro_drift_scale", k, FAULT_AT_S, 1),
                     None, cusum_mean_shift_s((k - 1) * sb, sg, DT_S, a_ins), "ins2", 1800.0))
    g = GnssSpec()
    a_g = arl0_samples(RATE_PER_H, 1, 1.0 / g.rate_hz)
    for r in (0.5, 2.0):
        ramp = Ramp(Interval(FAULT_AT_S, 1e9), (r, 0.0, 0.0))
        rows.append((f"GNSS ramp E {r:g} m/s", None, GnssSpec(ramps=(ramp,)),
                     ramp_s(r, g.pos_white_sigma_m[0], 1.0 / g.rate_hz, a_g), "gnss", 600.0))
    so = 10.0
    burst = OutlierBurst(Interval(FAULT_AT_S, FAULT_AT_S + 60.0), so)
    rho = 1.0 + (so / g.pos_white_sigma_m[0]) ** 2
    rows.append((f"GNSS outlier burst {so:g} m, 60 s", None, GnssSpec(outliers=(burst,)),
                 cusum_variance_s(rho, 2, 1.0 / g.rate_hz, a_g), "gnss", 600.0))
    bs = McConfig().baro
    rows.append(("baro step 20 m", McFault("baro_step", 20.0, FAULT_AT_S), None,
                 cusum_mean_shift_s(20.0, bs.white_sigma_m, 1.0 / bs.rate_hz,
                                    arl0_samples(RATE_PER_H, 1, 1.0 / bs.rate_hz)),
                 "baro", 600.0))
    return rows


def _times(r, source):
    """(detect (R,), isolate (R,), wrong (R,) bool) from the fault, s."""
    if source == "gnss":
        t = r.t_gnss_s - FAULT_AT_S
        det = np.fmin(r.t_detect_s - FAULT_AT_S, t)
        return det, t, np.isfinite(r.t_isolate_s).any(axis=1) | np.isfinite(r.t_exclude_s).any(1)
    if source == "baro":
        t = r.t_baro_s - FAULT_AT_S
        det = np.fmin(r.t_detect_s - FAULT_AT_S, t)
        return det, t, np.isfinite(r.t_isolate_s).any(axis=1) | np.isfinite(r.t_exclude_s).any(1)
    iso = np.fmin(r.t_isolate_s[:, 1], r.t_exclude_s[:, 1]) - FAULT_AT_S
    wrong = (np.isfinite(r.t_isolate_s[:, [0, 2]]).any(axis=1)
             | np.isfinite(r.t_exclude_s[:, [0, 2]]).any(axis=1) | np.isfinite(r.t_gnss_s)
             | np.isfinite(r.t_baro_s))
    return r.t_detect_s - FAULT_AT_S, iso, wrong


def _fmt(t, after_s):
    """'median / worst' s, with the count never reached."""
    ok = np.isfinite(t)
    if not ok.any():
        return f"— / — (0/{t.size} by {after_s:.0f} s)"
    med = np.median(np.where(ok, t, np.inf))
    worst = "—" if not ok.all() else f"{t.max():.1f}"
    miss = "" if ok.all() else f" ({ok.sum()}/{t.size})"
    return f"{med:.1f} / {worst}{miss}" if math.isfinite(med) else f"— / —{miss}"


def _tuning(args) -> FdiTuning:
    """The default tuning, with ``--sensor-test`` (and ``--cusum-h``, ``--cusum-freeze``) if
    given."""
    kw = {}
    if args.sensor_test:
        kw["sensor_test"] = args.sensor_test
    if args.cusum_h:
        kw["cusum_h"] = args.cusum_h
    if args.cusum_freeze is not None:
        kw["cusum_freeze"] = args.cusum_freeze
    return FdiTuning(**kw)


def _cli(args) -> str:
    """The non-default options, as typed."""
    out = f" --sensor-test {args.sensor_test}" if args.sensor_test else ""
    run_s = getattr(args, "run_s", HOUR_S)
    out += f" --run-s {run_s:g}" if run_s != HOUR_S else ""
    out += f" --cusum-h {args.cusum_h:g}" if args.cusum_h else ""
    return out + (f" --cusum-freeze {args.cusum_freeze:g}" if args.cusum_freeze is not None else "")


def _rows_cli(args) -> str:
    """The row filter, as typed."""
    if not args.only:
        return ""
    return f" --only '{args.only}'" + (" --exclude" if args.exclude else "")


def _suffix(args) -> str:
    """File-name suffix of a non-default sensor test."""
    return "" if args.sensor_test in (None, "window") else f"_{args.sensor_test}"


def table(args) -> None:
    imu = load_imu("STIM300")
    lines = ["| fault | T* (s) | detect median / worst (s) | isolate median / worst (s) | "
             "isolate median / T* | wrong source | wall (s) |", "|---|---|---|---|---|---|---|"]
    for label, fault, gspec, tstar, source, after in _rows(imu):
        if args.only and (args.only in label) == args.exclude:
            continue
        if args.quick and label not in QUICK["table"]["rows"]:
            continue
        after = getattr(args, "after_s", None) or after
        states = synthetic_states("manoeuvres", FAULT_AT_S + after)
        cfg = McConfig(fdi=_tuning(args)) if gspec is None else McConfig(gnss=gspec,
                                                                         fdi=_tuning(args))
        t0 = time.perf_counter()
        r = run_chunks(MonteCarlo(states, cfg, seed=0), args.seeds, args.seeds, fault,
                       workers=1)
        det, iso, wrong = _times(r, source)
        ok = np.isfinite(iso)
        ratio = (np.median(np.where(ok, iso, np.inf)) / tstar) if ok.any() else math.inf
        lines.append(f"| {label} | {tstar:.1f} | {_fmt(det, after)} | {_fmt(iso, after)} | "
                     f"{ratio:.2f} | {int(wrong.sum())}/{wrong.size} | "
                     f"{time.perf_counter() - t0:.0f} |")
        print(lines[-1], flush=True)
    part = "" if not args.only else ("_without_" if args.exclude else "_") + args.only.split()[-1]
    out = f"detection_limits{_suffix(args)}{part}.md"
    rows = (f" (quick run: the rows {', '.join(QUICK['table']['rows'])}, each run ending "
            f"{args.after_s:g} s after the fault)" if args.quick else "")
    head = (f"Seeds 0-{args.seeds - 1} of run seed 0, fault at t = {FAULT_AT_S:g} s of the "
            f"`manoeuvres` profile (`python bench/bench_detection.py table --seeds "
            f"{args.seeds}{_cli(args)}{_rows_cli(args)}`{rows}); T* at {RATE_PER_H:g} false "
            "alarms per hour.\n\n")
    report.write(out, head + "\n".join(lines))


LAYERS = ("stage-1 output pair |Δ|/σ", "sensor-level |z|", "stage-2 |Z_i − Ẑ|/σ",
          "innovation Σ NIS / χ²(1−α)")


def calibrate(args) -> None:
    states = synthetic_states("manoeuvres", args.run_s)
    t0 = time.perf_counter()
    r = run_chunks(MonteCarlo(states, McConfig(fdi=_tuning(args)), seed=args.seed), args.runs,
                   args.chunk, workers=args.workers)
    per_layer = 3e-4
    rows = []
    for j, name in enumerate(LAYERS):
        m = r.stat_max[:, j]
        loc, scale = gumbel_r.fit(m)
        per_run = per_layer * args.run_s / HOUR_S       # the rate per hour as a chance per run
        rows.append((name, f"{m.max():.2f}", f"{loc:.2f}, {scale:.3f}",
                     f"{gumbel_r.isf(per_run, loc, scale):.2f}"))
        print(rows[-1], flush=True)
    lines = [report.table(("layer", "max over the set", "Gumbel (loc, scale)",
                           f"threshold at {per_layer:g}/h"), rows)]
    head = (f"Calibration set: realisations 0-{args.runs - 1} of seed {args.seed}, "
            f"{_span(args.run_s)} of "
            f"the `manoeuvres` profile each (`python bench/bench_detection.py calibrate --runs "
            f"{args.runs} --seed {args.seed}{_cli(args)}`, {time.perf_counter() - t0:.0f} s "
            "wall).\n\n")
    report.write(f"fdi_calibration{_suffix(args)}.md", head + "\n".join(lines))


def _fa_chunk(job):
    """One chunk of the false-alarm set (worker process)."""
    seed, first, n, tuning, run_s = job
    states = synthetic_states("manoeuvres", run_s)
    return run_chunks(MonteCarlo(states, McConfig(fdi=tuning), seed=seed), n, n, first=first)


def false_alarms(args) -> None:
    """Chunks of ``--chunk`` realisations on ``--workers`` processes; the page is rewritten
    after every chunk, so an interrupted run leaves the counts of the chunks it finished."""
    from concurrent.futures import ProcessPoolExecutor

    t0 = time.perf_counter()
    jobs = [(args.seed, a, min(args.chunk, args.runs - a), _tuning(args), args.run_s)
            for a in range(0, args.runs, args.chunk)]
    done = []
    with ProcessPoolExecutor(max_workers=args.workers) as ex:
        for r in ex.map(_fa_chunk, jobs):
            done.append(r)
            _write_false_alarms(args, done, time.perf_counter() - t0)


def _write_false_alarms(args, parts, wall_s) -> None:
    r = McResult.concat(parts)
    n = r.index.size
    iso = np.isfinite(r.t_isolate_s).any(axis=1)
    exc = np.isfinite(r.t_exclude_s).any(axis=1)
    sens = np.isfinite(r.t_gnss_s) | np.isfinite(r.t_baro_s)
    det = np.isfinite(r.t_detect_s)
    anyf = iso | exc | sens
    k = int(anyf.sum())
    bound = chi2.ppf(0.95, 2 * k + 2) / 2 / (n * args.run_s / HOUR_S)
    state = "" if n == args.runs else f" — interrupted: {n} of the {args.runs} realisations run"
    text = (f"Disjoint set: realisations 0-{n - 1} of seed {args.seed}, {_span(args.run_s)} of the "
            f"`manoeuvres` profile each, default tuning (`python bench/bench_detection.py "
            f"false-alarms --runs {args.runs} --seed {args.seed} --chunk {args.chunk} "
            f"--workers {args.workers}{_cli(args)}`, {wall_s:.0f} s wall{state}).\n\n"
            "| runs | detections | isolations | exclusions | GNSS/baro named | "
            "any false removal | 95 % bound (1/h) |\n|---|---|---|---|---|---|---|\n"
            f"| {n} | {int(det.sum())} | {int(iso.sum())} | {int(exc.sum())} | "
            f"{int(sens.sum())} | {k} | {bound:.2e} |\n")
    if k:
        text += f"\nRealisations with a false removal: {list(r.index[anyf])}\n"
    report.write(f"fdi_false_alarms{_suffix(args)}.md", text)
    print(text, flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    report.add_quick(ap, "table, calibrate and false-alarms in turn at a few realisations each")
    sub = ap.add_subparsers(dest="cmd")
    t = sub.add_parser("table")
    t.add_argument("--seeds", type=int, default=20)
    t.add_argument("--only", default=None, help="rows whose label contains this text")
    t.add_argument("--exclude", action="store_true", help="rows whose label does not")
    subs = [t]
    for name, runs, seed in (("calibrate", 200, 1000), ("false-alarms", 1000, 2000)):
        c = sub.add_parser(name)
        subs.append(c)
        c.add_argument("--runs", type=int, default=runs)
        c.add_argument("--seed", type=int, default=seed)
        c.add_argument("--chunk", type=int, default=100)
        c.add_argument("--workers", type=int, default=1)
        c.add_argument("--run-s", type=float, default=HOUR_S,
                       help="simulated s of each realisation (default one hour)")
    for c in subs:
        c.add_argument("--sensor-test", choices=("window", "cusum"), default=None)
        c.add_argument("--cusum-h", type=float, default=None)
        c.add_argument("--cusum-freeze", type=float, default=None,
                       help="hold the CUSUM's reference above this fraction of h (default: never)")
    args = ap.parse_args()
    run = {"table": table, "calibrate": calibrate, "false-alarms": false_alarms}
    if not args.quick:
        if args.cmd is None:
            ap.error("name the run: table, calibrate or false-alarms (or --quick)")
        run[args.cmd](args)
        return
    for cmd in [args.cmd] if args.cmd else list(run):
        one = args if cmd == args.cmd else ap.parse_args(["--quick", cmd])
        for k, v in QUICK[cmd].items():
            if k != "rows":
                setattr(one, k, v)
        run[cmd](one)


if __name__ == "__main__":
    main()
