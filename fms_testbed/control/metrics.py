"""Step-response metrics of a vertical law run (settling, overshoot, interaction, throttle use).

All functions take the runner's timeseries columns (``t_s``, ``alt_m``, ``tas_mps``,
``cmd_alt_m``, ``cmd_tas_mps``, ``throttle``, ``ny``, ``cmd_ny``) as a pandas DataFrame, so JSBSim
and point-mass runs are measured by the same code.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd


@dataclass(frozen=True, slots=True)
class StepMetrics:
    """Metrics of one step in one channel, with the other channel's deviation.

    channel : ``"alt"`` or ``"speed"`` (the channel that was stepped)
    t_step_s : time of the command change, s
    step : commanded change (m for alt, m/s for speed)
    settling_s : time from the step until the response stays within ``band`` of the new target, s
        (``nan`` if it never does)
    rise_s : 10 → 90 % rise time, s
    overshoot_pct : overshoot past the new target, % of the step
    max_cross_dev : max |deviation| of the other channel from its target after the step
        (m/s for speed, m for altitude)
    throttle_activity_ps : mean |d throttle/dt| after the step, 1/s
    throttle_sat_frac : fraction of the time after the step with the throttle at a limit
    ny_range : (min, max) measured normal load factor after the step, g
    """

    channel: str
    t_step_s: float
    step: float
    settling_s: float
    rise_s: float
    overshoot_pct: float
    max_cross_dev: float
    throttle_activity_ps: float
    throttle_sat_frac: float
    ny_min: float
    ny_max: float

    def as_dict(self) -> dict:
        """Plain dict (JSON/YAML-ready)."""
        return asdict(self)


def find_steps(df: pd.DataFrame, col: str, tol: float = 1e-6) -> list[int]:
    """Row indices of ``df`` where the command column ``col`` changes by more than ``tol``."""
    c = df[col].to_numpy()
    return [int(i) + 1 for i in np.flatnonzero(np.abs(np.diff(c)) > tol)]


def settling_time(t_s: np.ndarray, y: np.ndarray, target: float, band: float) -> float:
    """Time (s, from ``t_s[0]``) after which ``|y - target| <= band`` for good; ``nan`` if never."""
    out = np.abs(y - target) > band
    if not out.any():
        return 0.0
    last = np.flatnonzero(out)[-1]
    if last == len(y) - 1:
        return float("nan")
    return float(t_s[last + 1] - t_s[0])


def rise_time(t_s: np.ndarray, y: np.ndarray, y0: float, target: float) -> float:
    """10 → 90 % rise time of ``y`` from ``y0`` to ``target`` over times ``t_s`` (s), s.

    ``nan`` if 90 % is never reached.
    """
    frac = (y - y0) / (target - y0)
    i10 = np.flatnonzero(frac >= 0.1)
    i90 = np.flatnonzero(frac >= 0.9)
    if len(i10) == 0 or len(i90) == 0:
        return float("nan")
    return float(t_s[i90[0]] - t_s[i10[0]])


def step_metrics(df: pd.DataFrame, channel: str, band_frac: float = 0.02,
                 band_min: float | None = None, throttle_min: float = 0.0,
                 throttle_max: float = 1.0, t_end_s: float | None = None,
                 reference: pd.DataFrame | None = None) -> StepMetrics:
    """Measure the first step of ``channel`` (``"alt"`` or ``"speed"``) in a run.

    Parameters
    ----------
    df : timeseries with the runner's columns
    channel : which command was stepped
    band_frac : settling band as a fraction of the step (default 2 %)
    band_min : lower bound on the band (m or m/s), e.g. sensor-level noise
    throttle_min, throttle_max : throttle limits for the saturation fraction
    t_end_s : evaluate up to this time (default: end of run or the channel's next command change)
    reference : optional run of the same commands (e.g. the ideal point-mass response); when
        given, the cross deviation is the other channel's distance from the reference over the
        whole step (for overlapping steps), else its distance from its command until either
        command changes again

    Notes
    -----
    A command that appears (NaN before the law engages) counts as a step from the measured
    value when it differs from it by more than 0.5 (m or m/s).
    """
    ycol, ccol, xcol, xc = (("alt_m", "cmd_alt_m", "tas_mps", "cmd_tas_mps") if channel == "alt"
                            else ("tas_mps", "cmd_tas_mps", "alt_m", "cmd_alt_m"))
    steps = find_steps(df, ccol) + _appearing(df, ccol, ycol)
    if not steps:
        raise ValueError(f"no {channel} command change in the run")
    i0 = min(steps)
    t = df["t_s"].to_numpy()
    end = _segment_end(df, ccol, i0, t, t_end_s)
    seg = slice(i0, end)
    ts, y = t[seg], df[ycol].to_numpy()[seg]
    prev = float(df[ccol].iloc[i0 - 1])
    y0 = prev if np.isfinite(prev) else float(df[ycol].iloc[i0 - 1])
    target = float(df[ccol].iloc[i0])
    step = target - y0
    band = abs(step) * band_frac
    if band_min is not None:
        band = max(band, band_min)
    over = max(0.0, float(np.max((y - target) * np.sign(step)))) / abs(step) * 100.0
    if reference is not None:
        xr = np.interp(ts, reference["t_s"].to_numpy(), reference[xcol].to_numpy())
        cross = np.abs(df[xcol].to_numpy()[seg] - xr)
    else:
        other = [i for i in find_steps(df, xc) if i > i0]
        cend = min([end] + other)
        cross = np.abs(df[xcol].to_numpy()[i0:cend] - df[xc].to_numpy()[i0:cend])
    thr = df["throttle"].to_numpy()[seg]
    act = float(np.sum(np.abs(np.diff(thr))) / max(ts[-1] - ts[0], 1e-9))
    sat = float(np.mean((thr >= throttle_max - 0.005) | (thr <= throttle_min + 0.005)))
    ny = df["ny"].to_numpy()[seg]
    return StepMetrics(channel, float(t[i0]), step, settling_time(ts, y, target, band),
                       rise_time(ts, y, y0, target), over, float(np.nanmax(cross)), act, sat,
                       float(ny.min()), float(ny.max()))


def _segment_end(df: pd.DataFrame, ccol: str, i0: int, t: np.ndarray,
                 t_end_s: float | None) -> int:
    """End index of the step starting at ``i0``: the channel's next command change or
    ``t_end_s`` (s), whichever is first."""
    later = [i for i in find_steps(df, ccol) if i > i0]
    end = min(later) if later else len(df)
    if t_end_s is not None:
        end = min(end, int(np.searchsorted(t, t_end_s)))
    return end


def _appearing(df: pd.DataFrame, ccol: str, ycol: str, tol: float = 0.5) -> list[int]:
    """Rows where the command goes from NaN to a value more than ``tol`` from the measurement."""
    c = df[ccol].to_numpy()
    y = df[ycol].to_numpy()
    idx = np.flatnonzero(~np.isfinite(c[:-1]) & np.isfinite(c[1:])) + 1
    return [int(i) for i in idx if abs(c[i] - y[i - 1]) > tol]

