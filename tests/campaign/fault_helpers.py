"""Worker functions for the fault tests (module-level: the local pool and Dask workers import
them by name). Each takes the case and a :class:`~fms_testbed.campaign.worker.FlyOptions` whose
``keep_dir`` is a scratch folder the test and the workers share."""

from __future__ import annotations

import os
import time
from pathlib import Path

from fms_testbed.campaign.rows import failed_row


def slow_once(case, opts):
    """The first attempt of every case writes its process id to ``keep_dir/<case_id>.pid``
    and sleeps (the test kills that process); a later attempt returns at once."""
    folder = Path(opts.keep_dir)
    pid_file = folder / f"{case.case_id}.pid"
    attempts = folder / f"{case.case_id}.attempts"
    n = int(attempts.read_text()) if attempts.exists() else 0
    attempts.write_text(str(n + 1))
    if n == 0:
        pid_file.write_text(str(os.getpid()))
        time.sleep(60.0)
    return failed_row(case, "ok", f"attempt {n + 1} in {os.getpid()}")


def slow(case, opts):
    """Every case takes 2 s (a scheduler can be stopped while cases are in flight)."""
    time.sleep(2.0)
    return failed_row(case, "ok", f"flown in {os.getpid()}")


def wait_for_file(path: Path, timeout_s: float = 60.0) -> str:
    """The text of ``path`` once it exists (AssertionError after ``timeout_s``)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        if path.exists() and path.read_text():
            return path.read_text()
        time.sleep(0.05)
    raise AssertionError(f"{path} did not appear within {timeout_s:g} s")
