"""Procedure flight speed over bare JSBSim speed, same aircraft, same process (issue 6 goal ≥ 0.5).

Bare: ``fdm.run()`` on the sanitised, trimmed model at 120 Hz with no Python work per step
(``bench_closed_loop.bare_steps_per_s``). Procedure flight: the demo SID (KJFK DEEZZ5 RW31L
CANDR from the embedded database), 15 simulated minutes, with the procedure guidance, the
coupled law and bank inner loops, logging at 10 Hz, truth navigation, at each ``--rates``
guidance/law rate (10 Hz is the procedure default, 20 Hz the runner's) — the path build
and the error analysis excluded (timed separately and printed). The two alternate ``--repeat``
times; medians are compared. Also prints the guidance's own cost per call.

    python bench/bench_fly.py [--sim-s 900] [--repeat 3]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_closed_loop import bare_steps_per_s  # noqa: E402

from fms_testbed.aircraft import load_aircraft  # noqa: E402
from fms_testbed.jsbsim_core import DT_S  # noqa: E402
from fms_testbed.paths import scenarios_dir  # noqa: E402


def procedure_steps_per_s(sim_s: float, rate_hz: float) -> tuple[float, float, float]:
    """(JSBSim frames per wall second of the procedure flight, build time s, µs per guidance
    call)."""
    import yaml

    from fms_testbed.fly import prepare, runner_log_every
    from fms_testbed.guidance.fms import ProcedureGuidance
    from fms_testbed.guidance.vertical import procedure_law
    from fms_testbed.runner import fly

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
    t0 = time.perf_counter()
    df, summary = fly(scn, cfg=cfg, guidance=g, progress=False, vertical_law=procedure_law(cfg))
    wall = time.perf_counter() - t0
    assert summary["status"] == "ok", summary
    return summary["duration_s"] / DT_S / wall, build, 1e6 * calls[1] / max(calls[0], 1)


def runner_only_steps_per_s(sim_s: float, rate_hz: float) -> float:
    """Frames per wall second of the runner alone at the same rates (coupled law holding the
    trimmed state, no guidance): the share of the slowdown that is not guidance."""
    from fms_testbed.runner import run_scenario

    scn = {"name": "bench", "aircraft": "737", "duration_s": sim_s, "hold": True,
           "outer_rate_hz": rate_hz, "initial": {"lat_deg": 40.6, "lon_deg": -73.8,
                                                 "alt_m": 3000.0, "tas_mps": 118.0,
                                                 "heading_deg": 300.0}}
    t0 = time.perf_counter()
    res = run_scenario(scn, progress=False)
    return res.summary["duration_s"] / DT_S / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim-s", type=float, default=900.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rates", type=float, nargs="+", default=[10.0, 20.0],
                    help="guidance/law rates to time, Hz (10 is the procedure default)")
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    cfg = load_aircraft("737")
    pt = cfg.default_condition
    bare = []
    runs = {r: ([], [], []) for r in args.rates}
    bare_runner = {r: [] for r in args.rates}
    for _ in range(args.repeat):
        bare.append(bare_steps_per_s(cfg, pt.alt_m, pt.tas_mps, args.sim_s))
        for r in args.rates:
            bare_runner[r].append(runner_only_steps_per_s(args.sim_s, r))
            p, b, c = procedure_steps_per_s(args.sim_s, r)
            for lst, v in zip(runs[r], (p, b, c)):
                lst.append(v)
    b = statistics.median(bare)
    print(f"737, demo SID, {args.sim_s:.0f} s simulated at 120 Hz, median of {args.repeat}")
    print(f"bare JSBSim:               {b:9.0f} steps/s ({b * DT_S:6.0f}x real time)")
    for r, (proc, builds, per_call) in runs.items():
        p = statistics.median(proc)
        print(f"procedure flight @ {r:4.0f} Hz: {p:9.0f} steps/s ({p * DT_S:6.0f}x real time), "
              f"ratio {p / b:.2f} (goal >= 0.50); guidance {statistics.median(per_call):.1f} "
              f"µs per call")
        q = statistics.median(bare_runner[r])
        print(f"  runner alone @ {r:4.0f} Hz:  {q:9.0f} steps/s, ratio {q / b:.2f} (no guidance)")
    print(f"path build {statistics.median(runs[args.rates[0]][1]):.2f} s (once, excluded)")

if __name__ == "__main__":
    main()
