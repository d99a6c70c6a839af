"""Output folders that can be trusted.

* :func:`check_out_dir` runs before any work: the target must be a folder (or creatable), not a
  file, not a symlink, writable; a folder that holds anything but a previous run of the same
  *kind* (the command that wrote it: ``fly``, ``imu-test``, ``montecarlo``, ``regress-run`` …,
  recorded as ``kind`` in its ``run.json``) is refused unless ``overwrite``, and so is a target
  that is, holds or lies inside one of the command's input folders or files (never with
  ``overwrite``). Problems are a one-line :class:`UserError` (CLI exit 2).
* :class:`OutputFolder` writes into a fresh temporary folder beside the target and moves it into
  place only when complete, with ``run.json`` written last as the completion marker; a previous
  run in the target is replaced as a whole (nothing of it stays). Nothing already in the target is
  written through, so a symlink there is never followed. A run killed mid-write leaves the
  previous outputs as they were and a hidden ``.NAME.partial-*`` folder (removed by the next run).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

from fms_testbed.core.errors import UserError
from fms_testbed.core.jsonio import dumps
from fms_testbed import __version__

RUN_MARKER = "run.json"
"""Written last into a complete output folder; a folder holding it is a testbed run."""


def previous_run(folder: str | Path) -> dict | None:
    """The ``run.json`` of a testbed run in ``folder`` (None: there is none, or it is not one).

    Parameters
    ----------
    folder : the folder
    """
    try:
        data = json.loads((Path(folder) / RUN_MARKER).read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("tool") == "fms-testbed" else None


def _marker_problem(folder: Path) -> str:
    """Why the folder's ``run.json`` is not a run record ('' when there is none to name)."""
    path = folder / RUN_MARKER
    if not path.is_file():
        return ""
    try:
        data = json.loads(path.read_text())
    except UnicodeDecodeError:
        return f"; its {RUN_MARKER} is not text"
    except json.JSONDecodeError as exc:
        return f"; its {RUN_MARKER} is not valid JSON: line {exc.lineno} col {exc.colno}"
    except OSError as exc:
        return f"; its {RUN_MARKER} cannot be read: {exc.strerror}"
    return "" if isinstance(data, dict) and data.get("tool") == "fms-testbed" else \
        f"; its {RUN_MARKER} is not a run record of fms-testbed"


def command_kind(argv: list[str] | None = None) -> str:
    """The kind of run a command line writes: its command word, e.g. ``fly`` or ``imu-test``
    (the word after the program name; ``unknown`` when it is an option or a path).

    Parameters
    ----------
    argv : the command line (default ``sys.argv``)
    """
    words = [str(a) for a in (sys.argv if argv is None else argv)[1:2]]
    words = [w for w in words if w and not w.startswith("-") and "/" not in w]
    return words[0] if words else "unknown"


def run_kind(info: dict) -> str:
    """The kind of a previous run: ``kind`` of its ``run.json``, else the command it records.

    Parameters
    ----------
    info : the run's ``run.json``
    """
    if info.get("kind"):
        return str(info["kind"])
    cmd = info.get("command")
    return command_kind(cmd) if isinstance(cmd, list) else "unknown"


def _check_inputs(out: Path, inputs) -> None:
    """Refuse an output path that is, holds or lies inside an input (a file or a folder)."""
    target = out.absolute().resolve()
    for given in inputs or ():
        if not given:
            continue
        src = Path(given).absolute().resolve()
        folder = src if src.is_dir() else src.parent if previous_run(src.parent) else None
        if target == src or src.is_relative_to(target) or (
                folder is not None and target.is_relative_to(folder)):
            raise UserError(f"--out {out}: is or lies inside the input {given}; write the "
                            "outputs elsewhere (an input is never replaced)")


