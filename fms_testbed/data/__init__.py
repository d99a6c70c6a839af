"""The package's own data: aircraft files, IMU presets, scenarios and the embedded procedures.

Everything the testbed needs to fly ships inside the package (``fms_testbed/data/``) and is found
with :mod:`importlib.resources`, so a wheel installed anywhere (a Dask worker, a fresh venv) finds
it. ``FMS_TESTBED_HOME`` names another folder with the same sub-folders (``aircraft/``, ``imu/``,
``scenarios/``, ``procedures/``) to use instead.
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path


def data_root() -> Path:
    """Return the folder that holds ``aircraft/``, ``imu/``, ``scenarios/`` and ``procedures/``."""
    env = os.environ.get("FMS_TESTBED_HOME")
    if env:
        return Path(env).resolve()
    return Path(str(files(__name__)))


def aircraft_dir() -> Path:
    """Folder of the aircraft configuration files (``aircraft/NAME.yaml``)."""
    return data_root() / "aircraft"


def imu_dir() -> Path:
    """Folder of the IMU preset files (``imu/NAME.yaml``)."""
    return data_root() / "imu"


def scenarios_dir() -> Path:
    """Folder of the shipped scenario files."""
    return data_root() / "scenarios"


def procedures_dir() -> Path:
    """Folder of the embedded ARINC-424 excerpt."""
    return data_root() / "procedures"


def results_dir() -> Path:
    """Default output folder for runs (``results/``), relative to the current directory."""
    return Path.cwd() / "results"
