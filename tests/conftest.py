"""Shared fixtures: every test runs in its own temporary working directory (JSBSim sandbox
pattern), so a stray file written by the code under test would show up there; ``cifp`` is the
FAA CIFP beside the repository, loaded once per session (tests that need it are skipped, with
the reason, when it is not there)."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

CIFP = Path(__file__).resolve().parents[2] / "shared" / "data" / "cifp" / "FAACIFP18_230126"
"""The FAA CIFP cycle 2301 (``../shared/data/cifp`` beside the repository)."""


@pytest.fixture(scope="session")
def cifp():
    """The CIFP as a :class:`~fms_testbed.procedures.database.Database` (skip when absent)."""
    from fms_testbed.procedures.database import load_database

    if not CIFP.exists():
        pytest.skip(f"the FAA CIFP is not at {CIFP}")
    return load_database(CIFP)


@pytest.fixture(autouse=True)
def _sandbox_cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    logging.getLogger("jsbsim").setLevel(logging.ERROR)
    yield tmp_path
