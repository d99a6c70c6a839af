"""Load an ARINC-424 file into an indexed database: fixes, airports, runways, procedures.

One pass over the file classifies each line by its section columns. Fix-like records are parsed
at once (tens of thousands); procedure records are grouped by airport as raw lines and parsed on
first use of that airport, so loading the whole FAA CIFP is a read plus a cheap split. A bad
record becomes a :class:`~.records.ParseIssue` (file, line, column, reason) and the rest loads.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

from fms_testbed.core.errors import UserError
from fms_testbed.data import procedures_dir
from fms_testbed.procedures.legrecord import LegRecord, parse_leg
from fms_testbed.procedures.records import (Fix, ParseIssue, RecordError, parse_airport, parse_localizer, parse_ndb,
                      parse_runway, parse_vhf, parse_waypoint)

log = logging.getLogger(__name__)

#: File name of the embedded excerpt inside ``procedures/``.
EMBEDDED_NAME = "cifp_excerpt.dat"


@dataclass(frozen=True, slots=True)
class Sequence:
    """One procedure transition: the legs sharing (airport, type, procedure, route, transition)."""

    airport: str
    proc_type: str
    proc_id: str
    route_type: str
    transition: str
    legs: tuple[LegRecord, ...]

    @property
    def name(self) -> str:
        """Readable id, e.g. 'KJFK SID DEEZZ5 RW04B'."""
        from fms_testbed.procedures.legrecord import PROC_TYPES
        t = f" {self.transition}" if self.transition else ""
        return f"{self.airport} {PROC_TYPES.get(self.proc_type, self.proc_type)} {self.proc_id}{t}"


@dataclass
class Database:
    """An ARINC-424 database held in memory.

    ``fixes`` maps (ident, region) to the fixes of that name by section; terminal fixes are
    looked up with their airport first. ``issues`` lists rejected records.
    """

    path: str
    fixes: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    terminal: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    airports: dict[str, Fix] = field(default_factory=dict)
    _raw_procs: dict[str, list[tuple[int, str]]] = field(default_factory=dict)
    _parsed: dict[str, list[Sequence]] = field(default_factory=dict)
    issues: list[ParseIssue] = field(default_factory=list)
    n_lines: int = 0

    # ------------------------------------------------------------------ lookup
    def airport_idents(self) -> list[str]:
        """Airports/heliports that have procedures, sorted."""
        return sorted(self._raw_procs)

    def find_fix(self, ref, airport: str) -> Fix | None:
        """Resolve a leg's :class:`~.legrecord.FixRef` (terminal records of ``airport`` first)."""
        if ref is None:
            return None
        sec = ref.section
        if sec in ("PA", "HA"):
            return self.airports.get(ref.ident)
        cands = self.terminal.get((airport, ref.ident))
        if cands:
            for f in cands:
                if f.section == sec or (sec in ("PC", "HC") and f.section == "PC"):
                    return f
            if sec[0] in ("P", "H"):
                return cands[0]
        cands = self.fixes.get((ref.ident, ref.region)) or self.fixes.get((ref.ident, ""))
        if cands:
            for f in cands:
                if f.section == sec:
                    return f
            return cands[0]
        return None

    def sequences(self, airport: str) -> list[Sequence]:
        """All procedure transitions of ``airport`` in file order (parsed on first use)."""
        if airport in self._parsed:
            return self._parsed[airport]
        raw = self._raw_procs.get(airport)
        if raw is None:
            raise UserError(f"{self.path}: airport {airport!r} has no procedures in this database")
        groups: dict[tuple, list[LegRecord]] = {}
        for lineno, rec in raw:
            try:
                leg = parse_leg(rec, lineno)
            except RecordError as exc:
                self.issues.append(ParseIssue(self.path, lineno, exc.column, exc.reason))
                continue
            groups.setdefault(leg.key, []).append(leg)
        seqs = [Sequence(*k, legs=tuple(sorted(v, key=lambda lg: lg.seq)))
                for k, v in groups.items()]
        self._parsed[airport] = seqs
        return seqs

    def select(self, airport: str, procedure: str | None = None,
               transition: str | None = None) -> list[Sequence]:
        """Sequences of an airport filtered by procedure id and transition id."""
        seqs = self.sequences(airport)
        if procedure:
            seqs = [s for s in seqs if s.proc_id == procedure]
        if transition is not None:
            seqs = [s for s in seqs if s.transition == transition]
        if not seqs:
            known = sorted({s.proc_id for s in self.sequences(airport)})
            what = f"procedure {procedure!r}" if procedure else "procedure"
            if transition is not None:
                what += f" with transition {transition!r}"
            raise UserError(f"{self.path}: no {what} at {airport}; procedures: "
                            f"{', '.join(known)}")
        return seqs


