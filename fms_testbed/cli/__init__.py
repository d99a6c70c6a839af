"""Command-line entry point ``fms-testbed``.

Each command group lives in its own module exposing ``register(subparsers)``; the handler it sets
with ``set_defaults(func=...)`` returns an exit code. User errors (:class:`UserError`) print one
line on stderr and exit 2, without a traceback; so do usage errors and an operating-system error
on a path the user gave (a name too long, not a folder, no space left).

Units at the edges, the same in every command:

* A wind is ``FROM_DEG/SPEED_KT`` everywhere it is taken (``run``, ``fly``, ``compare``), parsed by
  :func:`fms_testbed.cli.common.parse_wind`; a suffix selects another unit (``270/10mps``,
  ``270/36kmh``). Every other option names its unit in its help (``--rnp`` NM, ``--manual-nm``
  NM; the coupled-law commands' ``--speed``/``--dv`` km/h and ``--alt``/``--dh`` m, as the paper).
* Files are SI, with the unit in every column or key name (``alt_m``, ``tas_mps``, ``settle_s``).
* Printed figures state their unit. Flight commands (``run``, ``demo``, ``fly``, ``procedures``)
  print aviation units — NM, ft, kt — with path errors (FTE/TSE/NSE) in m; the engineering
  commands (``inner``, ``compare``, ``analyse``, ``tune``, ``ins``) print SI — m, s, deg, g — with
  speeds in km/h as the coupled-law paper does. Plots follow the same split
  (:mod:`fms_testbed.viz.run` states the rule).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import signal
import os
import sys
import threading

from fms_testbed import __version__
from fms_testbed.core.errors import UserError

#: Modules that contribute sub-commands; a new command group is added here and nowhere else.
COMMAND_MODULES = (
    "fms_testbed.cli.run",          # run, demo
    "fms_testbed.cli.inner",        # inner
    "fms_testbed.cli.procedures",   # procedures build / check / list
    "fms_testbed.cli.fly",          # fly
    "fms_testbed.cli.coupled",      # tune, compare, analyse
    "fms_testbed.cli.ins",         # ins
    "fms_testbed.cli.imu_test",     # imu-test
    "fms_testbed.cli.regress",      # regress run / diff / report
    "fms_testbed.cli.montecarlo",   # montecarlo
    "fms_testbed.cli.nav_replay",   # nav-replay
)


class _Parser(argparse.ArgumentParser):
    """A parser whose usage errors are one line on stderr (exit 2), naming ``--help``."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every available command group."""
    parser = _Parser(
        prog="fms-testbed",
        description="Flight-management-system testbed on JSBSim.")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    parser.add_argument("--version", action="version", version=f"fms-testbed {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # group not built yet
                continue
            raise
        mod.register(sub)
    return parser


_terminated: list[int] = []
"""The SIGTERM received, if any (its number)."""


def _exit_on_sigterm(signum, frame) -> None:  # pragma: no cover - exercised in a subprocess
    """SIGTERM ends the process through ``sys.exit`` so atexit handlers run (the JSBSim sandbox
    folder in the temporary folder is removed). Raised while a numba kernel is loaded, compiled
    or called, the exit surfaces as another exception (a SystemError from the dispatcher); the
    record lets :func:`main` end with the signal's exit code all the same."""
    _terminated.append(signum)
    raise SystemExit(128 + signum)


_interrupted = threading.Event()


def _on_sigint(signum, frame) -> None:  # pragma: no cover - exercised in a subprocess
    """SIGINT: remember it, then raise KeyboardInterrupt. Raised while a numba kernel is being
    compiled or called, the interrupt surfaces as another exception (a SystemError from the
    dispatcher); the flag lets :func:`main` report it as the interrupt it is."""
    _interrupted.set()
    raise KeyboardInterrupt


def _quiet_signal_unraisable(unraisable) -> None:  # pragma: no cover - in a subprocess
    """``sys.unraisablehook``: the exit or interrupt our signal handlers raise inside a callback
    that cannot propagate it (llvmlite's object-cache notification while numba compiles) is
    not reported as an ignored exception with its traceback — :func:`main` ends with the
    signal's exit code from its record; every other unraisable exception is reported as usual."""
    if issubclass(unraisable.exc_type, (SystemExit, KeyboardInterrupt)) and (
            _terminated or _interrupted.is_set()):
        return
    sys.__unraisablehook__(unraisable)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return the process exit code."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _exit_on_sigterm)
        signal.signal(signal.SIGINT, _on_sigint)
        sys.unraisablehook = _quiet_signal_unraisable
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.INFO,
        format="%(levelname)s %(name)s: %(message)s")
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except UserError as exc:    # one line, whatever the message (a parser's may span several)
        text = " ".join(part.strip() for part in str(exc).splitlines() if part.strip())
        print(f"fms-testbed: error: {text}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fms-testbed: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head`: stop quietly (Python docs, signal)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:   # a path the system refuses (name too long, not a folder, no space)
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"fms-testbed: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception:
        if _terminated:                # SIGTERM, surfacing through compiled code
            print("fms-testbed: terminated", file=sys.stderr)
            return 128 + _terminated[0]
        if _interrupted.is_set():      # the interrupt, surfacing through compiled code
            print("fms-testbed: interrupted", file=sys.stderr)
            return 130
        raise


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
