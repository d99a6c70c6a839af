"""Whole-database check: build and monitor every procedure transition, tabulate the outcome.

Work is split by airport; with ``workers > 1`` a process pool loads the database once per
worker and airports are handed out in chunks. Rows are sorted by (airport, file order) so the
table does not depend on the number of workers.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from fms_testbed.core.processes import die_with_parent
from fms_testbed.core.geodesy import gravity_mps2, inverse
from fms_testbed.core.segments import Arc
from fms_testbed.core.units import NM_M
from fms_testbed.procedures.database import Database, load_database
from fms_testbed.procedures.legrecord import PATH_TERMINATORS, PROC_TYPES
from fms_testbed.legs.model import BuildParams, Performance, ProcedurePath
from fms_testbed.path.monitor import check_path, leg_end_checks
from fms_testbed.path.segmentation import build_sequence



@dataclass(frozen=True, slots=True)
class Invariants:
    """Geometric invariants of one built path (what the whole-file tests assert).

    max_gap_m: largest distance between consecutive segments' end and start, m;
    fix_excess_m: largest (distance from a fix leg's end to its fix − allowed), m (≤ 0 = ok);
    rf_radius_err_m: largest |built RF radius − coded radius|, m;
    turn_mismatch: number of RF/AF arcs turning against the coded direction plus legs whose
    first turn goes against it (:func:`leg_turn_mismatches`).
    """

    max_gap_m: float
    fix_excess_m: float
    rf_radius_err_m: float
    turn_mismatch: int


def invariants(path: ProcedurePath) -> Invariants:
    """Measure the geometric invariants of a built path."""
    segs = path.segments
    gap = 0.0
    for a, b in zip(segs, segs[1:]):
        gap = max(gap, inverse(*a.geom.end, *b.geom.start)[0])
    excess = max((fc.miss_m - fc.allowed_m for fc in leg_end_checks(path)), default=-math.inf)
    rf_err = 0.0
    mism = leg_turn_mismatches(path)
    for seg in segs:
        if seg.role != "leg" or not isinstance(seg.geom, Arc) or seg.path_term not in ("RF", "AF"):
            continue
        rec = path.legs[seg.leg_index].record
        if seg.path_term == "RF" and rec.arc_radius_m:
            rf_err = max(rf_err, abs(seg.geom.radius_m - rec.arc_radius_m))
        if rec.turn_dir in ("L", "R") and seg.geom.turn != rec.turn_dir:
            mism += 1
    return Invariants(gap, excess, rf_err, mism)


def leg_turn_mismatches(path: ProcedurePath) -> int:
    """Legs whose first turn goes against the coded turn direction (col 44).

    The first turn of a leg is the fly-by arc that ends the previous leg into it, or the turn
    flown from the present position at its start; later turns of the same leg (the return onto
    a course after a 45° intercept, hold circuits, the procedure turn's 180°) are not the coded
    turn. Turns under 1° are ignored.
    """
    segs = path.segments
    first: dict[int, int] = {}
    for k, seg in enumerate(segs):
        first.setdefault(seg.leg_index, k)
    bad = 0
    for lg in path.legs:
        d = lg.record.turn_dir
        if d not in ("L", "R") or lg.path_term in ("HA", "HF", "HM", "PI", "RF", "AF", "IF"):
            continue
        k = first.get(lg.index)
        if k is None:
            continue
        arc = None
        if k > 0 and segs[k - 1].role == "flyby" and segs[k - 1].leg_index == lg.index - 1:
            # a fly-by ending the previous leg into this one (not one ending an earlier leg
            # into a leg that came out zero-length)
            arc = segs[k - 1].geom
        elif segs[k].role == "turn" and isinstance(segs[k].geom, Arc):
            arc = segs[k].geom
        if arc is not None and abs(arc.sweep_deg) > 1.0 and arc.turn != d:
            bad += 1
    return bad


def perf_for(aircraft: str) -> Performance:
    """Performance of a shipped aircraft (``aircraft/NAME.yaml``) or a YAML path."""
    from fms_testbed.config.aircraft import load_aircraft
    return Performance.from_aircraft(load_aircraft(aircraft))


def check_airport(db: Database, airport: str, perf: Performance,
                  params: BuildParams | None = None) -> list[dict]:
    """Build and monitor every transition of one airport; one row (dict) per transition."""
    rows = []
    params = params or BuildParams()
    for order, seq in enumerate(db.sequences(airport)):
        try:
            path = build_sequence(db, seq, perf, params)
            apt = db.airports.get(airport)
            path = check_path(path, perf, params, gravity_mps2(apt.lat_deg if apt else 45.0))
            inv = invariants(path)
            crash = ""
        except Exception as exc:  # one bad transition never kills the batch
            path, inv, crash = None, None, f"internal error: {type(exc).__name__}: {exc}"
        legs = [lg.path_term for lg in seq.legs]
        findings = [] if path is None else [
            f"leg {f.leg_index + 1} {f.category}{' [' + f.branch + ']' if f.branch else ''}: "
            f"{f.message}" for f in path.findings]
        rows.append({
            "airport": airport, "order": order,
            "procedure": seq.proc_id, "transition": seq.transition,
            "type": PROC_TYPES.get(seq.proc_type, seq.proc_type),
            "route_type": seq.route_type, "legs": " ".join(legs), "n_legs": len(legs),
            "status": "impossible" if path is None else path.status,
            "findings": "; ".join(findings) if not crash else crash,
            "branches": "" if path is None else "|".join(
                sorted({f.branch for f in path.findings if f.branch})),
            "flags": "" if path is None else ",".join(
                sorted({f.category for f in path.findings
                        if f.category in ("discontinuity", "loop", "no-intercept")})),
            "n_segments": 0 if path is None else len(path.segments),
            "length_nm": float("nan") if path is None else path.length_m() / NM_M,
            "max_gap_m": float("nan") if inv is None else inv.max_gap_m,
            "fix_excess_m": float("nan") if inv is None else inv.fix_excess_m,
            "rf_radius_err_nm": float("nan") if inv is None else inv.rf_radius_err_m / NM_M,
            "turn_mismatch": -1 if inv is None else inv.turn_mismatch,
            "built_legs": "" if path is None else " ".join(lg.path_term for lg in path.legs),
        })
    return rows


_WORKER: dict = {}


def _init_worker(db_path: str, perf: Performance, params: BuildParams) -> None:
    die_with_parent()                       # no orphan worker after a SIGKILL of the parent
    _WORKER["db"] = load_database(db_path)
    _WORKER["perf"] = perf
    _WORKER["params"] = params


def _work(airport: str) -> tuple[list[dict], list]:
    db = _WORKER["db"]
    n0 = len(db.issues)
    rows = check_airport(db, airport, _WORKER["perf"], _WORKER["params"])
    return rows, db.issues[n0:]


def check_database(db_path: str | None, perf: Performance, airports: list[str] | None = None,
                   workers: int = 1, params: BuildParams | None = None, progress: bool = True
                   ) -> tuple[list[dict], dict]:
    """Check a database; return (rows sorted by airport and file order, summary dict)."""
    t0 = time.perf_counter()
    params = params or BuildParams()
    db = load_database(db_path)
    todo = airports or db.airport_idents()
    missing = [a for a in todo if a not in db._raw_procs]
    if missing:
        from fms_testbed.core.errors import UserError
        raise UserError(f"{db.path}: no procedures for airport(s) {', '.join(missing)}")
    rows: list[dict] = []
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(todo), unit="airport", desc="procedures check", leave=False)
    if workers <= 1:
        for a in todo:
            rows.extend(check_airport(db, a, perf, params))
            if bar:
                bar.update(1)
    else:
        with ProcessPoolExecutor(workers, initializer=_init_worker,
                                 initargs=(str(db.path), perf, params)) as ex:
            for part, issues in ex.map(_work, todo,
                                       chunksize=max(1, len(todo) // (workers * 8))):
                rows.extend(part)
                db.issues.extend(issues)
                if bar:
                    bar.update(1)
    if bar:
        bar.close()
    rows.sort(key=lambda r: (r["airport"], r["order"]))
    return rows, summarise(rows, db, time.perf_counter() - t0, workers)


def summarise(rows: list[dict], db: Database, elapsed_s: float, workers: int) -> dict:
    """Counts by status and by leg type; leg types built at least once; invariant maxima."""
    by_status = Counter(r["status"] for r in rows)
    leg_all: Counter = Counter()
    leg_built: Counter = Counter()
    for r in rows:
        leg_all.update(r["legs"].split())
        if r["status"] != "impossible":
            leg_built.update(r["built_legs"].split())
    n = len(rows)
    good = by_status.get("ok", 0) + by_status.get("corrected", 0)
    finite = [r for r in rows if r["max_gap_m"] == r["max_gap_m"]]
    return {
        "database": db.path, "lines": db.n_lines, "parse_issues": len(db.issues),
        "transitions": n, "by_status": dict(by_status),
        "ok_or_corrected_pct": 100.0 * good / n if n else float("nan"),
        "by_leg_type": {pt: {"coded": leg_all.get(pt, 0), "built": leg_built.get(pt, 0)}
                        for pt in PATH_TERMINATORS},
        "leg_types_present_not_built": [pt for pt in PATH_TERMINATORS
                                        if leg_all.get(pt) and not leg_built.get(pt)],
        "max_gap_m": max((r["max_gap_m"] for r in finite), default=0.0),
        "max_fix_excess_m": max((r["fix_excess_m"] for r in finite), default=0.0),
        "max_rf_radius_err_nm": max((r["rf_radius_err_nm"] for r in finite), default=0.0),
        "turn_mismatches": sum(max(r["turn_mismatch"], 0) for r in rows),
        "branches": dict(Counter(b for r in rows for b in r["branches"].split("|") if b)),
        "flags": dict(Counter(f for r in rows for f in r["flags"].split(",") if f)),
        "elapsed_s": elapsed_s, "workers": workers,
    }
