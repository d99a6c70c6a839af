"""Whole-database check: build and monitor every procedure transition, tabulate the outcome.

Work is split by airport; with ``workers > 1`` a process pool loads the database once per
worker and airports are handed out in chunks. Rows are sorted by (airport, file order) so the
table does not depend on the number of workers.
"""

from __future__ import annotations

import logging
import math
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from fms_testbed.core.processes import die_with_parent
from fms_testbed.core.geodesy import gravity_mps2, inverse
from fms_testbed.core.segments import Arc
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.procedures.database import Database
from fms_testbed.procedures.legrecord import PATH_TERMINATORS, PROC_TYPES
from fms_testbed.legs.model import BuildParams, Performance, ProcedurePath
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.coding import coding_kind
from fms_testbed.path.monitor import check_path, leg_end_checks
from fms_testbed.path.segmentation import build_sequence

log = logging.getLogger(__name__)


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
        kind = LEG_TYPES[seg.path_term]
        if seg.role != "leg" or not isinstance(seg.geom, Arc) or kind.arc_centre is None:
            continue
        rec = path.legs[seg.leg_index].record
        if kind.arc_centre == "fix" and rec.arc_radius_m:
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
        kind = LEG_TYPES[lg.path_term]
        if d not in ("L", "R") or kind.course_reversal or kind.arc_centre or kind.initial:
            continue  # the coded direction is the hold's / PT's or the arc's, or no path
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


def _lines(seq) -> str:
    """'first-last' file lines of a transition's records ('' when it has none)."""
    return f"{seq.lines[0]}-{seq.lines[-1]}" if seq.lines else ""


def check_transition(db: Database, seq, perf: Performance, params: BuildParams):
    """Build and monitor one transition.

    Returns
    -------
    (path or None, invariants or None, internal error text or '')
        an exception from the builder or the monitor is a bug, not a verdict on the
        procedure: it is returned as 'internal error: <type>: <message> (records at lines
        a-b)' and the row is ``degraded``, counted apart (``internal_errors``), never
        'impossible'.
    """
    try:
        path = build_sequence(db, seq, perf, params)
        apt = db.airports.get(seq.airport)
        path = check_path(path, perf, params, gravity_mps2(apt.lat_deg if apt else 45.0))
        return path, invariants(path), ""
    except Exception as exc:  # noqa: BLE001 -- recorded with its type and lines, counted apart
        log.warning("%s: internal error building %s (lines %s)", db.path, seq.name,
                    _lines(seq), exc_info=True)
        return None, None, (f"internal error: {type(exc).__name__}: {exc} "
                            f"(records at lines {_lines(seq) or 'none'})")


ROW_COLUMNS = ("airport", "order", "procedure", "transition", "type", "route_type", "legs",
               "n_legs", "status", "findings", "branches", "flags", "n_segments", "length_nm",
               "max_gap_m", "fix_excess_m", "rf_radius_err_nm", "turn_mismatch", "built_legs",
               "monitor_status", "defects", "lines", "max_plan_alt_ft", "max_plan_tas_kt",
               "coding")
"""Columns of a check row (:func:`check_airport`), in order."""


