"""Guard against stale numba caches across modules.

numba's on-disk cache (``cache=True``) invalidates a compiled function only when *its own* source
file changes. The SINS kernels call each other across files (``navigation._sins_step`` inlines
``discretize._picard_sins``, ``model.build_F`` and ``simulate._psd_cholesky``), so editing one file
(or ``git pull`` touching only it) would leave the others' cached machine code running the old
version — silently wrong numbers. This stamps a hash of every ``.py`` file of the package into
``__pycache__`` and deletes the package's numba cache files when the hash changes. Costs < 1 ms
at import; does nothing where ``__pycache__`` is not writable (numba then caches elsewhere).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_STAMP = "fms_testbed_sins_sources.sha1"


def invalidate_if_sources_changed(package_dir: Path, also_hash: tuple[Path, ...] = ()) -> bool:
    """Delete ``package_dir/__pycache__/*.nbi|*.nbc`` when the package's sources (and those of the
    folders in ``also_hash``, whose kernels it inlines) changed since the last call; return True if
    it did."""
    try:
        h = hashlib.sha1()
        for d in (package_dir, *also_hash):
            for p in sorted(Path(d).glob("*.py")):
                h.update(p.name.encode())
                h.update(p.read_bytes())
        digest = h.hexdigest()
        cache = package_dir / "__pycache__"
        stamp = cache / _STAMP
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        removed = False
        if cache.is_dir():
            for f in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
                f.unlink()
                removed = True
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest + "\n")
        return removed
    except OSError:
        return False
