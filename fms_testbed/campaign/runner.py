"""A regression run: plan the cases, fly those not yet flown, write the dataset and ``run.json``.

:func:`plan` loads the database through its index, picks the airports (given, all, or a seeded
sample: :func:`~.cases.sample_airports`) and enumerates the cases (:mod:`.cases`).
:func:`run_campaign` checks the output folder (its kind, the inputs, permissions:
:func:`~fms_testbed.run.outputs.check_out_dir`), resumes what a previous run of the same cases
left there (same case set, or a one-line refusal; ``overwrite`` replaces another kind of run,
other files or a run of other cases), writes the plan, checks every part file already written
and moves the damaged ones into ``DIR/quarantine/`` (:mod:`.audit`), flies the cases without a
row on the local pool or a Dask cluster (:mod:`.executors`) and writes rows as they arrive
(:mod:`.store`), with a progress bar (cases/s and ETA) on a terminal. ``status: complete`` is
written only when every planned case has a row in a kept part. Interrupted (Ctrl-C, SIGTERM, SIGKILL), it leaves ``run.json``
with ``status: running`` and every finished batch; the same command resumes.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from fms_testbed.campaign.cases import (TYPE_NAMES, Case, aircraft_files, enumerate_cases,
                                        sample_airports)
from fms_testbed.campaign.conditions import Conditions, check_sources
from fms_testbed.campaign.audit import audit, quarantine, write_plan
from fms_testbed.campaign.executors import parse_scheduler, run_dask, run_local
from fms_testbed.campaign.store import (CASES, RUN_JSON, BatchWriter, RunLock, clean_partial,
                                        utc_now, write_json_atomic)
from fms_testbed.campaign.worker import FlyOptions
from fms_testbed.core.errors import UserError
from fms_testbed.procedures.index import DatabaseIndex, cache_dir, load_index, parser_hash
from fms_testbed.run.outputs import check_out_dir, previous_run, run_kind

RUN_KIND = "regress-run"
"""``run.json`` ``kind`` of a regression run folder."""
KEEP = ("timeseries", "plots")
"""Per-case artefacts ``--keep`` can keep."""


@dataclass
class RunConfig:
    """A regression run's options (the ``regress run`` command line; units in the names).

    Attributes
    ----------
    out : campaign folder
    db : ARINC-424 file (None/'embedded': the embedded excerpt)
    airports : ICAO idents (None: every airport with procedures)
    sample_airports, sample_seed, sample_min_transitions : a seeded sample of the airports
        (:func:`~.cases.sample_airports`); None: no sampling
    types : subsection codes to fly ('D', 'E', 'F')
    aircraft : aircraft names or files
    conditions : condition sets (:mod:`.conditions`)
    combinations : 'each' or 'all' (:mod:`.cases`)
    limit : fly the first ``limit`` cases only
    seed : campaign seed (part of every case id)
    workers : local pool size; scheduler : Dask scheduler address (instead of the pool)
    case_timeout_s : wall-time limit of one case, s (None: none)
    keep : per-case artefacts (:data:`KEEP`)
    progress : progress bar (None: on a terminal)
    command : the command line recorded in ``run.json`` (default ``sys.argv``)
    cache_dir : database index cache folder (None: the default)
    phase : Danilin phase, ``test-db`` or ``integration`` (None: inferred,
        :func:`phase_label`)
    batch_rows, batch_s : rows per part file, longest a row waits in memory (s)
    overwrite : replace a folder holding another kind of run, other files or a run of other
        cases (never an input)
    say : where the lines on quarantined parts go (default: stderr)
    """

    out: Path
    conditions: list[Conditions]
    db: str | None = None
    airports: list[str] | None = None
    sample_airports: int | None = None
    sample_seed: int = 0
    sample_min_transitions: int = 1
    types: list[str] = field(default_factory=lambda: ["D", "E", "F"])
    aircraft: list[str] = field(default_factory=lambda: ["737"])
    combinations: str = "each"
    limit: int | None = None
    seed: int = 0
    workers: int = 1
    scheduler: str | None = None
    case_timeout_s: float | None = None
    keep: tuple[str, ...] = ()
    progress: bool | None = None
    command: list[str] | None = None
    cache_dir: str | None = None
    phase: str | None = None
    batch_rows: int = 64
    batch_s: float = 15.0
    overwrite: bool = False
    say: Callable[[str], None] | None = None


def select_airports(index: DatabaseIndex, cfg: RunConfig) -> list[str]:
    """The airports of the run: given (checked, upper-cased, repeats merged) or all, then
    sampled when asked.

    Parameters
    ----------
    index : the database index; cfg : the run's options
    """
    from fms_testbed.evaluation.check import merge_airports
    from fms_testbed.procedures.catalogue import check_airport

    db = index.db
    given = merge_airports(cfg.airports)
    airports = [check_airport(db, a) for a in given] if given else db.airport_idents()
    if cfg.sample_airports is not None:
        airports = sample_airports(db, airports, cfg.sample_airports, cfg.sample_seed,
                                   cfg.types, cfg.sample_min_transitions)
    return airports


def plan(cfg: RunConfig) -> tuple[DatabaseIndex, list[str], list[Case]]:
    """The database index, the airports and the cases of a run (module docstring).

    Parameters
    ----------
    cfg : the run's options
    """
    if cfg.combinations not in ("each", "all"):
        raise UserError(f"--combinations {cfg.combinations!r}: expected 'each' or 'all'")
    if cfg.limit is not None and cfg.limit < 1:
        raise UserError(f"--limit {cfg.limit}: must be at least 1")
    bad = [k for k in cfg.keep if k not in KEEP]
    if bad:
        raise UserError(f"--keep {','.join(cfg.keep)}: {bad[0]!r} is not one of "
                        f"{', '.join(KEEP)}")
    if cfg.batch_rows < 1:
        raise UserError(f"--batch-rows {cfg.batch_rows}: must be at least 1")
    if cfg.case_timeout_s is not None and not cfg.case_timeout_s > 0:
        raise UserError(f"--case-timeout {cfg.case_timeout_s:g}: must be > 0 s")
    if cfg.phase is not None:
        phase_label(cfg.phase, 0, 0, 0, False)      # a bad --phase is refused before flying
    check_sources(cfg.conditions)
    aircraft = aircraft_files(cfg.aircraft)
    index = load_index(cfg.db, cfg.cache_dir)
    airports = select_airports(index, cfg)
    cases = enumerate_cases(index, airports, cfg.types, aircraft, cfg.conditions,
                            cfg.combinations, cfg.seed, cfg.limit)
    if not cases:
        kinds = ", ".join(TYPE_NAMES[t] for t in cfg.types)
        raise UserError(f"{index.path}: no {kinds} procedure at {', '.join(airports[:5])}"
                        f"{' …' if len(airports) > 5 else ''}: no case to fly")
    return index, airports, cases


def case_set_sha256(cases: list[Case]) -> str:
    """SHA-256 of the sorted case ids: what a resumed run must match.

    Parameters
    ----------
    cases : the run's cases
    """
    return hashlib.sha256("\n".join(sorted(c.case_id for c in cases)).encode()).hexdigest()


PHASES = {"test-db": "test database", "integration": "integration"}
"""``--phase`` values → the phase label ``run.json`` records (Danilin's phases)."""


def phase_label(given: str | None, n_airports: int, n_cases: int, n_procedures: int,
                has_manifest: bool) -> str:
    """The phase ``run.json`` records: ``--phase`` when given (``test-db`` or
    ``integration``; the labels themselves are accepted too), else inferred: 'test database'
    when the database has a test-database manifest, else :func:`infer_phase`.

    Parameters
    ----------
    given : the ``--phase`` value (None: infer)
    n_airports, n_cases, n_procedures : the run's size
    has_manifest : the database has a manifest of its own (:mod:`.manifest`)
    """
    if given is not None:
        if given in PHASES:
            return PHASES[given]
        if given in PHASES.values():
            return given
        raise UserError(f"--phase {given!r}: expected one of {', '.join(PHASES)}")
    if has_manifest:
        return "test database"
    return infer_phase(n_airports, n_cases, n_procedures)


def infer_phase(n_airports: int, n_cases: int, n_procedures: int) -> str:
    """Danilin's phase a run's size corresponds to: 'integration' (≥ 100 airports and ≥ 5,000
    flights), 'test database' (≤ 100 procedures), else 'between phases'.

    Parameters
    ----------
    n_airports, n_cases, n_procedures : the run's size
    """
    if n_airports >= 100 and n_cases >= 5000:
        return "integration"
    if n_procedures <= 100:
        return "test database"
    return "between phases"


def manifest_record(index: DatabaseIndex) -> dict | None:
    """``run.json``'s ``manifest`` entry: the test-database manifest beside the database
    (``FILE.manifest.json``) when it names this very file (its SHA-256), else None.

    Parameters
    ----------
    index : the run's database index
    """
    import json

    from fms_testbed.campaign.manifest import MANIFEST_KIND

    path = Path(str(index.path) + ".manifest.json")
    if not path.is_file():
        return None
    raw = path.read_bytes()
    try:
        m = json.loads(raw)
    except ValueError:
        return None
    if not isinstance(m, dict) or m.get("kind") != MANIFEST_KIND \
            or m.get("database_sha256") != index.sha256:
        return None
    return {"path": str(path), "sha256": hashlib.sha256(raw).hexdigest(),
            "cases": len(m.get("procedures", []))}


def _bar(total: int, initial: int, progress: bool | None):
    if progress is False:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, unit="case", desc="regress run", smoothing=0.05,
                dynamic_ncols=True, disable=None if progress is None else False)


