"""The INS/GNSS filter on its measurements, judged against the truth it cannot see (docs/results/
ins_gnss_on_measurements.md):

1. consistency on the strapdown: N seeded 10-min profile flights with turns and climbs
   (STIM300-class test IMU without scale-factor/misalignment errors, as the consistency test),
   mean NEES of position/velocity/attitude (9 states) over all N runs against its 95 % χ² band
   per epoch, NIS means, and pyins' per-run checks (RMS(error/σ) < 1.5 per state, innovation
   RMS < 3), with the number of runs a consistent filter would fail the per-run check given
   how its normalised errors are correlated (kalman.rms_check_failure_probability), and the same
   runs on a white-noise receiver (no GNSS Markov error: pyins' own test setup);
2. a 120-s GNSS outage in every other flight: the horizontal drift at the outage's end against
   the filter's own 95 % radius there;
3. strapdown against linear truth on the same turn-on realisation (the linear unit starts at the
   strapdown unit's errors after its alignment; in-run noise is each model's own), the same
   filter: per truth model the NEES band, NIS, horizontal/vertical NSE 95 %, and NSE and
   attitude error per window side by side (STIM300 preset, with its scale factors and
   misalignments).

    python bench/bench_ins_gnss_truth.py [--runs 100] [--seeds 20] [--md NAME] [--quick]
"""

from __future__ import annotations

import argparse
import math
import time
import sys
from pathlib import Path

import numpy as np
from scipy.stats import chi2

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.navigation import make_source
from fms_testbed.navigation.kalman import rms_check_failure_probability
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.analysis import horizontal_radius

IMU = {"name": "matched-tactical",
       "gyro": {"arw_deg_per_sqrt_h": 0.05, "bias_instability_deg_per_h": 0.05,
                "bias_correlation_time_s": 3600},
       "accelerometer": {"vrw_mps_per_sqrt_h": 0.06, "bias_turn_on_ug": 750,
                         "bias_instability_ug": 50, "bias_correlation_time_s": 3600}}
OUTAGE = (300.0, 420.0)
WHITE_GNSS = {"pos_markov_sigma_m": [0.001, 0.001, 0.001],
              "vel_markov_sigma_mps": [0.0001, 0.0001, 0.0001]}


def states():
    """600 s at 150 m/s: level, turns of ±3 °/s, a climb and a descent."""
    segs = [Segment(60.0), Segment(60.0, 3.0), Segment(60.0, 0.0, 3.0), Segment(60.0, -3.0),
            Segment(120.0, 1.0), Segment(60.0, 0.0, -3.0), Segment(180.0, -1.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))


def _spec(imu, truth_model, outage, gnss=None):
    g = {"outages": [{"start_s": OUTAGE[0], "end_s": OUTAGE[1]}]} if outage else {}
    g.update(gnss or {})
    return {"source": "ins_gnss", "imu": imu, "truth_model": truth_model, "gnss": g}


def _nees(nav) -> tuple[float, np.ndarray, np.ndarray]:
    """(NEES of the 9 navigation states, their normalised errors (9,), the errors (9,)) of
    unit 0 now: e = true error − the filter's estimate, NEES = eᵀ P⁻¹ e."""
    f = nav.filters[0]
    e = nav.bank.errors(0)[:9] - f.x[:9]
    P = f.P[:9, :9]
    return float(e @ np.linalg.solve(P, e)), e / np.sqrt(np.diag(P)), e


def _whole_second(t_s: float) -> bool:
    return t_s > 0.5 and abs(t_s - round(t_s)) < 1e-6


