"""Shared timing for the closed-loop benchmarks: a trimmed bare JSBSim instance and a flight
timed in alternating chunks.

This machine's speed drifts by tens of percent over seconds, so a ratio of two separately timed
runs swings by ±0.1. Here the bare instance and the closed loop alternate in chunks of 10 s of
simulated time (1200 frames; the order swaps every chunk) for the whole flight, and the ratio is
closed-loop frames per second over bare frames per second from the totals: both see the same
machine. A full garbage collection runs before the timing: the objects the setup left (the
database, the path build) would otherwise be walked once inside the first chunks, a one-off of
the process (0.1-0.2 s here), not a cost of the loop.
"""

from __future__ import annotations

import gc
import math
import time

import jsbsim

from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.sim.jsbsim_core import DT_S, bare_fdm

CHUNK_S = 10.0


def trimmed_bare_fdm(cfg, alt_m: float, tas_mps: float):
    """A sanitised JSBSim instance of ``cfg``'s model without the inner loops, trimmed; no
    Python work per frame is added to it (the denominator of every ratio)."""
    fdm = bare_fdm(cfg.jsbsim_model)
    fdm["aero/alpha-max-rad"] = math.radians(cfg.trim.alpha_max_deg)
    fdm["ic/h-sl-ft"] = alt_m / FT_M
    fdm["ic/vt-kts"] = tas_mps / KT_MPS
    fdm["ic/lat-geod-deg"] = 47.0
    fdm["gear/gear-cmd-norm"] = 0
    fdm.run_ic()
    fdm["propulsion/set-running"] = -1
    try:
        fdm["simulation/do_simple_trim"] = 1
    except jsbsim.TrimFailureError:  # the timing does not need a perfect trim
        pass
    return fdm


def interleaved_ratio(flight, cfg, chunk_s: float = CHUNK_S) -> dict:
    """Fly ``flight`` (a :class:`fms_testbed.loop.flight.Flight`, loaded and trimmed) to its end,
    alternating with a bare instance of the same aircraft every ``chunk_s`` simulated seconds.

    Returns ``{"ratio", "bare_fps", "closed_fps", "summary", "df"}`` (frames per wall second).
    """
    pt = cfg.default_condition
    bare = trimmed_bare_fdm(cfg, pt.alt_m, pt.tas_mps)
    run = bare.run
    steps = max(1, int(round(chunk_s / flight.dt_outer_s)))
    frames = steps * flight.n_frames
    fdm = flight.aircraft.fdm
    t_bare = t_closed = 0.0
    n_bare = n_closed = 0
    pc = time.perf_counter
    gc.collect()
    alive, i = True, 0
    while alive:
        for which in ((0, 1) if i % 2 == 0 else (1, 0)):
            if which == 0:
                t0 = pc()
                for _ in range(frames):
                    run()
                t_bare += pc() - t0
                n_bare += frames
            elif alive:
                sim0 = fdm.get_sim_time()
                t0 = pc()
                alive = flight.step(steps)
                t_closed += pc() - t0
                n_closed += int(round((fdm.get_sim_time() - sim0) / DT_S))
        i += 1
    df, summary = flight.result()
    b, c = n_bare / t_bare, n_closed / t_closed
    return {"ratio": c / b, "bare_fps": b, "closed_fps": c, "summary": summary, "df": df}


def system_only_ratio(flight, cfg, sim_s: float = 300.0, chunk_s: float = CHUNK_S) -> dict:
    """JSBSim with the testbed's inner-loop system engaged (``flight``'s instance, after one
    outer step) but no Python work per frame, interleaved with the bare instance: the ceiling
    of every closed-loop ratio (the system is JSBSim's own cost).

    Returns ``{"ratio", "bare_fps", "system_fps"}``."""
    pt = cfg.default_condition
    bare = trimmed_bare_fdm(cfg, pt.alt_m, pt.tas_mps)
    flight.step(1)
    runs = (bare.run, flight.aircraft.fdm.run)
    frames = int(round(chunk_s / DT_S))
    tot = [0.0, 0.0]
    pc = time.perf_counter
    gc.collect()
    for i in range(max(1, int(sim_s / chunk_s))):
        for which in ((0, 1) if i % 2 == 0 else (1, 0)):
            run = runs[which]
            t0 = pc()
            for _ in range(frames):
                run()
            tot[which] += pc() - t0
    n = frames * max(1, int(sim_s / chunk_s))
    return {"ratio": tot[0] / tot[1], "bare_fps": n / tot[0], "system_fps": n / tot[1]}
