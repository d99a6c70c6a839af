"""Run OpenBLAS single-threaded inside a block (restored afterwards).

On a shared 2-core machine OpenBLAS's threads make a 33×33 @ 33×1000 product ~30× slower
(1.7 ms vs 49 µs measured here); the Monte-Carlo is specified on one core anyway. This finds the
OpenBLAS libraries numpy and scipy have loaded (``/proc/self/maps``) and calls their
``*_set_num_threads``; where that is impossible it does nothing.
"""

from __future__ import annotations

import ctypes
import re
from contextlib import contextmanager
from functools import lru_cache

_SUFFIXES = ("64_", "", "_64")


@lru_cache(maxsize=1)
def _handles():
    """(get, set) pairs of the loaded OpenBLAS libraries (scanned once; scipy is loaded by then)."""
    try:
        maps = open("/proc/self/maps").read()
    except OSError:
        return ()
    out = []
    for path in sorted(set(re.findall(r"(/\S*openblas\S*\.so\S*)", maps))):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for prefix in ("scipy_openblas", "openblas"):
            for suf in _SUFFIXES:
                get = getattr(lib, f"{prefix}_get_num_threads{suf}", None)
                put = getattr(lib, f"{prefix}_set_num_threads{suf}", None)
                if get is not None and put is not None:
                    out.append((get, put))
                    break
            else:
                continue
            break
    return tuple(out)


@contextmanager
def single_thread_blas():
    """Context manager: OpenBLAS uses one thread inside, its previous setting afterwards."""
    hs = _handles()
    old = [get() for get, _ in hs]
    for _, put in hs:
        put(ctypes.c_int(1))
    try:
        yield
    finally:
        for (_, put), n in zip(hs, old):
            put(ctypes.c_int(n))
