"""The seed's figures reproduced over several switch-ons (seeds) of the preset.

The seed (Vorobyov et al.) reports maxima and one 2-hour record; one simulated switch-on is one
draw. :func:`reproduce` runs, per seed, the factory calibration and two static tests of the
seed's length (2 h): a chamber thermal cycle over the whole operating range (``ramp``: the
run-to-run figures are "over the whole temperature range") and a switch-on warm-up at room
temperature (``warmup``: the accumulated angles). The figures are aggregated as follows:

=============================== ======================================================== =======
figure                          measured as                                              paper
=============================== ======================================================== =======
raw zero signal                 median over seeds of max |calibration point| (all axes)  0.05
temperature residual            median over seeds of the calibration fit's max residual  0.00713
run-to-run error ("up to")      max over seeds of the ramp run's max after stage 1       0.017
run-to-run residual             median over seeds of the ramp run's max after stage 2    0.00684
2-h angle, uncompensated        median over seeds and axes of |angle| (warm-up)          108°
2-h angle, all three stages     max over seeds and axes of |angle| (warm-up)             1.7°
=============================== ======================================================== =======
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fms_testbed.core.units import DEG_RAD
from fms_testbed.sensors.mems.compensation import STAGES
from fms_testbed.sensors.mems.preset import MemsSpec, load_mems
from fms_testbed.sensors.mems.static_test import run_static_test

RULES = {
    "raw_zero_signal_deg_per_s": ("raw_zero", "median"),
    "temperature_residual_deg_per_s": ("temperature_residual", "median"),
    "run_to_run_error_deg_per_s": ("run_to_run_error", "max"),
    "run_to_run_residual_deg_per_s": ("run_to_run_residual", "median"),
    "angle_uncompensated_deg": ("angle_none", "median"),
    "angle_compensated_deg": ("angle_compensated", "max"),
}
"""Seed figure → (column of :attr:`Reproduction.rows`, aggregation over seeds)."""


@dataclass(frozen=True)
class Reproduction:
    """Per-seed measurements (``rows``: one row per seed and axis) and the seed's figures."""

    imu: str
    rows: pd.DataFrame
    reference: dict

    def figures(self) -> dict:
        """Figure → {paper, measured, ratio, rule} (module docstring for the rules)."""
        out = {}
        for key, (col, how) in RULES.items():
            if col in ("angle_none", "angle_compensated"):
                vals = self.rows[col].abs()
            else:
                vals = self.rows.groupby("seed")[col].max()
            v = float(vals.median() if how == "median" else vals.max())
            out[key] = {"paper": self.reference[key], "measured": float(f"{v:.5g}"),
                        "ratio": float(f"{v / self.reference[key]:.4g}"),
                        "rule": f"{how} over {'seeds and axes' if col.startswith('angle') else 'seeds'}"}
        return out

    def table(self) -> str:
        """A Markdown table of :meth:`figures`."""
        lines = ["| figure | paper | measured | ratio | measured as |", "|---|---|---|---|---|"]
        for k, f in self.figures().items():
            lines.append(f"| {k} | {f['paper']:g} | {f['measured']:g} | {f['ratio']:.3f} | "
                         f"{f['rule']} |")
        return "\n".join(lines)


def reproduce(imu: str | MemsSpec = "STIM210", seeds=range(10), rate_hz: float | None = None
              ) -> Reproduction:
    """Run the two static tests per seed (module docstring) and collect the measurements.

    Parameters
    ----------
    imu : MEMS preset name, path or spec
    seeds : switch-on seeds
    rate_hz : output rate, Hz (default the preset's)
    """
    spec = load_mems(imu)
    dur = float(spec.reference.duration_s)
    rows = []
    for seed in seeds:
        ramp = run_static_test(spec, dur, "ramp", STAGES[:3], seed, rate_hz=rate_hz)
        warm = run_static_test(spec, dur, "warmup", STAGES, seed, rate_hz=rate_hz)
        cal = ramp.calibration
        raw = np.abs(cal.point_zero_rps).max(axis=0) / DEG_RAD
        for a, ax in enumerate("xyz"):
            rows.append({
                "seed": int(seed), "axis": ax, "raw_zero": raw[a],
                "temperature_residual": cal.residual_max_rps[a] / DEG_RAD,
                "run_to_run_error": ramp.stage["temperature"].residual_max_deg_per_s[a],
                "run_to_run_residual": ramp.stage["run-to-run"].residual_max_deg_per_s[a],
                "angle_none": warm.stage["none"].angle_deg[a],
                "angle_compensated": warm.stage["slow-drift"].angle_deg[a]})
    return Reproduction(spec.name, pd.DataFrame(rows), spec.reference.model_dump())
