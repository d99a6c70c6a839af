"""Shared campaign fixtures: a private database-index cache for the session, and one small run
(KENV from the embedded excerpt, calm and a 30 kt west wind: 20 cases, about 5 s on two workers)
that the diff, report and determinism tests read."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from campaign_helpers import SMALL, regress


@pytest.fixture(scope="session", autouse=True)
def _index_cache(tmp_path_factory):
    folder = tmp_path_factory.mktemp("index-cache")
    old = os.environ.get("FMS_TESTBED_CACHE")
    os.environ["FMS_TESTBED_CACHE"] = str(folder)
    yield folder
    if old is None:
        os.environ.pop("FMS_TESTBED_CACHE", None)
    else:
        os.environ["FMS_TESTBED_CACHE"] = old


@pytest.fixture(scope="session")
def small_run(tmp_path_factory) -> Path:
    """The small case set flown on two local workers."""
    out = tmp_path_factory.mktemp("runs") / "small-2w"
    assert regress("run", *SMALL, "--workers", "2", "--no-progress", "--out", str(out)) == 0
    return out
