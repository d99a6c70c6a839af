"""The outcome of a flight: one vocabulary for ``run``, ``fly`` and the regression runs.

=====================  =========================================================  =========
status                 meaning                                                    exit code
=====================  =========================================================  =========
``ok``                 flown to its end, RNP-contained on every leg, every        0
                       constraint met, inside the aircraft's envelope
``diverged``           the flight had to be ended (non-finite state, ground       1
                       contact, stall, overspeed > 1.1 VMO, upset) or guidance
                       abandoned the procedure
``incomplete``         the duration ended before the procedure did                1
``degraded``           flown with ``--allow-degraded`` from a procedure with a    1
                       rejected, duplicated or misplaced record of its own
``envelope_exceeded``  above the ceiling, above VMO or MMO, or outside the        1
                       limit load factors of the aircraft file
``not_contained``      RNP containment lost: on some leg TSE95 > RNP or max       1
                       TSE > 2 × RNP (procedure flights); NSE95 > RNP or max
                       NSE > 2 × RNP (other flights with a navigation source);
                       or the on-board RNP alert was raised (ANP > RNP)
``constraints_missed`` a coded altitude/speed constraint was missed               1
=====================  =========================================================  =========

A user error (bad file, bad argument) is exit code 2 and no flight. When several apply, the
status is the first in the table's order (``diverged`` before ``incomplete`` before
``envelope_exceeded`` ...); the ``reason`` names every one that applies, and ``outcome.checks``
in the summary holds each check's verdict.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.earth import MEAN_RADIUS_M
from fms_testbed.core.units import FT_M, KT_MPS, NM_M

ORDER = ("diverged", "incomplete", "degraded", "envelope_exceeded", "not_contained",
         "constraints_missed")
"""Statuses other than ``ok``, most severe first."""

EXIT_CODES = {"ok": 0, **{s: 1 for s in ORDER}}
"""Process exit code per status (2 is a user error, never a status)."""

DEFAULT_ENROUTE_RNP_NM = 2.0
"""RNP applied to the navigation error of a flight without a procedure when the scenario names
no ``rnp_nm`` and its navigation source is not truth (RNAV/RNP 2, en route), NM."""


def envelope_violations(df: pd.DataFrame, cfg: AircraftConfig) -> list[str]:
    """The envelope limits the flight went past, each with the first time and the extreme value.

    Parameters
    ----------
    df : the flight's timeseries (``t_s``, ``alt_m``, ``cas_mps``, ``mach``, ``ny``)
    cfg : the aircraft (``limits.alt_max_m`` m, ``cas_max_mps`` m/s, ``mach_max``,
        ``ny_limit_min``/``ny_limit_max`` g: the limit load factors, not the laws' command limits)
    """
    if df.empty:
        return []
    lim = cfg.limits
    t = df["t_s"].to_numpy()
    out = []

    def first(mask, text):
        if mask.any():
            out.append(f"{text} from t={t[np.argmax(mask)]:.1f} s")

    alt = df["alt_m"].to_numpy()
    first(alt > lim.alt_max_m, f"altitude {alt.max() / FT_M:.0f} ft above the ceiling "
                               f"{lim.alt_max_m / FT_M:.0f} ft")
    cas = df["cas_mps"].to_numpy()
    first(cas > lim.cas_max_mps, f"CAS {cas.max() / KT_MPS:.0f} kt above VMO "
                                 f"{lim.cas_max_mps / KT_MPS:.0f} kt")
    mach = df["mach"].to_numpy()
    first(mach > lim.mach_max, f"Mach {mach.max():.3f} above MMO {lim.mach_max:.2f}")
    ny = df["ny"].to_numpy()
    first(ny > lim.ny_limit_max, f"load factor {ny.max():.2f} g above the limit "
                                 f"{lim.ny_limit_max:.2f} g")
    first(ny < lim.ny_limit_min, f"load factor {ny.min():.2f} g below the limit "
                                 f"{lim.ny_limit_min:.2f} g")
    return out


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


def navigation_containment(df: pd.DataFrame, rnp_nm: float) -> dict:
    """NSE containment of a flight without a defined path: NSE95 ≤ RNP and max NSE ≤ 2 × RNP.

    Parameters
    ----------
    df : timeseries with ``lat_deg``/``lon_deg`` (truth) and ``nav_lat_deg``/``nav_lon_deg``
    rnp_nm : the RNP, NM
    """
    nse = horizontal_distance_m(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(),
                                df["nav_lat_deg"].to_numpy(), df["nav_lon_deg"].to_numpy())
    nse = nse[np.isfinite(nse)]
    if not nse.size:
        return {"rnp_nm": rnp_nm, "nse95_m": None, "nse_max_m": None, "contained": None}
    p95, mx = float(np.percentile(nse, 95)), float(nse.max())
    rnp = rnp_nm * NM_M
    return {"rnp_nm": rnp_nm, "nse95_m": round(p95, 2), "nse_max_m": round(mx, 2),
            "contained": bool(p95 <= rnp and mx <= 2.0 * rnp)}


def decide(summary: dict, df: pd.DataFrame, cfg: AircraftConfig,
           rnp_nm: float | None = None) -> dict:
    """Set ``status``/``reason`` of a flight's summary from every check; add ``outcome``.

    Parameters
    ----------
    summary : the flight's summary (``status``/``reason`` from the flight loop: ``ok``,
        ``diverged`` or ``incomplete``; a procedure flight's ``rnp`` and ``constraints``)
    df : the timeseries
    cfg : the aircraft configuration (envelope limits)
    rnp_nm : RNP for the navigation error of a flight without a procedure, NM (None: no check)

    Returns
    -------
    the summary, updated in place
    """
    found: dict[str, list[str]] = {s: [] for s in ORDER}
    checks: dict = {}
    if summary["status"] in ("diverged", "incomplete"):
        found[summary["status"]].append(summary["reason"])
    degraded = (summary.get("procedure") or {}).get("degraded") or []
    checks["records"] = {"ok": not degraded, "defects": len(degraded)}
    if degraded:
        found["degraded"].append(f"built from a degraded procedure ({len(degraded)} record "
                                 f"defect(s), first: {degraded[0]})")
    env = envelope_violations(df, cfg)
    checks["envelope"] = {"ok": not env, "violations": env}
    found["envelope_exceeded"] += env
    if "rnp" in summary:
        r = summary["rnp"]
        checks["rnp"] = {"ok": bool(r["contained"]), "legs_not_contained": r["legs_not_contained"]}
        if not r["contained"]:
            found["not_contained"].append(f"RNP containment lost on legs {r['legs_not_contained']}")
    elif rnp_nm is not None:
        nc = navigation_containment(df, rnp_nm)
        checks["navigation"] = nc
        if nc["contained"] is False:
            found["not_contained"].append(
                f"navigation error NSE95 {nc['nse95_m']:.0f} m / max {nc['nse_max_m']:.0f} m "
                f"outside RNP {rnp_nm:g} NM")
    if "rnp_alert" in df and (df["rnp_alert"].to_numpy() > 0).any():
        t_alert = float(df["t_s"].to_numpy()[np.argmax(df["rnp_alert"].to_numpy() > 0)])
        checks["rnp_alert"] = {"ok": False, "first_t_s": round(t_alert, 2)}
        found["not_contained"].append(f"RNP alert (ANP > RNP) from t={t_alert:.1f} s")
    if "constraints" in summary:
        bad = [c for c in summary["constraints"] if c.get("ok") is False]
        checks["constraints"] = {"ok": not bad, "checked": len(summary["constraints"]),
                                 "missed": len(bad)}
        if bad:
            found["constraints_missed"].append(
                f"{len(bad)} constraint(s) missed: "
                + ", ".join(f"leg {c['leg']} {c['fix']}" for c in bad))
    failed = [s for s in ORDER if found[s]]
    if failed:
        summary["status"] = failed[0]
        summary["reason"] = "; ".join(r for s in failed for r in found[s])
    summary["outcome"] = {"status": summary["status"], "failed": failed, "checks": checks}
    return summary


__all__ = ["ORDER", "EXIT_CODES", "DEFAULT_ENROUTE_RNP_NM", "decide", "envelope_violations",
           "navigation_containment"]
