"""Where cases are flown: a local process pool (the default) or a dask.distributed cluster.

Both hand each case to :func:`fms_testbed.campaign.worker.fly_case` in a worker process and give
every row to ``on_row`` as it arrives (in completion order; the dataset does not depend on it).

Local pool (:func:`run_local`): ``concurrent.futures.ProcessPoolExecutor`` on the
``forkserver`` start method (a clean process with the testbed imported once, forked for every
worker: the parent's threads and open files never reach a worker), at most
:data:`WINDOW_PER_WORKER` × workers cases in flight. Each worker ends as soon as the campaign
process does, even after a SIGKILL of it alone (:func:`~.worker.init_pool_worker`). When a
worker process dies (a crash in native code, the out-of-memory killer, the watchdog of
``--case-timeout``) every case in flight is suspect: the pool is restarted and the suspects are
flown again one at a time, so the case that kills a worker again is found and recorded as
``error`` ("the worker process died"), and no other case is lost.

Dask (:func:`run_dask`): an existing cluster at ``tcp://HOST:PORT``. Its workers must be
processes with one thread each (JSBSim is one instance per process): a worker with more threads
is refused before any case is submitted, and so is a worker that cannot read the database file
(it must be on a filesystem the workers share) or holds another version of it. Cases are
submitted in chunks: at most ``chunk`` futures are held at a time, and one is submitted for each
one collected (``as_completed``), which bounds the scheduler's memory. A task the cluster cannot
run (a worker lost three times: ``KilledWorker``) becomes an ``error`` row. The dask import
stays inside this code path.
"""

from __future__ import annotations

import multiprocessing
import os
import time
import uuid
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Callable, Iterable

from fms_testbed.campaign.rows import failed_row
from fms_testbed.campaign.worker import FlyOptions, fly_case, init_pool_worker
from fms_testbed.core.errors import UserError

WINDOW_PER_WORKER = 2
"""Cases in flight per local worker (one flying, one queued: the worker never waits)."""
DASK_CHUNK = 1000
"""Futures held at a time on a Dask cluster (dask/distributed #3898, #4345)."""
CONNECT_TIMEOUT_S = 5.0
"""How long ``--scheduler`` waits for the scheduler to answer, s."""

OnRow = Callable[[dict], None]


def _pool(workers: int) -> ProcessPoolExecutor:
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(["fms_testbed.campaign.worker", "fms_testbed.run.api"])
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                               initializer=init_pool_worker, initargs=(os.getpid(),))


def _died(case, alone: bool, elapsed_s: float, opts: FlyOptions) -> dict:
    why = ("the worker process died flying this case, again when it flew alone (a crash in "
           "native code, the out-of-memory killer, or an external kill)")
    if opts.timeout_s is not None and elapsed_s > opts.timeout_s:
        why += f"; it ran {elapsed_s:.0f} s, past --case-timeout {opts.timeout_s:g} s (the "\
               "watchdog ends a worker stuck in native code)"
    return failed_row(case, "error", why, "WorkerDied")


def run_local(cases: Iterable, opts: FlyOptions, workers: int, on_row: OnRow,
              fly: Callable = fly_case) -> None:
    """Fly ``cases`` on a local pool of ``workers`` processes (module docstring).

    Parameters
    ----------
    cases : the cases to fly
    opts : what every case shares (:class:`~fms_testbed.campaign.worker.FlyOptions`)
    workers : number of worker processes
    on_row : called with each row as it arrives
    fly : the function a worker calls per case, ``fly(case, opts) -> row`` (a module-level
        function, importable by the workers; default :func:`~.worker.fly_case`)
    """
    if workers < 1:
        raise UserError(f"--workers {workers}: must be at least 1")
    todo = deque(cases)
    suspects: deque = deque()
    window = WINDOW_PER_WORKER * workers
    pool = _pool(workers)
    inflight: dict = {}             # future -> (case, is suspect, submit time)
    try:
        while todo or suspects or inflight:
            if suspects:            # isolation: one suspect at a time, nothing beside it
                if not inflight:
                    c = suspects.popleft()
                    inflight[pool.submit(fly, c, opts)] = (c, True, time.perf_counter())
            else:
                while todo and len(inflight) < window:
                    c = todo.popleft()
                    inflight[pool.submit(fly, c, opts)] = (c, False, time.perf_counter())
            done, _ = wait(list(inflight), return_when=FIRST_COMPLETED)
            broken = []
            for f in done:
                c, alone, t_sub = inflight.pop(f)
                try:
                    row = f.result()
                except BrokenProcessPool:
                    broken.append((c, alone, t_sub))
                    continue
                on_row(row)
            if broken:
                # the pool is unusable: every case still in flight failed with it as well
                for f, (c, alone, t_sub) in list(inflight.items()):
                    broken.append((c, alone, t_sub))
                inflight.clear()
                pool.shutdown(wait=False, cancel_futures=True)
                now = time.perf_counter()
                for c, alone, t_sub in broken:
                    if alone:
                        on_row(_died(c, alone, now - t_sub, opts))
                    else:
                        suspects.append(c)
                pool = _pool(workers)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _probe_db(path: str, sha: str) -> str:
    """Run on every Dask worker: '' when it can read the database file with that SHA-256."""
    import hashlib

    try:
        with open(path, "rb") as fh:
            got = hashlib.sha256(fh.read()).hexdigest()
    except OSError as exc:
        return f"cannot read {path}: {exc.strerror}"
    if got == sha:
        return ""
    return f"{path} has SHA-256 {got[:12]}…, the campaign's is {sha[:12]}…"


