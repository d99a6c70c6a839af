"""Monte-Carlo statistics of the three-INS navigation and its identification (the campaign behind
``fms-testbed montecarlo``; engine: :mod:`fms_testbed.navigation.montecarlo`).

Phases: one **fault-free** phase (N realisations of the whole trajectory, optional GNSS outages)
and one phase per **fault** (kind and size, injected on INS 2 at ``fault_at_s``). Statistics per
phase (one row of :meth:`McReport.to_pandas`):

* fault-free: false exclusions (any removal by any layer: a unit isolated or excluded, the GNSS
  or the baro named failed), false detections (any detection),
  the false-exclusion rate per hour and its 95 % upper confidence bound (Poisson: χ²_{0.95}(2k+2)
  / 2T for k events in T hours — 3/T for k = 0, the rule of three);
* fault: fraction detected (stage 1 after the fault), fraction with the faulty unit excluded,
  missed-detection rate (faulty unit not excluded by the end), wrong exclusions (a healthy unit
  excluded), median and 95th percentile of the times to detect, isolate and exclude, s;
* both: NSE95 of the output (horizontal, pooled over realisations and samples) with a GNSS fix
  used within two fix periods and while coasting, m; during outages the 95th percentile over
  realisations of the largest horizontal NSE, the largest ANP, and the fraction of outage samples
  with NSE ≤ RNP and with ANP ≤ RNP (RNP containment and the monitor's view of it); NSE95 of the
  whole output and, beside it, of the majority-voting baseline on the raw outputs, m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.stats import chi2

from fms_testbed.core.errors import UserError
from fms_testbed.navigation.montecarlo import (McConfig, McFault, McResult, MonteCarlo,
                                               percentile_from_hist, run_chunks)
from fms_testbed.sensors.profiles import PROFILES, Segment, aircraft_states, fly_profile

SYNTHETIC = ("turns", "straight", "manoeuvres")


def synthetic_segments(name: str, duration_s: float) -> list[Segment]:
    """Built-in profiles repeated to ``duration_s`` (s): ``straight`` (level, constant heading),
    ``turns`` (:data:`~fms_testbed.sensors.profiles.PROFILES` ``turns``: straights and 1.5-3 °/s
    turns), ``manoeuvres`` (random straights 60-240 s and turns 20-90 s at ±1.5/±3 °/s with
    climbs, descents and speed changes; profile seed 0, as ``bench_ins_gnss.py false-alarms``)."""
    if name == "straight":
        return [Segment(float(duration_s))]
    if name == "turns":
        base, segs = PROFILES["turns"], []
        while sum(s.duration_s for s in segs) < duration_s:
            segs += base
    elif name == "manoeuvres":
        rng = np.random.default_rng(0)
        segs = []
        while sum(s.duration_s for s in segs) < duration_s:
            segs += [Segment(float(rng.uniform(60, 240))),
                     Segment(float(rng.uniform(20, 90)), float(rng.choice([-3, -1.5, 1.5, 3])),
                             float(rng.choice([0, 0, 3, -3])), float(rng.choice([0, 0.3, -0.3])))]
    else:
        raise UserError(f"--profile {name!r}: choose one of {', '.join(SYNTHETIC)}")
    out, t = [], 0.0                    # cut the last segment at the duration
    for s in segs:
        d = min(s.duration_s, duration_s - t)
        if d <= 0:
            break
        out.append(Segment(d, s.turn_rate_dps, s.gamma_deg, s.accel_mps2))
        t += d
    return out


def synthetic_states(name: str, duration_s: float, dt_s: float = 0.1, speed_mps: float = 150.0):
    """True states of a built-in profile (:func:`synthetic_segments`) every ``dt_s`` (s)."""
    return aircraft_states(fly_profile(synthetic_segments(name, duration_s), dt_s=dt_s,
                                       speed_mps=speed_mps))


def flown_states(run_dir, dt_s: float = 0.1, duration_s: float | None = None):
    """True states of a flown run (``RUN_DIR/timeseries.parquet``) resampled every ``dt_s`` (s),
    cut at ``duration_s`` (s) after its start when given."""
    from fms_testbed.sensors.sins.trajectory import from_run_dir

    tr = from_run_dir(run_dir).resample(dt_s)
    states = aircraft_states(tr)
    if duration_s is not None:
        states = [s for s in states if s.t_s - states[0].t_s <= duration_s + 1e-9]
    return states


def rate_upper_95(k: int, hours: float) -> float:
    """95 % upper confidence bound of a Poisson rate with ``k`` events in ``hours`` h, 1/h."""
    return float(chi2.ppf(0.95, 2 * k + 2) / (2.0 * hours))


def _q(x: np.ndarray, p: float) -> float:
    x = x[np.isfinite(x)]
    return float(np.percentile(x, p)) if x.size else math.nan


@dataclass
class McReport:
    """The phases' results: ``phases`` maps a label (``fault-free`` or a fault's label) to its
    :class:`~fms_testbed.navigation.montecarlo.McResult`; ``cfg``, ``seed`` as run."""

    phases: dict[str, McResult]
    cfg: McConfig
    seed: int
    meta: dict = field(default_factory=dict)

    def row(self, label: str) -> dict:
        """Statistics of one phase (see the module docstring), SI."""
        r = self.phases[label]
        n = r.index.size
        hours = n * r.duration_s / 3600.0
        row = {"phase": label, "runs": n, "duration_s": round(r.duration_s, 1),
               "hours": round(hours, 2)}
        if r.fault is None:
            excl = (np.isfinite(r.t_exclude_s).any(axis=1) | np.isfinite(r.t_isolate_s).any(1)
                    | np.isfinite(r.t_gnss_s) | np.isfinite(r.t_baro_s))
            k = int(excl.sum())
            row.update(false_exclusions=k, false_detections=int(np.isfinite(r.t_detect_s).sum()),
                       false_exclusion_rate_per_h=k / hours if hours else math.nan,
                       false_exclusion_rate_upper95_per_h=rate_upper_95(k, hours))
        else:
            u, t0 = r.fault.unit, r.fault.t_s
            ex = r.t_exclude_s[:, u]
            others = np.delete(r.t_exclude_s, u, axis=1)
            det = r.t_detect_s
            row.update(detected_frac=float(np.isfinite(det).mean()),
                       excluded_frac=float(np.isfinite(ex).mean()),
                       missed_detection_rate=float((~np.isfinite(ex)).mean()),
                       wrong_exclusions=int(np.isfinite(others).any(axis=1).sum()),
                       ttd_median_s=_q(det - t0, 50), ttd_p95_s=_q(det - t0, 95),
                       tti_median_s=_q(r.t_isolate_s[:, u] - t0, 50),
                       tte_median_s=_q(ex - t0, 50), tte_p95_s=_q(ex - t0, 95))
        row.update(nse95_gnss_m=percentile_from_hist(r.hist_gnss, 95),
                   nse95_coast_m=percentile_from_hist(r.hist_coast, 95),
                   nse95_vote_m=percentile_from_hist(r.hist_vote, 95),
                   nse95_output_m=percentile_from_hist(r.hist_gnss + r.hist_coast, 95),
                   nse_max_p95_m=_q(r.nse_max_m, 95))
        if r.outage_samples:
            row.update(outage_nse_max_p95_m=_q(r.nse_outage_max_m, 95),
                       outage_anp_max_p95_m=_q(r.anp_max_outage_m, 95),
                       outage_nse_within_rnp=r.outage_nse_in / r.outage_samples,
                       outage_anp_within_rnp=r.outage_anp_in / r.outage_samples)
        row["wall_s"] = round(r.wall_s, 1)
        return row

    def to_pandas(self) -> pd.DataFrame:
        """One row per phase (:meth:`row`)."""
        return pd.DataFrame([self.row(k) for k in self.phases])


def run_campaign(states, cfg: McConfig, seed: int, runs: int, faults: list[McFault],
                 fault_states=None, fault_runs: int = 50, chunk: int = 250,
                 progress=None, workers: int = 1) -> McReport:
    """The fault-free phase (``runs`` realisations along ``states``) and one phase per fault
    (``fault_runs`` realisations along ``fault_states``, default ``states``), realisation seeds
    derived from ``seed`` (fault phases use realisation indices after the fault-free ones, so
    no phase reuses another's numbers); batches of ``chunk`` on ``workers`` processes."""
    phases: dict[str, McResult] = {}
    if runs > 0:
        phases["fault-free"] = run_chunks(MonteCarlo(states, cfg, seed), runs, chunk,
                                          progress=progress, workers=workers)
    if faults:
        mc = MonteCarlo(fault_states or states, cfg, seed)
        first = runs
        for f in faults:
            phases[f.label] = run_chunks(mc, fault_runs, chunk, f, first=first,
                                         progress=progress, workers=workers)
            first += fault_runs
    return McReport(phases, cfg, seed)


__all__ = ["McReport", "SYNTHETIC", "flown_states", "rate_upper_95", "run_campaign",
           "synthetic_segments", "synthetic_states"]
