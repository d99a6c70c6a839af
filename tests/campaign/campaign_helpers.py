"""Helpers of the campaign tests (imported by name: the test folders have no packages)."""

from __future__ import annotations

from fms_testbed.cli import main

SMALL = ["--airports", "KENV", "--wind", "calm", "270/30"]
"""The small case set of the embedded excerpt: 10 flyable sequences × 2 condition sets (20 cases,
class 1 and class 2 failures among them)."""


def regress(*argv: str) -> int:
    """``fms-testbed regress ARGV...`` in this process; its exit code."""
    return main(["regress", *argv])
