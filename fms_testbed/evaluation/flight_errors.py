"""Flight errors of a procedure flight: FTE, NSE, PDE, TSE, RNP containment, constraint compliance.

Definitions (RNP, ICAO Doc 9613; ``shared/notes/navigation-monitoring.md``), all horizontal, m:

* FTE — flight technical error: the navigation solution's cross-track from the path guidance
  flies (``nav_xtk_m``);
* NSE — navigation system error: distance between the navigation solution and the true position;
* PDE — path definition error: distance of the built path guidance flies from the path the
  record codes, per segment of the leg's own path (``pde_m``, :mod:`fms_testbed.guidance.pde`):
  TF the geodesic between the fixes; CF the course line into the fix; FA/FC/FD/FM the course
  line out of the fix; RF the circle of the coded radius about the centre fix; AF the DME arc
  at rho; HA/HF/HM the racetrack on the inbound course. NaN on transitions (fly-by arcs, turns
  and intercepts onto a leg, connectors) and on leg types that code no path (IF, DF, PI, the
  C*/V* legs from the present position): each leg class says which
  (:attr:`fms_testbed.legs.base.Leg.pde_reference`);
* TSE — total system error: the true position's cross-track from the path (``xtk_m``).

The straight parts of heading legs (VA/VD/VI/VM/VR, flown as a heading; ``heading_leg`` = 1)
have no defined ground track: they are left out of the FTE and TSE statistics and of RNP
containment (their turn arcs count); ``errors.heading_leg_samples`` says how many samples that is.

Statistics are the 95th percentile of the absolute value and the maximum, over the whole flight,
over **straight flight** (on a line segment at least :data:`STRAIGHT_MARGIN_M` from the nearest
arc, so roll-in/roll-out transients count as turns), and per leg. RNP containment: TSE95 ≤ the
leg's RNP value (record, else the scenario's ``rnp_nm``, else 1 NM for SID/STAR and 0.3 NM for
approaches). Constraint compliance: at the sample nearest each constrained fix (for a fly-by
fix, nearest the middle of its fly-by arc, where the path passes it; for a leg that ends at a
condition — altitude, DME, radial, intercept, distance — where it ended) the true altitude must
be inside the coded window within :data:`ALT_TOL_FT` and the CAS inside the coded speed limit within :data:`SPEED_TOL_KT`.
A circling approach's coded top below the lowest altitude guidance may descend to (the field
elevation + 591 ft) is checked against that floor (:func:`constraint_checks`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from fms_testbed.core.earth import MEAN_RADIUS_M
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.evaluation.records import (ConstraintCheck, ErrorParts, ErrorStat,
                                            FlightErrors, LegErrors, RnpContainment, Sequencing)
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.profile import window

ALT_TOL_FT = 50.0
SPEED_TOL_KT = 5.0
STRAIGHT_MARGIN_M = 2000.0
FIX_PASS_MAX_M = 1.0 * NM_M
"""A constrained fix counts as passed when the flight came within this distance of it, m."""


def _dist_m(lat1, lon1, lat2, lon2):
    """Equirectangular distance (deg inputs, vectorised), m — accurate to < 0.1 % at < 50 km."""
    la1, la2 = np.radians(lat1), np.radians(lat2)
    x = np.radians(np.asarray(lon2) - np.asarray(lon1)) * np.cos(0.5 * (la1 + la2))
    return MEAN_RADIUS_M * np.hypot(x, la2 - la1)


def _stats(x: np.ndarray) -> dict[str, float | None]:
    x = np.abs(x[np.isfinite(x)])
    if x.size == 0:
        return {"p95_m": None, "max_m": None, "n": 0}
    return {"p95_m": round(float(np.percentile(x, 95)), 2), "max_m": round(float(x.max()), 2),
            "n": int(x.size)}


def error_columns(df: pd.DataFrame) -> pd.DataFrame:
    """Add ``fte_m`` (= nav_xtk_m), ``tse_m`` (= xtk_m) and ``nse_m`` (nav vs truth) columns to
    the timeseries ``df`` (a copy);
    FTE and TSE are NaN on the straight part of heading legs (``heading_leg``), which have no
    defined ground track."""
    df = df.copy()
    free = df["heading_leg"].to_numpy() == 1 if "heading_leg" in df else np.zeros(len(df), bool)
    df["fte_m"] = np.where(free, np.nan, df["nav_xtk_m"])
    df["tse_m"] = np.where(free, np.nan, df["xtk_m"])
    df["nse_m"] = _dist_m(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(),
                          df["nav_lat_deg"].to_numpy(), df["nav_lon_deg"].to_numpy())
    return df


def error_stats(df: pd.DataFrame) -> dict[str, ErrorParts]:
    """FTE/NSE/PDE/TSE statistics of ``df`` (:func:`error_columns`) overall, on straight flight
    and in turns (module docstring)."""
    straight = (df["curvature_1pm"].to_numpy() == 0) & (df["straight_m"].to_numpy()
                                                       >= STRAIGHT_MARGIN_M)
    out = {}
    for name in ("fte", "nse", "pde", "tse"):
        x = df[f"{name}_m"].to_numpy(dtype=float)
        out[name] = ErrorParts(ErrorStat(**_stats(x)), ErrorStat(**_stats(x[straight])),
                               ErrorStat(**_stats(x[~straight])))
    return out


def per_leg(df: pd.DataFrame, seq_legs) -> list[LegErrors]:
    """Per-leg statistics of ``df`` (:func:`error_columns`) for the records ``seq_legs`` and
    RNP containment (TSE95 ≤ RNP and max TSE ≤ 2 × RNP)."""
    rows = []
    for k, rec in enumerate(seq_legs):
        d = df[df["leg_index"] == k]
        row = {"leg": k + 1, "code": rec.path_term, "fix": rec.fix.ident if rec.fix else "",
               "samples": int(len(d))}
        if len(d):
            rnp = float(d["rnp_m"].iloc[0])
            for name in ("fte", "nse", "pde", "tse"):
                s = _stats(d[f"{name}_m"].to_numpy(dtype=float))
                row[f"{name}95_m"], row[f"{name}_max_m"] = s["p95_m"], s["max_m"]
            row["rnp_nm"] = round(rnp / NM_M, 2)
            # RNP containment: TSE95 within RNP and the largest TSE within 2 x RNP
            row["rnp_contained"] = (None if row["tse95_m"] is None
                                    else bool(row["tse95_m"] <= rnp
                                              and row["tse_max_m"] <= 2.0 * rnp))
        rows.append(LegErrors(**row))
    return rows


FIX_LEFT_M = 2000.0
"""A constrained fix is checked at its first passage: the next leg's samples count until the
aircraft is this much farther from the fix than its closest approach so far, m."""


def constraint_checks(df: pd.DataFrame, fp, floor_m: float = -math.inf
                      ) -> list[ConstraintCheck]:
    """Altitude and speed compliance at each constrained fix of the built procedure ``fp`` in
    the timeseries ``df`` (module docstring).

    ``floor_m``: the lowest altitude guidance descends to, m (a circling approach: the airport
    elevation + ``guidance.vnav.CIRCLING_FLOOR_HEIGHT_M``). A coded top below it — the CIFP
    codes a circling MAP at the field elevation, not at an MDA — is checked against the floor
    instead (``floor_ft`` in the row): the aircraft must not descend below the coded bottom
    and must reach the floor, within the tolerance."""
    built = {lg.index: lg for lg in fp.path.legs}
    passing = _passing_points(fp.path)
    out = []
    leg_col = df["leg_index"].to_numpy()
    for k, rec in enumerate(fp.seq.legs):
        lo, hi = window(rec.alt_desc, rec.alt1_m, rec.alt2_m)
        spd = rec.speed_limit_mps
        if lo is None and hi is None and not spd:
            continue
        row = {"leg": k + 1, "code": rec.path_term, "fix": rec.fix.ident if rec.fix else "",
               "alt_desc": rec.alt_desc}
        bl = built.get(k)
        i = _check_row(df, leg_col, k, rec, bl.termination if bl is not None else None,
                       passing, row)
        if i is not None:
            _judge(row, float(df["alt_m"].iloc[i]) / FT_M, float(df["cas_mps"].iloc[i]) / KT_MPS,
                   lo, hi, spd, rec.speed_desc, floor_m)
        out.append(row)
    return [ConstraintCheck(**r) for r in out]


def _check_row(df, leg_col, k: int, rec, term, passing, row: dict) -> int | None:
    """The timeseries row at which leg ``k``'s constraint is checked (``row['where']`` says
    where), or None with ``row['ok']``/``row['why']`` set when it cannot be checked."""
    if term is not None and (term.kind == "altitude" or not term.fix_ident and term.kind
                             in ("dme", "radial", "intercept", "manual", "distance")):
        # a leg that ends where a condition is met (an HA at its altitude over its fix):
        # checked where it ended, not where it first passed the fix
        sel = np.flatnonzero(leg_col == k)
        if sel.size:
            row["where"] = "leg end"
            return int(sel[-1])
        # ended between two logged rows (an altitude already reached when the leg began):
        # check the state when the next leg began
        after = np.flatnonzero(leg_col > k)
        if not after.size:
            row.update(ok=False, why="leg not flown")
            return None
        row["where"] = "leg end (ended within one logged step)"
        return int(after[0])
    if term is None or term.lat_deg is None or k == 0 and LEG_TYPES[rec.path_term].initial \
            and not len(df):
        row.update(ok=None, why="no fix position to check against")
        return None
    sel = np.flatnonzero((leg_col >= k - 1) & (leg_col <= k + 1))
    if not sel.size:
        row.update(ok=False, why="fix never approached")
        return None
    # a fly-by fix is passed where its fly-by arc is nearest to it (the arc's middle), up to
    # R (1/cos(Ω/2) − 1) away: the check is against that planned point
    plat, plon = passing.get(k, (term.lat_deg, term.lon_deg))
    d = _dist_m(df["lat_deg"].to_numpy()[sel], df["lon_deg"].to_numpy()[sel], plat, plon)
    # the first passage: the next leg's samples only until the aircraft has left the fix (a
    # hold at the fix comes back to it a circuit later, lower)
    nxt = leg_col[sel] == k + 1
    left = nxt & (d > np.minimum.accumulate(d) + FIX_LEFT_M)
    if left.any():
        cut = int(np.argmax(left))
        sel, d = sel[:cut], d[:cut]
    j = int(np.argmin(d))
    what = "the fix" if k not in passing else "the fly-by point abeam the fix"
    row["where"] = f"{d[j]:.0f} m from {what}"
    if d[j] > FIX_PASS_MAX_M:
        row.update(ok=False, why=f"{what} passed {d[j] / NM_M:.2f} NM away")
        return None
    return int(sel[j])


def _judge(row: dict, alt_ft: float, cas_kt: float, lo: float | None, hi: float | None,
           spd: float | None, speed_desc: str, floor_m: float) -> None:
    """Set the row's altitude (ft), CAS (kt), window, verdict and why (module docstring)."""
    ok = True
    msgs = []
    row["alt_ft"] = round(alt_ft)
    if lo is not None or hi is not None:
        row["window_ft"] = [None if lo is None else round(lo / FT_M),
                            None if hi is None else round(hi / FT_M)]
        if hi is not None and hi < floor_m:
            row["floor_ft"] = round(floor_m / FT_M)
            hi = floor_m
        if lo is not None and alt_ft < lo / FT_M - ALT_TOL_FT:
            ok = False
            msgs.append(f"{lo / FT_M - alt_ft:.0f} ft below")
        if hi is not None and alt_ft > hi / FT_M + ALT_TOL_FT:
            ok = False
            msgs.append(f"{alt_ft - hi / FT_M:.0f} ft above")
    if spd:
        row["cas_kt"] = round(cas_kt, 1)
        row["speed_limit_kt"] = f"{speed_desc or '@'}{spd / KT_MPS:.0f}"
        lim = spd / KT_MPS
        if speed_desc in ("", "@", "-") and cas_kt > lim + SPEED_TOL_KT:
            ok = False
            msgs.append(f"{cas_kt - lim:.1f} kt fast")
        if speed_desc in ("", "@", "+") and cas_kt < lim - SPEED_TOL_KT:
            ok = False
            msgs.append(f"{lim - cas_kt:.1f} kt slow")
    row["ok"] = ok
    if msgs:
        row["why"] = ", ".join(msgs)


