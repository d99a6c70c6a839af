"""The package's layers: the import-linter contract in pyproject.toml holds, and importing every
module leaves matplotlib's backend as it was (a library never switches a notebook's backend)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_layers_contract_is_kept():
    r = subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports_command; "
                        "lint_imports_command()"], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    assert "0 broken" in r.stdout


def test_importing_every_module_keeps_the_matplotlib_backend():
    code = (
        "import matplotlib, importlib, pkgutil\n"
        "matplotlib.use('svg')\n"
        "import fms_testbed\n"
        "names = [m.name for m in pkgutil.walk_packages(fms_testbed.__path__, 'fms_testbed.')\n"
        "         if not m.name.endswith('__main__')]\n"
        "for n in names: importlib.import_module(n)\n"
        "assert matplotlib.get_backend() == 'svg', matplotlib.get_backend()\n"
        "print(len(names))\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert int(r.stdout.strip()) > 60
    # python-control imports pyplot itself; our own modules never choose a backend
    offenders = [p for p in (ROOT / "fms_testbed").rglob("*.py")
                 if "matplotlib.use(" in p.read_text() or "import matplotlib.pyplot" in p.read_text()]
    assert not offenders, offenders


def test_no_import_cycle_between_subpackages():
    import grimp

    graph = grimp.build_graph("fms_testbed")
    subs = sorted({m.split(".")[1] for m in graph.modules if m.count(".") >= 1})
    cycles = []
    for a in subs:
        for b in subs:
            if a < b and graph.chain_exists(f"fms_testbed.{a}", f"fms_testbed.{b}", as_packages=True) \
                    and graph.chain_exists(f"fms_testbed.{b}", f"fms_testbed.{a}", as_packages=True):
                cycles.append((a, b))
    assert not cycles, cycles
