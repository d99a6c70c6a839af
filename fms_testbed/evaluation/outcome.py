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
                       TSE > 2 × RNP (procedure flights); the navigation error
                       seen from truth NSE95 > RNP or max NSE > 2 × RNP (every
                       flight with a navigation source other than truth); the
                       on-board RNP alert was raised (ANP > RNP). A NSE past
                       the RNP with the alert silent is recorded as a missed
                       alert (``outcome.checks.missed_alert``, an event)
``constraints_missed`` a coded altitude/speed constraint was missed               1
``timeout``            stopped from outside before its end (a regression run's    1
                       ``--case-timeout``); the checks of what was flown are kept
=====================  =========================================================  =========

A user error (bad file, bad argument) is exit code 2 and no flight. When several apply, the
status is the first in the table's order (``diverged`` before ``incomplete`` before
``envelope_exceeded`` ...; ``timeout`` whatever the checks say); the ``reason`` names every one
that applies, and ``outcome.checks`` in the summary holds each check's verdict.

:func:`decide` is the one place a flight's status is decided: the flight loop reports how it
ended (:class:`~fms_testbed.core.contracts.Ending`), the checks here say what that means.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.contracts import RecordView
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.evaluation.navigation_truth import (has_solution, horizontal_distance_m,
                                                     missed_alert, navigation_containment)
from fms_testbed.evaluation.records import (AlertCheck, Checks, ConstraintsCheck, EnvelopeCheck,
                                            MissedAlert, NavigationCheck, Outcome, RecordsCheck,
                                            RnpCheck)

ORDER = ("diverged", "incomplete", "degraded", "envelope_exceeded", "not_contained",
         "constraints_missed")
"""Statuses other than ``ok``, most severe first."""

STOPPED = "timeout"
"""Status of a flight stopped from outside before its end (a wall-time limit); its checks are
still recorded."""

EXIT_CODES = {"ok": 0, **{s: 1 for s in ORDER}, STOPPED: 1}
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


@dataclass(frozen=True)
class Decision(RecordView):
    """The flight's status and reason and the :class:`~.records.Outcome` they come from."""

    status: str
    reason: str
    outcome: Outcome


def decide(flight: Mapping, df: pd.DataFrame, cfg: AircraftConfig,
           rnp_nm: float | None = None) -> Decision:
    """The status of a flight — the one place it is decided — from how its loop ended and every
    check (module docstring).

    Parameters
    ----------
    flight : the flight's record so far, in its JSON form: ``status`` / ``reason`` of the loop
        (:class:`~fms_testbed.core.contracts.Ending`: ``ok``, ``diverged``, ``incomplete`` or
        ``timeout``), and for a procedure flight ``rnp``, ``constraints`` and ``procedure``
        (its ``degraded`` records)
    df : the timeseries
    cfg : the aircraft configuration (envelope limits)
    rnp_nm : RNP for the navigation error of a flight without a procedure, NM (None: no check)

    Returns
    -------
    :class:`Decision`: the status (``timeout`` for a flight stopped from outside, else the
    first failing one of :data:`ORDER`, else ``ok``), the reason naming every failure, and
    the checks
    """
    found: dict[str, list[str]] = {s: [] for s in ORDER}
    if flight["status"] in ("diverged", "incomplete"):
        found[flight["status"]].append(flight["reason"])
    degraded = (flight.get("procedure") or {}).get("degraded") or []
    checks: dict = {"records": RecordsCheck(not degraded, len(degraded))}
    if degraded:
        found["degraded"].append(f"built from a degraded procedure ({len(degraded)} record "
                                 f"defect(s), first: {degraded[0]})")
    env = envelope_violations(df, cfg)
    checks["envelope"] = EnvelopeCheck(not env, env)
    found["envelope_exceeded"] += env
    _containment(flight, df, rnp_nm, checks, found["not_contained"])
    if "constraints" in flight:
        cons = flight["constraints"]
        bad = [c for c in cons if c.get("ok") is False]
        checks["constraints"] = ConstraintsCheck(not bad, len(cons), len(bad))
        if bad:
            found["constraints_missed"].append(
                f"{len(bad)} constraint(s) missed: "
                + ", ".join(f"leg {c['leg']} {c['fix']}" for c in bad))
    failed = [s for s in ORDER if found[s]]
    status, reason = flight["status"], flight["reason"]
    if status == STOPPED:
        pass                                   # stopped from outside: what was flown is judged
    elif failed:
        status, reason = failed[0], "; ".join(r for s in failed for r in found[s])
    return Decision(status, reason, Outcome(status, failed, Checks(**checks)))


def _containment(flight: Mapping, df: pd.DataFrame, rnp_nm: float | None, checks: dict,
                 found: list[str]) -> None:
    """RNP containment (a procedure flight's ``rnp``), the navigation error seen from truth
    against the RNP in force (:mod:`.navigation_truth`: a procedure flight on a navigation
    source other than truth, or another flight with ``rnp_nm``), the on-board RNP alert and a
    missed alert: their checks into ``checks``, their failures into ``found``."""
    if flight.get("rnp") is not None:
        r = flight["rnp"]
        checks["rnp"] = RnpCheck(bool(r["contained"]), list(r["legs_not_contained"]))
        if not r["contained"]:
            found.append(f"RNP containment lost on legs {r['legs_not_contained']}")
    nav_source = (flight.get("procedure") or {}).get("navigation")
    truth_check = has_solution(df) and (
        (flight.get("rnp") is not None and nav_source not in (None, "truth"))
        or (flight.get("rnp") is None and rnp_nm is not None))
    if truth_check:
        nc = navigation_containment(df, rnp_nm)
        checks["navigation"] = NavigationCheck(**nc)
        miss = missed_alert(df, rnp_nm)
        if miss is not None:
            checks["missed_alert"] = MissedAlert(**miss)      # an event, not a status
        if nc["contained"] is False:
            found.append(f"navigation error NSE95 {nc['nse95_m']:.0f} m / max "
                         f"{nc['nse_max_m']:.0f} m outside RNP {nc['rnp_nm']:g} NM (seen from "
                         "truth)" + ("" if miss is None else
                                     f"; missed alert: NSE {miss['nse_m']:.0f} m past the RNP "
                                     f"at t={miss['t_s']:.1f} s with the RNP alert silent"))
    if "rnp_alert" in df and (df["rnp_alert"].to_numpy() > 0).any():
        t_alert = float(df["t_s"].to_numpy()[np.argmax(df["rnp_alert"].to_numpy() > 0)])
        checks["rnp_alert"] = AlertCheck(False, round(t_alert, 2))
        found.append(f"RNP alert (ANP > RNP) from t={t_alert:.1f} s")


__all__ = ["ORDER", "EXIT_CODES", "DEFAULT_ENROUTE_RNP_NM", "STOPPED", "Decision", "decide",
           "envelope_violations", "horizontal_distance_m", "navigation_containment"]
