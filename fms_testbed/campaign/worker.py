"""Fly one case in a worker process: the database index loaded once per process, the case
built from it, flown, evaluated and turned into a row.

A worker (a process of the local pool, or a dask.distributed worker process) loads the index
of the campaign's database on its first case (:func:`worker_index`) and keeps it; after the
load the garbage collector's view of it is frozen (``gc.freeze``), so the flight loop's
collections do not walk the database's objects. The aircraft configuration is cached per
process by :func:`fms_testbed.config.aircraft.load_aircraft`. The JSBSim instance is not
reused between cases: a fresh instance costs a few ms (load + trim; ``docs/regression.md``), and
JSBSim keeps engine and FCS state across ``run_ic``, so a reused one would make a case's result
depend on the case flown before it on that worker.

:func:`fly_case` never raises: a procedure that cannot be built, a flight that diverges, a case
that exceeds ``--case-timeout`` and an exception are all rows with their status and reason.
Time limit: the flight is stepped in chunks of :data:`STEP_CHUNK` outer steps and stopped at the
deadline (what was flown is evaluated, status ``timeout``); in a worker's main thread
(the local pool) ``SIGALRM`` also ends a case stuck before or after the flight loop, and a
watchdog (``faulthandler``) ends the worker process when a case is stuck in native code for
three times the limit (the pool then records the case as ``error``: the worker died).
"""

from __future__ import annotations

import faulthandler
import gc
import signal
import sys
import threading
import time
import traceback
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from fms_testbed.campaign.rows import add_path_errors, add_sequence, failed_row, flown_row
from fms_testbed.core.errors import UserError
from fms_testbed.procedures.index import DatabaseIndex, load_index

STEP_CHUNK = 100
"""Outer steps flown between two deadline checks (10 s simulated, ≈ 25 ms of wall time)."""
WATCHDOG_FACTOR = 3.0
"""The worker process is ended after this many times ``--case-timeout`` on one case."""

_STATE: dict = {}
_LOCK = threading.Lock()


@dataclass(frozen=True)
class FlyOptions:
    """What every case of a run shares.

    Attributes
    ----------
    db_path : absolute path of the database file (on the worker's filesystem)
    db_sha256 : its SHA-256 (a worker refuses a file that changed)
    timeout_s : ``--case-timeout``, s (None: no limit)
    keep : artefacts kept per case: subset of {'timeseries', 'plots'}
    keep_dir : folder the artefacts go to (``DIR/cases``), one sub-folder per case id
    cache_dir : index cache folder (None: the default)
    """

    db_path: str
    db_sha256: str
    timeout_s: float | None = None
    keep: tuple[str, ...] = ()
    keep_dir: str | None = None
    cache_dir: str | None = None


class CaseTimeout(Exception):
    """A case ran past its deadline outside the flight loop (raised by ``SIGALRM``)."""


def worker_index(opts: FlyOptions) -> DatabaseIndex:
    """The database index of this process (loaded on first use, then kept).

    Parameters
    ----------
    opts : the run's :class:`FlyOptions` (database path and SHA-256, cache folder)
    """
    with _LOCK:
        ix = _STATE.get(opts.db_path)
        if ix is None:
            ix = load_index(opts.db_path, opts.cache_dir)
            if ix.sha256 != opts.db_sha256:
                raise UserError(f"{opts.db_path}: the file changed since the campaign started "
                                f"(SHA-256 {ix.sha256[:12]}…, expected {opts.db_sha256[:12]}…)")
            gc.collect()
            gc.freeze()
            _STATE[opts.db_path] = ix
        return ix


def init_pool_worker(campaign_pid: int | None = None) -> None:
    """Initializer of a local pool worker: never outlive the campaign (no orphan after a
    SIGKILL of it).

    A ``forkserver`` worker's parent is the fork server, which lives as long as any worker does,
    so :func:`~fms_testbed.core.processes.die_with_parent` alone does not end it: a daemon
    thread also waits on a pidfd of the campaign process (Linux ≥ 5.3) and ends the worker at
    once when that process is gone.

    Parameters
    ----------
    campaign_pid : process id of the campaign (the pool's owner); None: the parent only
    """
    from fms_testbed.core.processes import die_with_parent

    die_with_parent()
    if campaign_pid is not None:
        exit_with(campaign_pid)


def exit_with(pid: int) -> bool:
    """End this process (``os._exit``) as soon as process ``pid`` ends; False where pidfds are
    not available (then only :func:`~fms_testbed.core.processes.die_with_parent` applies).

    Parameters
    ----------
    pid : the process to follow
    """
    import os
    import select

    if not hasattr(os, "pidfd_open"):
        return False
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        os._exit(70)            # already gone
    except OSError:
        return False

    def _wait() -> None:
        p = select.poll()
        p.register(fd, select.POLLIN)
        while not p.poll():
            pass
        os._exit(70)            # EX_SOFTWARE: the campaign died; nothing of this case is kept

    threading.Thread(target=_wait, name="exit-with-campaign", daemon=True).start()
    return True


