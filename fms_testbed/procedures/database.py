"""Load an ARINC-424 file into an indexed database: fixes, airports, runways, procedures.

One pass over the file (:mod:`.loader`) classifies and checks each record. Fix-like records are
parsed at once (tens of thousands); procedure records are grouped by airport as raw lines and
parsed on first use of that airport, so loading the whole FAA CIFP is a read plus a cheap
split. A bad record never raises: it becomes a :class:`~.fields.RecordError` (file, line,
columns, field, reason, text) in ``Database.issues``, and the transitions it belongs to carry
a :class:`~.integrity.Defect` (``Sequence.defects``; ``Sequence.degraded``).
"""

from __future__ import annotations

import logging
import stat
from dataclasses import dataclass, field
from pathlib import Path

from fms_testbed.core.errors import UserError
from fms_testbed.data import procedures_dir
from fms_testbed.procedures.fields import FieldError, RecordError
from fms_testbed.procedures.integrity import (DEFECT_KINDS, Defect, Key, rejected_defect,
                                              sequence_defects)
from fms_testbed.procedures.legrecord import LegRecord, parse_leg, read_key
from fms_testbed.procedures.loader import scan_text
from fms_testbed.procedures.records import Fix
from fms_testbed.procedures.legrecord import PROC_TYPES

log = logging.getLogger(__name__)

#: File name of the embedded excerpt inside ``procedures/``.
EMBEDDED_NAME = "cifp_excerpt.dat"

MAX_DB_BYTES = 1 << 30
"""Largest ARINC-424 file read, bytes (1 GiB: 20 times the whole FAA CIFP, 51 MB; a world
database of 1.5 million 132-column records is about 200 MB)."""


@dataclass(frozen=True, slots=True)
class Sequence:
    """One procedure transition: the legs sharing (airport, type, procedure, route, transition)."""

    airport: str
    proc_type: str
    proc_id: str
    route_type: str
    transition: str
    legs: tuple[LegRecord, ...]
    defects: tuple[Defect, ...] = ()
    """Why this transition cannot be trusted (:mod:`.integrity`); empty when it can."""
    lines: tuple[int, ...] = ()
    """Every file line of this transition (primary, continuation and rejected records)."""

    @property
    def degraded(self) -> bool:
        """One of its own records is rejected, duplicated or out of place (``defects``)."""
        return bool(self.defects)

    @property
    def key(self) -> Key:
        """(airport, type, procedure, route type, transition), as :attr:`LegRecord.key`."""
        return self.airport, self.proc_type, self.proc_id, self.route_type, self.transition

    @property
    def name(self) -> str:
        """Readable id, e.g. 'KJFK SID DEEZZ5 RW04B'."""
        t = f" {self.transition}" if self.transition else ""
        return f"{self.airport} {PROC_TYPES.get(self.proc_type, self.proc_type)} {self.proc_id}{t}"


@dataclass
class Database:
    """An ARINC-424 database held in memory.

    ``fixes`` maps (ident, region) to the fixes of that name by section; terminal fixes are
    looked up with their airport first. ``issues`` lists rejected records
    (:class:`~.fields.RecordError`): those found while loading, and the leg records of each
    airport once its sequences have been read.
    """

    path: str
    fixes: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    terminal: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    airports: dict[str, Fix] = field(default_factory=dict)
    _raw_procs: dict[str, list[tuple[int, str]]] = field(default_factory=dict)
    _parsed: dict[str, list[Sequence]] = field(default_factory=dict)
    issues: list[RecordError] = field(default_factory=list)
    n_lines: int = 0
    _key_lines: dict[Key, list[int]] = field(default_factory=dict)
    _keys_by_airport: dict[str, list[Key]] = field(default_factory=dict)
    _key_defects: dict[Key, list[Defect]] = field(default_factory=dict)
    _rejected_refs: dict[tuple[str, str], list[RecordError]] = field(default_factory=dict)

    # ------------------------------------------------------------------ lookup
    def airport_idents(self) -> list[str]:
        """Airports/heliports that have procedures (even if every record was rejected), sorted."""
        return sorted(self._keys_by_airport)

    def record_count(self, airport: str) -> int:
        """Number of primary procedure records (one per leg) of ``airport``, counted without
        parsing them (0 when it has none): a measure of the work of checking it."""
        return len(self._raw_procs.get(airport, ()))

    def procedure_index(self, airport: str) -> set[tuple[str, str, str, str]]:
        """The sequence keys (type 'D'/'E'/'F', procedure id, route type, transition id) of
        ``airport``, read from the raw records without parsing the legs (cheap enough to
        summarise every airport of a whole CIFP). Empty when the airport has no procedures."""
        return {(rec[12], rec[13:19].strip(), rec[19], rec[20:25].strip())
                for _, rec in self._raw_procs.get(airport, ())}

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
        """All procedure transitions of ``airport`` in file order (parsed on first use),
        with their defects; a transition whose every record was rejected is there too, with
        no legs."""
        if airport in self._parsed:
            return self._parsed[airport]
        keys = self._keys_by_airport.get(airport)
        if keys is None:
            raise UserError(f"{self.path}: airport {airport!r} has no procedures in this database")
        legs: dict[Key, list[LegRecord]] = {k: [] for k in keys}
        defects: dict[Key, list[Defect]] = {k: list(self._key_defects.get(k, ())) for k in keys}
        for lineno, rec in self._raw_procs.get(airport, ()):
            try:
                leg = parse_leg(rec, lineno)
            except FieldError as exc:
                err = RecordError.from_field(exc, self.path, lineno, rec)
                self.issues.append(err)
                defects[read_key(rec)].append(rejected_defect(err))
                continue
            legs[leg.key].append(leg)
        seqs = []
        for k in keys:
            found = defects[k] + sequence_defects([(lg.line, lg.seq) for lg in legs[k]],
                                                  self.path)
            found += self._reference_defects(airport, legs[k])
            found.sort(key=lambda d: DEFECT_KINDS.index(d.kind))  # the most telling first
            seqs.append(Sequence(*k, legs=tuple(sorted(legs[k], key=lambda lg: lg.seq)),
                                 defects=tuple(found), lines=tuple(self._key_lines.get(k, ()))))
        self._parsed[airport] = seqs
        return seqs

    def _reference_defects(self, airport: str, legs: list[LegRecord]) -> list[Defect]:
        """``fix-rejected`` defects: the airport's reference point, or a fix, navaid or RF
        centre a leg names, has a rejected record."""
        if not self._rejected_refs:
            return []
        out = [Defect("fix-rejected", (e.line,), "airport", f"the record of airport {airport} "
                      f"was rejected: {e.field}: {e.reason}", self.path)
               for e in self._rejected_refs.get(("airport", airport), ())]
        for lg in legs:
            for what, ref in (("fix", lg.fix), ("navaid", lg.navaid), ("centre fix", lg.centre)):
                found = (self._rejected_refs.get((airport, ref.ident), [])
                         + self._rejected_refs.get(("", ref.ident), [])) if ref else []
                for e in found:
                    out.append(Defect("fix-rejected", (lg.line, e.line), what,
                                      f"leg {lg.seq:03d} names {ref.ident}, whose record "
                                      f"(line {e.line}) was rejected: {e.field}: {e.reason}",
                                      self.path))
        return out

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


