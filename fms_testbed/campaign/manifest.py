"""Phase 1 of Danilin's method: a run of the test database checked against its manifest.

The test database (:mod:`fms_testbed.procedures.testdb`) is written with a manifest beside it
(``FILE.manifest.json``) that states, per procedure, the case the run flies and the outcome it
is designed to have. :func:`check_manifest` matches each manifest entry to the run's row of the
same (airport, type, procedure, runway, transition) — the first aircraft and condition set when
the run has several — and decides whether the outcome agrees:

* ``fly`` — status in the expected ones (``ok``), the monitor's verdict in the expected ones,
  the findings matching ``says`` when given;
* ``refuse`` — status ``impossible`` or ``degraded`` as expected, the reason matching ``says``;
* ``flag`` — not a run failure (``timeout``/``error``), and the findings or the reason match
  ``says``;
* every kind: when the row has the flown path terminators (and is not ``degraded``: a
  rejected record is not in its sequence), they are the manifest's ``flown_legs`` (the case
  flies the combination it was designed for).

Residual-error rate of phase 1: the share of the manifest's cases that disagree with it (a
valid procedure that fails, a coding error that is flown without a word), with its 95 % Wilson
interval; a manifest case with no row counts as a disagreement once the run is complete.
Criterion (:data:`PHASE1_MAX_RATE`): at most 2 % — Danilin (seed 000) states that each
phase's residual rate decides the next phase but gives no figure; for ~50 designed cases 2 %
is one case, the resolution of the phase: every case has a known answer, so the software goes
on to the integration phase with at most one open disagreement, named in the report.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from fms_testbed.campaign.rows import RUN_FAILURES
from fms_testbed.core.errors import UserError

PHASE1_MAX_RATE = 0.02
"""Phase-1 criterion: residual-error rate (manifest disagreements / manifest cases) ≤ 2 %."""
MANIFEST_KIND = "fms-testbed-testdb-manifest"
KEY = ("airport", "type", "procedure", "runway", "transition")


def read_manifest(path: str | Path, db_sha256: str | None = None) -> dict:
    """A test-database manifest (JSON), checked; a user error in one line when it is not one
    or belongs to another database file.

    Parameters
    ----------
    path : the manifest file
    db_sha256 : the SHA-256 of the database the run flew (None: not checked)
    """
    path = Path(path)
    try:
        m = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise UserError(f"{path}: cannot read the manifest: {exc.strerror}") from None
    except json.JSONDecodeError as exc:
        raise UserError(f"{path}: not JSON: {exc.msg} (line {exc.lineno})") from None
    if not isinstance(m, dict) or m.get("kind") != MANIFEST_KIND:
        raise UserError(f"{path}: kind: not a test-database manifest ({MANIFEST_KIND!r})")
    if db_sha256 is not None and m.get("database_sha256") != db_sha256:
        raise UserError(f"{path}: database_sha256: the manifest is of another database file "
                        f"({str(m.get('database_sha256'))[:12]}…, the run flew "
                        f"{db_sha256[:12]}…)")
    return m


def find_manifest(info: dict) -> Path | None:
    """The manifest of a run: ``run.json``'s ``manifest.path``, else ``DB.manifest.json``
    beside its database when that file exists (None: the run has none).

    Parameters
    ----------
    info : the run's ``run.json``
    """
    rec = info.get("manifest") or {}
    if rec.get("path"):
        return Path(rec["path"])
    db = (info.get("database") or {}).get("path")
    if not db:
        return None
    p = Path(db).with_name(Path(db).name + ".manifest.json")
    return p if p.exists() else None


@dataclass
class ManifestCheck:
    """The outcome of :func:`check_manifest`: one row per manifest case (``table``) and the
    phase-1 residual-error rate."""

    table: pd.DataFrame
    cases: int
    disagreements: int
    missing: int
    rate: float
    ci_low: float
    ci_high: float
    complete: bool
    notes: list[str] = field(default_factory=list)

    @property
    def criterion_met(self) -> bool:
        """Rate ≤ :data:`PHASE1_MAX_RATE` and every manifest case flown."""
        return self.complete and self.missing == 0 and self.rate <= PHASE1_MAX_RATE


def _text(row) -> str:
    return f"{row.get('reason') or ''}; {row.get('findings') or ''}"


def judge(entry: dict, row) -> tuple[bool, str]:
    """Whether a run's row agrees with its manifest entry, and why not (module docstring).

    Parameters
    ----------
    entry : a manifest entry (``expect``, ``flown_legs``)
    row : the run's row of that case (mapping), or None when the run has none
    """
    if row is None:
        return False, "no row: the case was not flown"
    e = entry["expect"]
    status = row["status"]
    why = []
    says = e.get("says") or ""
    found = bool(re.search(says, _text(row), re.IGNORECASE)) if says else True
    if e["kind"] == "fly":
        if status not in e["status"]:
            why.append(f"status {status}, expected {'/'.join(e['status'])}")
        mon = row.get("monitor_status") or ""
        if e["monitor"] and mon not in e["monitor"]:
            why.append(f"monitor {mon or '—'}, expected {'/'.join(e['monitor'])}")
    elif e["kind"] == "refuse":
        if status not in e["status"]:
            why.append(f"status {status}, expected {'/'.join(e['status'])}")
    elif e["kind"] == "flag":
        if status in RUN_FAILURES:
            why.append(f"status {status}: the run failed")
    else:
        raise UserError(f"manifest: {entry['procedure']}: expect.kind {e['kind']!r} is not "
                        "fly, refuse or flag")
    if not found:
        why.append(f"nothing matches /{says}/")
    legs = row.get("leg_codes") or ""
    if legs and status != "degraded" and entry.get("flown_legs") and legs != entry["flown_legs"]:
        why.append(f"legs flown {legs!r}, designed {entry['flown_legs']!r}")
    return not why, "; ".join(why)


def check_manifest(df: pd.DataFrame, manifest: dict, complete: bool = True) -> ManifestCheck:
    """Compare a run's rows with the manifest (module docstring).

    Parameters
    ----------
    df : the run's ``flights`` table
    manifest : the manifest (:func:`read_manifest`)
    complete : the run is complete (a missing case then counts as a disagreement)
    """
    from fms_testbed.campaign.report import wilson_interval

    rows = {}
    for _, r in df.iterrows():
        k = tuple(str(r[c] or "") for c in KEY)
        rows.setdefault(k, r.to_dict())
    out = []
    n_bad = n_missing = 0
    for entry in manifest["procedures"]:
        k = tuple(str(entry[c] or "") for c in KEY)
        row = rows.get(k)
        ok, why = judge(entry, row)
        if row is None:
            n_missing += 1
        if not ok and (row is not None or complete):
            n_bad += 1
        e = entry["expect"]
        out.append({
            "procedure": f"{entry['airport']} {entry['type']} {entry['procedure']}"
                         + "".join(f" {x}" for x in (entry["runway"], entry["transition"]) if x),
            "coding": entry["coding"], "legs": entry["flown_legs"],
            "expected": e["kind"] + (f" {'/'.join(e['status'])}" if e["status"] else "")
                        + (f", monitor {'/'.join(e['monitor'])}" if e["monitor"] else "")
                        + (f", says /{e['says']}/" if e.get("says") else ""),
            "status": None if row is None else row["status"],
            "monitor": None if row is None else (row.get("monitor_status") or "—"),
            "agrees": "yes" if ok else "NO", "why not": why,
            "class": e.get("defect_class"),
            "reason / findings": "" if row is None else _text(row).strip("; ")[:300]})
    n = len(manifest["procedures"])
    lo, hi = wilson_interval(n_bad, n)
    notes = []
    extra = set(rows) - {tuple(str(e[c] or "") for c in KEY) for e in manifest["procedures"]}
    if extra:
        notes.append(f"{len(extra)} case(s) of the run are not in the manifest")
    return ManifestCheck(pd.DataFrame(out), n, n_bad, n_missing, n_bad / n if n else float("nan"),
                         lo, hi, complete, notes)


def check_run(folder: str | Path) -> ManifestCheck | None:
    """:func:`check_manifest` of a run folder (None: the run has no manifest).

    Parameters
    ----------
    folder : the campaign folder
    """
    from fms_testbed.campaign.store import read_flights, read_run_json

    info = read_run_json(Path(folder))
    if info is None:
        raise UserError(f"{folder}: not a regress run folder (no run.json)")
    path = find_manifest(info)
    if path is None:
        return None
    m = read_manifest(path, (info.get("database") or {}).get("sha256"))
    return check_manifest(read_flights(Path(folder)), m, info.get("status") == "complete")


__all__ = ["KEY", "MANIFEST_KIND", "PHASE1_MAX_RATE", "ManifestCheck", "check_manifest",
           "check_run", "find_manifest", "judge", "read_manifest"]