@contextmanager
def _alarm(seconds: float | None):
    """``SIGALRM`` after ``seconds`` raises :class:`CaseTimeout` (main thread only), and a
    watchdog ends the process after :data:`WATCHDOG_FACTOR` × ``seconds``."""
    main = threading.current_thread() is threading.main_thread()
    if not seconds or not main:
        yield
        return

    def _fire(signum, frame):
        raise CaseTimeout

    old = signal.signal(signal.SIGALRM, _fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    faulthandler.dump_traceback_later(WATCHDOG_FACTOR * seconds, exit=True, file=sys.stderr)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
        faulthandler.cancel_dump_traceback_later()


def _tail(exc: BaseException, frames: int = 6) -> str:
    return "".join(traceback.format_exception(type(exc), exc, exc.__traceback__,
                                              limit=-frames))


def fly_case(case, opts: FlyOptions) -> dict:
    """Fly one case; return its row (:mod:`fms_testbed.campaign.rows`). Never raises (module
    docstring).

    Parameters
    ----------
    case : the :class:`~fms_testbed.campaign.cases.Case`
    opts : what every case of the run shares (:class:`FlyOptions`)
    """
    t0 = time.perf_counter()
    stage = ["loading the database"]
    try:
        # the alarm fires a little after the deadline: the flight loop's own check ends a
        # slow flight cleanly first, with what was flown evaluated
        with _alarm(None if opts.timeout_s is None else opts.timeout_s + 5.0):
            row = _fly(case, opts, t0, stage)
    except CaseTimeout:
        row = failed_row(case, "timeout", f"--case-timeout {opts.timeout_s:g} s reached while "
                                          f"{stage[0]}")
    except UserError as exc:
        row = failed_row(case, "error", str(exc), type(exc).__name__)
    except Exception as exc:  # noqa: BLE001 -- a bug: status 'error' with its type and traceback
        row = failed_row(case, "error", f"{type(exc).__name__}: {exc} (while {stage[0]})",
                         type(exc).__name__, _tail(exc))
    row["wall_s"] = round(time.perf_counter() - t0, 4)
    return row


def _fly(case, opts: FlyOptions, t0: float, stage: list[str]) -> dict:
    db = worker_index(opts).db
    row, res = fly_on(case, db, opts.db_path, opts.timeout_s, t0, stage)
    if res is not None and opts.keep and opts.keep_dir:
        stage[0] = "writing the kept artefacts"
        res.save(Path(opts.keep_dir) / case.case_id, plots="plots" in opts.keep,
                 command=["fms-testbed", "regress", "run", "case", case.case_id])
    return row


def fly_on(case, db, db_path: str, timeout_s: float | None = None,
           t0: float | None = None, stage: list[str] | None = None):
    """Build and fly one case from a loaded database; return (row, Results or None when the
    procedure was not built). Raises what the flight raises (:func:`fly_case` records it).

    Parameters
    ----------
    case : the :class:`~fms_testbed.campaign.cases.Case`
    db : the loaded database; db_path : its file (named in the scenario)
    timeout_s : wall-time limit from ``t0`` (``time.perf_counter()``), s; None: none
    stage : a one-item list updated with what is being done (for a timeout's reason)
    """
    from fms_testbed.loop.flight import Flight
    from fms_testbed.loop.procedure import prepare_procedure
    from fms_testbed.path.plan import merge_parts, select_parts
    from fms_testbed.procedures.integrity import refusal
    from fms_testbed.run.api import results_of

    stage = stage if stage is not None else [""]
    t0 = time.perf_counter() if t0 is None else t0
    stage[0] = "selecting the procedure"
    try:
        seq = merge_parts(select_parts(db, case.airport, case.procedure,
                                       case.transition or None, case.runway or None))
    except UserError as exc:
        return failed_row(case, "impossible", str(exc)), None
    if seq.degraded:
        row = failed_row(case, "degraded", refusal(seq.name, seq.defects))
        add_sequence(row, seq)
        return row, None
    stage[0] = "building the procedure"
    try:
        scn, prepared = prepare_procedure(case.scenario(db_path), f"case {case.case_id}",
                                          db=db)
    except UserError as exc:
        row = failed_row(case, "impossible", str(exc))
        add_sequence(row, seq)
        return row, None
    stage[0] = "trimming"
    flight = Flight(scn, procedure=prepared, seed=case.seed, progress=False)
    stage[0] = "flying"
    deadline = None if timeout_s is None else t0 + timeout_s
    while flight.step(STEP_CHUNK):
        if deadline is not None and time.perf_counter() > deadline:
            flight.stop(f"--case-timeout {timeout_s:g} s reached")
            break
    stage[0] = "evaluating the flight"
    res = results_of(flight)
    row = flown_row(case, res.summary)
    add_path_errors(row, res.df, prepared.path.path.profile)
    return row, res


__all__ = ["STEP_CHUNK", "WATCHDOG_FACTOR", "CaseTimeout", "FlyOptions", "exit_with", "fly_case",
           "fly_on",
           "init_pool_worker", "worker_index"]