def _read(path: Path) -> str:
    """The text of an ARINC-424 file (Latin-1), after checking that it is a regular file of a
    plausible size; :class:`UserError` in one line otherwise."""
    try:
        st = path.stat()
    except OSError as exc:
        raise UserError(f"{path}: cannot read ARINC-424 file: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a directory" if stat.S_ISDIR(st.st_mode) else
                "a FIFO" if stat.S_ISFIFO(st.st_mode) else
                "a character device" if stat.S_ISCHR(st.st_mode) else
                "a block device" if stat.S_ISBLK(st.st_mode) else
                "a socket" if stat.S_ISSOCK(st.st_mode) else "not a regular file")
        raise UserError(f"{path}: is {kind}, not an ARINC-424 file (a regular file is needed)")
    if st.st_size > MAX_DB_BYTES:
        raise UserError(f"{path}: {st.st_size / 2**20:.0f} MiB is larger than the "
                        f"{MAX_DB_BYTES / 2**20:.0f} MiB an ARINC-424 database can plausibly be "
                        "(the whole FAA CIFP is 49 MiB); not read")
    try:
        with path.open("rb") as fh:
            data = fh.read(MAX_DB_BYTES + 1)
    except OSError as exc:
        raise UserError(f"{path}: cannot read ARINC-424 file: {exc.strerror or exc}") from None
    if len(data) > MAX_DB_BYTES:
        raise UserError(f"{path}: grew beyond {MAX_DB_BYTES / 2**20:.0f} MiB while read; not read")
    return data.decode("latin-1")


def load_database(path: str | Path | None = None) -> Database:
    """Read an ARINC-424 file (default: the embedded excerpt in ``procedures/``).

    Raises
    ------
    UserError
        when the file cannot be read, is not a regular file, is larger than
        :data:`MAX_DB_BYTES`, or holds no record at all. Malformed records do not raise: they
        are collected in ``Database.issues`` and degrade their transitions.
    """
    path = Path(path) if path else procedures_dir() / EMBEDDED_NAME
    return load_text(_read(path), str(path))


def load_text(text: str, name: str) -> Database:
    """A database from the text of an ARINC-424 file (``name`` is reported as its path).

    Raises
    ------
    UserError
        when the text holds no record at all (malformed records do not raise).
    """
    path = name
    scan = scan_text(text, name)
    if not scan.key_lines and not scan.fixes and not scan.airports:
        first = f"; first: {scan.errors[0]}" if scan.errors else ""
        raise UserError(f"{path}: no ARINC-424 records found (is this a 132-column file?)"
                        f"{first}")
    db = Database(path=str(path), fixes=scan.fixes, terminal=scan.terminal,
                  airports=scan.airports, _raw_procs=scan.raw_procs, issues=scan.errors,
                  n_lines=scan.n_lines, _key_lines=scan.key_lines,
                  _keys_by_airport=scan.keys_by_airport, _key_defects=scan.key_defects,
                  _rejected_refs=scan.rejected_refs)
    log.debug("%s: %d lines, %d airports with procedures, %d issues", path, scan.n_lines,
              len(scan.keys_by_airport), len(scan.errors))
    return db