def consistency(n_runs: int, st, gnss=None) -> dict:
    """NEES (9 navigation states) per whole second, NIS, per-run RMS(error/σ) and innovation
    RMS, the failures of the per-run check a consistent filter would have, outage drift vs
    predicted 95 % radius; odd runs carry the outage; ``gnss``: receiver keys overridden."""
    nees, nis, rms_z, innov, drift, zz = [], {}, [], [], [], []
    for r in range(n_runs):
        nav = make_source(_spec(IMU, "strapdown", r % 2 == 1, gnss), seed=2000 + r)
        row, zs = [], []
        for s in st:
            nav.update(s)
            if _whole_second(s.t_s):
                v, z, e = _nees(nav)
                row.append(v)
                zs.append(z)
                if r % 2 == 1 and abs(s.t_s - OUTAGE[1] + 1.0) < 1e-6:
                    P = nav.filters[0].P
                    drift.append((math.hypot(e[0], e[1]), horizontal_radius(P[0, 0], P[1, 1],
                                                                            P[0, 1])))
        nees.append(row)
        zz.append(zs)
        rms_z.append(np.sqrt(np.mean(np.array(zs) ** 2, axis=0)))
        for _, g, v, m in nav.nis_log:
            nis.setdefault(g, []).append(v / m)
        innov.append(max(math.sqrt(np.mean([v / m for _, g2, v, m in nav.nis_log if g2 == g]))
                         for g in ("gnss_pos", "gnss_vel")))
    zz = np.array(zz)
    p_fail = np.array([rms_check_failure_probability(zz[:, :, k]) for k in range(9)])
    return {"nees": np.array(nees), "nis": {g: float(np.mean(v)) for g, v in nis.items()},
            "rms_z": np.array(rms_z), "innov": np.array(innov), "drift": np.array(drift),
            "p_fail": p_fail, "mean_z2": (zz ** 2).mean(axis=(0, 1))}


def truth_models(n_seeds: int, st) -> list[dict]:
    """Strapdown and linear truth on the same turn-on realisation, both with the outage: per
    model the time series (t, horizontal NSE, heading error, roll error, vertical NSE, NEES;
    NaN between whole seconds) and the NIS / dimension of every GNSS group used."""
    out = []
    for sd in range(n_seeds):
        a = make_source(_spec("STIM300", "strapdown", True), seed=3000 + sd)
        b = make_source(_spec("STIM300", "linear", True), seed=3000 + sd)
        res = {"strapdown": [], "linear": []}
        for k, s in enumerate(st):
            sa, sb = a.update(s), b.update(s)
            if k == 0:
                b.bank.units[0].x = a.bank.errors(0).copy()     # the same realisation
            for name, sol, nav in (("strapdown", sa, a), ("linear", sb, b)):
                e = sol.errors
                nees = _nees(nav)[0] if _whole_second(s.t_s) else math.nan
                res[name].append((s.t_s, math.hypot(e["nse_east_m"], e["nse_north_m"]),
                                  e["att_err_heading_deg"], e["att_err_roll_deg"],
                                  e["nse_up_m"], nees))
        rec = {k: np.array(v) for k, v in res.items()}
        rec["nis"] = {name: [v / m for _, _, v, m in nav.nis_log]
                      for name, nav in (("strapdown", a), ("linear", b))}
        out.append(rec)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--md", default="ins_gnss_on_measurements.md")
    report.add_quick(ap, "2 consistency runs (one with the outage), 1 seed of the truth-model "
                         "comparison")
    a = ap.parse_args()
    if a.quick:
        a.runs, a.seeds = 2, 1
    st = states()
    t0 = time.perf_counter()
    c = consistency(a.runs, st)
    w = consistency(a.runs, st, WHITE_GNSS)
    tm = truth_models(a.seeds, st)
    write(c, w, tm, a, time.perf_counter() - t0)


def _window(arr, lo, hi):
    t = arr[:, 0]
    return arr[(t >= lo) & (t < hi)]


def nees_band(nees: np.ndarray, dim: int = 9) -> tuple[float, float, float, float]:
    """(lower, upper bound of the 95 % χ² band of the mean NEES over the runs, the fraction of
    epochs whose mean is inside it, the time-mean of the mean): nees (runs, epochs); the mean of
    m runs' NEES of a consistent filter is χ²(dim·m)/m."""
    m = nees.shape[0]
    lo, hi = chi2.ppf([0.025, 0.975], dim * m) / m
    mean = nees.mean(axis=0)
    return float(lo), float(hi), float(((mean > lo) & (mean < hi)).mean()), float(mean.mean())


