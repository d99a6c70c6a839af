"""Pool workers die with their parent: a SIGKILL of the parent leaves no orphan."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

CODE = """
import time
from concurrent.futures import ProcessPoolExecutor
from fms_testbed.core.processes import die_with_parent

def pid(_):
    import os
    return os.getpid()

def block(_):
    time.sleep(60)

if __name__ == "__main__":
    with ProcessPoolExecutor(2, initializer=die_with_parent) as ex:
        pids = set(ex.map(pid, range(8)))
        print(" ".join(map(str, sorted(pids))), flush=True)
        list(ex.map(block, range(2)))
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="prctl(PR_SET_PDEATHSIG) is Linux")
def test_workers_die_with_a_killed_parent(tmp_path):
    script = tmp_path / "pool.py"
    script.write_text(CODE)
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    pids = [int(x) for x in p.stdout.readline().split()]
    assert pids and all(_alive(q) for q in pids)
    os.kill(p.pid, signal.SIGKILL)
    p.wait(timeout=10)
    deadline = time.time() + 10
    while time.time() < deadline and any(_alive(q) for q in pids):
        time.sleep(0.1)
    assert not any(_alive(q) for q in pids), "orphan workers left"
