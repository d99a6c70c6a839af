"""The navigation error seen from truth: what the on-board monitors cannot see.

The on-board RNP monitor compares ANP — the navigation source's own estimate of its 95 %
horizontal error — with the RNP in force (:mod:`fms_testbed.navigation.monitor`). A common-mode
failure (every INS stuck, a filter that trusts a wrong solution) leaves ANP small while the
solution is wrong: the monitor stays silent. The evaluation, which knows the truth, checks the
actual navigation system error instead:

* NSE(t) — the great-circle distance between the true position (``lat_deg``/``lon_deg``) and the
  navigation solution (``nav_lat_deg``/``nav_lon_deg``), m (:func:`horizontal_distance_m`);
* containment (RNP containment of the navigation error, as DO-236C §2.1 defines it for the
  total system error): NSE95 ≤ RNP and max NSE ≤ 2 × RNP, each sample normalised by the RNP in
  force at it (``rnp_m`` column of a procedure flight, else one RNP);
* a *missed alert*: the NSE went past the RNP in force at some time, and the on-board RNP alert
  (``rnp_alert`` column) was not raised at that time or before — an event of the outcome
  (:func:`missed_alert`).

Only the evaluation reads truth; estimators, monitors and guidance never do.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from fms_testbed.core.earth import MEAN_RADIUS_M
from fms_testbed.core.units import NM_M


def horizontal_distance_m(lat1_deg, lon1_deg, lat2_deg, lon2_deg) -> np.ndarray:
    """Great-circle (haversine) distance between two tracks, vectorised, m — good to 0.5 % of the
    WGS-84 geodesic at any distance (enough for a containment verdict, unlike a flat-Earth
    approximation at the 1,000 km errors of a free-running MEMS INS).

    Parameters
    ----------
    lat1_deg, lon1_deg, lat2_deg, lon2_deg : positions, deg (arrays of one shape)
    """
    p1, p2 = np.radians(lat1_deg), np.radians(lat2_deg)
    dl = np.radians(np.asarray(lon2_deg) - np.asarray(lon1_deg))
    h = np.sin(0.5 * (p2 - p1)) ** 2 + np.cos(p1) * np.cos(p2) * np.sin(0.5 * dl) ** 2
    return 2.0 * MEAN_RADIUS_M * np.arcsin(np.sqrt(np.clip(h, 0.0, 1.0)))


def has_solution(df: pd.DataFrame) -> bool:
    """The timeseries holds a navigation solution beside the truth.

    Parameters
    ----------
    df : the flight's timeseries
    """
    return {"lat_deg", "lon_deg", "nav_lat_deg", "nav_lon_deg"} <= set(df.columns)


def nse_m(df: pd.DataFrame) -> np.ndarray:
    """Horizontal navigation system error per sample, m (truth against the solution).

    Parameters
    ----------
    df : timeseries with ``lat_deg``/``lon_deg`` (truth) and ``nav_lat_deg``/``nav_lon_deg``
    """
    return horizontal_distance_m(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(),
                                 df["nav_lat_deg"].to_numpy(), df["nav_lon_deg"].to_numpy())


def rnp_in_force_m(df: pd.DataFrame, rnp_nm: float | None) -> np.ndarray:
    """The RNP in force at each sample, m: the ``rnp_m`` column where the timeseries has one
    and it is finite, else ``rnp_nm`` (NaN where neither gives one).

    Parameters
    ----------
    df : the timeseries; rnp_nm : the flight's RNP, NM (None: only the column)
    """
    fallback = np.nan if rnp_nm is None else rnp_nm * NM_M
    if "rnp_m" in df:
        r = df["rnp_m"].to_numpy(dtype=float)
        return np.where(np.isfinite(r) & (r > 0), r, fallback)
    return np.full(len(df), fallback)


def navigation_containment(df: pd.DataFrame, rnp_nm: float | None) -> dict:
    """NSE containment against the RNP in force (module docstring): NSE95 and max NSE, m, the
    smallest RNP, NM, and contained (None: no sample with both a NSE and an RNP).

    Parameters
    ----------
    df : timeseries with truth and the solution (and ``rnp_m`` for a procedure flight)
    rnp_nm : the RNP where the timeseries has no ``rnp_m``, NM
    """
    nse = nse_m(df)
    rnp = rnp_in_force_m(df, rnp_nm)
    ok = np.isfinite(nse) & np.isfinite(rnp)
    rnp_min_nm = round(float(np.min(rnp[ok])) / NM_M, 3) if ok.any() else rnp_nm
    if not ok.any():
        return {"rnp_nm": rnp_min_nm, "nse95_m": None, "nse_max_m": None, "contained": None}
    ratio = nse[ok] / rnp[ok]
    return {"rnp_nm": rnp_min_nm, "nse95_m": round(float(np.percentile(nse[ok], 95)), 2),
            "nse_max_m": round(float(nse[ok].max()), 2),
            "contained": bool(np.percentile(ratio, 95) <= 1.0 and ratio.max() <= 2.0)}


def missed_alert(df: pd.DataFrame, rnp_nm: float | None) -> dict | None:
    """The first time the NSE went past the RNP in force while the on-board RNP alert had not
    been raised (None: the NSE stayed within the RNP, or the alert was raised by then).

    Parameters
    ----------
    df : timeseries with truth, the solution, ``t_s`` and (when the monitor ran)
        ``rnp_alert`` (0/1)
    rnp_nm : the RNP where the timeseries has no ``rnp_m``, NM

    Returns
    -------
    ``{"t_s", "nse_m", "rnp_nm", "alert_t_s"}``: when, how large the error was, m, the RNP, NM,
    and when the alert was raised (None: never)
    """
    nse = nse_m(df)
    rnp = rnp_in_force_m(df, rnp_nm)
    with np.errstate(invalid="ignore"):
        out = np.isfinite(nse) & np.isfinite(rnp) & (nse > rnp)
    if not out.any():
        return None
    k = int(np.argmax(out))
    t = df["t_s"].to_numpy(dtype=float)
    alert = df["rnp_alert"].to_numpy(dtype=float) > 0 if "rnp_alert" in df \
        else np.zeros(len(df), bool)
    if alert[:k + 1].any():
        return None
    return {"t_s": round(float(t[k]), 2), "nse_m": round(float(nse[k]), 2),
            "rnp_nm": round(float(rnp[k]) / NM_M, 3),
            "alert_t_s": round(float(t[np.argmax(alert)]), 2) if alert.any() else None}


__all__ = ["has_solution", "horizontal_distance_m", "missed_alert", "navigation_containment",
           "nse_m", "rnp_in_force_m"]