def _passing_points(path) -> dict[int, tuple[float, float]]:
    """Leg index → (lat_deg, lon_deg) of the middle of the fly-by arc the leg ends in (the
    planned point abeam its fix), for legs of ``path`` that end in one."""
    last: dict[int, object] = {}
    for sg in path.segments:
        last[sg.leg_index] = sg
    return {k: sg.geom.point_at(0.5 * sg.geom.length_m())
            for k, sg in last.items() if sg.role == "flyby"}


def sequencing(legs_sequenced: list[int], completed: bool, n_legs: int) -> Sequencing:
    """Legs entered in order: none skipped, none entered twice.

    Parameters
    ----------
    legs_sequenced : whole-procedure leg indices in the order guidance entered them
    completed : the path was flown to its end and not abandoned
    n_legs : legs of the procedure
    """
    seq = list(legs_sequenced)
    seen, repeated = set(), []
    for k in seq:
        if k in seen:
            repeated.append(k + 1)
        seen.add(k)
    last = max(seq) if seq else -1
    skipped = [k + 1 for k in range(last + 1) if k not in seen]
    return Sequencing(n_legs, len(seen), skipped, repeated, seq == sorted(seq), bool(completed))


@dataclass(frozen=True)
class ProcedureErrors:
    """What a procedure flight's errors give the summary: ``errors`` (None: nothing flown on a
    path), ``rnp`` (None: idem), ``constraints``, ``constraints_met``, ``sequencing``."""

    errors: FlightErrors | None
    rnp: RnpContainment | None
    constraints: list[ConstraintCheck]
    constraints_met: bool | None
    sequencing: Sequencing


