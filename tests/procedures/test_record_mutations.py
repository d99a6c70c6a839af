"""Mutations of the real records of the embedded excerpt: loading never raises, every rejected
record is listed on a mutated line, and a transition touched by a mutation is never silently
changed.

Which columns carry meaning for a transition. A procedure record's meaning is its parsed
:class:`~fms_testbed.procedures.legrecord.LegRecord` minus its line number: the key (cols 5-25),
sequence number (27-29), fix (30-38), description code (40-43), turn direction (44), RNP
(45-47), path terminator (48-49), turn-direction-valid (50), navaid (51-56, 79-80), arc radius,
theta, rho, course, distance/time (57-78), altitude descriptor and altitudes (83-94),
transition altitude (95-99), speed limit (100-102), vertical angle (103-106), RF centre
(107-116), speed descriptor (118). Columns 1-4, 11-12, 26, 39 ('0'/'1'), 81-82, 84, 112, 117,
119-132 (reserved, route qualifiers, file record number, cycle date) and the content of
continuation records are not read: a change there leaves the meaning as it was — unless the
new character is outside the ARINC-424 character set, which rejects the record.

What must hold after one mutation (a byte changed to any Latin-1 character, the record
truncated or extended, duplicated, swapped with or moved to another line), for the transition
T that owned the mutated line:

1. T is degraded, or
2. T means what it meant (its legs, minus line numbers, are the clean ones), or
3. the mutated line still parses as a leg of T: T holds exactly that leg in its place (a valid
   value replaced by another valid value — a course 043.8 → 053.8 — cannot be told from real
   data: ARINC-424 has no checksum or record count), or
4. the mutated line was T's first or last line and is no longer T's (a valid record of another
   transition, or of a section the testbed does not read): T holds exactly its other legs, and
   if the line now reads as a leg of another transition U, U is degraded or holds it.

A duplicated primary record always degrades T ('duplicate'). Every other transition is either
unchanged or degraded next to a mutated line.
"""

import dataclasses

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fms_testbed.data import procedures_dir
from fms_testbed.procedures.database import load_text
from fms_testbed.procedures.fields import FieldError, RecordError
from fms_testbed.procedures.legrecord import is_procedure_record, parse_leg, read_key

TEXT = (procedures_dir() / "cifp_excerpt.dat").read_text(encoding="latin-1")
LINES = TEXT.split("\n")[:-1]


def _meaning(leg):
    return dataclasses.replace(leg, line=0)


def _all_seqs(db, airports=None):
    return {s.key: s for a in (airports or db.airport_idents()) for s in db.sequences(a)}


CLEAN_DB = load_text(TEXT, "clean.dat")
CLEAN = _all_seqs(CLEAN_DB)
CLEAN_LEGS = {k: tuple(_meaning(lg) for lg in s.legs) for k, s in CLEAN.items()}
OWNER = {ln - 1: k for k, s in CLEAN.items() for ln in s.lines}       # 0-based line -> key
LEG_AT = {lg.line - 1: _meaning(lg) for s in CLEAN.values() for lg in s.legs}
PROC = sorted(OWNER)
LATIN1 = st.characters(min_codepoint=0, max_codepoint=255)


@st.composite
def mutation(draw):
    """(kind, line, detail): one mutation of one procedure line of the excerpt."""
    kind = draw(st.sampled_from(["byte"] * 6 + ["truncate", "extend", "duplicate", "swap",
                                                  "move"]))
    i = draw(st.sampled_from(PROC))
    if kind == "byte":
        return kind, i, (draw(st.integers(1, 132)), draw(LATIN1))
    if kind == "truncate":
        return kind, i, draw(st.integers(0, 131))
    if kind == "extend":
        return kind, i, draw(st.text(LATIN1, min_size=1, max_size=4))
    near = draw(st.booleans())
    j = draw(st.sampled_from([i + 1] if near and i + 1 in OWNER else PROC))
    return kind, i, j


