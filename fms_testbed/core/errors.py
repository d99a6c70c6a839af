"""User-facing errors: the CLI prints them on one line and exits non-zero, without a traceback."""

from __future__ import annotations


class UserError(Exception):
    """An error caused by user input (a file, a field, an argument) rather than a bug.

    The message must name the file and field/line and say why.
    """


class ConfigError(UserError):
    """A configuration or scenario file failed validation."""


class TrimError(UserError):
    """JSBSim could not trim the aircraft at the requested condition."""
