"""Why a procedure transition cannot be trusted: its :class:`Defect` list.

A transition (the legs sharing airport, type, procedure, route type and transition ident) is
*degraded* when one of its own records is in doubt. ARINC-424 carries no checksum or record
count per transition, so what can be checked is each record (:mod:`.fields`) and the file's
structure, which the FAA CIFP 2301 keeps without exception (385,111 lines, 51,706
transitions):

* ``rejected`` — one of its records was rejected (a field it could not read, the record
  length, the character set, a continuation record without its primary); a rejected line whose
  own transition cannot be read is laid on the transitions of the lines next to it;
* ``duplicate`` — a sequence number coded twice (a file concatenated with itself, a repeated
  record);
* ``order`` — sequence numbers not increasing in file order;
* ``interleaved`` — its records are not one run of consecutive lines (a line of something else
  between them, a record moved away), or its records sit between two lines of another
  transition (a key changed inside another transition);
* ``fix-rejected`` — a fix, navaid, RF centre or its airport's reference point it refers to has
  a rejected record;
* ``internal-error`` — the builder raised (added by :mod:`fms_testbed.evaluation.check`).
"""

from __future__ import annotations

from dataclasses import dataclass

Key = tuple[str, str, str, str, str]
"""(airport, type 'D'/'E'/'F', procedure ident, route type, transition ident)."""

DEFECT_KINDS = ("rejected", "duplicate", "order", "fix-rejected", "interleaved",
                "internal-error")
"""The defect kinds, most telling first (a transition's defects are listed in this order)."""


@dataclass(frozen=True, slots=True)
class Defect:
    """One reason a transition is degraded: ``kind`` (:data:`DEFECT_KINDS`), the 1-based file
    ``lines`` involved, the ``field`` and the ``reason``; ``file`` the database path."""

    kind: str
    lines: tuple[int, ...]
    field: str
    reason: str
    file: str = ""

    def __str__(self) -> str:
        where = f"{self.file}:{self.lines[0]}" if self.lines else self.file
        return f"{where}: {self.field}: {self.reason}"

    @property
    def finding(self) -> str:
        """The text of this defect in the check table's findings: 'degraded (kind) line N: …'."""
        ln = ", ".join(str(x) for x in self.lines[:6]) + (" …" if len(self.lines) > 6 else "")
        s = "s" if len(self.lines) > 1 else ""
        return f"degraded ({self.kind}) line{s} {ln}: {self.field}: {self.reason}"


def _runs(lines: list[int], wild: set[int]) -> list[tuple[int, int]]:
    """Runs of consecutive numbers in sorted ``lines``: [(first, last), ...]; numbers in
    ``wild`` may fill a gap."""
    runs = []
    start = prev = lines[0]
    for x in lines[1:]:
        if x != prev + 1 and not all(g in wild for g in range(prev + 1, x)):
            runs.append((start, prev))
            start = x
        prev = x
    runs.append((start, prev))
    return runs


def structure_defects(key_lines: dict[Key, list[int]], owner: dict[int, Key],
                      file: str, wild: set[int] = frozenset()) -> dict[Key, list[Defect]]:
    """``interleaved`` defects from where each transition's lines are in the file.

    Parameters
    ----------
    key_lines : every line (primary, continuation, rejected with a readable key) of each
        transition, in file order
    owner : line -> transition, for the same lines
    file : database path (named in the defects)
    wild : rejected lines of unknown transition (already laid on their neighbours): they do
        not interrupt a run
    """
    out: dict[Key, list[Defect]] = {}
    for key, lines in key_lines.items():
        runs = _runs(lines, wild)
        if len(runs) > 1:
            gaps = [(a[1] + 1, b[0] - 1) for a, b in zip(runs, runs[1:])]
            shown = ", ".join(f"{g0}" if g0 == g1 else f"{g0}-{g1}" for g0, g1 in gaps[:3])
            out.setdefault(key, []).append(Defect(
                "interleaved", tuple(r[0] for r in runs), "record order",
                f"its records (lines {lines[0]}-{lines[-1]}) are interrupted by line(s) {shown}"
                f"{' …' if len(gaps) > 3 else ''} that are not its own", file))
            continue
        first, last = runs[0]
        before, after = owner.get(first - 1), owner.get(last + 1)
        if before is not None and before == after and before != key:
            out.setdefault(key, []).append(Defect(
                "interleaved", (first,), "record order",
                f"its records (lines {first}-{last}) lie inside transition "
                f"{' '.join(x for x in before if x)} (lines {first - 1} and {last + 1})", file))
    return out


def sequence_defects(lines_seqs: list[tuple[int, int]], file: str) -> list[Defect]:
    """``duplicate`` and ``order`` defects of one transition from its primary records'
    (line, sequence number) in file order."""
    out = []
    seen: dict[int, int] = {}
    for k, (line, seq) in enumerate(lines_seqs):
        if seq in seen:
            out.append(Defect("duplicate", (seen[seq], line), "sequence number",
                              f"sequence number {seq:03d} is coded twice (lines {seen[seq]} "
                              f"and {line})", file))
            continue
        seen[seq] = line
        if k and seq < lines_seqs[k - 1][1]:
            pl, ps = lines_seqs[k - 1]
            out.append(Defect("order", (pl, line), "sequence number",
                              f"sequence number {seq:03d} (line {line}) follows {ps:03d} "
                              f"(line {pl})", file))
    return out


def rejected_defect(err, why: str = "") -> Defect:
    """The ``rejected`` defect of a :class:`~.fields.RecordError` (``why``: how it is laid on
    the transition, e.g. 'next to its records')."""
    return Defect("rejected", (err.line,), err.field,
                  f"record rejected, column {err.columns}: {err.reason}{why}", err.file)


def refusal(name: str, defects) -> str:
    """The one-line reason a degraded transition is not built or flown: its first defect
    (file:line: field: reason) and how many more it has."""
    more = f" (and {len(defects) - 1} more)" if len(defects) > 1 else ""
    return (f"{name} is degraded, not built: {defects[0]}{more}; "
            "allow it with --allow-degraded (procedure.allow_degraded: true)")