def _say(line: str) -> None:
    print(f"fms-testbed: {line}", file=sys.stderr)


def _check_target(cfg: RunConfig) -> tuple[Path, dict | None]:
    """The output folder (checked: kind, inputs, permissions) and its previous regress run."""
    db = None if cfg.db in (None, "embedded") else cfg.db
    out = check_out_dir(cfg.out, cfg.overwrite, RUN_KIND, [db])
    prev = previous_run(out)
    if prev is not None and run_kind(prev) != RUN_KIND:
        prev = None                 # another kind of run, replaced (--overwrite)
    if cfg.scheduler is None and cfg.workers < 1:
        raise UserError(f"--workers {cfg.workers}: must be at least 1")
    if cfg.scheduler is not None:
        parse_scheduler(cfg.scheduler)
    return out, prev


def _clear(out: Path) -> None:
    """Remove the folder's content (``--overwrite``): renamed aside first, then deleted."""
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}-{time.time_ns()}")
        os.rename(out, old)
        shutil.rmtree(old, ignore_errors=True)


def _resume_or_clear(cfg: RunConfig, out: Path, prev: dict | None, set_sha: str) -> dict | None:
    """The previous run to resume (None: start afresh, the folder cleared when it held
    anything and ``--overwrite`` was given)."""
    if prev is not None and prev.get("cases", {}).get("set_sha256") == set_sha:
        return prev
    if prev is not None and not cfg.overwrite:
        old_sha = prev.get("database", {}).get("sha256", "?")
        raise UserError(f"--out {out}: holds a run of other cases ({prev['cases'].get('count')} "
                        f"cases, database SHA-256 {old_sha[:12]}…); give the same options to "
                        "resume it, a new folder, or --overwrite to replace it")
    if out.exists() and any(out.iterdir()):
        _clear(out)
    return None


