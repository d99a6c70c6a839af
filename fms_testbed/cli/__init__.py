"""Command-line entry point ``fms-testbed``.

Each command group lives in its own module exposing ``register(subparsers)``; the handler it sets
with ``set_defaults(func=...)`` returns an exit code. User errors (:class:`UserError`) print one
line on stderr and exit 2, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys

from fms_testbed.core.errors import UserError

#: Modules that contribute sub-commands; a new command group is added here and nowhere else.
COMMAND_MODULES = (
    "fms_testbed.cli.run",          # run, demo
    "fms_testbed.cli.procedures",   # procedures build / check
    "fms_testbed.cli.fly",          # fly
    "fms_testbed.cli.coupled",      # tune, compare, analyse
    "fms_testbed.cli.ins",         # ins
)


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every available command group."""
    parser = argparse.ArgumentParser(
        prog="fms-testbed",
        description="Flight-management-system testbed on JSBSim.")
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
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


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return the process exit code."""
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
    except UserError as exc:
        print(f"fms-testbed: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fms-testbed: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
