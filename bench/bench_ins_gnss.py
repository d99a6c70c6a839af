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
"""

from __future__ import annotations

import argparse
import time

import numpy as np

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


def faults(n_seeds: int) -> None:
    segs = [Segment(120), Segment(60, 3), Segment(120), Segment(60, -3), Segment(120)]
    states = aircraft_states(fly_profile(segs, dt_s=0.1))
    for fault in FAULTS:
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
                   if e["kind"] == "detected" and e["unit"].startswith("ins")]
            exc = [(round(e["t_s"] - 200, 1), e["unit"]) for e in nav.events
                   if e["kind"] == "excluded"]
            print(f"{fault['kind']} {fault.get('axis', '')} {fault.get('size_dph', fault.get('size_ug', fault.get('factor', '')))}"
                  f" seed {seed}: detected {det[:1]}, excluded {exc[:1]}, NSE max after "
                  f"{max(nse):.2f} m")


def false_alarms(n_runs: int, first_seed: int) -> None:
    rng = np.random.default_rng(0)
    segs: list[Segment] = []
    while sum(s.duration_s for s in segs) < 3600:
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    sub.add_parser("approach").add_argument("--seeds", type=int, default=10)
    sub.add_parser("faults").add_argument("--seeds", type=int, default=2)
    fa = sub.add_parser("false-alarms")
    fa.add_argument("--runs", type=int, default=10)
    fa.add_argument("--first-seed", type=int, default=200)
    a = ap.parse_args()
    if a.what == "approach":
        approach(a.seeds)
    elif a.what == "faults":
        faults(a.seeds)
    else:
        false_alarms(a.runs, a.first_seed)


if __name__ == "__main__":
    main()
