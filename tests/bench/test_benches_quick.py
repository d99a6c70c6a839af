"""Every bench runs in its quick mode and writes pages whose figures are measured.

The default suite checks that every bench script offers ``--quick`` (through
``report.add_quick``); ``pytest -m slow`` runs each one (``python bench/X.py --quick``) with
``$FMS_BENCH_RESULTS``/``$FMS_BENCH_FIGURES`` pointed at a temporary folder — the published
pages in ``docs/results/`` are never touched — and checks the exit code, that each page it wrote
names its command and machine and has no NaN figure, and that each PNG it wrote is non-empty.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))
import report  # noqa: E402

LIBRARIES = {"report.py", "interleave.py"}
"""Modules of bench/ that are imported by the benches, not run."""


def _benches() -> list[str]:
    return sorted(f.name for f in BENCH.glob("*.py")
                  if f.name not in LIBRARIES and "def main" in f.read_text())


def test_every_runnable_bench_is_listed_and_the_rest_are_helpers():
    """A file of bench/ without a ``main`` is a helper module some bench imports."""
    for f in BENCH.glob("*.py"):
        if f.name in LIBRARIES or f.name in _benches():
            continue
        stem = f.stem
        assert any(f"import {stem}" in g.read_text() or f"from {stem} " in g.read_text()
                   for g in BENCH.glob("*.py") if g != f), f"{f.name}: neither a bench nor imported"


NOT_YET: set[str] = set()
"""Benches without ``--quick`` yet (the list only shrinks)."""


@pytest.mark.parametrize("name", _benches())
def test_every_bench_has_a_quick_mode(name):
    if name in NOT_YET:
        assert "report.add_quick(" not in (BENCH / name).read_text(), f"{name}: drop it from NOT_YET"
        pytest.xfail("no --quick yet")
    assert "report.add_quick(" in (BENCH / name).read_text(), \
        f"bench/{name}: no --quick (call report.add_quick on its parser)"


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(_benches()) - NOT_YET))
def test_every_bench_runs_in_quick_mode(name, tmp_path):
    res, fig = tmp_path / "results", tmp_path / "figures"
    env = {**os.environ, "FMS_BENCH_RESULTS": str(res), "FMS_BENCH_FIGURES": str(fig),
           "MPLBACKEND": "Agg"}
    docs = report.REPO / "docs"
    before = {p: p.stat().st_mtime_ns for p in docs.rglob("*") if p.is_file()}
    proc = subprocess.run([sys.executable, str(BENCH / name), "--quick"], env=env,
                          cwd=tmp_path, capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-3000:]
    for page in res.rglob("*.md"):
        text = page.read_text()
        assert "Command: `python" in text and "Machine:" in text, page
        assert not report._nan_cells(text), (page, report._nan_cells(text)[:2])
    for png in fig.rglob("*.png"):
        assert png.stat().st_size > 1000, png
    after = {p: p.stat().st_mtime_ns for p in docs.rglob("*") if p.is_file()}
    assert after == before, "a quick run wrote into docs/: " + ", ".join(
        str(p) for p in after if before.get(p) != after[p])
