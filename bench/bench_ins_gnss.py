"""INS/GNSS navigation figures of docs/navigation.md, printed (not written to docs/results).

    python bench/bench_ins_gnss.py approach [--seeds 10]      # ins-gnss-approach.yaml per seed
    python bench/bench_ins_gnss.py faults [--seeds 2]         # detection/isolation per fault
    python bench/bench_ins_gnss.py false-alarms [--runs 10] [--first-seed 200]   # 1-h runs

``approach`` flies ``scenarios/ins-gnss-approach.yaml`` (STIM300, GNSS outage 120-210 s) and
prints NSE95 with GNSS, NSE max and ANP max in the outage, TSE95, FTE max and loop wall time.
``faults`` injects each fault on INS 2 of three STIM300 units at t = 200 s of a synthetic profile
(straight 120 s, 3 °/s turn 60 s, straight 120 s, -3 °/s turn 60 s, straight 120 s) and prints
the times to the first detection and exclusion and the output's NSE max after it. ``false-alarms``
flies fault-free one-hour runs of a random manoeuvre profile (profile seed 0) and prints every
identification event.

    python bench/bench_ins_gnss.py speed [--sim-s 480] [--md ins_gnss_speed.md]

``speed`` times the three-INS navigation step (``InsGnssNavigation.update`` at 10 Hz on the
synthetic profile of ``faults``) as configured by default (truth-model discretisation shared by
the units and held in straight flight, the filters' covariance propagated over intervals ending
at each GNSS epoch, baro reading, 1 s or 1° of rotation, compiled identification and reference
description) and on the reference paths (every unit and filter discretised at every step),
interleaved in chunks of 10 s simulated in one process (the machine is shared and noisy: the
ratio is the robust figure), and writes ``docs/results/ins_gnss_speed.md``.

    python bench/bench_ins_gnss.py montecarlo --from DIR [DIR ...] [--md montecarlo.md]

``montecarlo`` turns the tables of ``fms-testbed montecarlo --out DIR`` runs (``montecarlo.csv``
and the command in ``run.json``) into ``docs/results/montecarlo.md``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.data import scenarios_dir
from fms_testbed.navigation import make_source
from fms_testbed.run import run_scenario
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile

FAULTS = [
    {"unit": "ins2", "kind": "accel_bias_step", "axis": "x", "size_ug": 3750.0},
    {"unit": "ins2", "kind": "accel_bias_step", "axis": "x", "size_ug": 10000.0},
    *({"unit": "ins2", "kind": "gyro_bias_step", "axis": ax, "size_dph": sz}
      for ax in "xz" for sz in (2.5, 20.0, 50.0, 100.0)),
    {"unit": "ins2", "kind": "stuck"},
    {"unit": "ins2", "kind": "drift_scale", "factor": 2.0},
]


def approach(n_seeds: int) -> None:
    for seed in range(n_seeds):
        res = run_scenario(scenarios_dir() / "ins-gnss-approach.yaml", seed=seed, progress=False)
        df, s = res.df, res.summary
        nse = np.hypot(df.nse_east_m, df.nse_north_m)
        g, o = df.nav_mode == 0, df.nav_mode == 1
        print(f"seed {seed}: {s['status']}, NSE95 with GNSS {np.percentile(nse[g], 95):.2f} m, "
              f"outage NSE max {nse[o].max():.1f} m, ANP max {df.anp_m[o].max():.1f} m, TSE95 "
              f"{s['errors']['tse']['all']['p95_m']} m, FTE max {s['errors']['fte']['all']['max_m']}"
              f" m, loop {s['loop_wall_time_s']:.2f} s")


def faults(n_seeds: int, kinds: list[dict] = FAULTS) -> None:
    segs = [Segment(120), Segment(60, 3), Segment(120), Segment(60, -3), Segment(120)]
    states = aircraft_states(fly_profile(segs, dt_s=0.1))
    for fault in kinds:
        for seed in range(n_seeds):
            nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=seed)
            nse = []
            for s in states:
                sol = nav.update(s)
                if abs(s.t_s - 200.0) < 1e-6:
                    nav.inject(fault, s.t_s)
                if s.t_s >= 200.0:
                    nse.append(np.hypot(sol.errors["nse_east_m"], sol.errors["nse_north_m"]))
            det = [e["t_s"] - 200 for e in nav.events
                   if e["kind"] == "detected" and e["unit"].startswith("ins") and e["t_s"] >= 200]
            exc = [(round(e["t_s"] - 200, 1), e["unit"]) for e in nav.events
                   if e["kind"] == "excluded" and e["t_s"] >= 200]
            print(f"{fault['kind']} {fault.get('axis', '')} {fault.get('size_dph', fault.get('size_ug', fault.get('factor', '')))}"
                  f" seed {seed}: detected {det[:1]}, excluded {exc[:1]}, NSE max after "
                  f"{max(nse):.2f} m")


def false_alarms(n_runs: int, first_seed: int, duration_s: float = 3600.0) -> None:
    rng = np.random.default_rng(0)
    segs: list[Segment] = []
    while sum(s.duration_s for s in segs) < duration_s:
        segs += [Segment(float(rng.uniform(60, 240))),
                 Segment(float(rng.uniform(20, 90)), float(rng.choice([-3, -1.5, 1.5, 3])),
                         float(rng.choice([0, 0, 3, -3])), float(rng.choice([0, 0.3, -0.3])))]
    states = aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150))
    for seed in range(first_seed, first_seed + n_runs):
        t0 = time.perf_counter()
        nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=seed)
        for s in states:
            nav.update(s)
        print(seed, f"{time.perf_counter() - t0:.1f} s",
              [(e["t_s"], e["unit"], e["kind"], e["reason"][:50]) for e in nav.events], flush=True)


def _pair(us: dict) -> str:
    """'straight / turning' µs of a step, '–' for a kind of chunk the profile did not have."""
    return " / ".join("–" if us[w] is None else f"{us[w]:.0f}" for w in (False, True))


def speed(sim_s: float, md: str) -> None:
    segs = [Segment(120), Segment(60, 3), Segment(120), Segment(60, -3), Segment(120)]
    states = aircraft_states(fly_profile(segs, dt_s=0.1))
    states = [s for s in states if s.t_s <= sim_s + 1e-9]
    navs = {}
    for mode in ("per-unit", "fast"):
        spec = {"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}
        if mode == "per-unit":
            spec["matrices_dt_s"] = 0.0
        nav = make_source(spec, seed=1)
        nav.fused = nav.bank.share = mode == "fast"
        navs[mode] = nav
    spent = {m: [] for m in navs}
    chunk = 100                                       # 10 s simulated at 10 Hz
    for k in range(0, len(states), chunk):
        order = list(navs) if (k // chunk) % 2 == 0 else list(navs)[::-1]
        for m in order:
            t0 = time.perf_counter()
            for s in states[k:k + chunk]:
                navs[m].update(s)
            if k > 0:                                 # first chunk: compilation and warm-up
                spent[m].append((time.perf_counter() - t0) / len(states[k:k + chunk]))
    us = {m: 1e6 * statistics.median(v) for m, v in spent.items()}    # robust to a stray chunk
    turning = [max(abs(s.r_rps) for s in states[k:k + chunk]) > 0.01
               for k in range(chunk, len(states), chunk)]
    split = {m: {w: (1e6 * statistics.median(sel) if (sel := [t for t, tr in zip(v, turning)
                                                            if tr == w]) else None)
                 for w in (False, True)} for m, v in spent.items()}
    ratio = [a / b for a, b in zip(spent["fast"], spent["per-unit"])]
    print(f"three-INS navigation step, {len(states) - chunk} steps timed: fast {us['fast']:.0f} µs,"
          f" per-unit {us['per-unit']:.0f} µs, ratio fast/per-unit median "
          f"{statistics.median(ratio):.2f}")
    rows = [["default (shared and held truth model, multi-rate filters)", f"**{us['fast']:.0f}**",
             _pair(split['fast']),
             f"{statistics.median(ratio):.2f}", "≤ 100"],
            ["reference (every unit and filter at every step)", f"{us['per-unit']:.0f}",
             _pair(split['per-unit']), "1", "–"]]
    report.write(md, report.table(["three-INS step (3 INS, 3 filters, identification)",
                                   "µs per step (median over 10 s chunks)",
                                   "straight / turning chunks, µs", "ratio to per-unit, median over chunks",
                                   "goal µs"], rows),
                 note=f"STIM300 ×3, GNSS 1 Hz, baro, 10 Hz, synthetic profile (straight, ±3 °/s "
                      f"turns) {sim_s:.0f} s, the two configurations interleaved in 10 s chunks "
                      "in one process (first chunk unmeasured).")


def montecarlo_table(dirs: list[str], md: str) -> None:
    import json

    import pandas as pd

    ff_rows, f_rows, cmds = [], [], []
    for d in dirs:
        run = json.loads((Path(d) / "run.json").read_text())
        cmds.append("`" + " ".join(a for a in run["command"] if a != "--overwrite") + "`")
        summ = json.loads((Path(d) / "summary.json").read_text())
        df = pd.read_csv(Path(d) / "montecarlo.csv")
        for _, r in df.iterrows():
            cell = lambda v, f="{:.1f}": "–" if pd.isna(v) else f.format(v)  # noqa: E731
            if r["phase"] == "fault-free":
                ff_rows.append([f"{int(r['runs'])} × {r['duration_s'] / 60:.0f} min "
                                f"({summ['trajectory']})", f"**{int(r['false_exclusions'])}**",
                                f"{r['false_exclusion_rate_upper95_per_h']:.2e}",
                                int(r["false_detections"]), cell(r["nse95_gnss_m"], "{:.2f}"),
                                cell(r.get("nse95_coast_m"), "{:.0f}"),
                                cell(r.get("outage_nse_max_p95_m"), "{:.0f}"),
                                cell(r.get("outage_nse_within_rnp"), "{:.4f}"),
                                cell(r.get("outage_anp_within_rnp"), "{:.4f}"),
                                f"{r['wall_s']:.0f}"])
            else:
                f_rows.append([r["phase"], int(r["runs"]), f"{100 * r['excluded_frac']:.0f} %",
                               f"{100 * r['missed_detection_rate']:.0f} %",
                               int(r["wrong_exclusions"]), cell(r["ttd_median_s"]),
                               cell(r["ttd_p95_s"]), cell(r["tte_median_s"]),
                               cell(r["tte_p95_s"]), cell(r["nse_max_p95_m"], "{:.2f}")])
    body = ""
    if ff_rows:
        body += report.table(["fault-free runs", "false exclusions",
                              "false-exclusion rate, 95 % upper bound, 1/h",
                              "stage-1 detections", "NSE95 with GNSS, m", "NSE95 coasting, m",
                              "NSE max in outage, p95 over runs, m", "outage samples NSE ≤ RNP",
                              "outage samples ANP ≤ RNP", "wall s"], ff_rows) + "\n\n"
    if f_rows:
        body += report.table(["fault on INS 2 at 200 s", "runs", "faulty unit excluded",
                              "missed", "healthy unit excluded", "time to detect, median s",
                              "p95 s", "time to exclude, median s", "p95 s",
                              "NSE max, p95 over runs, m"], f_rows)
    report.write(md, body, note="From " + "; ".join(cmds) + " (the CLI's `montecarlo.csv`).")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what")
    sub.add_parser("approach").add_argument("--seeds", type=int, default=10)
    sub.add_parser("faults").add_argument("--seeds", type=int, default=2)
    fa = sub.add_parser("false-alarms")
    fa.add_argument("--runs", type=int, default=10)
    fa.add_argument("--first-seed", type=int, default=200)
    sp = sub.add_parser("speed")
    sp.add_argument("--sim-s", type=float, default=480.0)
    sp.add_argument("--md", default="ins_gnss_speed.md", help="docs/results table ('' to skip)")
    mp = sub.add_parser("montecarlo")
    mp.add_argument("--from", dest="dirs", nargs="+", required=True)
    mp.add_argument("--md", default="montecarlo.md", help="docs/results table ('' to skip)")
    report.add_quick(ap, "without a subcommand: one approach, two faults, a 5-min fault-free "
                         "run and the speed over 60 s simulated")
    a = ap.parse_args()
    if a.what is None:
        if not a.quick:
            ap.error("a subcommand is required (or --quick)")
        approach(1)
        faults(1, FAULTS[:2])
        false_alarms(1, 200, duration_s=300.0)
        speed(60.0, "ins_gnss_speed.md")
    elif a.what == "montecarlo":
        montecarlo_table(a.dirs, a.md)
    elif a.what == "speed":
        speed(a.sim_s, a.md)
    elif a.what == "approach":
        approach(a.seeds)
    elif a.what == "faults":
        faults(a.seeds)
    else:
        false_alarms(a.runs, a.first_seed)


if __name__ == "__main__":
    main()