def _run_info(cfg: RunConfig, index, airports: list[str], cases: list[Case], set_sha: str,
              prev: dict | None) -> dict:
    n_proc = len({(c.airport, c.procedure) for c in cases})
    manifest = manifest_record(index)
    return {
        "tool": "fms-testbed", "kind": RUN_KIND, "version": _version(),
        "command": cfg.command if cfg.command is not None else sys.argv,
        "status": "running",
        "database": {"path": str(index.path), "sha256": index.sha256,
                     "parser_sha256": parser_hash(), "index": index.source,
                     "index_load_s": round(index.load_s, 3)},
        "cases": {"count": len(cases), "set_sha256": set_sha, "airports": len(airports),
                  "procedures": n_proc},
        "phase": phase_label(cfg.phase, len(airports), len(cases), n_proc, manifest is not None),
        "manifest": manifest,
        "options": {"airports": airports, "types": [TYPE_NAMES[t] for t in cfg.types],
                    "aircraft": cfg.aircraft,
                    "conditions": [c.canonical() for c in cfg.conditions],
                    "combinations": cfg.combinations, "limit": cfg.limit, "seed": cfg.seed,
                    "sample": None if cfg.sample_airports is None else {
                        "airports": cfg.sample_airports, "seed": cfg.sample_seed,
                        "min_transitions": cfg.sample_min_transitions},
                    "case_timeout_s": cfg.case_timeout_s, "keep": list(cfg.keep)},
        "execution": {"workers": None if cfg.scheduler else cfg.workers,
                      "scheduler": cfg.scheduler},
        "started_utc": (prev or {}).get("started_utc") or utc_now(),
        "sessions": list((prev or {}).get("sessions", [])),
    }


