"""Distributed faults: a worker process killed by PID in the middle of a case (local pool, Dask
LocalCluster) costs no case — the case is flown again; a scheduler stopped mid-run ends the run
with one line and the same command resumes from what was written; a write that fails leaves no
half-written part and stops the run with the reason."""

from __future__ import annotations

import errno
import hashlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time

import pandas as pd
import pytest

from fms_testbed.campaign.executors import run_dask, run_local
from fms_testbed.campaign.store import BatchWriter, part_files, read_flights
from fms_testbed.campaign.worker import FlyOptions
from fms_testbed.core.errors import UserError

from campaign_helpers import SMALL, regress
from fault_helpers import slow, slow_once, wait_for_file
from test_campaign_run import _cases, comparable


def _kill_when_flying(folder, case_id: str) -> threading.Thread:
    def kill():
        os.kill(int(wait_for_file(folder / f"{case_id}.pid")), signal.SIGKILL)

    th = threading.Thread(target=kill, daemon=True)
    th.start()
    return th


def test_local_worker_killed_by_pid_mid_case_is_flown_again(tmp_path):
    _, cases = _cases(4)
    victim = cases[2]
    for c in cases:                                  # only the victim sleeps on its 1st try
        if c is not victim:
            (tmp_path / f"{c.case_id}.attempts").write_text("1")
    killer = _kill_when_flying(tmp_path, victim.case_id)
    rows = []
    run_local(cases, FlyOptions("", "", keep_dir=str(tmp_path)), 2, rows.append, fly=slow_once)
    killer.join(5)
    by_id = {r["case_id"]: r for r in rows}
    assert sorted(by_id) == sorted(c.case_id for c in cases) and len(rows) == len(cases)
    assert all(r["status"] == "ok" for r in rows)
    assert by_id[victim.case_id]["reason"].startswith("attempt 2")       # flown again, once
    assert (tmp_path / f"{victim.case_id}.attempts").read_text() == "2"


def _db_file(tmp_path):
    db = tmp_path / "db.dat"
    db.write_text("not read by these workers\n")
    return str(db), hashlib.sha256(db.read_bytes()).hexdigest()


def test_dask_worker_killed_by_pid_mid_case_is_flown_again(tmp_path):
    from distributed import LocalCluster

    _, cases = _cases(3)
    victim = cases[0]
    for c in cases[1:]:
        (tmp_path / f"{c.case_id}.attempts").write_text("1")
    db, sha = _db_file(tmp_path)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=50) as cluster:
        killer = _kill_when_flying(tmp_path, victim.case_id)
        rows = []
        run_dask(cluster.scheduler_address, cases, FlyOptions(db, sha, keep_dir=str(tmp_path)),
                 rows.append, fly=slow_once)
        killer.join(5)
    by_id = {r["case_id"]: r for r in rows}
    assert sorted(by_id) == sorted(c.case_id for c in cases)
    assert all(r["status"] == "ok" for r in rows)
    assert by_id[victim.case_id]["reason"].startswith("attempt 2")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start(args):
    """A Dask process that imports the testbed and these tests' helpers."""
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.pathsep.join([here, os.environ.get("PYTHONPATH", "")])
    return subprocess.Popen([sys.executable, "-m", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True,
                            env={**os.environ, "PYTHONPATH": path})


def test_scheduler_lost_mid_run_stops_in_one_line(tmp_path):
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    sched = _start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port",
                    str(port), "--no-dashboard"])
    worker = _start(["distributed.cli.dask_worker", address, "--nthreads", "1",
                     "--no-dashboard"])
    try:
        from distributed import Client

        with Client(address, timeout="60s", set_as_default=False) as c:
            c.wait_for_workers(1, timeout=60)
        _, cases = _cases(5)
        db, sha = _db_file(tmp_path)
        rows = []

        def on_row(row):
            rows.append(row)
            if len(rows) == 2:
                os.killpg(sched.pid, signal.SIGKILL)

        t0 = time.monotonic()
        with pytest.raises(UserError, match="the scheduler was lost mid-run") as err:
            run_dask(address, cases, FlyOptions(db, sha), on_row, fly=slow)
        assert time.monotonic() - t0 < 60.0
        assert len(str(err.value).splitlines()) == 1 and 2 <= len(rows) < len(cases) == 5
    finally:
        for p in (worker, sched):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
            p.wait(10)


def test_an_unreachable_or_malformed_scheduler_is_one_line(tmp_path, capsys):
    for bad in ("not a url", "http://127.0.0.1:8786", "tcp://127.0.0.1", "tcp://:8786"):
        assert regress("run", *SMALL, "--scheduler", bad, "--no-progress", "--out",
                       str(tmp_path / "o")) == 2
        err = capsys.readouterr().err.strip()
        assert "expected tcp://HOST:PORT" in err and len(err.splitlines()) == 1, err
    t0 = time.monotonic()
    assert regress("run", *SMALL, "--scheduler", f"tcp://127.0.0.1:{_free_port()}",
                   "--no-progress", "--out", str(tmp_path / "o")) == 2
    err = capsys.readouterr().err.strip()
    assert "cannot connect within 5 s" in err and len(err.splitlines()) == 1, err
    assert time.monotonic() - t0 < 30.0


def test_a_failed_write_leaves_no_half_part_and_stops(small_run, tmp_path, monkeypatch,
                                                      capsys):
    calls = [0]
    real = BatchWriter.write

    def fill_disk(tab, fh):
        calls[0] += 1
        if calls[0] == 2:                         # the second part: half written, then ENOSPC
            fh.write(b"PAR1" + b"\0" * 64)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(tab, fh)

    monkeypatch.setattr(BatchWriter, "write", staticmethod(fill_disk))
    out = tmp_path / "full"
    argv = ["run", *SMALL, "--workers", "1", "--batch-rows", "3", "--no-progress", "--out",
            str(out)]
    assert regress(*argv) == 2
    err = capsys.readouterr().err.strip()
    assert "No space left on device" in err and "the run stops" in err
    assert len(err.splitlines()) == 1, err
    # the first part is whole (3 rows, or fewer when the 15-s flush came first); the second,
    # half written when the disk filled, is gone with its temporary file
    assert len(part_files(out)) == 1 and not list((out / "flights").glob(".part-*"))
    assert 1 <= len(read_flights(out)) <= 3
    monkeypatch.setattr(BatchWriter, "write", staticmethod(real))
    assert regress(*argv) == 0                    # the same command resumes
    pd.testing.assert_frame_equal(comparable(read_flights(out)),
                                  comparable(read_flights(small_run)))