def _add(d: dict, key, fix: Fix) -> None:
    d.setdefault(key, []).append(fix)


def load_database(path: str | Path | None = None) -> Database:
    """Read an ARINC-424 file (default: the embedded excerpt in ``procedures/``).

    Raises
    ------
    UserError
        when the file cannot be read. Malformed records do not raise: they are collected in
        ``Database.issues`` with file, line, column and reason.
    """
    path = Path(path) if path else procedures_dir() / EMBEDDED_NAME
    try:
        text = path.read_text(encoding="latin-1")
    except OSError as exc:
        raise UserError(f"{path}: cannot read ARINC-424 file: {exc.strerror or exc}") from None
    db = Database(path=str(path))
    raw = db._raw_procs
    lines = text.splitlines()
    db.n_lines = len(lines)
    for i, rec in enumerate(lines, 1):
        if not rec or rec[0] != "S":
            if rec.startswith("HDR") or not rec.strip():
                continue
            db.issues.append(ParseIssue(str(path), i, 1, f"record type {rec[:1]!r} is not 'S'"))
            continue
        sec = rec[4:6]
        sub = rec[12:13] if len(rec) > 12 else ""
        try:
            if sec in ("P ", "H "):
                if sub in ("D", "E", "F"):
                    if rec[38:39] in ("0", "1"):
                        raw.setdefault(rec[6:10].strip(), []).append((i, rec))
                elif rec[21:22] not in ("0", "1") and sub != "A":
                    continue  # continuation record of a fix/runway
                elif sub == "C":
                    f = parse_waypoint(rec, i)
                    _add(db.terminal, (f.airport, f.ident), f)
                elif sub == "A":
                    if rec[21:22] in ("0", "1"):
                        f = parse_airport(rec, i)
                        db.airports[f.ident] = f
                elif sub == "G":
                    f = parse_runway(rec, i)
                    _add(db.terminal, (f.airport, f.ident), f)
                elif sub == "I":
                    f = parse_localizer(rec, i)
                    _add(db.terminal, (f.airport, f.ident), f)
            elif sec == "EA":
                if rec[21:22] in ("0", "1"):
                    f = parse_waypoint(rec, i)
                    _add(db.fixes, (f.ident, f.region), f)
            elif sec == "D ":
                if rec[21:22] in ("0", "1"):
                    f = parse_vhf(rec, i)
                    _add(db.fixes, (f.ident, f.region), f)
                    if f.airport:
                        _add(db.terminal, (f.airport, f.ident), f)
            elif sec in ("DB", "PN"):
                if rec[21:22] in ("0", "1"):
                    f = parse_ndb(rec, i)
                    _add(db.fixes, (f.ident, f.region), f)
                    if sec == "PN":
                        _add(db.terminal, (f.airport, f.ident), f)
        except RecordError as exc:
            db.issues.append(ParseIssue(str(path), i, exc.column, exc.reason))
        except (IndexError, ValueError) as exc:  # truncated line
            db.issues.append(ParseIssue(str(path), i, len(rec), f"malformed record: {exc}"))
    if not raw and not db.fixes and not db.airports:
        raise UserError(f"{path}: no ARINC-424 records found (is this a 132-column file?)")
    log.debug("%s: %d lines, %d airports with procedures, %d issues", path, len(lines),
              len(raw), len(db.issues))
    return db
