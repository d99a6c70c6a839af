"""The strapdown INS measured: speed in the closed loop, exactness on a JSBSim flight, and the
linear 33-state model against it with the same sensor-error realisations.

    python bench/bench_strapdown.py speed  [--sim-s 600] [--md strapdown_speed.md]
    python bench/bench_strapdown.py exact  [--sim-s 600] [--md strapdown_exact.md]
    python bench/bench_strapdown.py linear [--sim-s 600] [--seeds 5] [--md strapdown_linear.md]
    python bench/bench_strapdown.py [speed|exact|linear] --quick

``speed``: bare JSBSim (12 frames per 10-Hz step), the closed loop on truth navigation, and the
same closed loop with three strapdown INS (STIM300) riding along on the per-frame samples (the
bank sees its IMU only; the flight is the truth flight), timed in alternating 10 s chunks over
the whole flight (this machine's speed drifts: only ratios within one run compare). Reports µs
per 10-Hz step, the bank's own share (timed inside), the sampling's (the rest), and the ratios.

``exact``: an error-free IMU over the flight (turns, climbs, a speed change) with the IMU at the
CG and 12 m ahead of it: the largest position, velocity and attitude error of the mechanised
increments against JSBSim's trajectory.

``linear``: per preset and seed, one realisation made deterministic (constant sensor errors)
in the strapdown and in the 33-state model (:func:`fms_testbed.navigation.inertial.twin.linear_twin`)
along the same flight: horizontal position error of each at the end, their difference relative
to the strapdown's, and the second-order prediction ½|ε| (ε the largest attitude error).

``--quick``: :data:`QUICK` (the first 120 s of the flight, one seed), all three when none is named.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path
from unittest.mock import patch

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import report  # noqa: E402
from interleave import CHUNK_S, trimmed_bare_fdm  # noqa: E402

from fms_testbed.config.aircraft import load_aircraft  # noqa: E402
from fms_testbed.config.scenario import parse_scenario  # noqa: E402
from fms_testbed.loop.flight import Flight  # noqa: E402
from fms_testbed.navigation.inertial.bank import StrapdownBank  # noqa: E402
from fms_testbed.navigation.inertial.twin import linear_twin  # noqa: E402
from fms_testbed.navigation.ins_bank import derive_seeds  # noqa: E402
from fms_testbed.navigation.truth import TruthNavigation  # noqa: E402
from tests.navigation.strapdown_helpers import EVENTS, BankProbe, fly_with, scenario  # noqa: E402

PRESETS = ["HG9900", "HG1700", "STIM300", "ADIS16488", "consumer_MEMS"]
QUICK = {"sim_s": 120.0, "seeds": 1}
"""``--quick``: simulated s (a heading change and the start of a climb), seeds per preset."""


def flight_words(sim_s: float) -> str:
    """What the strapdown tests' flight does in its first ``sim_s`` s (its events before then)."""
    ev = [e for e in EVENTS if e["t_s"] < sim_s]
    words = {"heading_deg": "heading change", "alt_m": "altitude change", "tas_kmh": "speed change"}
    n = {k: sum(k in e for e in ev) for k in words}
    return ", ".join(f"{n[k]} {w}{'' if n[k] == 1 else 's'}" for k, w in words.items())


class TimedProbe(BankProbe):
    """A :class:`BankProbe` that times the bank's update (and keeps no log)."""

    def __init__(self, bank):
        super().__init__(bank, every=10 ** 9)
        self.t_bank = 0.0

    def update(self, truth, frames=None):
        t0 = time.perf_counter()
        self.bank.update(truth, frames)
        self.t_bank += time.perf_counter() - t0
        return TruthNavigation.update(self, truth)


def _flight(sim_s: float, source=None) -> Flight:
    scn, cfg = parse_scenario(scenario(sim_s)), load_aircraft("737")
    if source is None:
        return Flight(scn, cfg=cfg, progress=False)
    with patch("fms_testbed.loop.flight.make_source", lambda spec, seed=None: source):
        return Flight(scn, cfg=cfg, progress=False)


