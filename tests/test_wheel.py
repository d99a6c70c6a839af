"""The package installed from a wheel carries its data: the demo flies from an unrelated folder
with nothing of the clone on the path (what a Dask worker or a fresh venv sees)."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
def test_wheel_flies_the_demo_outside_the_clone(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                        str(tmp_path / "whl"), str(ROOT)], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    wheel = next((tmp_path / "whl").glob("fms_testbed-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    for data in ("fms_testbed/data/aircraft/737.yaml", "fms_testbed/data/imu/STIM300.yaml",
                 "fms_testbed/data/scenarios/demo-sid.yaml",
                 "fms_testbed/data/procedures/cifp_excerpt.dat"):
        assert data in names
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site)}
    env.pop("FMS_TESTBED_HOME", None)
    code = ("import fms_testbed, sys; assert fms_testbed.__file__.startswith(sys.argv[1]), "
            "fms_testbed.__file__; from fms_testbed.cli import main; "
            "sys.exit(main(['demo', '--out', 'demo']))")
    r = subprocess.run([sys.executable, "-c", code, str(site)], cwd=elsewhere, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert (elsewhere / "demo" / "summary.json").is_file()
