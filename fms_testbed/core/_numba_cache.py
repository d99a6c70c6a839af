"""Guard against stale numba caches across modules.

numba's on-disk cache (``cache=True``) invalidates a compiled function only when *its own* source
file changes; the machine code of the functions it calls, and the module globals it reads
(frozen as constants), are baked in. The SINS kernels call each other across files
(``navigation.sins._sins_step`` inlines ``discretize._picard_sins``, ``model.build_F`` and
``simulate._psd_cholesky``; ``build_F`` inlines the radii and gravity of :mod:`.earth`), and
:mod:`.vincenty` reads the WGS-84 constants of :mod:`.earth`. Editing one file (or ``git pull``
touching only it) would leave the others' cached machine code running the old version —
silently wrong numbers. :func:`invalidate_if_sources_changed` stamps a hash of the sources a
package's kernels depend on into its ``__pycache__`` and deletes the package's numba cache files
when the hash changes. Costs < 1 ms at import; does nothing where ``__pycache__`` is not writable
(numba then caches elsewhere).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_STAMP = "fms_testbed_numba_sources.sha1"


def invalidate_if_sources_changed(package_dir: Path, also_hash: tuple[Path, ...] = ()) -> bool:
    """Delete the package's numba cache files when its sources changed since the last call.

    Parameters
    ----------
    package_dir : folder whose ``__pycache__/*.nbi|*.nbc`` are cleared; all its ``*.py`` are hashed.
    also_hash : further folders (all their ``*.py``) or single ``.py`` files whose kernels or
        constants the package's kernels inline.

    Returns
    -------
    bool : True if cache files were deleted.
    """
    try:
        h = hashlib.sha1()
        for d in (package_dir, *also_hash):
            d = Path(d)
            for p in ([d] if d.is_file() else sorted(d.glob("*.py"))):
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