def check_airport(db: Database, airport: str, perf: Performance,
                  params: BuildParams | None = None) -> list[dict]:
    """Build and monitor every transition of one airport; one row (dict) per transition.

    ``status`` is the monitor's ('ok', 'corrected', 'impossible') for a transition whose
    records are all sound, and ``degraded`` for one with a rejected, duplicated or misplaced
    record of its own (:mod:`fms_testbed.procedures.integrity`) or an internal error;
    ``monitor_status`` keeps what the monitor said ('' when nothing was built,
    'internal-error'), ``defects`` the defect kinds, ``lines`` the file lines of its records.
    """
    rows = []
    params = params or BuildParams()
    for order, seq in enumerate(db.sequences(airport)):
        path = inv = None
        crash = ""
        if seq.legs:
            path, inv, crash = check_transition(db, seq, perf, params)
        legs = [lg.path_term for lg in seq.legs]
        findings = [d.finding for d in seq.defects]
        if crash:
            findings.append(crash)
        if path is not None:
            findings += [f"leg {f.leg_index + 1} {f.category}"
                         f"{' [' + f.branch + ']' if f.branch else ''}: {f.message}"
                         for f in path.findings]
        kinds = sorted({d.kind for d in seq.defects} | ({"internal-error"} if crash else set()))
        monitor = path.status if path is not None else ("internal-error" if crash else "")
        rows.append({
            "airport": airport, "order": order,
            "procedure": seq.proc_id, "transition": seq.transition,
            "type": PROC_TYPES.get(seq.proc_type, seq.proc_type),
            "route_type": seq.route_type, "legs": " ".join(legs), "n_legs": len(legs),
            "status": "degraded" if kinds else monitor,
            "findings": "; ".join(findings),
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
            "monitor_status": monitor, "defects": ",".join(kinds), "lines": _lines(seq),
            "max_plan_alt_ft": math.nan if path is None else path.max_plan_alt_m() / FT_M,
            "max_plan_tas_kt": math.nan if path is None else path.max_plan_tas_mps() / KT_MPS,
            "coding": "" if path is None else ",".join(
                sorted({coding_kind(f) for f in path.findings if f.category == "coding"})),
        })
    return rows


def _load(db_path) -> Database:
    """The database through its index (:func:`~fms_testbed.procedures.index.load_index`: the
    file parsed once, then unpickled in a fraction of a second by every worker)."""
    from fms_testbed.procedures.index import load_index
    return load_index(db_path).db


_WORKER: dict = {}


def _init_worker(db_path: str, perf: Performance, params: BuildParams) -> None:
    """A pool worker's state: the database of ``db_path`` — inherited from the parent when the
    worker is forked (:func:`_share_with_workers`), else loaded — the performance and the
    build settings."""
    die_with_parent()                       # no orphan worker after a SIGKILL of the parent
    if _WORKER.get("db_path") != db_path:
        _WORKER["db"] = _load(db_path)
        _WORKER["db_path"] = db_path
    _WORKER["perf"] = perf
    _WORKER["params"] = params


def _share_with_workers(db: Database) -> None:
    """Leave the parent's loaded database where forked workers find it: they start without
    loading the index again. Spawned workers (another start method) load their own."""
    _WORKER["db"] = db
    _WORKER["db_path"] = str(db.path)


def _work(airport: str) -> tuple[list[tuple], list]:
    """Check one airport in a pool worker: its rows as tuples in :data:`ROW_COLUMNS` order
    (a compact payload, rebuilt into dicts by the parent) and the records it rejected."""
    db = _WORKER["db"]
    n0 = len(db.issues)
    rows = check_airport(db, airport, _WORKER["perf"], _WORKER["params"])
    return [tuple(r[c] for c in ROW_COLUMNS) for r in rows], db.issues[n0:]


