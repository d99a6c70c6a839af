"""Benches check themselves: the one guard (``bench/report.py``) refuses a degenerate run, every
bench writes its page through it, and the procedure benches run in a quick mode (two airports
of the FAA cycle) and write a page whose figures are measured."""

import math
import re
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench"
sys.path.insert(0, str(BENCH))
import report  # noqa: E402


@pytest.mark.parametrize("outcomes, headline", [({}, None), ({"impossible": 51706}, None),
                                                ({"impossible": 3, "error": 2}, None),
                                                ({"ok": 3}, math.nan), ({"ok": 1}, math.inf)])
def test_the_guard_refuses_a_degenerate_run(outcomes, headline):
    with pytest.raises(report.DegenerateRun):
        report.refuse_degenerate(outcomes, headline=headline, what="bench")


def test_the_guard_passes_a_real_run():
    report.refuse_degenerate({"ok": 10, "impossible": 3}, headline=4.6)


def test_write_refuses_a_table_with_a_nan_figure(tmp_path):
    body = report.table(["stage", "time, s"], [["build", "nan"], ["total", "4.6"]])
    with pytest.raises(report.DegenerateRun):
        report.write(tmp_path / "x.md", body)
    assert not (tmp_path / "x.md").exists()
    ok = report.table(["stage", "time, s"], [["build (nano seconds)", "1.2"]])
    assert report.write(tmp_path / "y.md", ok).exists()


DIRECT = re.compile(r"(?<!report\.)RESULTS\s*/|docs/results/[\w.]+\"\)\.write"
                    r"|\"docs\"\s*/\s*\"(results|figures)\"")
"""A path into docs/results/ or docs/figures/ made by a bench itself, not through
``report.RESULTS``/``report.FIGURES`` (which ``$FMS_BENCH_RESULTS``/``$FMS_BENCH_FIGURES``
redirect)."""


def test_the_direct_path_pattern_catches_what_it_must():
    for bad in ('RESULTS / "x.md"', 'ROOT / "docs" / "results" / name', 'REPO / "docs" / '
                '"figures" / "tuning"', 'Path("docs/results/x.md").write'):
        assert DIRECT.search(bad), bad
    for ok in ('report.write("x.md", body)', 'report.FIGURES / "tuning"',
               'report.RESULTS / "x.md"'):
        assert not DIRECT.search(ok), ok


NOT_YET: dict[str, str] = {}
"""Benches known to make a docs/ path by themselves; each must still do so (the list only
shrinks)."""


def test_every_bench_writes_its_page_through_the_guard():
    """No bench writes a file of docs/results/ (or a figure of docs/figures/) by a path of its
    own: each page goes through ``report.write`` (where the NaN guard is), each figure into
    ``report.FIGURES``, so a quick run's output can be sent elsewhere — but those of
    :data:`NOT_YET`."""
    direct = [f.name for f in sorted(BENCH.glob("*.py"))
              if f.name != "report.py" and DIRECT.search(f.read_text())]
    assert direct == sorted(NOT_YET), direct


AIRPORTS = ["KDLS", "KAUS"]


def _cifp():
    if not report.CIFP.exists():
        pytest.skip(f"the FAA CIFP is not at {report.CIFP}")
    return str(report.CIFP)


@pytest.mark.parametrize("name", ["bench_check", "bench_procedures", "bench_coding"])
def test_procedure_benches_run_in_quick_mode(tmp_path, name, monkeypatch):
    monkeypatch.setenv("FMS_TESTBED_CACHE", str(tmp_path / "cache"))
    mod = __import__(name)
    md = tmp_path / f"{name}.md"
    argv = ["--db", _cifp(), "--airports", *AIRPORTS, "--md", str(md)]
    if name != "bench_check":
        argv += ["--workers", "2"]
    mod.main(argv)
    text = md.read_text()
    assert "Command: `python" in text and "|---|" in text
    assert not re.search(r"\|\s*nan\s*\|", text, re.I)