def model_rows(tm: list[dict]) -> list[list]:
    """Per truth model over the seeds: NEES band, NIS mean, horizontal and vertical NSE 95 %
    (all epochs; with GNSS; at the outage's end)."""
    rows = []
    for model in ("strapdown", "linear"):
        nees = np.array([r[model][:, 5][~np.isnan(r[model][:, 5])] for r in tm])
        lo, hi, inside, mean = nees_band(nees)
        nis = np.concatenate([r["nis"][model] for r in tm])
        arr = np.concatenate([r[model] for r in tm])
        gnss = (arr[:, 0] < OUTAGE[0]) | (arr[:, 0] >= OUTAGE[1] + 30.0)
        end = np.abs(arr[:, 0] - (OUTAGE[1] - 1.0)) < 1e-6
        rows.append([model, f"{100 * inside:.1f} % in [{lo:.2f}, {hi:.2f}]", f"{mean:.2f}",
                     f"{nis.mean():.3f}",
                     f"{np.percentile(arr[gnss, 1], 95):.2f}",
                     f"{np.percentile(np.abs(arr[gnss, 4]), 95):.2f}",
                     f"{np.percentile(arr[end, 1], 95):.2f}",
                     f"{np.percentile(np.abs(arr[end, 4]), 95):.2f}"])
    return rows


NAMES = ["δp E", "δp N", "δp U", "δV E", "δV N", "δV U", "ε E", "ε N", "ε U"]


def per_run_lines(c, what: str) -> list[str]:
    """pyins' per-run checks of one consistency set, beside the failures a consistent filter
    would have (per state p_k; runs failing some state ≈ n (1 − Π(1 − p_k)), states taken
    independent)."""
    rz, p = c["rms_z"], c["p_fail"]
    n = len(rz)
    fails = (rz >= 1.5).sum(axis=0)
    return [f"pyins' per-run checks over all {n} runs ({what}): RMS(error/σ) < 1.5 for every "
            f"state in {int(np.sum((rz < 1.5).all(axis=1)))} of {n} runs (worst state per run, "
            f"median {np.median(rz.max(axis=1)):.2f}, max {rz.max():.2f}). Innovation RMS < 3 "
            f"in {int(np.sum(c['innov'] < 3))} of {len(c['innov'])} runs (max "
            f"{c['innov'].max():.2f}).", "",
            report.table(["", *NAMES],
                         [["runs failing RMS(e/σ) < 1.5", *[str(int(v)) for v in fails]],
                          ["expected of a consistent filter", *[f"{n * v:.1f}" for v in p]],
                          ["mean (e/σ)² over runs and epochs", *[f"{v:.2f}" for v in c["mean_z2"]]],
                          ["median RMS(e/σ)", *[f"{v:.2f}" for v in np.median(rz, axis=0)]]]),
            "",
            f"Runs failing some state: {int(np.sum((rz >= 1.5).any(axis=1)))}; a consistent "
            f"filter whose normalised errors are correlated as these are would fail "
            f"{n * (1 - np.prod(1 - p)):.1f} (states taken independent).", ""]


