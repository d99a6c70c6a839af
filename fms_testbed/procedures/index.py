"""The database parsed once: an index of an ARINC-424 file that loads in a fraction of a second.

:func:`load_index` reads a file with :func:`~.database.load_database` the first time and keeps
the loaded :class:`~.database.Database` (before any airport's legs are parsed) as a pickle in a
cache folder; every later load of the same file by the same parser unpickles it. Its large
read-only tables (fixes, airports, raw procedure records, line lists) are held as
:class:`PackedMapping`: one blob per table, each value unpickled when a flight first looks it up.
The whole FAA CIFP (53 MB, 196,178 leg records) parses in 3-6 s and loads through the index in
about 0.1 s (``docs/results/regress.md`` gives the measurement and the command).

Cache key (the file name of the index): the SHA-256 of the file's bytes, its absolute path (the
database reports it in every message), the *parser hash* — the SHA-256 of the source of every
module of :mod:`fms_testbed.procedures` that reads records (all of them but this one and
:mod:`.catalogue`/:mod:`.synth`) and of :mod:`fms_testbed.core.units` — the index format
:data:`INDEX_FORMAT` and the Python version. A changed file, a changed parser or another Python
gives another key, so a stale index is never used; the index of an older key for the same path
is removed when a new one is written.

The file's SHA-256 is remembered beside the index with the file's size, modification time (ns),
inode and device; while these are unchanged the file is not read again to hash it (the stat
trust of ``git`` and ``make``).

Cache folder: ``$FMS_TESTBED_CACHE`` when set, else ``$XDG_CACHE_HOME/fms-testbed/index``, else
``~/.cache/fms-testbed/index``. An index file is written to a temporary name and renamed into
place (a killed process never leaves half an index); one that is not a regular file owned by
the current user, or that cannot be read back, is ignored and rebuilt (pickles execute code when
loaded: only the user's own files are read).

Besides the database the index holds a 64-bit BLAKE2b digest of every line of the file
(:attr:`DatabaseIndex.line_digests`, line ``n`` at position ``n - 1``, numbered as the loader
numbers them), so a campaign can name the exact records a flight uses (:meth:`record_digest`)
without the text of the file.
"""

from __future__ import annotations

import copyreg
import dataclasses
from collections.abc import Mapping
import gc
import hashlib
import io
import logging
import os
import pickle
import sys
import tempfile
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from fms_testbed.data import procedures_dir
from fms_testbed.procedures.database import EMBEDDED_NAME, Database, Sequence, _read, load_text
from fms_testbed.procedures.integrity import Defect
from fms_testbed.procedures.legrecord import FixRef, LegRecord
from fms_testbed.procedures.loader import split_lines
from fms_testbed.procedures.records import Fix

log = logging.getLogger(__name__)

INDEX_FORMAT = 3
"""Version of the index layout; part of the cache key."""

#: Modules of this package that do not read records (not part of the parser hash).
_NOT_PARSER = frozenset({"index.py", "catalogue.py", "synth.py"})
_FIX_FIELDS = tuple(f.name for f in dataclasses.fields(Fix))
_FAST_CLASSES = (LegRecord, FixRef, Sequence, Defect)
"""Frozen slotted dataclasses of the parsed procedures, pickled as field tuples."""


