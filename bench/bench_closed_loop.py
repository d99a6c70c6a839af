"""Closed-loop speed over bare JSBSim speed, same aircraft, same process (issue 2 goal >= 0.7).

Bare: ``fdm.run()`` on the sanitised model at 120 Hz, trimmed, controls untouched, no Python
work per frame. Closed loop: the testbed's :class:`~fms_testbed.runner.Flight` flying a scenario
(turns, a level change) with every inner loop active (JSBSim system), heading hold and the coupled
law in Python at the default outer rate (10 Hz), logging at 10 Hz.

The two are timed in alternating 10 s chunks over the whole flight (``interleave.py``: this
machine's speed drifts too much for separate runs). The closed loop is measured with the aircraft
file's inner-loop rate (60 Hz, ``frames_per_update: 2``) and, for reference, at 120 Hz.

    python bench/bench_closed_loop.py [--aircraft 737] [--sim-s 600]
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import CHUNK_S, interleaved_ratio  # noqa: E402

from fms_testbed.aircraft import load_aircraft  # noqa: E402
from fms_testbed.jsbsim_core import DT_S  # noqa: E402
from fms_testbed.runner import Flight, run_scenario  # noqa: E402
from fms_testbed.scenario import parse_scenario  # noqa: E402

def bench_scenario(aircraft: str, alt_m: float, tas_mps: float, sim_s: float) -> dict:
    """The benchmark flight: hold, a heading change, a 300 m climb, a heading change back."""
    return {"name": "bench", "aircraft": aircraft, "duration_s": sim_s, "hold": True,
            "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": alt_m, "tas_mps": tas_mps,
                        "heading_deg": 90},
            "events": [{"t_s": 10, "heading_deg": 180}, {"t_s": 60, "alt_m": alt_m + 300},
                       {"t_s": 200, "heading_deg": 90}]}


def measure(cfg, scn: dict) -> dict:
    """Interleaved ratio of the benchmark flight with aircraft configuration ``cfg``."""
    res = interleaved_ratio(Flight(parse_scenario(scn), cfg=cfg, progress=False), cfg)
    if res["summary"]["status"] != "ok":
        raise SystemExit(f"benchmark flight failed: {res['summary']['reason']}")
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--sim-s", type=float, default=600.0)
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    cfg = load_aircraft(args.aircraft)
    pt = cfg.default_condition
    scn = bench_scenario(args.aircraft, pt.alt_m, pt.tas_mps, args.sim_s)
    rate = 1.0 / (DT_S * cfg.inner_loops.frames_per_update)
    m = measure(cfg, scn)
    ratio, b, c = m["ratio"], m["bare_fps"], m["closed_fps"]
    cfg120 = cfg.model_copy(update={"inner_loops": cfg.inner_loops.model_copy(
        update={"frames_per_update": 1})})
    m120 = measure(cfg120, scn)
    ratio120, b120, c120 = m120["ratio"], m120["bare_fps"], m120["closed_fps"]
    res = run_scenario(scn, progress=False)
    whole = res.summary["duration_s"] / DT_S / res.summary["wall_time_s"]
    print(f"aircraft {args.aircraft}, {args.sim_s:.0f} s simulated at 120 Hz, outer loop "
          f"{scn.get('outer_rate_hz', 10)} Hz, interleaved in {CHUNK_S:.0f} s chunks")
    print(f"bare JSBSim:             {b:9.0f} frames/s ({b * DT_S:5.0f}x real time)")
    print(f"closed loop:             {c:9.0f} frames/s ({c * DT_S:5.0f}x real time), "
          f"inner loops at {rate:.0f} Hz")
    print(f"ratio closed/bare: {ratio:.2f}  (goal >= 0.70)")
    print(f"  with the inner loops at 120 Hz: {ratio120:.2f} "
          f"(bare {b120:.0f}, closed {c120:.0f} frames/s)")
    print(f"  whole run_scenario (load, trim, loop, DataFrame), not interleaved: "
          f"{whole:.0f} frames/s = {whole / b:.2f} of bare")


if __name__ == "__main__":
    main()