def _fly_all(cfg: RunConfig, out: Path, todo: list[Case], opts: FlyOptions, bar) -> dict:
    """Fly ``todo`` and write the rows; the session's figures."""
    writer = BatchWriter(out, cfg.batch_rows, cfg.batch_s)
    session: Counter = Counter()
    wall = [0.0, 0.0]

    def on_row(row: dict) -> None:
        writer.add(row)
        session[row["status"]] += 1
        wall[0] += row["loop_wall_s"] or 0.0
        wall[1] += row["wall_s"] or 0.0
        if bar is not None:
            bar.update(1)
            bad = sum(v for k, v in session.items() if k != "ok")
            bar.set_postfix_str(f"not ok {bad}", refresh=False)

    t0 = time.perf_counter()
    try:
        if todo and cfg.scheduler:
            run_dask(cfg.scheduler, todo, opts, on_row)
        elif todo:
            run_local(todo, opts, min(cfg.workers, len(todo)), on_row)
    finally:
        if bar is not None:
            bar.close()
        writer.flush()
    elapsed = time.perf_counter() - t0
    n = sum(session.values())
    return {"cases_flown": n, "elapsed_s": round(elapsed, 2),
            "flights_per_hour": round(3600.0 * n / elapsed) if n and elapsed > 0 else None,
            "sum_wall_s": round(wall[1], 2), "sum_loop_wall_s": round(wall[0], 2)}


def run_campaign(cfg: RunConfig) -> dict:
    """Fly a campaign into ``cfg.out`` (module docstring); return the final ``run.json``.

    Parameters
    ----------
    cfg : the run's options
    """
    out, prev = _check_target(cfg)
    t_plan = time.perf_counter()
    index, airports, cases = plan(cfg)
    t_plan = time.perf_counter() - t_plan
    set_sha = case_set_sha256(cases)
    prev = _resume_or_clear(cfg, out, prev, set_sha)
    out.mkdir(parents=True, exist_ok=True)
    say = cfg.say or _say
    with RunLock(out):
        clean_partial(out)
        info = _run_info(cfg, index, airports, cases, set_sha, prev)
        write_json_atomic(out / RUN_JSON, info)
        write_plan(out, cases)
        found = audit(out)
        quarantined = quarantine(out, found)
        for line in quarantined:
            say(line)
        todo = [c for c in cases if c.case_id not in found.written]
        opts = FlyOptions(str(index.path), index.sha256, cfg.case_timeout_s, tuple(cfg.keep),
                          str(out / CASES) if cfg.keep else None,
                          cfg.cache_dir or str(cache_dir()))
        started = utc_now()
        sess = _fly_all(cfg, out, todo, opts, _bar(len(cases), len(cases) - len(todo),
                                                   cfg.progress))
        info["sessions"].append({
            "started_utc": started, **sess, "cases_skipped": len(cases) - len(todo),
            "plan_s": round(t_plan, 2), "quarantined": quarantined,
            "workers": None if cfg.scheduler else cfg.workers, "scheduler": cfg.scheduler})
        final = audit(out)
        counts = Counter(s for t in final.tables for s in t.column("status").to_pylist())
        info["status"] = "complete" if not final.missing and not final.damaged else "running"
        info["counts"] = dict(sorted(counts.items()))
        info["finished_utc"] = utc_now()
        write_json_atomic(out / RUN_JSON, info)
    return info


def _version() -> str:
    from fms_testbed import __version__

    return __version__


__all__ = ["KEEP", "PHASES", "RUN_KIND", "RunConfig", "case_set_sha256", "infer_phase",
           "manifest_record", "phase_label", "plan",
           "run_campaign", "select_airports"]