@lru_cache(maxsize=1)
def parser_hash() -> str:
    """SHA-256 (hex) of the source of the record-reading modules (module docstring)."""
    here = Path(__file__).resolve().parent
    files = sorted(p for p in here.glob("*.py") if p.name not in _NOT_PARSER)
    files.append(here.parent / "core" / "units.py")
    h = hashlib.sha256()
    for p in files:
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def cache_dir() -> Path:
    """The folder index files go to (module docstring)."""
    env = os.environ.get("FMS_TESTBED_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "fms-testbed" / "index"


def resolve_db_path(db: str | Path | None) -> Path:
    """The file a ``--db`` value names: None, '' or 'embedded' is the embedded excerpt."""
    if db in (None, "", "embedded"):
        return procedures_dir() / EMBEDDED_NAME
    return Path(db).absolute()


@dataclass
class DatabaseIndex:
    """A loaded database with what a campaign needs to name its records.

    Attributes
    ----------
    db : the :class:`~.database.Database` (legs parsed per airport on first use, as always)
    path : absolute path of the file
    sha256 : SHA-256 (hex) of the file's bytes
    line_digests : uint64 BLAKE2b-64 digest of each line (line n at n - 1)
    source : 'index' (loaded from the cache), 'parsed' (read and parsed now)
    load_s : wall time of :func:`load_index`, s
    """

    db: Database
    path: Path
    sha256: str
    line_digests: np.ndarray
    source: str
    load_s: float

    def record_digest(self, lines) -> str:
        """SHA-256 (hex) of the digests of the given file lines, in the order given (1-based
        line numbers; 0 — a record built without a line — is skipped)."""
        idx = np.asarray([n - 1 for n in lines if n > 0], dtype=np.int64)
        if idx.size and (idx.max() >= self.line_digests.size):
            raise ValueError(f"{self.path}: line {int(idx.max()) + 1} beyond the file's "
                             f"{self.line_digests.size} lines")
        return hashlib.sha256(self.line_digests[idx].tobytes()).hexdigest()


RECORD_NUMBER_COLS = slice(123, 128)
"""ARINC-424 columns 124-128, the file record number: where a record sits in the file, not
what it says (left out of a line's digest)."""


def record_content(line: str) -> str:
    """A record's text without its file record number (columns 124-128 blanked; a line shorter
    than 128 characters is kept whole).

    Parameters
    ----------
    line : one line of the file
    """
    if len(line) < RECORD_NUMBER_COLS.stop:
        return line
    return line[:RECORD_NUMBER_COLS.start] + " " * 5 + line[RECORD_NUMBER_COLS.stop:]


def line_digests(text: str) -> np.ndarray:
    """64-bit BLAKE2b digest of each line of ``text`` (split as the loader splits it), over the
    record's content: the file record number (columns 124-128) left out
    (:func:`record_content`), so a record inserted earlier in the file changes no digest of
    the records after it."""
    out = np.empty(0, dtype=np.uint64)
    lines = split_lines(text)
    if lines:
        raw = b"".join(hashlib.blake2b(record_content(ln).encode("latin-1", "replace"),
                                       digest_size=8).digest() for ln in lines)
        out = np.frombuffer(raw, dtype=np.uint64).copy()
    return out


#: Database fields held packed (:class:`PackedMapping`): read-only after loading, and large
#: (``_parsed``: every airport's procedure transitions, parsed when the index is written).
PACKED_FIELDS = ("fixes", "terminal", "airports", "_raw_procs", "_key_lines",
                 "_keys_by_airport", "_parsed")
_MISSING = object()


class PackedMapping(Mapping):
    """A read-only mapping whose values stay pickled until first looked up.

    Unpickling the CIFP's 107,000 fixes and 196,000 procedure records as objects is most of
    the cost of loading a whole database; a flight looks up a few dozen of them. The keys are a
    plain dict (key -> position), the values one ``bytes`` blob with their offsets; a value is
    unpickled on first access and kept. Iteration, ``in``, ``len`` and ``get`` behave as for the
    dict it was packed from.
    """

    __slots__ = ("_pos", "_blob", "_off", "_memo")

    def __init__(self, pos: dict, blob: bytes, offsets: np.ndarray):
        self._pos, self._blob, self._off = pos, memoryview(blob), offsets
        self._memo: dict = {}

    @classmethod
    def pack(cls, d: Mapping) -> "PackedMapping":
        """Pack a mapping (values pickled one by one, fixes as field tuples)."""
        pos, parts, off = {}, [], [0]
        for i, (k, v) in enumerate(d.items()):
            b = _dump(v)
            parts.append(b)
            off.append(off[-1] + len(b))
            pos[k] = i
        return cls(pos, b"".join(parts), np.asarray(off, dtype=np.int64))

    def __getitem__(self, key):
        v = self._memo.get(key, _MISSING)
        if v is _MISSING:
            i = self._pos[key]
            v = self._memo[key] = pickle.loads(self._blob[self._off[i]:self._off[i + 1]])
        return v

    def get(self, key, default=None):
        """The value of ``key``, else ``default``."""
        v = self._memo.get(key, _MISSING)
        if v is not _MISSING:
            return v
        return self[key] if key in self._pos else default

    def __contains__(self, key) -> bool:
        return key in self._pos

    def __iter__(self):
        return iter(self._pos)

    def __len__(self) -> int:
        return len(self._pos)

    def __reduce__(self):
        return PackedMapping, (self._pos, self._blob.tobytes(), self._off)


def packed(db: Database) -> Database:
    """The database with every airport's procedures parsed (their rejected records in
    ``issues``) and its large read-only tables packed (:data:`PACKED_FIELDS`).

    Parameters
    ----------
    db : a loaded database
    """
    for airport in db.airport_idents():
        db.sequences(airport)
    repl = {f: PackedMapping.pack(getattr(db, f)) for f in PACKED_FIELDS
            if isinstance(getattr(db, f, None), dict)}
    return dataclasses.replace(db, **repl)


def _key(path: Path, sha: str) -> str:
    where = hashlib.sha256(str(path).encode()).hexdigest()[:12]
    py = f"py{sys.version_info.major}{sys.version_info.minor}"
    return f"{sha[:20]}-{where}-{parser_hash()[:12]}-v{INDEX_FORMAT}-{py}"


def _reduce_fix(f: Fix):
    return Fix, tuple(getattr(f, n) for n in _FIX_FIELDS)


def _reducer(cls):
    """A pickle reducer of a frozen slotted dataclass to its field tuple (unpickled by one
    constructor call, not field by field)."""
    names = tuple(f.name for f in dataclasses.fields(cls))

    def reduce(obj):
        return cls, tuple(getattr(obj, n) for n in names)
    return reduce


def _dump(obj) -> bytes:
    """Pickle with fixes reduced to their field tuples (a frozen slotted dataclass unpickles
    field by field otherwise: 2.5 times slower for the CIFP's 107,000 fixes)."""
    buf = io.BytesIO()
    p = pickle.Pickler(buf, protocol=pickle.HIGHEST_PROTOCOL)
    p.dispatch_table = {**copyreg.dispatch_table, Fix: _reduce_fix,
                        **{c: _reducer(c) for c in _FAST_CLASSES}}
    p.dump(obj)
    return buf.getvalue()


def _loads(data: bytes):
    """Unpickle with the garbage collector paused (its collections while 400,000 objects are
    created cost three times the load itself)."""
    was = gc.isenabled()
    gc.disable()
    try:
        return pickle.loads(data)
    finally:
        if was:
            gc.enable()


def _read_index(file: Path, sha: str, path: Path):
    """The (db, digests) held in an index file, or None when it cannot be trusted or read."""
    try:
        st = file.lstat()
    except FileNotFoundError:
        return None
    if not file.is_file() or file.is_symlink() or st.st_uid != os.getuid():
        log.warning("%s: not a regular file of this user; index ignored", file)
        return None
    try:
        payload = _loads(file.read_bytes())
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError,
            TypeError, ValueError) as exc:
        log.warning("%s: unreadable index (%s); rebuilt", file, exc)
        return None
    if not (isinstance(payload, dict) and payload.get("sha256") == sha
            and payload.get("path") == str(path) and isinstance(payload.get("db"), Database)):
        log.warning("%s: index does not match %s; rebuilt", file, path)
        return None
    return payload["db"], payload["digests"]


