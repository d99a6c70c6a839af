"""The example notebooks run: each is executed with nbclient in the test's temporary folder, and
its own assertion cells (and the checks here) must pass. Committed notebooks carry no outputs."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="nbformat not installed (pip install -e '.[test]')")
nbclient = pytest.importorskip("nbclient", reason="nbclient not installed (pip install -e '.[test]')")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NOTEBOOKS = sorted(EXAMPLES.glob("*.ipynb"))
BUDGET_S = 60.0


def _text_outputs(nb) -> str:
    out = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o.get("output_type") == "stream":
                out.append(o["text"])
            elif "data" in o:
                out.append(o["data"].get("text/plain", ""))
    return "\n".join(out)


def test_there_is_an_example_notebook():
    assert NOTEBOOKS, f"no notebook in {EXAMPLES}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_is_committed_without_outputs(path):
    nb = nbformat.read(path, as_version=4)
    dirty = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"
             and (c.get("outputs") or c.get("execution_count") is not None)]
    assert not dirty, f"{path.name}: cells {dirty} carry outputs; clear them before committing"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path, tmp_path):
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=int(BUDGET_S), kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    t0 = time.perf_counter()
    client.execute()            # raises CellExecutionError, with the cell, if any cell fails
    wall = time.perf_counter() - t0
    assert wall <= BUDGET_S, f"{path.name} took {wall:.0f} s (budget {BUDGET_S:.0f} s)"
    text = _text_outputs(nb)
    if path.name == "fly-a-procedure.ipynb":
        assert "checks passed" in text
        assert "ok (guidance complete)" in text
        figures = [o for c in nb.cells for o in c.get("outputs", [])
                   if "image/png" in o.get("data", {})]
        assert len(figures) >= 2, "the figures were not displayed"
    written = sorted(p.name for p in tmp_path.iterdir())
    assert not written, f"{path.name} wrote {written} into its working folder"
