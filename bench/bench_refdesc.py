"""Fault identification over seeded runs (docs/navigation.md, "Two-stage identification: seeded
distributions" and "Reference description"); prints, writes nothing.

    python bench/bench_refdesc.py steps [--seeds 20] [--extra-s 0] [--only gyro]   # 5σ steps
    python bench/bench_refdesc.py drift [--seeds 5] [--factors 2 5 10] [--imu STIM300]  # 1 h
                                        [--duration-s 3600]
    python bench/bench_refdesc.py false-alarms [--seeds 10] [--duration-s 3600]  # fault-free
    python bench/bench_refdesc.py --quick                         # all three, one seed each

``steps``: three STIM300 units (``ins_gnss``, baro) on a synthetic profile (straight 120 s,
3 °/s turn 60 s, straight 120 s, -3 °/s turn 60 s, straight 120 s, 150 m/s), a bias step of
5σ of the declared bias on INS 2 at t = 200 s: gyro x 2.5 °/h (σ 0.5 °/h) or accelerometer x
3,750 µg (the 750 µg turn-on σ); prints per seed the time from the injection to the first
detection (any stage naming an INS) and to the first isolation/exclusion of INS 2, and the
distribution (median, 90th percentile, worst, counts within 10 s / 30 s).

``drift``: the same units on a one-hour profile (straight legs and ±3 °/s turns every 10 min,
200 m/s), GNSS outage 2,700-3,000 s, INS 2's gyro drift ×k of declared (``drift_scale``) at
t = 600 s (``--duration-s``: a profile of that length, the fault and the outage at the same
fractions of it); prints when the reference-description monitor excludes INS 2 (or another unit), the
fraction of the post-fault time majority voting keeps INS 2 in, and NSE95 after the fault (and in
the outage) of the reference-description output and of the voting output.

``false-alarms``: the one-hour profile without a fault: every exclusion (any stage).

``--quick``: the three in turn at the sizes of :data:`QUICK` (one seed, one drift factor).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from fms_testbed.navigation import make_source
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile

STEPS = {"gyro x 2.5 deg/h (5 sigma)": {"unit": "ins2", "kind": "gyro_bias_step", "axis": "x",
                                          "size_dph": 2.5},
         "accel x 3750 ug (5 sigma)": {"unit": "ins2", "kind": "accel_bias_step", "axis": "x",
                                        "size_ug": 3750.0}}
SPEC = {"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}
QUICK = {"steps": ["--seeds", "1"],
         "drift": ["--seeds", "1", "--factors", "10", "--duration-s", "600"],
         "false-alarms": ["--seeds", "1", "--duration-s", "300"]}
"""``--quick``: the options of each measurement."""

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402


def _fly(states, spec, seed, fault=None, at_s=None):
    nav = make_source(spec, seed=seed)
    rows = []
    for s in states:
        sol = nav.update(s)
        if fault is not None and abs(s.t_s - at_s) < 1e-6:
            nav.inject(fault, s.t_s)
        rows.append((s.t_s, sol.errors))
    return nav, rows


def _dist(x: list[float | None], name: str) -> str:
    got = np.array([v for v in x if v is not None])
    if not got.size:
        return f"{name}: none of {len(x)}"
    return (f"{name}: {got.size}/{len(x)} runs, median {np.median(got):.1f} s, p90 "
            f"{np.percentile(got, 90):.1f} s, worst {got.max():.1f} s; ≤10 s {int((got <= 10).sum())}"
            f", ≤30 s {int((got <= 30).sum())}")


def steps(n_seeds: int, extra_s: float = 0.0, only: str = "") -> None:
    segs = [Segment(120), Segment(60, 3), Segment(120), Segment(60, -3), Segment(120)]
    while extra_s > 0:                      # longer runs: 3 °/s turns every 5 min
        segs += [Segment(min(270.0, extra_s)), Segment(30, 3 if len(segs) % 4 else -3)]
        extra_s -= 300.0
    states = aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150))
    for name, fault in STEPS.items():
        if only and not name.startswith(only):
            continue
        det, iso, wrong = [], [], 0
        for seed in range(n_seeds):
            nav, _ = _fly(states, SPEC, seed, fault, 200.0)
            d = [e["t_s"] - 200 for e in nav.events if e["kind"] == "detected"
                 and e["unit"].startswith("ins") and e["t_s"] >= 200]
            i = [e["t_s"] - 200 for e in nav.events if e["kind"] in ("isolated", "excluded")
                 and e["unit"] == "ins2" and e["t_s"] >= 200]
            wrong += any(e["kind"] == "excluded" and e["unit"] in ("ins1", "ins3")
                         for e in nav.events)
            det.append(round(d[0], 1) if d else None)
            iso.append(round(i[0], 1) if i else None)
            print(f"{name} seed {seed}: detected {det[-1]} s, isolated {iso[-1]} s", flush=True)
        print(_dist(det, f"{name} detection"))
        print(_dist(iso, f"{name} isolation"), f"; wrong unit excluded in {wrong} runs")


def _hour_profile(duration_s: float = 3600.0):
    """Straight 120 s, then ±3 °/s turns of 30 s every 10 min, 200 m/s, at least ``duration_s``
    long."""
    segs: list[Segment] = [Segment(120)]
    while sum(s.duration_s for s in segs) < duration_s:
        segs += [Segment(30, 3 if len(segs) % 4 == 1 else -3), Segment(570)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=200))


def drift(n_seeds: int, factors: list[float], imu: str = "STIM300",
          duration_s: float = 3600.0) -> None:
    states = _hour_profile(duration_s)
    at_s = round(duration_s / 6.0, 1)                       # 600 s of the hour
    o0, o1 = round(0.75 * duration_s, 1), round(duration_s * 5.0 / 6.0, 1)  # 2,700-3,000 s
    spec = {**SPEC, "imu": imu, "gnss": {"outages": [{"start_s": o0, "end_s": o1}]}}
    for k in factors:
        for seed in range(n_seeds):
            fault = {"unit": "ins2", "kind": "drift_scale", "factor": k}
            nav, rows = _fly(states, spec, seed, fault, at_s)
            t = np.array([r[0] for r in rows])
            e = {c: np.array([r[1].get(c, np.nan) for r in rows]) for c in
                 ("nse_ref_east_m", "nse_ref_north_m", "nse_vote_east_m", "nse_vote_north_m",
                  "ins_used_vote")}
            after, out = t >= at_s, (t >= o0) & (t < o1)
            ref = np.hypot(e["nse_ref_east_m"], e["nse_ref_north_m"])
            vote = np.hypot(e["nse_vote_east_m"], e["nse_vote_north_m"])
            keep = float(np.mean(e["ins_used_vote"][after].astype(int) & 2 > 0))
            exc = [(round(ev["t_s"] - at_s, 0), ev["unit"], ev["stage"]) for ev in nav.events
                   if ev["kind"] == "excluded" and ev["unit"].startswith("ins")]
            print(f"{imu} drift x{k:g} seed {seed}: excluded (s after fault, unit, stage) {exc}; vote "
                  f"keeps ins2 {keep:.0%}; NSE95 after fault ref {np.percentile(ref[after], 95):.1f}"
                  f" m, vote {np.percentile(vote[after], 95):.1f} m; in the outage ref "
                  f"{np.percentile(ref[out], 95):.1f} m, vote {np.percentile(vote[out], 95):.1f} m",
                  flush=True)


def false_alarms(n_seeds: int, duration_s: float = 3600.0) -> None:
    states = _hour_profile(duration_s)
    for seed in range(100, 100 + n_seeds):
        nav, _ = _fly(states, SPEC, seed)
        ev = [(e["t_s"], e["unit"], e["kind"], e["stage"]) for e in nav.events
              if e["kind"] in ("excluded", "detected")]
        print(f"fault-free seed {seed}: {ev}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    report.add_quick(ap, "steps, drift and false-alarms in turn, one seed each")
    sub = ap.add_subparsers(dest="what")
    st = sub.add_parser("steps")
    st.add_argument("--seeds", type=int, default=20)
    st.add_argument("--extra-s", type=float, default=0.0,
                    help="fly this much longer after the profile, s (turns every 5 min)")
    st.add_argument("--only", default="", help="only the steps whose name starts with this")
    dr = sub.add_parser("drift")
    dr.add_argument("--seeds", type=int, default=5)
    dr.add_argument("--factors", type=float, nargs="+", default=[2.0, 5.0, 10.0])
    dr.add_argument("--imu", default="STIM300")
    fa = sub.add_parser("false-alarms")
    fa.add_argument("--seeds", type=int, default=10)
    for p in (dr, fa):
        p.add_argument("--duration-s", type=float, default=3600.0,
                       help="simulated s of the profile (default one hour)")
    a = ap.parse_args()
    if not a.quick:
        if a.what is None:
            ap.error("name the measurement: steps, drift or false-alarms (or --quick)")
        run(a)
        return
    for what in [a.what] if a.what else list(QUICK):
        run(ap.parse_args([what, *QUICK[what]]))


def run(a) -> None:
    """One measurement, with the parsed options ``a``."""
    if a.what == "steps":
        steps(a.seeds, a.extra_s, a.only)
    elif a.what == "drift":
        drift(a.seeds, a.factors, a.imu, a.duration_s)
    else:
        false_alarms(a.seeds, a.duration_s)


if __name__ == "__main__":
    main()
