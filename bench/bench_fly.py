"""Procedure flight speed over bare JSBSim speed, same aircraft, same process (goal ≥ 0.8 at 10 Hz).

Bare: ``fdm.run()`` on the sanitised, trimmed model at 120 Hz with no Python work per frame.
Procedure flight: the demo SID (KJFK DEEZZ5 RW31L CANDR from the embedded database), 15
simulated minutes, with the procedure guidance, the coupled law and the inner loops, logging at
10 Hz, truth navigation, at each ``--rates`` guidance/law rate (10 Hz is the default). Each flight
is timed interleaved with the bare instance in 10 s chunks (``interleave.py``); the path build
and the error analysis are excluded (the build is timed separately and printed). Also prints the
guidance's own cost per call and the runner alone (holding, no guidance) for comparison.

    python bench/bench_fly.py [--sim-s 900] [--md fly_speed.md]

Writes the figures as a Markdown table to ``docs/results/fly_speed.md`` (``--md ''``: do not).
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import interleaved_ratio  # noqa: E402
import report  # noqa: E402

from fms_testbed.config.aircraft import load_aircraft  # noqa: E402
from fms_testbed.data import scenarios_dir  # noqa: E402


def procedure_ratio(sim_s: float, rate_hz: float) -> tuple[dict, float, float]:
    """(interleaved timing of the procedure flight, path build time s, µs per guidance call)."""
    import yaml

    from fms_testbed.loop.flight import Flight
    from fms_testbed.run import load

    raw = yaml.safe_load((scenarios_dir() / "demo-sid.yaml").read_text())
    raw["duration_s"] = sim_s
    raw["outer_rate_hz"] = rate_hz
    t0 = time.perf_counter()
    scn, proc = load(raw)
    build = time.perf_counter() - t0
    cfg = load_aircraft(scn.aircraft)
    flight = Flight(scn, cfg=cfg, procedure=proc, progress=False)
    g = flight.guidance
    calls = [0, 0.0]
    inner = g.update

    def timed(*args, **kwargs):
        t = time.perf_counter()
        out = inner(*args, **kwargs)
        calls[1] += time.perf_counter() - t
        calls[0] += 1
        return out

    g.update = timed       # the flight's loop looks the method up when it starts
    res = interleaved_ratio(flight, cfg)
    assert res["summary"]["status"] in ("ok", "incomplete"), res["summary"]
    return res, build, 1e6 * calls[1] / max(calls[0], 1)


def runner_only_ratio(sim_s: float, rate_hz: float) -> dict:
    """The runner alone at the same rate (coupled law holding the trimmed state, no guidance),
    interleaved: the share of the slowdown that is not guidance."""
    from fms_testbed.loop.flight import Flight
    from fms_testbed.config.scenario import parse_scenario

    cfg = load_aircraft("737")
    scn = {"name": "bench", "aircraft": "737", "duration_s": sim_s, "hold": True,
           "outer_rate_hz": rate_hz, "initial": {"lat_deg": 40.6, "lon_deg": -73.8,
                                                 "alt_m": 3000.0, "tas_mps": 118.0,
                                                 "heading_deg": 300.0}}
    return interleaved_ratio(Flight(parse_scenario(scn), cfg=cfg, progress=False), cfg)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim-s", type=float, default=900.0)
    ap.add_argument("--rates", type=float, nargs="+", default=[10.0, 20.0],
                    help="guidance/law rates to time, Hz (10 is the procedure default)")
    ap.add_argument("--md", default="fly_speed.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "60 s simulated at 10 Hz only")
    args = ap.parse_args()
    if args.quick:
        args.sim_s, args.rates = 60.0, [10.0]
    logging.basicConfig(level=logging.WARNING)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"737, demo SID, {args.sim_s:.0f} s simulated at 120 Hz, each flight interleaved with "
          "bare JSBSim in 10 s chunks")
    build = None
    rows = []
    for r in args.rates:
        res, build, per_call = procedure_ratio(args.sim_s, r)
        print(f"procedure flight @ {r:4.0f} Hz: {res['closed_fps']:9.0f} frames/s "
              f"(bare {res['bare_fps']:.0f}), ratio {res['ratio']:.2f}{' (goal >= 0.80)' if r == 10 else ''}; "
              f"guidance {per_call:.1f} µs per call; flew {res['summary']['duration_s']:.0f} s "
              f"({res['summary']['reason']})")
        q = runner_only_ratio(args.sim_s, r)
        print(f"  runner alone @ {r:4.0f} Hz: {q['closed_fps']:9.0f} frames/s, ratio "
              f"{q['ratio']:.2f} (no guidance)")
        default = " (default)" if r == 10 else ""
        rows.append([f"procedure flight, guidance + law at {r:g} Hz{default}",
                     f"{res['closed_fps']:.0f}", f"{res['bare_fps']:.0f}",
                     f"**{res['ratio']:.2f}**" if r == 10 else f"{res['ratio']:.2f}",
                     f"{per_call:.1f}", "≥ 0.80" if r == 10 else "–"])
        rows.append([f"flight loop alone at {r:g} Hz (law holding, no guidance)",
                     f"{q['closed_fps']:.0f}", f"{q['bare_fps']:.0f}", f"{q['ratio']:.2f}", "",
                     "–"])
    print(f"path build {build:.2f} s (once, excluded)")
    report.write(args.md, report.table(
        ["run", "frames/s", "bare JSBSim frames/s", "ratio to bare", "guidance µs per call",
         "goal"], rows),
        note=f"737, demo SID (KJFK DEEZZ5 RW31L CANDR, embedded database), {args.sim_s:.0f} s "
             f"simulated at 120 Hz, truth navigation, logging at 10 Hz; each flight timed "
             f"interleaved with a bare JSBSim instance in 10 s chunks. The path build "
             f"({build:.2f} s, once) is excluded. Load average at the start: {load}.")


if __name__ == "__main__":
    main()
