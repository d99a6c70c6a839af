"""One pass over an ARINC-424 file: split it into records, classify and check each one.

Lines are split at "\\n" only (``str.splitlines()`` also splits at \\x85, \\x0c, \\x1c-\\x1e and
would shift every later line number); one trailing "\\r" (CRLF files) is dropped. Header lines
(``HDR``) and blank lines at the end are skipped; a blank line between records is
rejected (it may be a record blanked out). Every other line must be a 132-column record in the
ARINC-424 character set of a known section; fix-like records (waypoints, navaids, airports,
runways, localizers) are parsed at once, procedure records are kept raw per airport and parsed
on first use (:meth:`~.database.Database.sequences`). A record that cannot be read becomes a
:class:`~.fields.RecordError`; which transitions it degrades is decided here
(:mod:`.integrity`): its own when its key (cols 5-25) can be read, else those of the lines
next to it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from fms_testbed.procedures.fields import FieldError, RecordError, check_record
from fms_testbed.procedures.integrity import Defect, Key, rejected_defect, structure_defects
from fms_testbed.procedures.legrecord import check_leg_record, is_procedure_record, read_key
from fms_testbed.procedures.records import (Fix, parse_airport, parse_localizer, parse_ndb,
                                            parse_runway, parse_vhf, parse_waypoint)

#: Sections (cols 5-6) outside the airport/heliport sections 'P'/'H' that a record may have.
OTHER_SECTIONS = frozenset({"AS", "D ", "DB", "EA", "EM", "EP", "ER", "ET", "EU", "EV", "R ",
                            "RA", "TC", "TG", "TN", "UC", "UF", "UR"})
#: Subsections (col 13) of airport ('P') and heliport ('H') records.
AIRPORT_SUBSECTIONS = {"P": frozenset("ABCDEFGIKLMNPRSTV"), "H": frozenset("ACDEFKPSV")}
_CONTINUATION = re.compile(r"[2-9A-Z]")
_REJECTED = "\0rejected"   # stands for "the line before was rejected"
#: Where the ident of a fix-like record is (1-based columns), by section code.
_IDENT_COLS = {"EA": (14, 18), "PC": (14, 18), "PG": (14, 18), "D ": (14, 17), "DB": (14, 17),
               "PN": (14, 17), "PI": (14, 17), "PA": (7, 10)}


def split_lines(text: str) -> list[str]:
    """Records of a file: split at "\\n" only, one trailing "\\r" dropped per line, blank
    lines at the end dropped."""
    lines = [ln[:-1] if ln.endswith("\r") else ln for ln in text.split("\n")]
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


@dataclass
class Scan:
    """What one pass over a file found (see the module docstring).

    raw_procs: airport -> [(line, record)] of the primary procedure records whose key reads;
    key_lines: transition -> every line of it (primary, continuation, rejected) in file order;
    keys_by_airport: airport -> its transitions in file order; owner: line -> transition;
    key_defects: transition -> defects found here; rejected_refs: (airport, ident) for a
    terminal fix, ('', ident) for an enroute one, ('airport', ident) for an airport reference
    point -> the rejected records that carried it; errors: every rejected record.
    """

    file: str
    fixes: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    terminal: dict[tuple[str, str], list[Fix]] = field(default_factory=dict)
    airports: dict[str, Fix] = field(default_factory=dict)
    raw_procs: dict[str, list[tuple[int, str]]] = field(default_factory=dict)
    key_lines: dict[Key, list[int]] = field(default_factory=dict)
    keys_by_airport: dict[str, list[Key]] = field(default_factory=dict)
    owner: dict[int, Key] = field(default_factory=dict)
    key_defects: dict[Key, list[Defect]] = field(default_factory=dict)
    rejected_refs: dict[tuple[str, str], list[RecordError]] = field(default_factory=dict)
    errors: list[RecordError] = field(default_factory=list)
    n_lines: int = 0


def _add(d: dict, key, fix: Fix) -> None:
    d.setdefault(key, []).append(fix)


def _fix_record(scan: Scan, rec: str, i: int, prev: str | None) -> None:
    """Parse one non-procedure record into the scan (raises FieldError)."""
    p, s6, sub = rec[4], rec[5], rec[12]
    if p in "PH":
        if s6 != " " and not (p == "P" and s6 == "N"):
            raise FieldError(6, "section", f"{rec[4:6]!r} is not a known ARINC-424 section")
        if s6 == " " and sub not in AIRPORT_SUBSECTIONS[p]:
            raise FieldError(13, "subsection", f"{sub!r} is not a known "
                                               f"{'airport' if p == 'P' else 'heliport'} "
                                               "subsection")
        sec = "PN" if s6 == "N" else ("P" + sub if sub in "ACGI" else "")
    elif rec[4:6] in OTHER_SECTIONS:
        sec = rec[4:6] if rec[4:6] in ("EA", "D ", "DB") else ""
    else:
        raise FieldError(5, "section", f"{rec[4:6]!r} is not a known ARINC-424 section", 6)
    if not sec:
        return  # a section the testbed does not read (airways, MSA, path points, airspace...)
    cont = rec[21]
    if cont not in "01":
        if not _CONTINUATION.fullmatch(cont):
            raise FieldError(22, "continuation number", f"{cont!r} is not 0-9 or A-Z")
        if prev is None or prev[:21] != rec[:21]:
            raise FieldError(22, "continuation number", "continuation record without its "
                                                        "primary record on the line before")
        return
    if sec == "PC":
        f = parse_waypoint(rec, i)
        _add(scan.terminal, (f.airport, f.ident), f)
    elif sec == "PA":
        f = parse_airport(rec, i)
        scan.airports[f.ident] = f
    elif sec == "PG":
        f = parse_runway(rec, i)
        _add(scan.terminal, (f.airport, f.ident), f)
    elif sec == "PI":
        f = parse_localizer(rec, i)
        _add(scan.terminal, (f.airport, f.ident), f)
    elif sec == "EA":
        f = parse_waypoint(rec, i)
        _add(scan.fixes, (f.ident, f.region), f)
    elif sec == "D ":
        f = parse_vhf(rec, i)
        _add(scan.fixes, (f.ident, f.region), f)
        if f.airport:
            _add(scan.terminal, (f.airport, f.ident), f)
    else:  # DB, PN
        f = parse_ndb(rec, i)
        _add(scan.fixes, (f.ident, f.region), f)
        if sec == "PN":
            _add(scan.terminal, (f.airport, f.ident), f)


def _procedure_record(scan: Scan, rec: str, i: int, key: Key, prev: str | None,
                      bad: RecordError | None) -> None:
    """File one procedure record whose key reads under its transition. ``prev``: the line
    before (None at the start or after a blank line; :data:`_REJECTED` when it was rejected
    here: a continuation after a rejected primary is not reported again)."""
    scan.owner[i] = key
    lines = scan.key_lines.get(key)
    if lines is None:
        lines = scan.key_lines[key] = []
        scan.keys_by_airport.setdefault(key[0], []).append(key)
    lines.append(i)
    cont = rec[38:39]
    if cont in ("0", "1") and bad is None:
        scan.raw_procs.setdefault(key[0], []).append((i, rec))  # parsed (and checked) on use
        return
    err = bad
    if err is None and not _CONTINUATION.fullmatch(cont):
        err = RecordError(scan.file, i, 39, "continuation number",
                          f"{cont!r} is not 0-9 or A-Z", 39, rec)
    if err is None and prev is not _REJECTED and (prev is None or prev[:29] != rec[:29]):
        err = RecordError(scan.file, i, 39, "continuation number",
                          "continuation record without its primary record (the line before "
                          "is not a record of the same leg)", 39, rec)
    if err is not None:
        scan.errors.append(err)
        scan.key_defects.setdefault(key, []).append(rejected_defect(err))


def _neighbour(scan: Scan, lines: list[str], line: int, step: int, skip: set[int]) -> Key | None:
    """Transition of the nearest line before (step -1) or after (+1) ``line`` that is not
    itself a rejected line of unknown transition."""
    j = line + step
    while 1 <= j <= len(lines) and j in skip:
        j += step
    return scan.owner.get(j)


def _reject_refs(scan: Scan, rec: str, bad: RecordError) -> None:
    """Record a rejected fix-like record under the idents legs would look it up by (its
    airport's, the enroute one, or both for a VHF navaid)."""
    sec = "PN" if rec[4:6] == "PN" else (
        "P" + rec[12:13] if rec[4:5] in ("P", "H") else rec[4:6])
    cols = _IDENT_COLS.get(sec)
    ident = rec[cols[0] - 1:cols[1]].strip() if cols else ""
    if not ident:
        return
    apt = rec[6:10].strip()
    scopes = (("airport", ident),) if sec == "PA" else (
        (("", ident),) if sec in ("EA", "DB") or not apt else
        ((apt, ident),) if sec != "D " else (("", ident), (apt, ident)))
    for scope in scopes:
        scan.rejected_refs.setdefault(scope, []).append(bad)


def _attribute_to_neighbours(scan: Scan, lines: list[str], unattributed: list) -> None:
    """A rejected line whose own transition cannot be read degrades the transitions of the
    records next to it."""
    skip = {e.line for e in unattributed}
    for err in unattributed:
        for key in {k for k in (_neighbour(scan, lines, err.line, -1, skip),
                                _neighbour(scan, lines, err.line, +1, skip)) if k}:
            scan.key_defects.setdefault(key, []).append(rejected_defect(
                err, " (a line next to its records whose own transition cannot be read)"))


def scan_text(text: str, file: str) -> Scan:
    """Classify and check every record of an ARINC-424 file's text (module docstring)."""
    scan = Scan(file)
    lines = split_lines(text)
    scan.n_lines = len(lines)
    unattributed: list[RecordError] = []
    prev: str | None = None
    for i, rec in enumerate(lines, 1):
        if rec.startswith("HDR"):
            prev = None
            continue
        if not rec.strip():      # a record blanked out, or an empty line inserted
            bad = RecordError(file, i, 1, "record", "blank line between records",
                              len(rec), rec)
            scan.errors.append(bad)
            unattributed.append(bad)
            prev = _REJECTED
            continue
        bad = None
        try:
            (check_leg_record if is_procedure_record(rec) else check_record)(rec)
            if rec[0] != "S":
                raise FieldError(1, "record type", f"{rec[0]!r} is not 'S' (standard)")
        except FieldError as exc:
            bad = RecordError.from_field(exc, file, i, rec)
        if is_procedure_record(rec):
            try:
                key = read_key(rec)
            except FieldError as exc:
                key, bad = None, bad or RecordError.from_field(exc, file, i, rec)
            if key is not None:
                _procedure_record(scan, rec, i, key, prev, bad)
                prev = _REJECTED if bad else rec
                continue
        elif bad is None:
            try:
                _fix_record(scan, rec, i, prev)
            except FieldError as exc:
                bad = RecordError.from_field(exc, file, i, rec)
        prev = _REJECTED if bad else rec
        if bad is not None:
            scan.errors.append(bad)
            unattributed.append(bad)
            _reject_refs(scan, rec, bad)
    _attribute_to_neighbours(scan, lines, unattributed)
    skip = {e.line for e in unattributed}
    for key, found in structure_defects(scan.key_lines, scan.owner, file, skip).items():
        scan.key_defects.setdefault(key, []).extend(found)
    return scan
