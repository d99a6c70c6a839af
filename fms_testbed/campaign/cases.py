"""The cases of a campaign: one flyable sequence × one aircraft × one condition set.

Flyable sequences (assembled as :func:`fms_testbed.path.plan.select_parts` assembles them):

* SID/STAR — a runway transition (``RWxx``/``RWxxB``), the common route, an en-route
  transition. ``each`` (the default) flies the fewest sequences that fly every transition at
  least once: max(runway transitions, en-route transitions) sequences, the i-th pairing the
  i-th runway and the i-th en-route transition (cycling through the shorter list); ``all``
  flies every runway × en-route combination.
* approach — an approach transition, then the final approach to the MAP. ``each``: one
  sequence per approach transition (the final alone when there is none); ``all`` adds the
  final alone (straight in from its first fix) to those.

Order: airports sorted, then SIDs, STARs, approaches, each by ident, then the sequences as
above, then aircraft and condition sets in the order given; ``--limit`` keeps the first cases.

Case id: the first 16 hex digits of a SHA-256 over the airport, type, procedure, runway and
transition idents, the *records* (:attr:`Case.records_sha256`: the content digests of every file
line the sequence uses — its procedure records, in flying order, then the records of every fix,
navaid, RF centre, runway and airport reference point they name, sorted by digest — each without
its file record number, columns 124-128:
:func:`~fms_testbed.procedures.index.record_content`; where a record sits in the file changes no
id, what it says does), the aircraft name and file's SHA-256,
the condition set (canonical JSON) and the campaign seed. The per-case seed
(:func:`case_seed`) comes from the case id alone, so a case flies the same on any worker, in any
order, in any run.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fms_testbed.campaign.conditions import Conditions
from fms_testbed.core.errors import UserError
from fms_testbed.procedures.index import DatabaseIndex

TYPES = {"SID": "D", "STAR": "E", "APPROACH": "F"}
"""Procedure types by name (the ``--types`` values) → ARINC-424 subsection code."""
TYPE_NAMES = {v: k for k, v in TYPES.items()}
CASE_ID_HEX = 16
"""Hex digits of a case id (64 bits: a collision among a million cases has odds ~3e-8)."""


@dataclass(frozen=True)
class Case:
    """One flight of a campaign (module docstring).

    Attributes
    ----------
    case_id : stable id (module docstring)
    airport, type, procedure : ICAO ident, 'SID'/'STAR'/'APPROACH', procedure ident
    runway : runway transition flown ('' for none; approaches: '')
    transition : en-route (SID/STAR) or approach transition flown ('' for none)
    aircraft : aircraft name or file as given; aircraft_sha256 : SHA-256 of its file
    conditions : the condition set
    campaign_seed : the campaign's ``--seed``
    records_sha256 : SHA-256 of the digests of the database lines the sequence uses
    """

    case_id: str
    airport: str
    type: str
    procedure: str
    runway: str
    transition: str
    aircraft: str
    aircraft_sha256: str
    conditions: Conditions
    campaign_seed: int
    records_sha256: str

    @property
    def seed(self) -> int:
        """Seed of every stochastic part of the flight (:func:`case_seed`)."""
        return case_seed(self.case_id)

    @property
    def key(self) -> tuple[str, ...]:
        """What matches this case to its twin in another run (``regress diff``)."""
        return (self.airport, self.type, self.procedure, self.runway, self.transition,
                self.aircraft, self.conditions.name)

    @property
    def name(self) -> str:
        """Readable label, e.g. 'KBFI SID CBAIN1 RW32L 737 calm'."""
        parts = [self.airport, self.type, self.procedure, self.runway, self.transition,
                 self.aircraft, self.conditions.name]
        return " ".join(p for p in parts if p)

    def scenario(self, db: str) -> dict:
        """The procedure scenario mapping this case flies (``db``: the file to build it from)."""
        proc = {"db": db, "airport": self.airport, "procedure": self.procedure}
        if self.runway:
            proc["runway"] = self.runway
        if self.transition:
            proc["transition"] = self.transition
        if self.conditions.missed and self.type == "APPROACH":
            proc["missed"] = True
        return {"name": f"{self.airport}-{self.procedure}-{self.case_id}".lower(),
                "aircraft": self.aircraft, "procedure": proc, **self.conditions.overrides()}


def case_seed(case_id: str) -> int:
    """The seed of a case from its id alone: ``numpy.random.SeedSequence`` of the id's integer
    value, first 32-bit word, top bit cleared (JSBSim takes a signed 32-bit seed).

    Parameters
    ----------
    case_id : the case id (hex digits)
    """
    state = np.random.SeedSequence(int(case_id, 16)).generate_state(1, dtype=np.uint32)
    return int(state[0]) & 0x7FFFFFFF


def _distinct(idents) -> list[str]:
    return list(dict.fromkeys(idents))


def flyable_sequences(seqs: list, combinations: str = "each") -> list[tuple[str, str]]:
    """The (runway, transition) pairs to fly for one procedure (module docstring); '' where a
    part is not flown.

    Parameters
    ----------
    seqs : the database sequences of one procedure (``proc_type``, ``transition``,
        ``route_type``)
    combinations : 'each' or 'all'
    """
    if combinations not in ("each", "all"):
        raise UserError(f"--combinations {combinations!r}: expected 'each' or 'all'")
    if seqs[0].proc_type == "F":
        trans = _distinct(s.transition for s in seqs if s.route_type == "A")
        pairs = [("", t) for t in trans]
        if not trans or combinations == "all":
            pairs.append(("", ""))
        return pairs
    rw = _distinct(s.transition for s in seqs if s.transition.startswith("RW"))
    en = _distinct(s.transition for s in seqs
                   if s.transition not in ("", "ALL") and not s.transition.startswith("RW"))
    if combinations == "all":
        return [(r, t) for r in (rw or [""]) for t in (en or [""])]
    n = max(len(rw), len(en), 1)
    return [(rw[i % len(rw)] if rw else "", en[i % len(en)] if en else "") for i in range(n)]


def used_lines(db, parts: list) -> list[int]:
    """File lines a sequence uses (module docstring), procedure records first in flying order,
    then the named fixes' records (sorted).

    Parameters
    ----------
    db : the database; parts : the sequences flown, in flying order
    """
    lines = [ln for p in parts for ln in p.lines]
    if not parts:
        return lines
    airport = parts[0].airport
    refs = set()
    apt = db.airports.get(airport)
    if apt is not None:
        refs.add(apt.line)
    for p in parts:
        for lg in p.legs:
            for ref in (lg.fix, lg.navaid, lg.centre):
                f = db.find_fix(ref, airport)
                if f is not None:
                    refs.add(f.line)
        t = p.transition
        if t.startswith("RW"):
            names = [t] + ([t[:-1] + s for s in "LRC"] if t.endswith("B") else [])
            for nm in names:
                refs.update(f.line for f in db.terminal.get((airport, nm), ())
                            if f.section == "PG")
    return lines + sorted(r for r in refs if r > 0)


def _parts(db, airport: str, procedure: str, runway: str, transition: str, seqs: list) -> list:
    from fms_testbed.path.plan import select_parts

    try:
        return select_parts(db, airport, procedure, transition or None, runway or None)
    except UserError:
        return seqs      # not assembled: the case reports why when it is flown


def records_sha256(index: DatabaseIndex, seqs: list, runway: str, transition: str) -> str:
    """:attr:`Case.records_sha256` of (runway, transition) of a procedure.

    Parameters
    ----------
    index : the database index; seqs : the procedure's database sequences
    runway, transition : the transitions flown ('' for none)
    """
    s0 = seqs[0]
    parts = _parts(index.db, s0.airport, s0.proc_id, runway, transition, seqs)
    lines = used_lines(index.db, parts)
    n_proc = sum(len(p.lines) for p in parts)
    d = index.line_digests
    own = np.asarray([n - 1 for n in lines[:n_proc] if n > 0], dtype=np.int64)
    refs = np.asarray([n - 1 for n in lines[n_proc:] if 0 < n <= d.size], dtype=np.int64)
    if own.size and own.max() >= d.size:
        raise ValueError(f"{index.path}: line {int(own.max()) + 1} beyond the file's "
                         f"{d.size} lines")
    return hashlib.sha256(np.concatenate([d[own], np.sort(d[refs])]).tobytes()).hexdigest()


def make_case(seqs: list, runway: str, transition: str, records: str, aircraft: str,
              aircraft_sha256: str, conditions: Conditions, campaign_seed: int) -> Case:
    """The case flying (runway, transition) of a procedure (module docstring: the case id).

    Parameters
    ----------
    seqs : the procedure's database sequences; runway, transition : the transitions flown
    records : :func:`records_sha256` of them
    aircraft, aircraft_sha256 : the aircraft as given and its file's SHA-256
    conditions : the condition set; campaign_seed : the campaign's seed
    """
    s0 = seqs[0]
    ident = {"v": 1, "airport": s0.airport, "type": TYPE_NAMES[s0.proc_type],
             "procedure": s0.proc_id, "runway": runway, "transition": transition,
             "records": records, "aircraft": aircraft, "aircraft_sha256": aircraft_sha256,
             "conditions": json.loads(conditions.canonical()), "seed": int(campaign_seed)}
    cid = hashlib.sha256(json.dumps(ident, sort_keys=True, separators=(",", ":")).encode()
                         ).hexdigest()[:CASE_ID_HEX]
    return Case(cid, s0.airport, TYPE_NAMES[s0.proc_type], s0.proc_id, runway, transition,
                aircraft, aircraft_sha256, conditions, int(campaign_seed), records)


def parse_types(text: str | None) -> list[str]:
    """``SID,STAR,APPROACH`` (any case, any subset; None: all) → subsection codes.

    Parameters
    ----------
    text : the ``--types`` value
    """
    if not text:
        return list(TYPES.values())
    out = []
    for t in (x.strip().upper() for x in text.split(",")):
        if t not in TYPES:
            raise UserError(f"--types {text!r}: {t!r} is not one of SID, STAR, APPROACH")
        out.append(TYPES[t])
    return _distinct(out)


def sample_airports(db, candidates: list[str], n: int, seed: int, types: list[str],
                    min_transitions: int = 1) -> list[str]:
    """A seeded, reproducible choice of ``n`` airports (sorted).

    Rule: of ``candidates``, those with at least ``min_transitions`` database transitions of
    the selected ``types`` (counted from the raw records), ranked by the SHA-256 of
    ``'<seed>:<ICAO>'``; the first ``n``. Independent of the Python and numpy versions.

    Parameters
    ----------
    db : the database; candidates : ICAO idents to choose from; n : how many
    seed : the sample seed; types : subsection codes counted; min_transitions : the least
        number of transitions of those types an airport must have
    """
    if n < 1:
        raise UserError(f"--sample-airports {n}: must be at least 1")
    eligible = [a for a in candidates
                if sum(1 for k in db.procedure_index(a) if k[0] in types) >= min_transitions]
    if len(eligible) < n:
        raise UserError(f"--sample-airports {n}: only {len(eligible)} airports have "
                        f"≥ {min_transitions} transitions of the selected types")
    ranked = sorted(eligible, key=lambda a: hashlib.sha256(f"{seed}:{a}".encode()).hexdigest())
    return sorted(ranked[:n])


def aircraft_files(names: list[str]) -> list[tuple[str, str]]:
    """(name as given, SHA-256 of its file) for each aircraft; a user error in one line for an
    unknown aircraft or an unreadable file.

    Parameters
    ----------
    names : aircraft names (``aircraft/NAME.yaml``) or YAML files
    """
    from fms_testbed.config.aircraft import load_aircraft

    out = []
    for name in names:
        cfg = load_aircraft(name)
        src = Path(cfg.source_file)
        try:
            sha = hashlib.sha256(src.read_bytes()).hexdigest()
        except OSError as exc:
            raise UserError(f"--aircraft {name}: cannot read {src}: {exc.strerror}") from None
        out.append((name, sha))
    return out


def enumerate_cases(index: DatabaseIndex, airports: list[str], types: list[str],
                    aircraft: list[tuple[str, str]], conditions: list[Conditions],
                    combinations: str = "each", seed: int = 0,
                    limit: int | None = None) -> list[Case]:
    """Every case of a campaign, in the order of the module docstring.

    Parameters
    ----------
    index : the database index
    airports : ICAO idents (each must have procedures)
    types : subsection codes ('D', 'E', 'F') to fly
    aircraft : (name, file SHA-256) pairs (:func:`aircraft_files`)
    conditions : the condition sets
    combinations : 'each' or 'all' (module docstring)
    seed : the campaign seed (part of every case id)
    limit : keep the first ``limit`` cases
    """
    db = index.db
    out: list[Case] = []
    for apt in airports:
        groups: dict[tuple[str, str], list] = {}
        for s in db.sequences(apt):
            if s.proc_type in types:
                groups.setdefault((s.proc_type, s.proc_id), []).append(s)
        order = sorted(groups, key=lambda k: ("DEF".index(k[0]), k[1]))
        for key in order:
            seqs = groups[key]
            for runway, trans in flyable_sequences(seqs, combinations):
                records = records_sha256(index, seqs, runway, trans)
                for name, sha in aircraft:
                    for cond in conditions:
                        out.append(make_case(seqs, runway, trans, records, name, sha, cond,
                                             seed))
                        if limit is not None and len(out) >= limit:
                            return out
    return out



def case_from_row(row) -> Case:
    """The case a ``flights`` row records (to fly it again: same id, so the same seed). The
    aircraft file's SHA-256 is not in the row: it is left empty.

    Parameters
    ----------
    row : a row of the ``flights`` table (mapping or pandas Series)
    """
    from fms_testbed.campaign.conditions import make_conditions

    cond = json.loads(row["conditions_json"])
    return Case(str(row["case_id"]), str(row["airport"]), str(row["type"]),
                str(row["procedure"]), str(row["runway"] or ""), str(row["transition"] or ""),
                str(row["aircraft"]), "", make_conditions(cond, f"case {row['case_id']}"),
                int(row["campaign_seed"]), str(row["records_sha256"]))


__all__ = ["CASE_ID_HEX", "TYPES", "TYPE_NAMES", "Case", "aircraft_files", "case_from_row",
           "case_seed",
           "enumerate_cases", "flyable_sequences", "make_case", "parse_types", "records_sha256",
           "sample_airports", "used_lines"]