def speed(sim_s: float) -> dict:
    """Interleaved µs per 10-Hz step: bare JSBSim, closed loop on truth, and with the bank."""
    cfg = load_aircraft("737")
    pt = cfg.default_condition
    bare = trimmed_bare_fdm(cfg, pt.alt_m, pt.tas_mps)
    probe = TimedProbe(StrapdownBank(["STIM300"] * 3, derive_seeds(0, 3)))
    flights = {"truth": _flight(sim_s), "strapdown": _flight(sim_s, probe)}
    steps = int(round(CHUNK_S / flights["truth"].dt_outer_s))
    n_frames = flights["truth"].n_frames
    wall = {"bare": 0.0, "truth": 0.0, "strapdown": 0.0}
    n = {"bare": 0, "truth": 0, "strapdown": 0}
    order = ["bare", "truth", "strapdown"]
    alive = {"truth": True, "strapdown": True}
    i = 0
    while any(alive.values()):
        for name in order[i % 3:] + order[:i % 3]:
            t0 = time.perf_counter()
            if name == "bare":
                for _ in range(steps * n_frames):
                    bare.run()
                n[name] += steps
            elif alive[name]:
                alive[name] = flights[name].step(steps)
                n[name] += steps
            wall[name] += time.perf_counter() - t0
        i += 1
    us = {k: wall[k] / n[k] * 1e6 for k in wall}
    us["bank"] = probe.t_bank / n["strapdown"] * 1e6
    us["sampling"] = us["strapdown"] - us["truth"] - us["bank"]
    return us


def exact(sim_s: float) -> list[tuple]:
    """Largest errors of an error-free IMU over the flight, IMU at the CG and 12 m ahead."""
    rows = []
    for lever in ((0.0, 0.0, 0.0), (12.0, 0.5, 1.5)):
        probe = fly_with(StrapdownBank([{}], [1], lever_arm_m=lever), sim_s)
        E = np.array([e[0] for _, e in probe.log])
        rows.append((lever, np.max(np.hypot(E[:, 0], E[:, 1])), np.max(np.abs(E[:, 2])),
                     np.max(np.linalg.norm(E[:, 3:6], axis=1)),
                     np.max(np.linalg.norm(E[:, 6:9], axis=1))))
    return rows


def linear(sim_s: float, seeds: int) -> list[tuple]:
    """Per preset and seed: strapdown and linear horizontal error at the end, the difference."""
    probe = fly_with(StrapdownBank([{}], [1], lever_arm_m=(1.0, 0.0, 0.0)), sim_s,
                     keep_frames=True)
    calls = probe.calls
    out = []
    for preset in PRESETS:
        for seed in range(seeds):
            bank = StrapdownBank([preset], derive_seeds(seed, 1))
            bank.imu.make_deterministic()
            bank.update(calls[0][0])
            twin = linear_twin(bank, 0)
            twin.update(calls[0][0])
            eps = 0.0
            for truth, frames in calls[1:]:
                bank.update(truth, frames[:, :len(bank.frame_properties)])
                twin.update(truth)
                eps = max(eps, float(np.max(np.abs(bank.errors(0)[6:9]))))
            e, x = bank.errors(0), twin.x
            out.append((preset, seed, eps, math.hypot(e[0], e[1]), math.hypot(x[0], x[1]),
                        math.hypot(e[0] - x[0], e[1] - x[1]), abs(math.degrees(e[8])),
                        abs(math.degrees(x[8]))))
    return out


def _speed_md(us: dict, sim_s: float) -> str:
    rows = [("bare JSBSim, 12 frames", f"{us['bare']:.1f}", "1.000", "–"),
            ("closed loop on truth navigation", f"{us['truth']:.1f}",
             f"{us['bare'] / us['truth']:.3f}", "1.000"),
            ("… with three strapdown INS (STIM300) on the per-frame samples",
             f"{us['strapdown']:.1f}", f"{us['bare'] / us['strapdown']:.3f}",
             f"**{us['truth'] / us['strapdown']:.3f}**"),
            ("   of which the bank's update (IMU synthesis, errors, 3 mechanisations)",
             f"{us['bank']:.1f}", "", ""),
            ("   of which the per-frame sampling (6 properties × 12 frames)",
             f"{us['sampling']:.1f}", "", "")]
    load = os.getloadavg()
    return (f"737, {sim_s:.0f} s simulated (the strapdown tests' flight: {flight_words(sim_s)}), "
            f"JSBSim at 120 Hz, navigation step 10 Hz; the three timed in rotating "
            f"10 s chunks. Load average at the end {load[0]:.2f} (2 cores).\n\n"
            + report.table(["configuration", "µs per 10-Hz step", "speed / bare JSBSim",
                            "speed / closed loop on truth"], rows))


