"""The documentation: the README's shape, the mkdocs site (built with ``--strict`` into a
temporary folder), its generated reference pages, and the provenance of every measured table."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"
README = REPO / "README.md"
QUICK_START = ['pip install -e . && fms-testbed demo', 'pip install -e ".[test]" && pytest']
#: dated or host-dependent prose that goes stale (the documentation states what is, not when)
DATED = re.compile(r"\b(today|yesterday|this week|until this build|since this build|"
                   r"this build|host (was )?busy|busy host|the last run|recently)\b", re.I)


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks_reference",
                                                  DOCS / "hooks" / "reference.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _layers() -> list[str]:
    conf = tomllib.loads((REPO / "pyproject.toml").read_text())
    contract = next(c for c in conf["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    return [name.rsplit(".", 1)[-1] for name in contract["layers"]]


# ---------------------------------------------------------------- README

def test_readme_is_short():
    n = len(README.read_text().splitlines())
    assert n <= 250, f"README.md has {n} lines (at most 250; the rest belongs in docs/)"


def test_readme_quick_start_is_the_two_commands_in_one_block():
    text = README.read_text()
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```[a-z]*\n(.*?)```", section, re.S)
    assert len(blocks) == 1, "Quick start must have exactly one code block"
    assert blocks[0].strip().splitlines() == QUICK_START


def test_readme_lists_every_layer():
    text = README.read_text()
    missing = [layer for layer in _layers() if f"`{layer}/`" not in text]
    assert not missing, f"README layout does not list the layers {missing}"


def test_readme_links_resolve():
    text = README.read_text()
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" in target:
            continue
        assert (REPO / target).exists(), f"README links to {target}, which does not exist"


def test_no_dated_prose():
    pages = [README, *DOCS.glob("*.md")]
    hits = [f"{p.relative_to(REPO)}: {m.group(0)!r}" for p in pages
            for m in DATED.finditer(p.read_text())]
    assert not hits, "dated prose: " + "; ".join(hits)


# ---------------------------------------------------------------- measured tables

def test_every_results_table_names_a_bench_script_that_exists():
    tables = sorted((DOCS / "results").glob("*.md"))
    assert tables, "no docs/results/*.md"
    for t in tables:
        m = re.search(r"Command: `python (bench/[\w.]+\.py)", t.read_text())
        assert m, f"{t.name} does not say which bench command wrote it"
        script = REPO / m.group(1)
        assert script.exists(), f"{t.name} was written by {m.group(1)}, which does not exist"
        assert f'"{t.name}"' in script.read_text(), f"{m.group(1)} does not write {t.name}"
        assert "Machine: " in t.read_text(), f"{t.name} does not describe the machine"


def test_every_results_table_is_included_by_a_page():
    pages = "\n".join(p.read_text() for p in DOCS.rglob("*.md") if "results" not in p.parts)
    orphans = [t.name for t in (DOCS / "results").glob("*.md")
               if f'--8<-- "results/{t.name}"' not in pages]
    assert not orphans, f"results tables no page includes: {orphans}"


# ---------------------------------------------------------------- generated pages

def test_cli_reference_has_every_command():
    from fms_testbed.cli import build_parser

    hooks = _hooks()
    text = hooks.cli_markdown()
    commands = []

    def walk(path, parser):
        for name, sub, _ in hooks._subcommands(parser):
            commands.append(f"{path} {name}")
            walk(f"{path} {name}", sub)

    walk("fms-testbed", build_parser())
    assert len(commands) >= 8
    missing = [c for c in commands if f"## `{c}`" not in text]
    assert not missing, f"CLI reference misses {missing}"
    assert "--out" in text and "usage: fms-testbed run" in text


def test_scenario_reference_has_every_schema_field():
    from fms_testbed.config.aircraft import AircraftConfig
    from fms_testbed.config.procedure import ProcedureSpec
    from fms_testbed.config.scenario import Scenario

    text = _hooks().scenario_markdown()
    for model in (Scenario, ProcedureSpec, AircraftConfig):
        missing = [k for k in model.model_fields if k != "source_file" and f"| `{k}` |" not in text]
        assert not missing, f"{model.__name__} fields missing from the reference: {missing}"


def test_generated_tables_expand_and_unknown_names_fail():
    hooks = _hooks()
    out = hooks.expand("a\n<!-- generated: timeseries_columns -->\nb")
    assert "| `t_s` |" in out and "generated:" not in out
    with pytest.raises(KeyError):
        hooks.expand("<!-- generated: no_such_table -->")


def test_rst_roles_and_literal_blocks_become_markdown():
    sys.path.insert(0, str(DOCS / "hooks"))
    from griffe_rst import rst_to_markdown

    md = rst_to_markdown("See :class:`~fms_testbed.run.results.Results` and ``x_m``.\n\n"
                         "Example::\n\n    a: 1\n    b: 2\n\nafter")
    assert 'identifier="fms_testbed.run.results.Results"' in md and "<code>Results</code>" in md
    assert "`x_m`" in md and "``x_m``" not in md
    assert "```text\na: 1\nb: 2\n```" in md and md.rstrip().endswith("after")


def test_rst_simple_table_to_markdown():
    table = _hooks().rst_simple_table(
        "=====  ===========\nname   meaning\n=====  ===========\n``a``  first line\n"
        "       continued\n``b``  second\n=====  ===========\n")
    assert table.splitlines() == ["| name | meaning |", "|---|---|",
                                  "| `a` | first line continued |", "| `b` | second |"]


# ---------------------------------------------------------------- the site

def test_mkdocs_build_strict(tmp_path):
    pytest.importorskip("mkdocs", reason="mkdocs not installed (pip install -e '.[docs]')")
    pytest.importorskip("material", reason="mkdocs-material not installed (pip install -e '.[docs]')")
    pytest.importorskip("mkdocstrings_handlers.python",
                        reason="mkdocstrings[python] not installed (pip install -e '.[docs]')")
    site = tmp_path / "site"
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict",
                           "-f", str(REPO / "mkdocs.yml"), "-d", str(site)],
                          capture_output=True, text=True, cwd=tmp_path,
                          env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stderr[-4000:]}"
    for page in ("index.html", "reference/cli/index.html", "reference/scenario/index.html",
                 "api/run/index.html", "results/index.html"):
        assert (site / page).exists(), f"{page} missing from the site"
    api = (site / "api" / "run" / "index.html").read_text()
    assert 'id="fms_testbed.run.api.run_scenario"' in api, "the API reference lost run_scenario"
    html = "\n".join(p.read_text() for p in site.rglob("*.html"))
    assert "generated: " not in html and "--8&lt;--" not in html, "an unexpanded marker"