def write(c, w, tm, a, wall_s) -> None:
    nees = c["nees"]
    lo, hi, inside, mean = nees_band(nees)
    lo0, hi0, inside0, mean0 = nees_band(nees[0::2])
    m = nees.shape[0]
    d = c["drift"]
    L = ["**The INS/GNSS filter on its measurements (strapdown truth)**", "",
         f"{a.runs} runs, {a.seeds} seeds, {wall_s:.0f} s wall on 2 shared cores. Profile: 600 s at 150 m/s, 47° N, 3000 m; "
         "level, ±3 °/s turns, a 3° climb and descent, 1 °/s turns; GNSS 1 Hz, 0.1 s latency, "
         "the default receiver; baro; one INS.", "",
         "**Consistency.**", "",
         f"{m} Monte-Carlo runs on the strapdown (seeds 2000-{2000 + m - 1}; the odd ones with "
         f"the 120-s GNSS outage below; the test IMU of "
         "tests/navigation/test_ins_gnss_consistency.py, no scale-factor or misalignment "
         f"errors). Mean NEES of the 9 navigation states over all {m} runs inside its 95 % χ² "
         f"band [{lo:.2f}, {hi:.2f}] at {100 * inside:.1f} % of the {nees.shape[1]} epochs "
         f"(goal ≥ 95 %); time-mean NEES {mean:.2f} (9 for a consistent filter). The "
         f"{len(nees[0::2])} runs without the outage alone: {100 * inside0:.1f} % inside "
         f"[{lo0:.2f}, {hi0:.2f}], time-mean {mean0:.2f}.", "",
         "NIS mean / dimension (goal within ±10 %): " + ", ".join(
             f"{g} {v:.3f}" for g, v in c["nis"].items()) + ".", "",
         *per_run_lines(c, "with and without the outage, the default receiver"),
         "The check's spread is set by how long the errors stay correlated: the default "
         "receiver's position Markov error (τ 300 s) leaves the position errors correlated over "
         "minutes, a few independent samples per 600-s run, so a run of an honest filter fails "
         f"RMS(e/σ) < 1.5 on a position state in {100 * c['p_fail'][:3].mean():.1f} % of runs "
         "(the row above). The same runs on a white-noise receiver (no GNSS Markov error, as "
         "pyins' own test):", "",
         *per_run_lines(w, "white-noise receiver, with and without the outage"),
         f"Mean NEES of that set inside its band at {100 * nees_band(w['nees'])[2]:.1f} % of "
         "the epochs; NIS mean / dimension " + ", ".join(
             f"{g} {v:.3f}" for g, v in w["nis"].items()) + ".", "",
         "**A 120-s GNSS outage.**", "",
         f"{len(d)} runs with no fix from {OUTAGE[0]:g} to {OUTAGE[1]:g} s. Horizontal drift at "
         f"the outage's end: 95th percentile {np.percentile(d[:, 0], 95):.2f} m against the "
         f"filter's own 95 % radius there, mean {d[:, 1].mean():.2f} m (ratio "
         f"{np.percentile(d[:, 0], 95) / d[:, 1].mean():.2f}; goal within ±20 %); "
         f"{int(np.sum(d[:, 0] <= d[:, 1]))} of {len(d)} runs inside their own 95 % radius.", "",
         "**Strapdown against linear truth.**", "",
         f"{len(tm)} seeds (3000-{3000 + len(tm) - 1}), the STIM300 preset (with its scale "
         "factors and misalignments), the same outage; the linear unit starts at the strapdown "
         "unit's errors after the alignment, the in-run noise is each model's own; the filter "
         "is the same. Per truth model over all seeds: the mean NEES (9 states, whole seconds) "
         "against its 95 % χ² band, the NIS mean / dimension of the GNSS groups, and the 95th "
         "percentiles of the horizontal and vertical NSE with GNSS (before the outage and from "
         "30 s after it) and at the outage's end:", "",
         report.table(["truth", "mean NEES inside band", "time-mean NEES", "NIS mean / dim",
                       "horizontal NSE 95 %, m (GNSS)", "vertical NSE 95 %, m (GNSS)",
                       "horizontal 95 %, m (outage end)", "vertical 95 %, m (outage end)"],
                      model_rows(tm)), "",
         "Median over seeds of the RMS in each window:", "",
         "| window | horizontal NSE, m: strapdown | linear | heading error, deg: strapdown | "
         "linear | roll error, deg: strapdown | linear |", "|---|---:|---:|---:|---:|---:|---:|"]
    for label, w0, w1 in (("0-60 s (level)", 0, 60), ("60-300 s (turns, climb)", 60, 300),
                          ("300-420 s (outage)", 300, 420), ("420-600 s (after)", 420, 600)):
        vals = []
        for col in (1, 2, 3):
            for model in ("strapdown", "linear"):
                x = [np.sqrt(np.mean(_window(r[model], w0, w1)[:, col] ** 2)) for r in tm]
                vals.append(np.median(x))
        L.append(f"| {label} | " + " | ".join(
            f"{v:.3f}" for v in (vals[0], vals[1], vals[2], vals[3], vals[4], vals[5])) + " |")
    report.write(a.md, "\n".join(L))


if __name__ == "__main__":
    main()
