"""Closed-loop speed over bare JSBSim speed, same aircraft, same process (goal ≥ 0.9 on truth).

Bare: ``fdm.run()`` on the sanitised model at 120 Hz, trimmed, controls untouched, no Python
work per frame. Closed loop: the testbed's :class:`~fms_testbed.loop.flight.Flight` flying a scenario
(turns, a level change) with every inner loop active (JSBSim system), heading hold and the coupled
law in Python at the default outer rate (10 Hz), logging at 10 Hz.

The two are timed in alternating 10 s chunks over the whole flight (``interleave.py``: this
machine's speed drifts too much for separate runs). The ceiling of every ratio is measured the
same way: JSBSim with the inner-loop system engaged and no Python work per frame; the Python
work per outer step is ``n_frames (1/closed − 1/ceiling)`` from the two rates. The closed loop is measured with the aircraft
file's inner-loop rate (60 Hz, ``frames_per_update: 2``) and, for reference, at 120 Hz, and at
60 Hz flying on the ``ins_gnss`` source with three INS (STIM300, two-stage identification) instead
of the true state (issue 14's goal: closed loop with it ≥ 0.5 × bare JSBSim).

    python bench/bench_closed_loop.py [--aircraft 737] [--sim-s 600] [--md closed_loop.md] [--quick]

Prints the figures and writes them as a Markdown table to ``docs/results/closed_loop.md``
(``--md ''``: do not write). ``--quick``: :data:`QUICK` (one 80 s flight per configuration,
short warm-up, fewer floor repetitions): every stage runs, the ratios are not the published ones.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import CHUNK_S, interleaved_ratio, system_only_ratio  # noqa: E402
import report  # noqa: E402

from fms_testbed.config.aircraft import load_aircraft  # noqa: E402
from fms_testbed.sim.jsbsim_core import DT_S  # noqa: E402
from fms_testbed.loop.flight import Flight  # noqa: E402
from fms_testbed.run import run_scenario  # noqa: E402
from fms_testbed.config.scenario import parse_scenario  # noqa: E402

INS3 = {"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}
"""The navigation of the third configuration: three INS, GNSS, baro, two-stage identification."""
QUICK = {"sim_s": 80.0, "repeat": 1, "warmup_s": 20.0, "floor_n": 2000}
"""``--quick``: simulated s per flight (the turn and the start of the climb), flights per
configuration, simulated s of each warm-up flight, calls per floor repetition."""


def bench_scenario(aircraft: str, alt_m: float, tas_mps: float, sim_s: float) -> dict:
    """The benchmark flight: hold, a heading change, a 300 m climb, a heading change back."""
    return {"name": "bench", "aircraft": aircraft, "duration_s": sim_s, "hold": True,
            "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": alt_m, "tas_mps": tas_mps,
                        "heading_deg": 90},
            "events": [{"t_s": 10, "heading_deg": 180}, {"t_s": 60, "alt_m": alt_m + 300},
                       {"t_s": 200, "heading_deg": 90}]}


def python_floor_us(cfg, scn: dict, n: int = 20000) -> dict[str, float]:
    """Process time of the Python work no outer step can skip (µs, best of 5 × ``n`` calls):
    the 37 property reads the log needs, the true state, the coupled law, the three inner-loop
    commands."""
    import time

    f = Flight(parse_scenario({**scn, "duration_s": 60.0}), cfg=cfg, progress=False)
    f.step(20)
    ac, law = f.aircraft, f.vertical_law
    raw = ac.read_raw()
    s = ac.state(raw)
    parts = {"read_raw": ac.read_raw, "state": lambda: ac.state(raw),
             "law": lambda: law.update(0.1, s, s.alt_m, s.tas_mps),
             "command": lambda: ac.command(bank_rad=0.0, ny=1.0, nx=0.0)}
    out = {}
    for name, fn in parts.items():
        best = 1e9
        for _ in range(5):
            t0 = time.process_time()
            for _ in range(n):
                fn()
            best = min(best, (time.process_time() - t0) / n)
        out[name] = 1e6 * best
    return out


_NAV = "fms_testbed.navigation."
NAV_PARTS = [(label, _NAV + mod, cls, meth) for mod, cls, parts in (
    ("inertial.bank", "StrapdownBank", (("update", "mechanisations"), ("correct", "feedback"))),
    ("ins_filter", "InsGnssFilter", (("gnss_update", "filters: GNSS updates"),
                                     ("baro_update", "filters: baro updates"))),
    ("fdi", "TwoStageFdi", (("update", "  of it: two-stage identification"),)),
    ("ins_gnss", "InsGnssNavigation", (
        ("_predict", "filters: prediction"), ("solution", "monitors"),
        ("_sensor_pairs", "  of it: sensor-level comparator"),
        ("_reference_description", "  of it: reference description"),
        ("update", "navigation step, all")))) for meth, label in parts]
"""(label, module, class, method) of the parts of P_nav timed by :func:`nav_parts_us`."""


def nav_parts_us(cfg, scn: dict, sim_s: float) -> dict[str, float]:
    """Process time per outer step (µs) of each part of the three-INS navigation step
    (:data:`NAV_PARTS`: each method wrapped with a process-time counter, ~0.3 µs per call) over
    one closed-loop flight of ``sim_s`` simulated seconds; "flight" is the whole loop's."""
    import importlib
    import time

    spent: dict[str, float] = {}
    saved = []
    for label, mod, cls, meth in NAV_PARTS:
        klass = getattr(importlib.import_module(mod), cls)
        fn = getattr(klass, meth)
        saved.append((klass, meth, fn))

        def timed(*a, _fn=fn, _label=label, **k):
            t0 = time.process_time()
            try:
                return _fn(*a, **k)
            finally:
                spent[_label] = spent.get(_label, 0.0) + time.process_time() - t0
        setattr(klass, meth, timed)
    try:
        f = Flight(parse_scenario({**scn, "duration_s": sim_s}), cfg=cfg, progress=False)
        t0 = time.process_time()
        f.run()
        spent["flight"] = time.process_time() - t0
    finally:
        for klass, meth, fn in saved:
            setattr(klass, meth, fn)
    steps = sim_s * scn.get("outer_rate_hz", 10)
    return {k: 1e6 * v / steps for k, v in spent.items()}


