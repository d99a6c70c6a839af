"""Shared fixtures: every test runs in its own temporary working directory (JSBSim sandbox
pattern), so a stray file written by the code under test would show up there."""

from __future__ import annotations

import logging

import pytest


@pytest.fixture(autouse=True)
def _sandbox_cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    logging.getLogger("jsbsim").setLevel(logging.ERROR)
    yield tmp_path
