"""Flight-test attitude-reference mode (seed 004): the estimation error of the reference's
heading, roll and pitch errors from 60 s on, per profile, over seeds, against the paper's goal
(0.06° heading, 0.01° roll, 0.02° pitch) and the filter's 3σ. Writes
``docs/results/flight_test_attitude.md``.

    python bench/flight_test_attitude.py [--seeds 10] [--gnss both|dgnss|standalone] [--md NAME]
                                         [--figure docs/figures/navigation/flight_test_attitude.png]

Profiles: ``flight-test-attitude-level.yaml`` (straight and level),
``flight-test-attitude-speed.yaml`` (straight and level with speed changes),
``flight-test-attitude.yaml`` (turn sequence), ``flight-test-attitude-climb.yaml`` (climb with
turns), flown by JSBSim with the
project's laws; seeds 0..N-1 (each seed draws the reference's constant errors and drifts, the
accelerometer biases, the GNSS errors). ``dgnss``: the scenarios as shipped (the flight-test
recorder's differential GNSS); ``standalone``: the same flights with the project's default GNSS
error model (``navigation.gnss`` left at its defaults). The figure is the run's
``attitude_reference`` plot (seed 004 Fig. 2) of the turn sequence, seed 0, DGNSS.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario
from fms_testbed.viz.figure import save

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

PROFILES = {"straight and level": "flight-test-attitude-level.yaml",
            "straight and level, speed changes": "flight-test-attitude-speed.yaml",
            "turn sequence": "flight-test-attitude.yaml",
            "climb with turns": "flight-test-attitude-climb.yaml"}
ANGLES = ("heading", "roll", "pitch")
STANDALONE_GNSS = {"rate_hz": 1, "latency_s": 0.1}     # the project's default error model


FIGURE_OF = ("flight-test-attitude.yaml", 0, "dgnss")     # the flight whose plot is kept
figures: dict = {}


def fly(path: Path, seed: int, gnss: str) -> dict:
    """One flight; its ``attitude_reference`` summary block (plus status and wall time)."""
    over = None
    if gnss == "standalone":
        nav = dict(read_mapping(path)["navigation"])
        nav["gnss"] = STANDALONE_GNSS
        over = {"navigation": nav}
    t0 = time.perf_counter()
    res = run_scenario(path, seed=seed, plots=False, progress=False, overrides=over)
    if (path.name, seed, gnss) == FIGURE_OF:
        figures.update(res.plot())
    block = dict(res.summary["attitude_reference"])
    block["status"] = res.summary["status"]
    block["wall_s"] = time.perf_counter() - t0
    return block


def rows_of(blocks: list[dict]) -> list[list]:
    """Per angle: median/max of the largest |error| from 60 s on, median σ at 60 s, runs
    meeting the goal, runs inside 3σ, median time from which the error stays in the goal."""
    out = []
    for a in ANGLES:
        v = [b["angles"][a] for b in blocks]
        mx = np.array([x["max_abs_err_after_deg"] for x in v])
        sig = np.array([x["sigma_at_s_deg"] for x in v])
        ratio = np.array([x["max_err_over_sigma_after"] for x in v])
        within = [x["within_goal_from_s"] for x in v]
        w = [x for x in within if x is not None]
        out.append([a, f"{v[0]['goal_deg']:g}", f"{np.median(mx):.4f}", f"{mx.max():.4f}",
                    f"{np.median(sig):.4f}",
                    f"{sum(x['meets_goal'] for x in v)}/{len(v)}",
                    f"{sum(x['inside_3sigma'] for x in v)}/{len(v)} (max {ratio.max():.2f})",
                    f"{np.median(w):.0f}" if len(w) == len(within) else
                    (f"{np.median(w):.0f} ({len(within) - len(w)} never)" if w else "never")])
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--gnss", choices=("both", "dgnss", "standalone"), default="both")
    ap.add_argument("--md", default="flight_test_attitude.md")
    ap.add_argument("--figure", default=str(report.REPO / "docs" / "figures" / "navigation" /
                                            "flight_test_attitude.png"))
    args = ap.parse_args()
    grades = ("dgnss", "standalone") if args.gnss == "both" else (args.gnss,)
    header = ["angle", "goal, deg", "max |e| from 60 s, median", "max |e| from 60 s, worst",
              "σ at 60 s, median", "runs meeting the goal", "runs inside 3σ (max |e|/σ)",
              "within goal from, s (median)"]
    body, wall = [], 0.0
    for grade in grades:
        body.append(f"### GNSS: {grade}\n")
        for name, file in PROFILES.items():
            blocks = [fly(scenarios_dir() / file, s, grade) for s in range(args.seeds)]
            bad = [b["status"] for b in blocks if b["status"] != "ok"]
            wall += sum(b["wall_s"] for b in blocks)
            body.append(f"**{name}** (`scenarios/{file}`, seeds 0-{args.seeds - 1}"
                        f"{', statuses ' + ', '.join(bad) if bad else ''}; all three angles "
                        f"within the goal in {sum(b['meets_goal'] for b in blocks)}/{len(blocks)} "
                        f"runs, inside 3σ in {sum(b['inside_3sigma'] for b in blocks)}/"
                        f"{len(blocks)})\n")
            body.append(report.table(header, rows_of(blocks)) + "\n")
            print(body[-2], body[-1], sep="\n", flush=True)
    note = ("Estimation error e = estimate - injected error of the reference's angle, judged at "
            "every logged sample (10 Hz) from 60 s to the end of the 240 s flight; 'meeting the "
            "goal': |e| ≤ goal at all those samples; 'inside 3σ': |e| ≤ 3σ (the filter's) at all "
            f"of them. Flight wall time {wall:.0f} s in all.")
    report.write(args.md, "\n".join(body), note)
    if args.figure and "attitude_reference" in figures:
        Path(args.figure).parent.mkdir(parents=True, exist_ok=True)
        print(f"figure written to {save(figures['attitude_reference'], args.figure)}")


if __name__ == "__main__":
    main()
