"""Flight-test attitude-reference mode (seed 004): the estimation error of the reference's
heading, roll and pitch errors from 60 s on, per profile, over seeds, against the paper's goal
(0.06° heading, 0.01° roll, 0.02° pitch) and the filter's 3σ, on both truth models. Writes
``docs/results/flight_test_attitude.md``.

    python bench/flight_test_attitude.py [--seeds 10] [--gnss both|dgnss|standalone]
                                         [--truth-model both|strapdown|linear] [--md NAME]
                                         [--figure PATH] [--quick]

Profiles: ``flight-test-attitude-level.yaml`` (straight and level),
``flight-test-attitude-speed.yaml`` (straight and level with speed changes),
``flight-test-attitude.yaml`` (turn sequence), ``flight-test-attitude-climb.yaml`` (climb with
turns), flown by JSBSim with the
project's laws; seeds 0..N-1 (each seed draws the reference's constant errors and drifts, the
accelerometer errors, the GNSS errors). ``strapdown``: the computer mechanises the
accelerometers' measured increments with the reference's angles (the default);
``linear``: truth ⊕ the computer's linear error model (the fast mode). ``dgnss``: the scenarios
as shipped (the flight-test recorder's differential GNSS); ``standalone``: the same flights with
the project's default GNSS error model (``navigation.gnss`` left at its defaults). The figure is
the run's ``attitude_reference`` plot (seed 004 Fig. 2) of the turn sequence, seed 0, DGNSS, on
the strapdown. ``--quick``: one seed, 70-s flights (the goal is judged from 60 s), both truth
models and GNSS grades.
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


FIGURE_OF = ("flight-test-attitude.yaml", 0, "dgnss", "strapdown")   # the flight whose plot is kept
figures: dict = {}


def fly(path: Path, seed: int, gnss: str, truth_model: str, duration_s: float | None = None
        ) -> dict:
    """One flight; its ``attitude_reference`` summary block (plus status and wall time)."""
    nav = dict(read_mapping(path)["navigation"])
    if gnss == "standalone":
        nav["gnss"] = STANDALONE_GNSS
    nav["truth_model"] = truth_model
    over = {"navigation": nav}
    if duration_s is not None:
        over["duration_s"] = duration_s
    t0 = time.perf_counter()
    res = run_scenario(path, seed=seed, plots=False, progress=False, overrides=over)
    if res.summary["navigation"]["truth_model"] != truth_model:
        raise SystemExit(f"{path.name}: flew {res.summary['navigation']['truth_model']}, "
                         f"asked {truth_model}")
    if (path.name, seed, gnss, truth_model) == FIGURE_OF:
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


def comparison(results: dict, models: tuple[str, ...], grade: str) -> str:
    """Strapdown against linear per profile and angle: median of the largest |e| from 60 s,
    median σ at 60 s, runs inside 3σ."""
    header = ["profile", "angle"] + [f"{k}: {m}" for k in
                                     ("max |e| median", "σ at 60 s median", "inside 3σ")
                                     for m in models]
    rows = []
    for name in PROFILES:
        for a in ANGLES:
            cells = {m: [b["angles"][a] for b in results[(m, grade, name)]] for m in models}
            row = [name, a]
            row += [f"{np.median([x['max_abs_err_after_deg'] for x in cells[m]]):.4f}"
                    for m in models]
            row += [f"{np.median([x['sigma_at_s_deg'] for x in cells[m]]):.4f}" for m in models]
            row += [f"{sum(x['inside_3sigma'] for x in cells[m])}/{len(cells[m])}"
                    for m in models]
            rows.append(row)
    return report.table(header, rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--gnss", choices=("both", "dgnss", "standalone"), default="both")
    ap.add_argument("--truth-model", choices=("both", "strapdown", "linear"), default="both")
    ap.add_argument("--md", default="flight_test_attitude.md")
    ap.add_argument("--figure", default=str(report.FIGURES / "navigation" /
                                            "flight_test_attitude.png"))
    report.add_quick(ap, "one seed, 70-s flights, both truth models and GNSS grades")
    args = ap.parse_args()
    seeds, duration = (1, 70.0) if args.quick else (args.seeds, None)
    grades = ("dgnss", "standalone") if args.gnss == "both" else (args.gnss,)
    models = ("strapdown", "linear") if args.truth_model == "both" else (args.truth_model,)
    header = ["angle", "goal, deg", "max |e| from 60 s, median", "max |e| from 60 s, worst",
              "σ at 60 s, median", "runs meeting the goal", "runs inside 3σ (max |e|/σ)",
              "within goal from, s (median)"]
    body, wall, results = [], {m: 0.0 for m in models}, {}
    for model in models:
        for grade in grades:
            body.append(f"### Truth: {model}, GNSS: {grade}\n")
            for name, file in PROFILES.items():
                blocks = [fly(scenarios_dir() / file, s, grade, model, duration)
                          for s in range(seeds)]
                results[(model, grade, name)] = blocks
                bad = [b["status"] for b in blocks if b["status"] != "ok"]
                wall[model] += sum(b["wall_s"] for b in blocks)
                body.append(f"**{name}** (`scenarios/{file}`, seeds 0-{seeds - 1}"
                            f"{', statuses ' + ', '.join(bad) if bad else ''}; all three angles "
                            f"within the goal in {sum(b['meets_goal'] for b in blocks)}/"
                            f"{len(blocks)} runs, inside 3σ in "
                            f"{sum(b['inside_3sigma'] for b in blocks)}/{len(blocks)})\n")
                body.append(report.table(header, rows_of(blocks)) + "\n")
                print(body[-2], body[-1], sep="\n", flush=True)
    head = []
    if len(models) == 2:
        for grade in grades:
            head += [f"### Strapdown against linear truth, GNSS: {grade}\n",
                     comparison(results, models, grade) + "\n"]
    length = f"{duration:g} s" if duration else "240 s"
    note = ("Estimation error e = estimate - injected error of the reference's angle, judged at "
            f"every logged sample (10 Hz) from 60 s to the end of the {length} flight; 'meeting "
            "the goal': |e| ≤ goal at all those samples; 'inside 3σ': |e| ≤ 3σ (the filter's) "
            "at all of them. Flight wall time in all: " +
            ", ".join(f"{m} {w:.0f} s" for m, w in wall.items()) + " (same machine, same run).")
    report.write(args.md, "\n".join(head + body), note)
    if args.figure and "attitude_reference" in figures:
        Path(args.figure).parent.mkdir(parents=True, exist_ok=True)
        print(f"figure written to {save(figures['attitude_reference'], args.figure)}")


if __name__ == "__main__":
    main()
