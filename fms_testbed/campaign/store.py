"""A campaign's folder: ``run.json``, the ``flights/`` Parquet dataset, kept artefacts.

::

    DIR/run.json              command, version, database (path, SHA-256), case count, options,
                              status ('running' / 'complete'), counts by status, timings
    DIR/flights/part-*.parquet  one row per finished case (:data:`~.rows.SCHEMA`)
    DIR/cases/<case_id>/      --keep timeseries,plots: the flight's outputs (``Results.save``)

Atomic and resumable: rows are written a batch at a time (:class:`BatchWriter`: every
``batch_rows`` rows or ``batch_s`` seconds, and at the end), each batch to a hidden temporary
file in ``flights/`` that is renamed into place once written and synced. A run killed at any
moment (SIGKILL of everything) leaves only whole part files; the hidden temporary files are
ignored by every Parquet reader (names starting with '.') and removed by the next run. Resuming
lists the case ids of the part files that pass :func:`~.audit.audit` (:func:`finished_ids`) and
flies only the others, so nothing is lost or written twice. A part that cannot be written (no
space left) is removed and the run stops with a one-line :class:`UserError`. One run at a time: ``DIR/.lock`` is held (``flock``) while a
run writes (the kernel releases it when the process dies).
"""

from __future__ import annotations

import fcntl
import json
import os
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import pyarrow.parquet as pq

from fms_testbed.campaign.rows import table
from fms_testbed.core.errors import UserError
from fms_testbed.core.jsonio import dumps

FLIGHTS = "flights"
CASES = "cases"
RUN_JSON = "run.json"


def _umask() -> int:
    old = os.umask(0)
    os.umask(old)
    return old


_FILE_MODE = 0o666 & ~_umask()
"""Mode of the files written (temporary files are created 0600; the results are not secret)."""


def _fsync_dir(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_json_atomic(path: Path, data: dict) -> None:
    """Strict JSON written to a temporary file beside ``path`` and renamed over it.

    Parameters
    ----------
    path : the file; data : the mapping (:func:`fms_testbed.core.jsonio.dumps`)
    """
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    os.fchmod(fd, _FILE_MODE)
    with os.fdopen(fd, "w") as fh:
        fh.write(dumps(data))
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    _fsync_dir(path.parent)


def read_run_json(out: Path) -> dict | None:
    """``DIR/run.json`` of a previous run, or None.

    Parameters
    ----------
    out : the campaign folder
    """
    try:
        data = json.loads((out / RUN_JSON).read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("tool") == "fms-testbed" else None


def part_files(out: Path) -> list[Path]:
    """The complete part files of ``DIR/flights`` (sorted by name).

    Parameters
    ----------
    out : the campaign folder
    """
    folder = out / FLIGHTS
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.suffix == ".parquet"
                  and not p.name.startswith((".", "_")))


def finished_ids(out: Path) -> set[str]:
    """Case ids already written: those of the part files :func:`~.audit.audit` keeps.

    Parameters
    ----------
    out : the campaign folder
    """
    from fms_testbed.campaign.audit import audit

    return audit(out).written


def clean_partial(out: Path) -> int:
    """Remove hidden temporary part files a killed run left; return how many.

    Parameters
    ----------
    out : the campaign folder
    """
    folder = out / FLIGHTS
    n = 0
    if folder.is_dir():
        for p in folder.glob(".part-*"):
            p.unlink(missing_ok=True)
            n += 1
    return n


class RunLock:
    """``DIR/.lock`` held exclusively for the life of a run (one writer per folder)."""

    def __init__(self, out: Path):
        self.path = out / ".lock"
        self.fd: int | None = None

    def __enter__(self) -> "RunLock":
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self.fd)
            self.fd = None
            raise UserError(f"--out {self.path.parent}: another regress run is writing into "
                            "this folder") from None
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            fcntl.flock(self.fd, fcntl.LOCK_UN)
            os.close(self.fd)
            self.fd = None


class BatchWriter:
    """Collect rows; write them as one part file every ``batch_rows`` rows or ``batch_s``
    seconds (module docstring).

    Parameters
    ----------
    out : the campaign folder
    batch_rows : rows per part file at most
    batch_s : the longest time a finished row waits in memory, s
    """

    def __init__(self, out: Path, batch_rows: int = 64, batch_s: float = 15.0):
        self.folder = out / FLIGHTS
        self.folder.mkdir(parents=True, exist_ok=True)
        self.batch_rows, self.batch_s = batch_rows, batch_s
        self.rows: list[dict] = []
        self.t_last = time.monotonic()
        self.n_files = 0
        self.n_rows = 0

    @staticmethod
    def write(tab, fh) -> None:
        """Write one part's table into the open file (Parquet, zstd)."""
        pq.write_table(tab, fh, compression="zstd")

    def add(self, row: dict) -> None:
        """Add one row; write the batch when it is due."""
        self.rows.append(row)
        if len(self.rows) >= self.batch_rows or time.monotonic() - self.t_last >= self.batch_s:
            self.flush()

    def flush(self) -> None:
        """Write the rows held (if any) as one part file, atomically."""
        self.t_last = time.monotonic()
        if not self.rows:
            return
        tab = table(self.rows)
        name = f"part-{time.time_ns():020d}-{os.getpid()}-{self.rows[0]['case_id']}.parquet"
        tmp = None
        try:
            fd, tmp = tempfile.mkstemp(prefix=".part-", suffix=".tmp", dir=self.folder)
            os.fchmod(fd, _FILE_MODE)
            with os.fdopen(fd, "wb") as fh:
                self.write(tab, fh)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, self.folder / name)
            _fsync_dir(self.folder)
        except OSError as exc:
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)
            n, self.rows = len(self.rows), []
            raise UserError(f"{self.folder}: cannot write a part file: "
                            f"{exc.strerror or exc}; the run stops ({n} finished case(s) not "
                            "written, flown again on resume: run the same command once the "
                            "cause is fixed)") from None
        except BaseException:
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)
            raise
        self.n_files += 1
        self.n_rows += len(self.rows)
        self.rows = []


def utc_now() -> str:
    """The current UTC time, ISO 8601 to the second."""
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


__all__ = ["CASES", "FLIGHTS", "RUN_JSON", "BatchWriter", "RunLock", "clean_partial",
           "finished_ids", "part_files", "read_flights", "read_run_json", "utc_now",
           "write_json_atomic"]


def read_flights(out: str | Path):
    """The ``flights/`` dataset of a campaign folder as a DataFrame (every column of
    :data:`~.rows.SCHEMA`, even when no part file is written yet): the rows of the part files
    :func:`~.audit.audit` keeps; a folder that is not a regression run is a one-line
    :class:`UserError`.

    Parameters
    ----------
    out : the campaign folder
    """
    from fms_testbed.campaign.audit import read_checked

    return read_checked(out)[0]
