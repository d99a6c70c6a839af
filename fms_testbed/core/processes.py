"""Process hygiene for worker pools: a worker never outlives the process that started it."""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys

PR_SET_PDEATHSIG = 1
"""prctl(2) option: the signal a process gets when its parent dies (Linux)."""


def die_with_parent(sig: int = signal.SIGKILL) -> bool:
    """Ask the kernel to send ``sig`` to this process when its parent dies (Linux ``prctl``).

    Call it first in a pool worker (``initializer=``): a SIGKILL of the parent then takes its
    workers with it instead of leaving them blocked forever. Returns False where the platform
    has no such mechanism (the worker then relies on the pool's own shutdown).

    Parameters
    ----------
    sig : the signal the worker gets, default SIGKILL
    """
    if not sys.platform.startswith("linux"):
        return False
    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) != 0:
        return False
    # the parent may have died between fork and prctl: then we are already orphaned
    if os.getppid() == 1:
        os.kill(os.getpid(), sig)
    return True


__all__ = ["die_with_parent"]