def flight_errors(df: pd.DataFrame, fp, legs_sequenced: list[int], completed: bool,
                  floor_m: float = -math.inf) -> ProcedureErrors:
    """Errors, RNP containment, constraints and sequencing of a procedure flight.

    Parameters
    ----------
    df : the timeseries with the guidance columns (``xtk_m``, ``nav_xtk_m``, ``leg_index`` …)
    fp : the built procedure flown; legs_sequenced, completed : :func:`sequencing`'s
    floor_m : the lowest altitude guidance descends to, m (:func:`constraint_checks`)
    """
    if df.empty or "xtk_m" not in df:
        return ProcedureErrors(None, None, [], None, sequencing(legs_sequenced, completed, 0))
    d = error_columns(df)
    legs = per_leg(d, fp.seq.legs)
    flown = [r for r in legs if r.samples]
    cons = constraint_checks(d, fp, floor_m)
    tse95 = _stats(d["tse_m"].to_numpy(dtype=float))["p95_m"]
    st = error_stats(d)
    return ProcedureErrors(
        FlightErrors(st["fte"], st["nse"], st["pde"], st["tse"], legs,
                     int(d["heading_leg"].sum()) if "heading_leg" in d else 0),
        RnpContainment(all(r.rnp_contained is not False for r in flown),
                       [r.leg for r in flown if r.rnp_contained is False], tse95,
                       round(min(r.rnp_nm for r in flown), 2) if flown else None),
        cons, all(c.ok is not False for c in cons),
        sequencing(legs_sequenced, completed, len(fp.seq.legs)))


__all__ = ["ProcedureErrors", "error_columns", "error_stats", "per_leg", "constraint_checks",
           "sequencing", "flight_errors"]