def measure(cfg, scn: dict, chunk_s: float = CHUNK_S) -> dict:
    """Interleaved ratio of the benchmark flight with aircraft configuration ``cfg``."""
    res = interleaved_ratio(Flight(parse_scenario(scn), cfg=cfg, progress=False), cfg, chunk_s)
    if res["summary"]["status"] != "ok":
        raise SystemExit(f"benchmark flight failed: {res['summary']['reason']}")
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--sim-s", type=float, default=600.0)
    ap.add_argument("--chunk-s", type=float, default=CHUNK_S,
                    help="simulated seconds per interleaved chunk")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved flights per configuration")
    ap.add_argument("--md", default="closed_loop.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "one 80 s flight per configuration, a 20 s warm-up")
    args = ap.parse_args()
    warmup_s, floor_n, ceiling_s = 60.0, 20000, 300.0
    if args.quick:
        args.sim_s, args.repeat = QUICK["sim_s"], QUICK["repeat"]
        warmup_s, floor_n, ceiling_s = QUICK["warmup_s"], QUICK["floor_n"], QUICK["sim_s"]
    logging.basicConfig(level=logging.WARNING)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    cfg = load_aircraft(args.aircraft)
    pt = cfg.default_condition
    scn = bench_scenario(args.aircraft, pt.alt_m, pt.tas_mps, args.sim_s)
    cfg120 = cfg.model_copy(update={"inner_loops": cfg.inner_loops.model_copy(
        update={"frames_per_update": 1})})
    rate = 1.0 / (DT_S * cfg.inner_loops.frames_per_update)
    runs = {"default": [], "120": [], "ins3": []}
    nav = {"navigation": INS3}
    # warm-up (imports, first JSBSim load, caches): a short flight of each, not measured
    for c in (cfg, cfg120):
        measure(c, bench_scenario(args.aircraft, pt.alt_m, pt.tas_mps, warmup_s), args.chunk_s)
    measure(cfg, {**bench_scenario(args.aircraft, pt.alt_m, pt.tas_mps, warmup_s), **nav},
            args.chunk_s)
    for _ in range(args.repeat):
        runs["default"].append(measure(cfg, scn, args.chunk_s))
        runs["120"].append(measure(cfg120, scn, args.chunk_s))
        runs["ins3"].append(measure(cfg, {**scn, **nav}, args.chunk_s))
    ceil = [system_only_ratio(Flight(parse_scenario(scn), cfg=cfg, progress=False), cfg,
                              ceiling_s) for _ in range(args.repeat)]
    res = run_scenario(scn, progress=False)
    whole = res.summary["duration_s"] / DT_S / res.summary["wall_time_s"]
    print(f"aircraft {args.aircraft}, {args.sim_s:.0f} s simulated at 120 Hz, outer loop "
          f"{scn.get('outer_rate_hz', 10)} Hz, logging 10 Hz, each flight interleaved with bare "
          f"JSBSim in {args.chunk_s:g} s chunks, {args.repeat} flights per configuration")
    labels = {"default": f"inner loops at {rate:.0f} Hz (aircraft file)",
              "120": "inner loops at 120 Hz",
              "ins3": f"inner loops at {rate:.0f} Hz, navigation ins_gnss with three INS"}
    for key, label in labels.items():
        ms = runs[key]
        ratios = [m["ratio"] for m in ms]
        print(f"{label}:")
        for m in ms:
            print(f"  bare {m['bare_fps']:7.0f} frames/s, closed loop {m['closed_fps']:7.0f} "
                  f"frames/s, ratio {m['ratio']:.3f}")
        print(f"  ratio closed/bare: median {statistics.median(ratios):.3f}, "
              f"min {min(ratios):.3f}" + {"default": "  (goal >= 0.90)",
                                         "ins3": "  (goal >= 0.50)"}.get(key, ""))
    c_med = statistics.median(c["ratio"] for c in ceil)
    print(f"ceiling (inner-loop system, no Python): ratio {c_med:.3f}")
    n_frames = int(round(0.1 / DT_S))
    py_us = [1e6 * n_frames * (1.0 / m["closed_fps"] - 1.0 / (m["bare_fps"] * c_med))
             for m in runs["default"]]
    print(f"Python per outer step (default): median {statistics.median(py_us):.1f} us")
    floor = python_floor_us(cfg, scn, floor_n)
    print("Python no outer step can skip: " + ", ".join(f"{k} {v:.2f}" for k, v in floor.items())
          + f" = {sum(floor.values()):.1f} us")
    # the speed goal: the closed loop on three INS against the closed loop on truth, flight by
    # flight (each interleaved with its own bare JSBSim); ratio = T_truth / (T_truth + P_nav)
    nav_ratio = [n["ratio"] / d["ratio"] for n, d in zip(runs["ins3"], runs["default"])]
    t_truth = [1e6 * n_frames / m["closed_fps"] for m in runs["default"]]
    p_nav = [1e6 * n_frames * (1.0 / n["closed_fps"] - 1.0 / d["closed_fps"])
             for n, d in zip(runs["ins3"], runs["default"])]
    print(f"closed loop on three INS / on truth: {', '.join(f'{r:.3f}' for r in nav_ratio)}, "
          f"median {statistics.median(nav_ratio):.3f} (goal >= 0.5); T_truth "
          f"{statistics.median(t_truth):.0f} us, P_nav {statistics.median(p_nav):.0f} us per "
          "outer step (wall, from the rates)")
    parts = nav_parts_us(cfg, {**scn, **nav}, min(args.sim_s, 120.0))
    print("P_nav by part (process time per outer step): " + ", ".join(
        f"{k} {v:.1f} us" for k, v in parts.items()))
    b = statistics.median(m["bare_fps"] for m in runs["default"])
    print(f"whole run_scenario (load, trim, loop, DataFrame), not interleaved: {whole:.0f} "
          f"frames/s = {whole / b:.2f} of the median bare rate")
    rows = []
    labels["120"] = "inner loops at 120 Hz (`frames_per_update: 1`)"
    labels["ins3"] = (f"inner loops at {rate:.0f} Hz, navigation `ins_gnss` three INS "
                      "(STIM300, identification)")
    for key, label in labels.items():
        ms = runs[key]
        ratios = [m["ratio"] for m in ms]
        rows.append([label, ", ".join(f"{r:.3f}" for r in ratios),
                     f"**{statistics.median(ratios):.3f}**",
                     f"{min(m['bare_fps'] for m in ms):.0f}-{max(m['bare_fps'] for m in ms):.0f}",
                     {"default": "≥ 0.90", "ins3": "≥ 0.50"}.get(key, "–")])
    rows.append(["ceiling: JSBSim with the inner-loop system engaged, no Python per frame",
                 ", ".join(f"{c['ratio']:.3f}" for c in ceil), f"**{c_med:.3f}**",
                 f"{min(c['bare_fps'] for c in ceil):.0f}-{max(c['bare_fps'] for c in ceil):.0f}",
                 "–"])
    nav_rows = [[label.strip(), f"{v:.0f}", f"{100 * v / parts['navigation step, all']:.0f} %"]
                for label, v in parts.items() if label not in ("flight",)]
    nav_md = "\n".join([
        "", f"**Navigation on three strapdown INS against truth navigation** (the flights above, "
        f"paired): ratio {', '.join(f'{r:.3f}' for r in nav_ratio)}, median "
        f"**{statistics.median(nav_ratio):.3f}** (goal ≥ 0.5). Per outer step from the rates: "
        f"T_truth {statistics.median(t_truth):.0f} µs, P_nav {statistics.median(p_nav):.0f} µs "
        f"(wall); ratio = T_truth / (T_truth + P_nav), so 0.5 needs P_nav ≤ T_truth.", "",
        f"P_nav by part: process time per outer step, one {min(args.sim_s, 120.0):.0f}-s flight "
        "with each part's method wrapped by a counter (the whole flight "
        f"{parts['flight']:.0f} µs per step):", "",
        report.table(["part", "µs per outer step", "share of the navigation step"], nav_rows)])
    report.write(args.md, report.table(
        ["configuration", "ratio closed loop / bare JSBSim, each flight", "median",
         "bare JSBSim frames/s", "goal"], rows) + "\n" + nav_md,
        note=f"{args.aircraft}, {args.sim_s:.0f} s simulated per flight ("
             + ("quick run: hold, 90° turn, the start of the 300 m climb" if args.quick else
                "hold, 90° turn, 300 m climb, turn back")
             + f"; a {warmup_s:.0f} s unmeasured warm-up flight first), JSBSim at 120 Hz, "
             f"heading hold and coupled law at "
             f"{scn.get('outer_rate_hz', 10)} Hz, logging at 10 Hz; each flight timed "
             f"interleaved with a bare JSBSim instance in {args.chunk_s:g} s chunks. Python work "
             f"per outer step at the default configuration, from the rates: median "
             f"{statistics.median(py_us):.1f} µs; of it no outer step can skip the property reads "
             f"the log needs, the true state, the coupled law and the commands, "
             f"{sum(floor.values()):.1f} µs (process time: "
             + ", ".join(f"{k} {v:.2f}" for k, v in floor.items())
             + f"). Load average at the start: {load}.")


if __name__ == "__main__":
    main()
