"""Where the shipped assets live (aircraft configs, scenarios, procedure excerpt).

The assets sit at the repository root (``aircraft/``, ``scenarios/``, ``procedures/``); the
package is installed in editable/development mode from a clone, so they are found relative to
this file. ``FMS_TESTBED_HOME`` overrides the root for installed copies.
"""

from __future__ import annotations

import os
from pathlib import Path


def project_root() -> Path:
    """Return the folder that holds ``aircraft/``, ``scenarios/`` and ``procedures/``."""
    env = os.environ.get("FMS_TESTBED_HOME")
    if env:
        return Path(env).resolve()
    return Path(__file__).resolve().parent.parent


def aircraft_dir() -> Path:
    """Folder of the aircraft configuration files (``aircraft/NAME.yaml``)."""
    return project_root() / "aircraft"


def scenarios_dir() -> Path:
    """Folder of the shipped scenario files."""
    return project_root() / "scenarios"


def procedures_dir() -> Path:
    """Folder of the embedded ARINC-424 excerpt."""
    return project_root() / "procedures"


def results_dir() -> Path:
    """Default output folder for runs (``results/``), relative to the current directory."""
    return Path.cwd() / "results"
