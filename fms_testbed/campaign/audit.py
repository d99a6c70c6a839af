"""What a campaign folder really holds, counted from its data, never from ``run.json``.

``DIR/plan.parquet`` (written by ``regress run`` before the first case flies) lists every case
of the run: its id and the columns that name it. :func:`audit` reads every part file of
``DIR/flights`` in name order and keeps a part only when it is

* readable (a whole Parquet file: a truncated or overwritten part is not),
* of the dataset's schema (:data:`~.rows.SCHEMA`: the same columns and types),
* made of cases of this run (every case id in the plan; a row of another run is *foreign*),
* new (no case id repeated inside it or already in a part kept before it: a copied part is a
  *duplicate*).

Every other part is *damaged*: ``regress run`` moves it into ``DIR/quarantine/`` with a line
naming it and the reason (:func:`quarantine`), and its cases are flown again because they are
not in a kept part; ``regress report`` works on the kept parts and states the damage; ``regress
diff`` refuses a damaged folder, naming the file and the cases (exit 2). The case counts of a
report (written, missing, duplicated, foreign) are those of :class:`Audit`.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass, field
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from fms_testbed.campaign.rows import SCHEMA
from fms_testbed.campaign.store import RUN_JSON, part_files
from fms_testbed.core.errors import UserError

PLAN = "plan.parquet"
"""The run's cases (``case_id`` and the naming columns), beside ``run.json``."""
QUARANTINE = "quarantine"
"""Folder damaged part files are moved into."""
PLAN_COLUMNS = ("case_id", "airport", "type", "procedure", "runway", "transition", "aircraft",
                "conditions")
PLAN_SCHEMA = pa.schema([(c, pa.string()) for c in PLAN_COLUMNS])
REGRESS_KIND = "regress-run"


def load_run_json(out: str | Path, what: str = "regress run folder") -> dict:
    """``DIR/run.json`` of a regression run; a one-line :class:`UserError` when it is missing,
    not JSON (line and column), not the testbed's, or of another kind of run.

    Parameters
    ----------
    out : the campaign folder
    what : what the folder should be (named in the message)
    """
    out = Path(out)
    path = out / RUN_JSON
    if not out.is_dir():
        raise UserError(f"{out}: not a folder (a {what} is a folder holding run.json)")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(f"{out}: not a {what} (no run.json)") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        info = json.loads(text)
    except json.JSONDecodeError as exc:
        raise UserError(f"{path}: run.json is not valid JSON: line {exc.lineno} col "
                        f"{exc.colno}: {exc.msg}") from None
    if not isinstance(info, dict) or info.get("tool") != "fms-testbed":
        raise UserError(f"{path}: not a run record of fms-testbed (no \"tool\": \"fms-testbed\")")
    kind = info.get("kind") or "?"
    if kind != REGRESS_KIND:
        raise UserError(f"{out}: holds a {kind} run, not a {what}")
    return info


def write_plan(out: Path, cases) -> None:
    """Write ``DIR/plan.parquet`` (atomically) from the run's cases.

    Parameters
    ----------
    out : the campaign folder; cases : the run's :class:`~.cases.Case` list
    """
    cols = {c: [str(getattr(k, c) if c != "conditions" else k.conditions.name) for k in cases]
            for c in PLAN_COLUMNS}
    tmp = out / f".{PLAN}.tmp"
    pq.write_table(pa.table(cols, schema=PLAN_SCHEMA), tmp)
    tmp.replace(out / PLAN)


def read_plan(out: Path) -> pa.Table | None:
    """The run's plan (None: the folder has none, or it cannot be read).

    Parameters
    ----------
    out : the campaign folder
    """
    try:
        t = pq.read_table(out / PLAN)
    except (OSError, pa.ArrowException):
        return None
    return t if set(PLAN_COLUMNS) <= set(t.column_names) else None


@dataclass
class Damaged:
    """A part file that is not kept: its path, why, and the case ids it holds (when readable)."""

    path: Path
    reason: str
    case_ids: list[str] = field(default_factory=list)


@dataclass
class Audit:
    """What :func:`audit` found (module docstring).

    Attributes
    ----------
    kept : the part files kept, in name order
    tables : their tables
    damaged : the parts not kept
    planned : case ids of the plan (None: the folder has no plan)
    written : case ids in the kept parts
    duplicate_rows, foreign_rows : rows in damaged parts that repeat a kept case, or belong to
        no case of the plan
    """

    kept: list[Path]
    tables: list[pa.Table]
    damaged: list[Damaged]
    planned: list[str] | None
    written: set[str]
    duplicate_rows: int = 0
    foreign_rows: int = 0

    @property
    def missing(self) -> list[str]:
        """Planned case ids not in a kept part (plan order)."""
        return [c for c in self.planned or [] if c not in self.written]

    def damage_line(self, out: Path) -> str:
        """One line naming every damaged part, why, and the cases without a row."""
        if not self.damaged:
            return ""
        parts = "; ".join(f"{d.path.relative_to(out)}: {d.reason}" for d in self.damaged)
        miss = self.missing
        cases = (f"; {len(miss)} case(s) without a row, e.g. {', '.join(miss[:3])}"
                 if miss else "")
        return f"{out}: {len(self.damaged)} damaged part file(s): {parts}{cases}"


