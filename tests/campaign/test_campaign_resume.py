"""A regression run killed with SIGKILL — every process of it, or the parent alone — resumes
with the same command: the dataset then has every case exactly once, each row equal to an
uninterrupted run's, and no worker outlives its killed parent."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from fms_testbed.campaign.store import part_files, read_flights

from campaign_helpers import SMALL, regress
from test_campaign_run import comparable

CASES = SMALL                  # 20 cases, ≈ 5 s on 2 workers; the same as the small_run fixture


def _start(out: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "fms_testbed", "regress", "run", *CASES, "--workers", "2",
           "--batch-rows", "1", "--no-progress", "--out", str(out)]
    return subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, env=dict(os.environ))


def _wait_for_parts(p: subprocess.Popen, out: Path, n: int, timeout_s: float = 60.0) -> None:
    t0 = time.time()
    while len(part_files(out)) < n:
        assert p.poll() is None, f"run ended early: {p.stderr.read().decode()}"
        assert time.time() - t0 < timeout_s, "no part file written"
        time.sleep(0.02)


def _descendants(pid: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(d))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            if c not in out:
                out.add(c)
                todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and PDEATHSIG are Linux")
def test_sigkill_of_everything_then_resume_loses_and_repeats_nothing(tmp_path, small_run):
    out = tmp_path / "killed"
    p = _start(out)
    _wait_for_parts(p, out, 2)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait(timeout=10)
    written = len(read_flights(out))
    assert 2 <= written < 20, f"{written} rows before the kill"
    assert regress("run", *CASES, "--workers", "2", "--no-progress", "--out", str(out)) == 0
    df = read_flights(out)
    assert len(df) == 20 and df["case_id"].is_unique
    pd.testing.assert_frame_equal(comparable(df), comparable(read_flights(small_run)))
    assert not list((out / "flights").glob(".part-*"))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and PDEATHSIG are Linux")
def test_workers_die_with_a_killed_parent(tmp_path):
    out = tmp_path / "orphans"
    p = _start(out)
    _wait_for_parts(p, out, 1)
    family = _descendants(p.pid)
    assert len(family) >= 3, "expected the fork server and two workers"
    os.kill(p.pid, signal.SIGKILL)
    p.wait(timeout=10)
    t0 = time.time()
    while time.time() - t0 < 15 and any(_alive(q) for q in family):
        time.sleep(0.1)
    left = [q for q in family if _alive(q)]
    for q in left:
        os.kill(q, signal.SIGKILL)
    assert not left, f"processes outlived the killed run: {left}"
