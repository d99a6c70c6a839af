"""Procedure flight speed over bare JSBSim speed, same aircraft, same process (issue 6 goal ≥ 0.5).

Bare: ``fdm.run()`` on the sanitised, trimmed model at 120 Hz with no Python work per frame.
Procedure flight: the demo SID (KJFK DEEZZ5 RW31L CANDR from the embedded database), 15
simulated minutes, with the procedure guidance, the coupled law and the inner loops, logging at
10 Hz, truth navigation, at each ``--rates`` guidance/law rate (10 Hz is the default). Each flight
is timed interleaved with the bare instance in 10 s chunks (``interleave.py``); the path build
and the error analysis are excluded (the build is timed separately and printed). Also prints the
guidance's own cost per call and the runner alone (holding, no guidance) for comparison.

    python bench/bench_fly.py [--sim-s 900]
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from interleave import interleaved_ratio  # noqa: E402

from fms_testbed.config.aircraft import load_aircraft  # noqa: E402
from fms_testbed.data import scenarios_dir  # noqa: E402


def procedure_ratio(sim_s: float, rate_hz: float) -> tuple[dict, float, float]:
    """(interleaved timing of the procedure flight, path build time s, µs per guidance call)."""
    import yaml

    from fms_testbed.loop.procedure import prepare, runner_log_every
    from fms_testbed.guidance.fms import ProcedureGuidance
    from fms_testbed.guidance.vertical import procedure_law
    from fms_testbed.loop.flight import Flight

    raw = yaml.safe_load((scenarios_dir() / "demo-sid.yaml").read_text())
    raw["duration_s"] = sim_s
    raw["outer_rate_hz"] = rate_hz
    t0 = time.perf_counter()
    scn, spec, fp, db = prepare(raw, "demo-sid.yaml")
    build = time.perf_counter() - t0
    cfg = load_aircraft(scn.aircraft)
    g = ProcedureGuidance(fp, cfg, db=db, spec=spec, log_every=runner_log_every(scn))
    calls = [0, 0.0]
    inner = g.update

    def timed(dt_s, nav, truth):
        t = time.perf_counter()
        out = inner(dt_s, nav, truth)
        calls[1] += time.perf_counter() - t
        calls[0] += 1
        return out

    g.update = timed
    flight = Flight(scn, cfg=cfg, guidance=g, progress=False, vertical_law=procedure_law(cfg))
    res = interleaved_ratio(flight, cfg)
    assert res["summary"]["status"] == "ok", res["summary"]
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
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    print(f"737, demo SID, {args.sim_s:.0f} s simulated at 120 Hz, each flight interleaved with "
          "bare JSBSim in 10 s chunks")
    build = None
    for r in args.rates:
        res, build, per_call = procedure_ratio(args.sim_s, r)
        print(f"procedure flight @ {r:4.0f} Hz: {res['closed_fps']:9.0f} frames/s "
              f"(bare {res['bare_fps']:.0f}), ratio {res['ratio']:.2f} (goal >= 0.50); "
              f"guidance {per_call:.1f} µs per call; flew {res['summary']['duration_s']:.0f} s "
              f"({res['summary']['reason']})")
        q = runner_only_ratio(args.sim_s, r)
        print(f"  runner alone @ {r:4.0f} Hz: {q['closed_fps']:9.0f} frames/s, ratio "
              f"{q['ratio']:.2f} (no guidance)")
    print(f"path build {build:.2f} s (once, excluded)")


if __name__ == "__main__":
    main()
