"""Campaign check of a tuning: the same procedure sample flown with two aircraft files (the file
gains and the tuned schedule) and the shift of the per-flight error distributions.

Flights of the two runs are paired by :data:`KEY` (airport, procedure type, procedure, runway,
transition, condition set). Per run: the number of cases, of flights with an error metric, of
``ok`` flights, of constraints checked and missed, and the median and 90th percentile of each of
:data:`METRICS` over the flown flights. Per pair: the median of the differences new − old. The
campaign goal (:func:`goal_lines`): median ``fte_p95_m`` and ``vpe_p95_m`` no worse than with
the file gains, and fewer constraints missed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

KEY = ["airport", "type", "procedure", "runway", "transition", "conditions"]
"""Columns that pair a flight of one run with the same flight of the other."""
METRICS = ("fte_p95_m", "vpe_p95_m", "spd_err_p95_kt")
"""Per-flight error metrics compared (m, m, kt)."""
OLD, NEW = "file gains", "tuned schedule"
"""Labels of the two runs."""


def conditions_yaml(wind: dict, turbulence: str) -> str:
    """The ``regress run --conditions`` file of the check: one set, the steady wind ``wind``
    (the scenario's mapping: ``from_deg`` and ``speed_kt``, ``speed_mps`` or ``speed_kmh``) and
    turbulence of ``turbulence`` severity."""
    import yaml

    speed = "-".join(f"{v:g}{k.removeprefix('speed_')}" for k, v in wind.items()
                     if k.startswith("speed"))
    name = f"wind-{wind['from_deg']:g}-{speed}-{turbulence}"
    return yaml.safe_dump({"conditions": [{"name": name, "wind": dict(wind),
                                           "turbulence": {"severity": turbulence}}]},
                          sort_keys=False)


def summary(df: pd.DataFrame) -> dict:
    """Per-run figures of the flights table ``df`` (regress rows): cases, flown (a metric of
    :data:`METRICS` present), ok, constraints checked and missed, median and p90 of each
    metric over the flown flights."""
    flown = df[df[list(METRICS)].notna().any(axis=1)]
    row = {"cases": len(df), "flown": len(flown), "ok": int((df.status == "ok").sum()),
           "constraints_checked": int(df.constraints_checked.fillna(0).sum()),
           "constraints_missed": int(df.constraints_missed.fillna(0).sum())}
    for m in METRICS:
        v = flown[m].dropna()
        row[f"{m} median"] = float(v.median()) if len(v) else np.nan
        row[f"{m} p90"] = float(v.quantile(0.9)) if len(v) else np.nan
    return row


@dataclass
class CampaignShift:
    """Outcome of :func:`campaign_shift`: the per-run table (:func:`summary` per column), the
    median paired difference new − old of each metric, the number of pairs, the two flights
    tables."""

    table: pd.DataFrame
    diffs: dict[str, float]
    n_pairs: int
    runs: dict[str, pd.DataFrame]


def campaign_shift(old: pd.DataFrame, new: pd.DataFrame) -> CampaignShift:
    """Compare the flights tables ``old`` (file gains) and ``new`` (tuned) (module docstring).

    The paired difference of metric ``m`` is ``median_i (m_new,i − m_old,i)`` over the pairs
    where both are present.
    """
    runs = {OLD: old, NEW: new}
    table = pd.DataFrame({k: summary(v) for k, v in runs.items()})
    both = old.set_index(KEY).merge(new.set_index(KEY), left_index=True, right_index=True,
                                    suffixes=("_old", "_new"))
    diffs = {m: float((both[f"{m}_new"] - both[f"{m}_old"]).median()) for m in METRICS}
    return CampaignShift(table, diffs, len(both), runs)


def goal_lines(s: CampaignShift) -> list[tuple[bool, str]]:
    """(met, text) of the campaign goal: median FTE95 and vertical path error p95 no worse than
    with the file gains, fewer constraints missed (of as many checked: a run that flew less
    cannot meet it; a NaN median never does)."""
    t = s.table
    out = []
    for m, what in (("fte_p95_m", "median FTE95"), ("vpe_p95_m", "median vertical path error p95")):
        a, b = t.loc[f"{m} median", OLD], t.loc[f"{m} median", NEW]
        out.append((bool(b <= a), f"campaign {what} no worse: {b:.2f} m (file gains {a:.2f} m)"))
    a, b = int(t.loc["constraints_missed", OLD]), int(t.loc["constraints_missed", NEW])
    checked = int(t.loc["constraints_checked", NEW])
    out.append((b < a and checked == int(t.loc["constraints_checked", OLD]) and s.n_pairs > 0,
                f"campaign constraints missed fewer: {b} (file gains {a}) of {checked}"))
    return out


def shift_markdown(s: CampaignShift, old_ref: str, new_ref: str, wind: str, turbulence: str,
                   table_md: str) -> str:
    """The check's Markdown section: aircraft, conditions, pairs, the per-run table (already
    rendered: ``table_md``), the median paired differences and the goal lines."""
    goals = "\n".join(f"- {'PASS' if ok else 'FAIL'}: {t}" for ok, t in goal_lines(s))
    return (f"Aircraft: `{old_ref}` (file gains) and `{new_ref}` (tuned schedule). "
            f"Conditions: wind {wind} kt, {turbulence} turbulence; {s.n_pairs} paired "
            f"flights.\n\n{table_md}\n\n"
            "Median of the paired differences (tuned − file gains): "
            + ", ".join(f"{m} {v:+.3g}" for m, v in s.diffs.items()) + f"\n\n{goals}\n")


__all__ = ["KEY", "METRICS", "NEW", "OLD", "CampaignShift", "campaign_shift", "conditions_yaml",
           "goal_lines", "shift_markdown", "summary"]