def _write_index(folder: Path, key: str, payload: dict) -> Path | None:
    """Write an index atomically; remove older indexes of the same path. None on failure (the
    index is an optimisation: a read-only cache folder only costs the parse)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        data = _dump(payload)
        fd, tmp = tempfile.mkstemp(prefix=".index-", dir=folder)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        final = folder / f"{key}.pickle"
        os.replace(tmp, final)
    except OSError as exc:
        log.warning("%s: cannot write the database index (%s)", folder, exc.strerror or exc)
        return None
    where = key.split("-")[1]
    for old in folder.glob(f"*-{where}-*.pickle"):
        if old != final:
            old.unlink(missing_ok=True)
    return final


def load_index(db: str | Path | None = None, folder: str | Path | None = None,
               use_cache: bool = True) -> DatabaseIndex:
    """Load an ARINC-424 database through its index (module docstring).

    Parameters
    ----------
    db : the file ('embedded' or None: the embedded excerpt)
    folder : cache folder (default :func:`cache_dir`)
    use_cache : False reads and parses the file and writes no index

    Raises
    ------
    UserError : the file cannot be read or holds no ARINC-424 record (as
        :func:`~.database.load_database`)
    """
    t0 = time.perf_counter()
    path = resolve_db_path(db)
    folder = Path(folder) if folder is not None else cache_dir()
    raw = None
    sha = _memo_sha(folder, path) if use_cache else None
    if sha is None:
        raw = _bytes(path)
        sha = hashlib.sha256(raw).hexdigest()
    key = _key(path, sha)
    if use_cache:
        got = _read_index(folder / f"{key}.pickle", sha, path)
        if got is not None:
            dbase, digests = got
            return DatabaseIndex(dbase, path, sha, digests, "index", time.perf_counter() - t0)
    if raw is None:
        raw = _bytes(path)
        sha = hashlib.sha256(raw).hexdigest()
        key = _key(path, sha)
    text = raw.decode("latin-1")
    dbase = load_text(text, str(path))
    digests = line_digests(text)
    if use_cache:
        if _write_index(folder, key, {"sha256": sha, "path": str(path), "db": packed(dbase),
                                      "digests": digests}) is not None:
            _write_memo(folder, path, sha)
    return DatabaseIndex(dbase, path, sha, digests, "parsed", time.perf_counter() - t0)


def _stat_key(path: Path) -> str | None:
    """(size, mtime, inode, device) of a regular file, as text; None when it cannot be read."""
    try:
        st = path.stat()
    except OSError:
        return None
    return f"{st.st_size}:{st.st_mtime_ns}:{st.st_ino}:{st.st_dev}"


def _memo_file(folder: Path, path: Path) -> Path:
    return folder / f"{hashlib.sha256(str(path).encode()).hexdigest()[:12]}.sha256"


def _memo_sha(folder: Path, path: Path) -> str | None:
    """The file's SHA-256 remembered from the last index write, when its size, modification
    time (ns), inode and device are unchanged since (as ``git`` and ``make`` trust a stat);
    None otherwise (the file is then read and hashed)."""
    memo = _memo_file(folder, path)
    now = _stat_key(path)
    try:
        if now is None or memo.lstat().st_uid != os.getuid():
            return None
        stat_text, sha = memo.read_text().split()
    except (OSError, ValueError):
        return None
    return sha if stat_text == now and len(sha) == 64 else None


def _write_memo(folder: Path, path: Path, sha: str) -> None:
    now = _stat_key(path)
    if now is None:
        return
    try:
        fd, tmp = tempfile.mkstemp(prefix=".memo-", dir=folder)
        with os.fdopen(fd, "w") as fh:
            fh.write(f"{now} {sha}\n")
        os.replace(tmp, _memo_file(folder, path))
    except OSError:
        pass          # the memo only saves a hash of the file next time


def _bytes(path: Path) -> bytes:
    """The file's bytes, with the loader's checks (regular file, size; one-line UserError)."""
    text = _read(path)          # checks and decodes; re-encoding Latin-1 is exact
    return text.encode("latin-1")


__all__ = ["INDEX_FORMAT", "PACKED_FIELDS", "DatabaseIndex", "PackedMapping", "packed",
           "cache_dir", "line_digests", "load_index", "record_content",
           "parser_hash", "resolve_db_path"]