def schedule(db: Database, airports: list[str], workers: int) -> tuple[list[str], int]:
    """The order airports are handed to pool workers and the chunk size.

    Largest first (by :meth:`~fms_testbed.procedures.database.Database.record_count`, ties by
    ident) so the last airports handed out are the small ones and the workers finish together;
    chunks of about 1/32 of each worker's share keep the per-task overhead small. The rows
    are sorted afterwards, so the table does not depend on this order.
    """
    order = sorted(airports, key=lambda a: (-db.record_count(a), a))
    return order, max(1, len(order) // (workers * 32))


@dataclass
class CheckResult:
    """What a database check found: ``rows`` (one per transition, sorted by airport and file
    order), ``summary`` (:func:`summarise`), ``rejected`` (every rejected record read, as
    :class:`~fms_testbed.procedures.fields.RecordError`, sorted by line)."""

    rows: list[dict]
    summary: dict
    rejected: list


def merge_airports(airports: list[str] | None) -> list[str] | None:
    """Airport idents upper-cased, repeats merged (first occurrence kept): 'KBFI KBFI kbfi'
    is one airport."""
    if not airports:
        return None
    return list(dict.fromkeys(a.upper() for a in airports))


def run_check(db_path: str | None, perf: Performance, airports: list[str] | None = None,
              workers: int = 1, params: BuildParams | None = None, progress: bool = True
              ) -> CheckResult:
    """Check a database (every airport, or ``airports``, repeats merged case-insensitively)."""
    t0 = time.perf_counter()
    params = params or BuildParams()
    db = _load(db_path)
    known = set(db.airport_idents())
    todo = merge_airports(airports) or sorted(known)
    missing = [a for a in todo if a not in known]
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
        _share_with_workers(db)
        with ProcessPoolExecutor(workers, initializer=_init_worker,
                                 initargs=(str(db.path), perf, params)) as ex:
            order, chunk = schedule(db, todo, workers)
            for part, issues in ex.map(_work, order, chunksize=chunk):
                rows.extend(dict(zip(ROW_COLUMNS, t)) for t in part)
                db.issues.extend(issues)
                if bar:
                    bar.update(1)
        _WORKER.clear()
    if bar:
        bar.close()
    rows.sort(key=lambda r: (r["airport"], r["order"]))
    db.issues.sort(key=lambda e: (e.line, e.column))
    return CheckResult(rows, summarise(rows, db, time.perf_counter() - t0, workers), db.issues)


def check_database(db_path: str | None, perf: Performance, airports: list[str] | None = None,
                   workers: int = 1, params: BuildParams | None = None, progress: bool = True
                   ) -> tuple[list[dict], dict]:
    """:func:`run_check`; return (rows sorted by airport and file order, summary dict)."""
    res = run_check(db_path, perf, airports, workers, params, progress)
    return res.rows, res.summary


def summarise(rows: list[dict], db: Database, elapsed_s: float, workers: int) -> dict:
    """Counts by status and by leg type; leg types built at least once; invariant maxima.

    ``ok_or_corrected_pct`` is over every transition, degraded ones included; degraded rows
    are left out of the leg types built and of the invariant maxima (their geometry comes from
    records in doubt), and counted by defect kind in ``degraded_by_defect``;
    ``internal_errors`` counts the transitions whose build raised (a bug, never 'impossible').
    """
    by_status = Counter(r["status"] for r in rows)
    leg_all: Counter = Counter()
    leg_built: Counter = Counter()
    for r in rows:
        leg_all.update(r["legs"].split())
        if r["status"] not in ("impossible", "degraded"):
            leg_built.update(r["built_legs"].split())
    n = len(rows)
    good = by_status.get("ok", 0) + by_status.get("corrected", 0)
    sound = [r for r in rows if r["status"] != "degraded"]
    finite = [r for r in sound if r["max_gap_m"] == r["max_gap_m"]]
    return {
        "database": db.path, "lines": db.n_lines, "parse_issues": len(db.issues),
        "rejected_records": len(db.issues),
        "transitions": n, "by_status": dict(by_status),
        "ok_or_corrected_pct": 100.0 * good / n if n else float("nan"),
        "degraded_by_defect": dict(Counter(k for r in rows for k in r["defects"].split(",")
                                           if k)),
        "internal_errors": sum(r["monitor_status"] == "internal-error" for r in rows),
        "by_leg_type": {pt: {"coded": leg_all.get(pt, 0), "built": leg_built.get(pt, 0)}
                        for pt in PATH_TERMINATORS},
        "leg_types_present_not_built": [pt for pt in PATH_TERMINATORS
                                        if leg_all.get(pt) and not leg_built.get(pt)],
        "max_gap_m": max((r["max_gap_m"] for r in finite), default=0.0),
        "max_fix_excess_m": max((r["fix_excess_m"] for r in finite), default=0.0),
        "max_rf_radius_err_nm": max((r["rf_radius_err_nm"] for r in finite), default=0.0),
        "turn_mismatches": sum(max(r["turn_mismatch"], 0) for r in sound),
        "branches": dict(Counter(b for r in rows for b in r["branches"].split("|") if b)),
        "flags": dict(Counter(f for r in rows for f in r["flags"].split(",") if f)),
        "class3_transitions": sum(bool(r["coding"]) or "loop" in r["flags"] for r in rows),
        "class3_by_kind": dict(Counter(k for r in rows for k in r["coding"].split(",") if k)),
        "elapsed_s": elapsed_s, "workers": workers,
    }
