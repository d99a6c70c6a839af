"""What an ARINC-424 database holds: its airports, their procedures, a procedure's transitions.

Three queries on a :class:`~fms_testbed.procedures.database.Database`, each returning a
:class:`pandas.DataFrame` (``fms-testbed procedures list`` formats them as a table or JSON):

* :func:`airports` — one row per airport/heliport with procedures: ``airport`` (ICAO ident),
  ``name`` (from the airport record, cols 94-123; '' when the database has no airport record),
  ``sids``, ``stars``, ``approaches`` (number of procedures of each type) and ``transitions``
  (number of procedure transitions, the database's sequences). Read from the raw records, so the
  whole FAA CIFP (196,178 leg records) is summarised in 0.07 s without parsing them.
* :func:`procedures` — one row per procedure of an airport: ``type`` (SID/STAR/APPROACH),
  ``procedure`` (ident), ``runways`` (runway transitions ``RWxx``/``RWxxB`` of a SID/STAR; for
  an approach the runway fixes its legs reach and the runway its ident names),
  ``transitions`` (en-route transitions of a SID/STAR, approach transitions of an approach),
  ``leg_codes`` (path terminators used, in the ARINC-424 order) and ``n_legs``.
* :func:`transitions` — one row per transition (sequence) of one procedure: ``transition``
  (ident, '' for the common route or the final approach), ``part`` (``runway``, ``common``,
  ``en-route``, ``approach transition``, ``final``), ``route_type`` (col 20), ``n_legs``,
  ``legs`` (the path-terminator sequence), ``fixes`` (the fix of each leg, '' when it has
  none) and ``degraded`` (one of its records is rejected, duplicated or out of place:
  ``procedures build`` refuses it unless ``--allow-degraded``).

An unknown airport or procedure raises :class:`~fms_testbed.core.errors.UserError` in one line
that lists the nearest idents (``difflib``).
"""

from __future__ import annotations

import difflib
import re

import pandas as pd

from fms_testbed.core.errors import UserError
from fms_testbed.procedures.database import Database, Sequence
from fms_testbed.procedures.legrecord import PATH_TERMINATORS, PROC_TYPES

_PT_ORDER = {pt: i for i, pt in enumerate(PATH_TERMINATORS)}
_TYPE_ORDER = {"D": 0, "E": 1, "F": 2}

AIRPORT_COLUMNS = ("airport", "name", "sids", "stars", "approaches", "transitions")
PROCEDURE_COLUMNS = ("type", "procedure", "runways", "transitions", "leg_codes", "n_legs")
TRANSITION_COLUMNS = ("transition", "part", "route_type", "n_legs", "legs", "fixes", "degraded")


def near_matches(ident: str, known: list[str], n: int = 5) -> list[str]:
    """Up to ``n`` idents of ``known`` closest to ``ident`` (difflib ratio ≥ 0.5; else those
    sharing its first two characters)."""
    close = difflib.get_close_matches(ident, known, n=n, cutoff=0.5)
    return close or [k for k in known if ident[:2] and k.startswith(ident[:2])][:n]


def _unknown(what: str, ident: str, known: list[str]) -> UserError:
    """``what`` holds ``{}`` where the quoted ident goes."""
    near = near_matches(ident, known)
    hint = (f"near matches: {', '.join(near)}" if near
            else f"{len(known)} known, e.g. {', '.join(known[:5])}")
    return UserError(f"no {what.format(repr(ident))}; {hint}")


def check_airport(db: Database, airport: str) -> str:
    """The airport ident upper-cased, when ``db`` has procedures for it.

    Raises
    ------
    UserError : the airport has no procedures in ``db`` (one line, with the near matches)
    """
    ident = airport.strip().upper()
    known = db.airport_idents()
    if ident not in known:
        raise _unknown(f"airport {{}} with procedures in {db.path}", ident, known)
    return ident


def airports(db: Database) -> pd.DataFrame:
    """Every airport/heliport of ``db`` that has procedures (columns :data:`AIRPORT_COLUMNS`),
    sorted by ident."""
    rows = []
    for ident in db.airport_idents():
        index = db.procedure_index(ident)
        procs = {(t, p) for t, p, _, _ in index}
        apt = db.airports.get(ident)
        rows.append({"airport": ident, "name": apt.name if apt is not None else "",
                     "sids": sum(t == "D" for t, _ in procs),
                     "stars": sum(t == "E" for t, _ in procs),
                     "approaches": sum(t == "F" for t, _ in procs),
                     "transitions": len(index)})
    return pd.DataFrame(rows, columns=list(AIRPORT_COLUMNS))