def _check_part(path: Path, planned: set[str] | None, seen: set[str]) -> tuple[pa.Table | None,
                                                                              Damaged | None]:
    try:
        tab = pq.read_table(path)
    except (OSError, pa.ArrowException) as exc:
        return None, Damaged(path, "unreadable: not a whole Parquet file "
                                   f"({type(exc).__name__})")
    ids = tab.column("case_id").to_pylist() if "case_id" in tab.column_names else []
    if not tab.schema.equals(SCHEMA, check_metadata=False):
        diff = sorted(set(tab.schema.names) ^ set(SCHEMA.names)) or ["column types"]
        return None, Damaged(path, f"not the dataset's schema ({', '.join(diff[:3])})", ids)
    if len(set(ids)) != len(ids):
        return None, Damaged(path, "repeats a case inside it", ids)
    foreign = [i for i in ids if planned is not None and i not in planned]
    if foreign:
        return None, Damaged(path, f"{len(foreign)} row(s) of cases not in this run "
                                   f"(e.g. {foreign[0]})", ids)
    again = [i for i in ids if i in seen]
    if again:
        return None, Damaged(path, f"{len(again)} row(s) already written in an earlier part "
                                   f"(e.g. {again[0]})", ids)
    return tab, None


def audit(out: str | Path) -> Audit:
    """Read and check every part file of a campaign folder (module docstring).

    Parameters
    ----------
    out : the campaign folder
    """
    out = Path(out)
    plan = read_plan(out)
    planned = None if plan is None else plan.column("case_id").to_pylist()
    pset = None if planned is None else set(planned)
    kept, tables, damaged, seen = [], [], [], set()
    dup = foreign = 0
    for p in part_files(out):
        tab, bad = _check_part(p, pset, seen)
        if bad is not None:
            damaged.append(bad)
            dup += sum(1 for i in bad.case_ids if i in seen)
            foreign += sum(1 for i in bad.case_ids if pset is not None and i not in pset)
            continue
        kept.append(p)
        tables.append(tab)
        seen.update(tab.column("case_id").to_pylist())
    return Audit(kept, tables, damaged, planned, seen, dup, foreign)


def quarantine(out: Path, found: Audit) -> list[str]:
    """Move the damaged parts into ``DIR/quarantine/``; one line per part moved.

    Parameters
    ----------
    out : the campaign folder; found : its :func:`audit`
    """
    lines = []
    if not found.damaged:
        return lines
    folder = out / QUARANTINE
    folder.mkdir(exist_ok=True)
    for d in found.damaged:
        target = folder / d.path.name
        n = 1
        while target.exists():
            target = folder / f"{d.path.stem}.{n}{d.path.suffix}"
            n += 1
        shutil.move(str(d.path), target)
        lines.append(f"{d.path.relative_to(out)}: {d.reason}; moved to "
                     f"{target.relative_to(out)}, its cases are flown again")
    return lines


def flights_frame(found: Audit):
    """The kept rows as a DataFrame (every column of :data:`~.rows.SCHEMA`).

    Parameters
    ----------
    found : an :func:`audit`
    """
    if not found.tables:
        return SCHEMA.empty_table().to_pandas()
    return pa.concat_tables(found.tables).to_pandas()


def read_checked(out: str | Path, refuse_damage: bool = False):
    """(flights DataFrame of the kept parts, ``run.json``, :class:`Audit`) of a campaign
    folder; with ``refuse_damage`` a damaged folder is a one-line :class:`UserError`.

    Parameters
    ----------
    out : the campaign folder
    refuse_damage : refuse a folder with damaged parts (``regress diff``)
    """
    out = Path(out)
    info = load_run_json(out)
    found = audit(out)
    if refuse_damage and found.damaged:
        raise UserError(found.damage_line(out))
    return flights_frame(found), info, found


__all__ = ["PLAN", "PLAN_COLUMNS", "QUARANTINE", "Audit", "Damaged", "audit", "flights_frame",
           "load_run_json", "quarantine", "read_checked", "read_plan", "write_plan"]