def main() -> None:
    """Command line (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", nargs="?", choices=["speed", "exact", "linear"],
                    help="the measurement (with --quick and none named: all three)")
    ap.add_argument("--sim-s", type=float, default=600.0)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--md", default=None, help="output file in docs/results ('' : none)")
    report.add_quick(ap, "the first 120 s of the flight, one seed per preset")
    a = ap.parse_args()
    if a.quick:
        a.sim_s, a.seeds = QUICK["sim_s"], QUICK["seeds"]
    elif a.what is None:
        ap.error("name the measurement: speed, exact or linear (or --quick)")
    if a.what is None and a.md:
        ap.error("--md names one page: name the measurement too")
    for what in [a.what] if a.what else ["speed", "exact", "linear"]:
        measure(what, a)


def measure(what: str, a) -> None:
    """Run the measurement ``what`` with the options ``a`` and write its page."""
    if what == "speed":
        # warm-up: JSBSim's and numba's caches (the kernels load at a bank's first call)
        _flight(30.0, TimedProbe(StrapdownBank(["STIM300"] * 3, derive_seeds(0, 3)))).run()
        us = speed(a.sim_s)
        print({k: round(v, 1) for k, v in us.items()})
        report.write("strapdown_speed.md" if a.md is None else a.md, _speed_md(us, a.sim_s))
    elif what == "exact":
        rows = exact(a.sim_s)
        body = report.table(
            ["IMU lever arm (x, y, z) m", "horizontal position m", "height m", "velocity m/s",
             "attitude rad"],
            [(str(tuple(r[0])), f"{r[1]:.1e}", f"{r[2]:.1e}", f"{r[3]:.1e}", f"{r[4]:.1e}")
             for r in rows])
        note = (f"Error-free IMU, 737, {a.sim_s:.0f} s ({flight_words(a.sim_s)}): the largest "
                "error of the mechanised increments against JSBSim's trajectory, sampled every "
                "second.")
        print(body)
        report.write("strapdown_exact.md" if a.md is None else a.md, body, note)
    else:
        rows = linear(a.sim_s, a.seeds)
        body = _linear_md(rows, a.sim_s)
        print(body)
        report.write("strapdown_linear.md" if a.md is None else a.md, body)


def _linear_md(rows: list[tuple], sim_s: float) -> str:
    out = []
    for preset in PRESETS:
        r = [x for x in rows if x[0] == preset]
        rel = [x[5] / x[3] for x in r]
        out.append((preset, f"{statistics.median(x[2] for x in r):.3g}",
                    f"{statistics.median(x[3] for x in r):.0f}",
                    f"{statistics.median(x[4] for x in r):.0f}",
                    f"{statistics.median(rel) * 100:.2g} ({min(rel) * 100:.2g}-"
                    f"{max(rel) * 100:.2g})",
                    f"{statistics.median(0.5 * x[2] for x in r) * 100:.2g}",
                    f"{statistics.median(abs(x[6] - x[7]) for x in r):.2g}"))
    return (f"737 flight of {sim_s:.0f} s (the strapdown tests' flight: {flight_words(sim_s)}), "
            "one deterministic "
            "realisation per seed (constant sensor errors: turn-on and in-run biases frozen, "
            "scale factors, misalignments; no noise) in both models, stationary alignment at the "
            "start; medians over the seeds.\n\n"
            + report.table(["preset", "max |ε| rad", "strapdown horizontal error m",
                            "linear model m", "difference / strapdown % (range)",
                            "½ max|ε| %", "heading difference °"], out))


if __name__ == "__main__":
    main()