def apply(m):
    """The mutated file's lines, which of them are mutated (new 1-based numbers), the original
    lines touched (0-based) and the mutated text of line i (None when moved/duplicated)."""
    kind, i, d = m
    entries = [[t, False] for t in LINES]
    text = None
    if kind == "byte":
        col, ch = d
        text = LINES[i][:col - 1] + ch + LINES[i][col:]
        entries[i] = [text, True]
    elif kind == "truncate":
        text = LINES[i][:d]
        entries[i] = [text, True]
    elif kind == "extend":
        text = LINES[i] + d
        entries[i] = [text, True]
    elif kind == "duplicate":
        entries.insert(d + 1 if d == i + 1 else d, [LINES[i], True])
    elif kind == "swap":
        entries[i], entries[d] = [LINES[d], True], [LINES[i], True]
    else:  # move line i to before line d
        moved = entries.pop(i)
        entries.insert(d if d < i else d - 1, [moved[0], True])
    lines, mutated = [], set()
    for t, flag in entries:
        for part in t.split("\n"):
            lines.append(part)
            if flag:
                mutated.add(len(lines))
    orig = {i} | ({d} if kind in ("swap", "move", "duplicate") else set())
    return lines, mutated, orig, text


def _as_leg(text):
    """The leg a mutated line parses to, or None (rejected, or not a primary leg record)."""
    if text is None or "\n" in text or not is_procedure_record(text) or text[38:39] not in "01":
        return None
    try:
        return _meaning(parse_leg(text, 0))
    except FieldError:
        return None


def _gainer(text, owner):
    if text is None or "\n" in text or len(text) < 29 or not is_procedure_record(text):
        return None
    try:
        key = read_key(text)
    except FieldError:
        return None
    return key if key != owner else None


def _orphaned(err, mutated, orig) -> bool:
    """A continuation record reported because the line before it was changed or its primary
    moved away (its own line is intact)."""
    if err.field != "continuation number":
        return False
    return err.line - 1 in mutated or (err.text in LINES and LINES.index(err.text) - 1 in orig)


def _by_seq(legs):
    return tuple(sorted(legs, key=lambda lg: lg.seq))


def check_one_mutation(m):
    """Assert the module docstring's rules for one mutation; return the mutated database."""
    kind, i, d = m
    lines, mutated, orig, text = apply(m)
    db = load_text("".join(ln + "\n" for ln in lines), "mut.dat")   # never raises
    owner = OWNER[i]
    r0, r1 = LEG_AT.get(i), _as_leg(text)
    gainer = _gainer(text, owner)
    airports = sorted({OWNER[x][0] for x in orig} | ({gainer[0]} if gainer else set()))
    seqs = _all_seqs(db, [a for a in airports if a in db.airport_idents()])
    for err in db.issues:
        assert isinstance(err, RecordError)
        assert err.line in mutated or _orphaned(err, mutated, orig), (m, err)
    touched = {OWNER[x] for x in orig}
    for t in touched:
        now = seqs.get(t)
        clean_lines = [ln - 1 for ln in CLEAN[t].lines]
        if now is None:                  # every line of T was mutated away
            assert set(clean_lines) <= orig, (m, t)
            continue
        if kind == "duplicate" and t == owner and r0 is not None:
            assert "duplicate" in {x.kind for x in now.defects}, (m, now.defects)
        if now.degraded:
            continue
        legs = tuple(_meaning(lg) for lg in now.legs)
        if legs == CLEAN_LEGS[t]:
            continue                     # rule 2
        assert kind == "byte" and r0 is not None and t == owner, (m, t, "changed silently")
        rest = tuple(lg for lg in CLEAN_LEGS[t] if lg != r0)
        if r1 is not None and r1.key == t:
            assert legs == _by_seq(rest + (r1,)), (m, t)       # rule 3
            continue
        assert i in (clean_lines[0], clean_lines[-1]), (m, t, "lost a record inside")
        assert legs == rest, (m, t)                            # rule 4
    if gainer is not None:
        u = _all_seqs(db, [gainer[0]]).get(gainer)
        assert u is not None, (m, gainer)
        if not u.degraded:
            assert r1 is not None and r1.key == gainer, (m, gainer)
            assert tuple(_meaning(lg) for lg in u.legs) == _by_seq(
                CLEAN_LEGS.get(gainer, ()) + (r1,)), (m, gainer)
    for k, s in seqs.items():            # the others: unchanged, or degraded next to a mutation
        if k in touched or k == gainer:
            continue
        if s.degraded:
            lo, hi = s.lines[0] - 1, s.lines[-1] + 1
            near = any(lo <= x <= hi for x in mutated) or any(
                x in mutated for dft in s.defects for x in dft.lines)
            assert near, (m, k, s.defects)
        else:
            assert tuple(_meaning(lg) for lg in s.legs) == CLEAN_LEGS[k], (m, k)
    return db


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(m=mutation())
def test_one_mutation_of_a_real_record_is_never_silent(m):
    check_one_mutation(m)


