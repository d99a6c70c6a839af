"""Closed-loop speed over bare JSBSim speed, same aircraft, same process (issue 2 goal >= 0.7).

Bare: ``fdm.run()`` on the sanitised model at 120 Hz, trimmed, controls untouched, no Python
work per step. Closed loop: the testbed's runner flying a scenario with every inner loop active
(JSBSim system), heading hold and the coupled law in Python at the default outer rate (10 Hz),
logging at 10 Hz; timed over the flight loop (``summary['loop_steps_per_s']``), and also over
the whole run including model load, trim and building the DataFrame.
Both are timed for the same simulated duration; the runs alternate three times and the median
of each is used.

    python bench/bench_closed_loop.py [--aircraft 737] [--sim-s 600]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time

from fms_testbed.aircraft import load_aircraft
from fms_testbed.jsbsim_core import DT_S, FT, KT, bare_fdm
from fms_testbed.runner import run_scenario


def trimmed_bare_fdm(cfg, alt_m: float, tas_mps: float):
    """A sanitised JSBSim instance of ``cfg``'s model without the inner loops, trimmed."""
    import math

    fdm = bare_fdm(cfg.jsbsim_model)
    fdm["aero/alpha-max-rad"] = math.radians(cfg.trim.alpha_max_deg)
    fdm["ic/h-sl-ft"] = alt_m / FT
    fdm["ic/vt-kts"] = tas_mps / KT
    fdm["ic/lat-geod-deg"] = 47.0
    fdm["gear/gear-cmd-norm"] = 0
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    try:
        fdm["simulation/do_simple_trim"] = 1
    except Exception:  # the timing does not need a perfect trim
        pass
    return fdm


def bare_steps_per_s(cfg, alt_m: float, tas_mps: float, sim_s: float) -> float:
    """Steps per second of a trimmed bare JSBSim instance."""
    fdm = trimmed_bare_fdm(cfg, alt_m, tas_mps)
    n = int(sim_s / DT_S)
    run = fdm.run
    t0 = time.perf_counter()
    for _ in range(n):
        run()
    return n / (time.perf_counter() - t0)


def closed_loop_steps_per_s(aircraft: str, alt_m: float, tas_mps: float, sim_s: float) -> float:
    """JSBSim frames per wall second of a full closed-loop scenario (turns, level change)."""
    scn = {"name": "bench", "aircraft": aircraft, "duration_s": sim_s, "hold": True,
           "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": alt_m, "tas_mps": tas_mps,
                       "heading_deg": 90},
           "events": [{"t_s": 10, "heading_deg": 180}, {"t_s": 60, "alt_m": alt_m + 300},
                      {"t_s": 200, "heading_deg": 90}]}
    res = run_scenario(scn, progress=False)
    assert res.summary["status"] == "ok", res.summary
    return res.summary["loop_steps_per_s"], res.summary["duration_s"] / DT_S / res.summary["wall_time_s"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--sim-s", type=float, default=600.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    cfg = load_aircraft(args.aircraft)
    pt = cfg.default_condition
    bare, closed, whole = [], [], []
    for _ in range(args.repeat):
        bare.append(bare_steps_per_s(cfg, pt.alt_m, pt.tas_mps, args.sim_s))
        loop, run = closed_loop_steps_per_s(args.aircraft, pt.alt_m, pt.tas_mps, args.sim_s)
        closed.append(loop)
        whole.append(run)
    b, c, w = statistics.median(bare), statistics.median(closed), statistics.median(whole)
    print(f"aircraft {args.aircraft}, {args.sim_s:.0f} s simulated at 120 Hz, outer loop at the "
          f"scenario default, median of {args.repeat}")
    print(f"bare JSBSim:             {b:9.0f} steps/s ({b * DT_S:6.0f}x real time)")
    print(f"closed loop:             {c:9.0f} steps/s ({c * DT_S:6.0f}x real time)")
    print(f"  incl. load+trim+output {w:9.0f} steps/s")
    print(f"ratio closed/bare: {c / b:.2f}  (goal >= 0.70); with setup {w / b:.2f}")


if __name__ == "__main__":
    main()
