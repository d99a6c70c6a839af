"""On-board performance monitoring and alerting (RNP = RNAV + monitoring, seed 000): ANP from the
filter's covariance against the RNP of the leg flown, and the navigation-mode codes logged with it.

ANP (actual navigation performance, also EPU) is the radius of the circle that contains the
horizontal position error with 95 % probability given the filter's covariance
(:func:`fms_testbed.sensors.sins.analysis.horizontal_radius`). The RNP alert is raised when ANP has
exceeded RNP for ``delay_s`` (a debounce against single-sample crossings) and cleared when ANP is
back below RNP; ICAO's time to alert is 10 s in terminal and approach airspace and 30 s en route
(PANS-OPS; ``shared/notes/navigation-monitoring.md``), so ``delay_s`` must stay below the
phase's limit (checked by :func:`rnp_alerts`). The monitor is causal — each verdict uses only the
samples up to its time — so run over the logged timeseries it gives the verdicts an on-board
monitor running at the log rate would have given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import NM_M

NAV_MODES = {0: "gnss", 1: "coast", 2: "invalid"}
"""``nav_mode`` codes of the timeseries: 0 GNSS-aided (a fix used within the last two fix
periods), 1 inertial coasting (no fix used: outage or every fix rejected), 2 no valid solution."""

TIME_TO_ALERT_S = {"terminal": 10.0, "approach": 10.0, "enroute": 30.0}
"""ICAO time-to-alert limits per flight phase, s."""

DEFAULT_ALERT_DELAY_S = 2.0
"""Default persistence of ANP > RNP before the alert, s."""

TERMINAL_RNP_M = 1.0 * NM_M
"""An RNP at or below this (m) is terminal/approach airspace (TTA 10 s); above it, en route."""


@dataclass(frozen=True)
class AlertTrace:
    """The RNP monitor's verdict per sample and its transitions.

    alert : (n,) bool, True while the RNP alert is raised
    events : one dict per raise/clear: ``t_s``, ``kind`` (``alert``), ``stage`` (``rnp``),
        ``unit`` (``fms``), ``reason`` (ANP and RNP in m, or ``cleared``)
    time_to_alert_s : for each raise, time since ANP first exceeded RNP, s
    """

    alert: np.ndarray
    events: list[dict]
    time_to_alert_s: list[float]


def time_to_alert_limit_s(rnp_m: float) -> float:
    """ICAO time to alert for an RNP value (m): 10 s at ≤ 1 NM (terminal/approach), else 30 s."""
    return TIME_TO_ALERT_S["approach"] if rnp_m <= TERMINAL_RNP_M else TIME_TO_ALERT_S["enroute"]


def rnp_alerts(t_s: np.ndarray, anp_m: np.ndarray, rnp_m: np.ndarray,
               delay_s: float = DEFAULT_ALERT_DELAY_S) -> AlertTrace:
    """Run the RNP monitor over samples (causal).

    Parameters
    ----------
    t_s : (n,) increasing sample times, s
    anp_m : (n,) ANP, m (NaN: no estimate — never raises, never clears)
    rnp_m : (n,) RNP of the leg flown, m (NaN: no RNP — no alert)
    delay_s : how long ANP > RNP must persist before the alert, s; must be below the time to
        alert of every RNP in ``rnp_m``

    Returns
    -------
    :class:`AlertTrace`

    Raises
    ------
    ConfigError : ``delay_s`` not below the time to alert of an RNP flown
    """
    t = np.asarray(t_s, float)
    anp = np.asarray(anp_m, float)
    rnp = np.asarray(rnp_m, float)
    finite_rnp = rnp[np.isfinite(rnp)]
    if finite_rnp.size:
        limit = min(time_to_alert_limit_s(float(r)) for r in np.unique(finite_rnp))
        if not delay_s < limit:
            raise ConfigError(f"navigation.alert_delay_s: {delay_s:g} s is not below the time "
                              f"to alert {limit:g} s of the RNP flown")
    alert = np.zeros(t.size, bool)
    events: list[dict] = []
    tta: list[float] = []
    raised = False
    since = None                         # time ANP first exceeded RNP (current excursion)
    for k in range(t.size):
        a, r = anp[k], rnp[k]
        if np.isfinite(a) and np.isfinite(r):
            if a > r:
                if since is None:
                    since = t[k]
                if not raised and t[k] - since >= delay_s - 1e-9:
                    raised = True
                    tta.append(float(t[k] - since))
                    events.append({"t_s": round(float(t[k]), 3), "unit": "fms", "kind": "alert",
                                   "stage": "rnp", "reason": f"ANP {a:.0f} m > RNP {r:.0f} m "
                                                             f"since t={since:.1f} s"})
            else:
                since = None
                if raised:
                    raised = False
                    events.append({"t_s": round(float(t[k]), 3), "unit": "fms", "kind": "alert",
                                   "stage": "rnp", "reason": f"cleared: ANP {a:.0f} m <= RNP "
                                                             f"{r:.0f} m"})
        alert[k] = raised
    return AlertTrace(alert, events, tta)


def monitor_flight(df: pd.DataFrame, source, rnp_m: float | None
                   ) -> tuple[pd.DataFrame, dict | None]:
    """The flight's navigation monitoring: the RNP alert over its timeseries and the source's
    events, for ``summary.json``'s ``navigation`` block.

    Parameters
    ----------
    df : the timeseries; ``anp_m`` (from the source) and, for a procedure flight, ``rnp_m`` (the
        leg's RNP, from guidance)
    source : the navigation source (its ``events`` list and ``alert_delay_s`` when it has them)
    rnp_m : RNP for a flight without a procedure, m (None: no RNP, no alert)

    Returns
    -------
    (df with an ``rnp_alert`` column 0/1 when ANP was logged, the ``navigation`` block: ``events``
    sorted by time and ``rnp_alert`` {raised, first_t_s, time_to_alert_s, delay_s}; None when the
    source logs neither ANP nor events nor has a ``truth_model``; ``truth_model`` the source's)
    """
    events = [dict(e) for e in getattr(source, "events", None) or []]
    truth_model = getattr(source, "truth_model", None)
    if "anp_m" not in df and not events and truth_model is None:
        return df, None
    block: dict = {}
    if "anp_m" in df:
        delay = float(getattr(source, "alert_delay_s", DEFAULT_ALERT_DELAY_S))
        if "rnp_m" in df:
            rnp = df["rnp_m"].to_numpy(float)
        else:
            rnp = np.full(len(df), np.nan if rnp_m is None else float(rnp_m))
        trace = rnp_alerts(df["t_s"].to_numpy(), df["anp_m"].to_numpy(float), rnp, delay)
        df = df.assign(rnp_alert=trace.alert.astype(float))
        events += trace.events
        raised = [e for e in trace.events if not e["reason"].startswith("cleared")]
        anp = df["anp_m"].to_numpy(float)
        block["rnp_alert"] = {
            "raised": bool(raised), "first_t_s": raised[0]["t_s"] if raised else None,
            "time_to_alert_s": [round(x, 2) for x in trace.time_to_alert_s], "delay_s": delay,
            "anp_max_m": round(float(np.nanmax(anp)), 2) if np.isfinite(anp).any() else None}
    nse95 = nse95_by_output(df)
    if nse95:
        block["nse95_m"] = nse95
    block["events"] = sorted(events, key=lambda e: e["t_s"])
    if truth_model is not None:
        block["truth_model"] = truth_model
    return df, block


NSE_OUTPUTS = {"output": "nse", "reference": "nse_ref", "vote": "nse_vote"}
"""Outputs whose horizontal NSE is logged: the flown output, the reference-description
monitor's and the majority-voting baseline's (``<prefix>_east_m``, ``<prefix>_north_m``)."""


def nse95_by_output(df: pd.DataFrame) -> dict:
    """95th percentile of the horizontal NSE √(E² + N²) of each logged output, m (the flown
    output, the reference-description monitor's, majority voting's; only those logged).

    Parameters
    ----------
    df : the timeseries with ``nse_east_m``/``nse_north_m`` and optionally ``nse_ref_*``,
        ``nse_vote_*`` (m)
    """
    out = {}
    for name, pre in NSE_OUTPUTS.items():
        if f"{pre}_east_m" in df and f"{pre}_north_m" in df:
            h = np.hypot(df[f"{pre}_east_m"].to_numpy(float), df[f"{pre}_north_m"].to_numpy(float))
            h = h[np.isfinite(h)]
            if h.size:
                out[name] = round(float(np.percentile(h, 95)), 2)
    return out


__all__ = ["AlertTrace", "NSE_OUTPUTS", "monitor_flight", "nse95_by_output", "DEFAULT_ALERT_DELAY_S", "NAV_MODES", "TIME_TO_ALERT_S", "rnp_alerts",
           "time_to_alert_limit_s"]