def parse_scheduler(address: str) -> tuple[str, int]:
    """``tcp://HOST:PORT`` → (host, port); a one-line :class:`UserError` for anything else.

    Parameters
    ----------
    address : the ``--scheduler`` value
    """
    from urllib.parse import urlsplit

    try:
        u = urlsplit(address)
        port = u.port
    except ValueError:
        port, u = None, None
    if u is None or u.scheme != "tcp" or not u.hostname or port is None or port == 0 \
            or u.path not in ("", "/") or u.query or u.fragment:
        raise UserError(f"--scheduler {address!r}: expected tcp://HOST:PORT, e.g. "
                        "tcp://127.0.0.1:8786")
    return u.hostname, port


def _connect(address: str):
    try:
        from distributed import Client
    except ImportError:
        raise UserError("--scheduler needs dask.distributed: pip install "
                        "'fms-testbed[dist]'") from None
    parse_scheduler(address)
    try:
        return Client(address, timeout=f"{CONNECT_TIMEOUT_S:g}s", set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise UserError(f"--scheduler {address}: cannot connect within "
                        f"{CONNECT_TIMEOUT_S:g} s: {type(exc).__name__}: "
                        f"{str(exc).splitlines()[0] if str(exc) else 'no answer'}") from None


def _check_cluster(client, address: str, opts: FlyOptions) -> None:
    threads = client.nthreads()
    if not threads:
        raise UserError(f"--scheduler {address}: the cluster has no workers")
    multi = sorted(w for w, n in threads.items() if n != 1)
    if multi:
        raise UserError(f"--scheduler {address}: workers {', '.join(multi[:3])} run "
                        f"{threads[multi[0]]} threads; start them with --nthreads 1 (JSBSim "
                        "is one instance per process)")
    bad = {w: e for w, e in client.run(_probe_db, opts.db_path, opts.db_sha256).items() if e}
    if bad:
        w, e = next(iter(sorted(bad.items())))
        raise UserError(f"--scheduler {address}: worker {w}: {e} (the database must be on "
                        "a filesystem every worker reads)")


def _lost(client, address: str) -> UserError:
    return UserError(f"--scheduler {address}: the scheduler was lost mid-run (client "
                     f"{client.status}); every row collected so far is written: run the same "
                     "command again to resume")


def _dask_row(client, address: str, f, c) -> dict:
    """The row of a collected future; a lost scheduler stops the run (never an error row)."""
    from distributed import CancelledError

    try:
        return f.result()
    except CancelledError:
        raise _lost(client, address) from None
    except Exception as exc:  # noqa: BLE001 -- the cluster could not run it: an 'error' row
        if client.status not in ("running", "connecting"):
            raise _lost(client, address) from None
        text = " ".join(str(exc).split())
        return failed_row(c, "error", f"dask: {type(exc).__name__}: {text}", type(exc).__name__)


def run_dask(address: str, cases: Iterable, opts: FlyOptions, on_row: OnRow,
             chunk: int = DASK_CHUNK, fly: Callable = fly_case) -> None:
    """Fly ``cases`` on the dask.distributed cluster at ``address`` (module docstring).

    Parameters
    ----------
    address : the scheduler, ``tcp://HOST:PORT``
    cases : the cases to fly
    opts : what every case shares (:class:`~fms_testbed.campaign.worker.FlyOptions`)
    on_row : called with each row as it arrives
    chunk : futures held at a time at most
    fly : the function a worker calls per case (as :func:`run_local`'s)
    """
    from distributed import as_completed

    client = _connect(address)
    try:
        _check_cluster(client, address, opts)
        token = uuid.uuid4().hex[:8]
        it = iter(cases)
        held: dict = {}

        def submit(c):
            f = client.submit(fly, c, opts, key=f"fly-{c.case_id}-{token}", pure=False)
            held[f.key] = c
            return f

        first = [submit(c) for _, c in zip(range(chunk), it)]
        ac = as_completed(first, loop=client.loop)
        for f in ac:
            c = held.pop(f.key)
            row = _dask_row(client, address, f, c)
            f.release()
            on_row(row)
            nxt = next(it, None)
            if nxt is not None:
                ac.add(submit(nxt))
    finally:
        client.close(timeout=CONNECT_TIMEOUT_S)


__all__ = ["CONNECT_TIMEOUT_S", "DASK_CHUNK", "WINDOW_PER_WORKER",
           "parse_scheduler", "run_dask", "run_local"]