def check_out_dir(out_dir: str | Path, overwrite: bool = False, kind: str | None = None,
                  inputs=()) -> Path:
    """Check that ``out_dir`` can take a run's outputs; raise :class:`UserError` (one line) if not.

    Parameters
    ----------
    out_dir : the target folder
    overwrite : replace a folder that holds something other than a previous run of this kind
    kind : the kind of run to write (default :func:`command_kind` of ``sys.argv``)
    inputs : the command's input files and folders (the target may not be one, hold one, or
        lie inside an input folder or inside the run folder an input file belongs to)

    Returns
    -------
    the target as an absolute path
    """
    out = Path(out_dir)
    if not str(out_dir).strip():
        raise UserError("--out '': give a folder name")
    _check_inputs(out, inputs)
    kind = kind or command_kind()
    if out.is_symlink():
        raise UserError(f"--out {out}: is a symbolic link; give the real folder")
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out}: is a file, not a folder")
    if out.is_dir():
        try:
            content = [p.name for p in out.iterdir() if not p.name.startswith(f".{out.name}.")]
        except OSError as exc:
            raise UserError(f"--out {out}: cannot list the folder: {exc.strerror}") from None
        prev = previous_run(out)
        if content and prev is None and not overwrite:
            raise UserError(f"--out {out}: the folder holds other files ({', '.join(content[:3])}"
                            f"{', ...' if len(content) > 3 else ''}){_marker_problem(out)}; give "
                            "an empty or new folder, or --overwrite to replace it")
        if prev is not None and run_kind(prev) != kind and not overwrite:
            raise UserError(f"--out {out}: holds a {run_kind(prev)} run, not a {kind} run; give "
                            "a new folder, or --overwrite to replace it")
        if not os.access(out, os.W_OK | os.X_OK):
            raise UserError(f"--out {out}: the folder is read-only (permission denied)")
    parent = out.absolute().parent
    probe = parent
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise UserError(f"--out {out}: {probe} is not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise UserError(f"--out {out}: cannot write in {probe} (permission denied)")
    return out.absolute()


def file_sha256(path: str | Path) -> str | None:
    """SHA-256 of a file's bytes (None when it cannot be read).

    Parameters
    ----------
    path : the file
    """
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


class OutputFolder:
    """A run's output folder, written atomically (module docstring).

    Use as a context manager: ``with OutputFolder(out, overwrite) as tmp: ...write into tmp...``;
    on a clean exit :meth:`commit` is called with the ``run.json`` content given to
    :meth:`set_run_info`; on an exception the partial folder is removed and the target is left
    as it was.
    """

    def __init__(self, out_dir: str | Path, overwrite: bool = False, kind: str | None = None,
                 inputs=()):
        self.kind = kind or command_kind()
        self.out = check_out_dir(out_dir, overwrite, self.kind, inputs)
        self.tmp: Path | None = None
        self.info: dict = {}
        self.started = datetime.now(timezone.utc)

    def open(self) -> Path:
        """Create the temporary folder beside the target and return it (what ``with`` does);
        finish with :meth:`commit`. If the command fails first, the hidden
        ``.NAME.partial-*`` folder is left behind and removed by the next run into the target."""
        return self.__enter__()

    def __enter__(self) -> Path:
        parent = self.out.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            for stale in parent.glob(f".{self.out.name}.partial-*"):
                shutil.rmtree(stale, ignore_errors=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.out.name}.partial-", dir=parent))
        except OSError as exc:
            raise UserError(f"--out {self.out}: cannot create the output folder: "
                            f"{exc.strerror}") from None
        return self.tmp

    def set_run_info(self, **info) -> None:
        """Fields of ``run.json`` (command, seed, inputs, status, ...)."""
        self.info.update(info)

    def commit(self) -> Path:
        """Write ``run.json`` last, then move the folder into place (replacing a previous run)."""
        assert self.tmp is not None
        run = {"tool": "fms-testbed", "kind": self.kind, "version": __version__,
               "command": self.info.pop("command", sys.argv),
               **self.info,
               "started_utc": self.started.isoformat(timespec="seconds"),
               "finished_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}
        with open(self.tmp / RUN_MARKER, "w") as f:
            f.write(dumps(run))
            f.flush()
            os.fsync(f.fileno())
        old = None
        if self.out.exists():
            old = self.out.with_name(f".{self.out.name}.old-{os.getpid()}-{time.time_ns()}")
            os.rename(self.out, old)
        os.rename(self.tmp, self.out)
        self.tmp = None
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return self.out

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            try:
                self.commit()
            except OSError as err:
                self._discard()
                raise UserError(f"--out {self.out}: cannot finish writing: {err.strerror}") from None
            return False
        self._discard()
        return False

    def _discard(self) -> None:
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None


__all__ = ["RUN_MARKER", "OutputFolder", "check_out_dir", "command_kind", "file_sha256",
           "previous_run", "run_kind"]