def _is_runway_transition(seq: Sequence) -> bool:
    return seq.proc_type in ("D", "E") and seq.transition.startswith("RW")


def _part(seq: Sequence) -> str:
    if seq.proc_type == "F":
        return "approach transition" if seq.route_type == "A" else "final"
    if _is_runway_transition(seq):
        return "runway"
    return "common" if seq.transition in ("", "ALL") else "en-route"


def _runways(db: Database, seqs: list[Sequence]) -> list[str]:
    """SID/STAR: the runway transitions. Approach: the runway fixes its legs reach, and the
    runway its ident names (``I22L``, ``R22LX``: type letter + runway) when the database has
    that runway."""
    s0 = seqs[0]
    if s0.proc_type != "F":
        return sorted({s.transition for s in seqs if _is_runway_transition(s)})
    found = {lg.fix.ident for s in seqs for lg in s.legs
             if lg.fix is not None and lg.fix.section in ("PG", "HG")}
    m = re.match(r"[A-Z](\d{2}[LRC]?)", s0.proc_id)
    if m:
        rw = "RW" + m.group(1)
        if any(f.section == "PG" for f in db.terminal.get((s0.airport, rw), ())):
            found.add(rw)
    return sorted(found)


def _leg_codes(seqs: list[Sequence]) -> list[str]:
    return sorted({lg.path_term for s in seqs for lg in s.legs}, key=_PT_ORDER.__getitem__)


def procedures(db: Database, airport: str) -> pd.DataFrame:
    """The procedures of ``airport`` (columns :data:`PROCEDURE_COLUMNS`): SIDs, then STARs, then
    approaches, each sorted by ident.

    Raises
    ------
    UserError : ``airport`` has no procedures in ``db``
    """
    ident = check_airport(db, airport)
    groups: dict[tuple[str, str], list[Sequence]] = {}
    for seq in db.sequences(ident):
        groups.setdefault((seq.proc_type, seq.proc_id), []).append(seq)
    rows = []
    for (ptype, pid), seqs in sorted(groups.items(),
                                     key=lambda kv: (_TYPE_ORDER.get(kv[0][0], 9), kv[0][1])):
        trans = sorted({s.transition for s in seqs
                        if s.transition and _part(s) in ("en-route", "approach transition")})
        rows.append({"type": PROC_TYPES.get(ptype, ptype), "procedure": pid,
                     "runways": _runways(db, seqs), "transitions": trans,
                     "leg_codes": _leg_codes(seqs), "n_legs": sum(len(s.legs) for s in seqs)})
    return pd.DataFrame(rows, columns=list(PROCEDURE_COLUMNS))


def transitions(db: Database, airport: str, procedure: str) -> pd.DataFrame:
    """The transitions of one procedure in database order (columns :data:`TRANSITION_COLUMNS`).

    Raises
    ------
    UserError : unknown airport, or ``procedure`` is not one of its procedures
    """
    ident = check_airport(db, airport)
    pid = procedure.strip().upper()
    seqs = db.sequences(ident)
    mine = [s for s in seqs if s.proc_id == pid]
    if not mine:
        known = sorted({s.proc_id for s in seqs})
        raise _unknown(f"procedure {{}} at {ident} in {db.path}", pid, known)
    rows = [{"transition": s.transition, "part": _part(s), "route_type": s.route_type,
             "n_legs": len(s.legs), "legs": [lg.path_term for lg in s.legs],
             "fixes": [lg.fix.ident if lg.fix is not None else "" for lg in s.legs],
             "degraded": bool(s.degraded)}
            for s in mine]
    return pd.DataFrame(rows, columns=list(TRANSITION_COLUMNS))


__all__ = ["AIRPORT_COLUMNS", "PROCEDURE_COLUMNS", "TRANSITION_COLUMNS", "airports",
           "check_airport", "near_matches", "procedures", "transitions"]