@pytest.mark.slow
@settings(max_examples=4000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(m=mutation())
def test_one_mutation_of_a_real_record_is_never_silent_large_sample(m):
    check_one_mutation(m)


@pytest.mark.parametrize("m", [
    ("byte", LINES.index(next(r for r in LINES if r[4:6] == "P " and r[12] == "D")),
     (71, "\xb2")),                                           # a superscript two in a course
    ("byte", PROC[10], (124, "9")),                            # file record number: meaning kept
    ("byte", PROC[10], (39, "2")),                             # primary -> continuation
    ("truncate", PROC[20], 10),                                # key unreadable
    ("duplicate", PROC[30], PROC[30] + 1),
    ("swap", PROC[40], PROC[40] + 1),
    ("move", PROC[50], PROC[-1]),
])
def test_named_mutations(m):
    check_one_mutation(m)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ms=st.lists(mutation().filter(lambda m: m[0] in ("byte", "truncate", "extend")),
                   min_size=2, max_size=8, unique_by=lambda m: m[1]))
def test_many_mutations_lose_no_record_silently(ms):
    """Several changed lines: every rejected record is on a changed line, and every record is
    accounted for — held as a leg (as it was, or as the changed line now reads), or rejected, or
    in a transition that is degraded."""
    entries = list(LINES)
    for kind, i, d in ms:
        if kind == "byte":
            entries[i] = entries[i][:d[0] - 1] + d[1] + entries[i][d[0]:]
        elif kind == "truncate":
            entries[i] = entries[i][:d]
        else:
            entries[i] = entries[i] + d
    text = "".join(e.replace("\n", " ") + "\n" for e in entries)  # one line per record here
    db = load_text(text, "mut.dat")
    changed = {i + 1 for _, i, _ in ms}
    for err in db.issues:
        assert err.line in changed or (err.field == "continuation number"
                                       and err.line - 1 in changed), err
    seqs = _all_seqs(db)
    held = {lg.line: _meaning(lg) for s in seqs.values() for lg in s.legs}
    for i, leg in LEG_AT.items():
        if i + 1 not in changed:
            assert held.get(i + 1) == leg          # an unchanged record is held as it was
    for _, i, _ in ms:
        t = OWNER[i]
        if t in seqs and not seqs[t].degraded and i in LEG_AT:
            # not degraded: the changed record is held (as it now reads), or it left T at an
            # end of T's lines
            lines0 = [ln - 1 for ln in CLEAN[t].lines]
            assert i + 1 in held or i in (lines0[0], lines0[-1]), (ms, t)


_CLEAN_ROWS: dict = {}


def _clean_status(airport):
    from fms_testbed.evaluation.check import check_airport, perf_for
    if airport not in _CLEAN_ROWS:
        seqs = CLEAN_DB.sequences(airport)
        rows = check_airport(CLEAN_DB, airport, perf_for("737"))
        _CLEAN_ROWS[airport] = {s.key: r["status"] for s, r in zip(seqs, rows)}
    return _CLEAN_ROWS[airport]


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(m=mutation())
def test_check_rows_after_a_mutation_are_honest(m):
    """The check table of the mutated airport: 'degraded' exactly for the degraded
    transitions, no internal error, and the clean status for every transition that means what
    it meant."""
    from fms_testbed.evaluation.check import check_airport, perf_for
    db = check_one_mutation(m)
    apt = OWNER[m[1]][0]
    clean = _clean_status(apt)
    seqs = db.sequences(apt)
    rows = check_airport(db, apt, perf_for("737"))
    assert len(rows) == len(seqs)
    for s, r in zip(seqs, rows):
        assert r["monitor_status"] != "internal-error", (m, r["findings"])
        assert (r["status"] == "degraded") == s.degraded, (m, s.key)
        if not s.degraded and tuple(_meaning(lg) for lg in s.legs) == CLEAN_LEGS.get(s.key):
            assert r["status"] == clean[s.key], (m, s.key)
