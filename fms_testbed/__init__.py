"""fms-testbed: a flight-management-system testbed on JSBSim.

The package is layered along the data path (each layer imports only the layers below it; an
import-linter contract in ``pyproject.toml`` holds it)::

    cli → campaign → run → viz → evaluation → loop → navigation → sensors → sim → control
        → guidance → path → legs → procedures → config → data → core

Units and frames
----------------
* SI inside the package: metres, seconds, radians for computation, m/s, kg. Public names carry
  their unit as a suffix: ``alt_m``, ``tas_mps``, ``bank_deg``, ``rate_dps``, ``bias_dph``
  (:mod:`fms_testbed.core.units` holds every conversion factor).
* Aviation units (ft, kt, NM, FL) appear only at the edges: ARINC-424 records, scenario files where
  the key says so (``alt_ft``, ``cas_kt``), the CLI, and plot labels.
* Geodetic coordinates are WGS-84 latitude/longitude in degrees and altitude above mean sea level
  in metres. The navigation frame is local ENU (east, north, up); body axes are forward,
  right, down (JSBSim's).
* Load factors are in g: ``nx`` (tangential, along the air-relative velocity, 0 in steady level
  flight) and ``ny`` (normal, the lift-axis load factor: 1 in level flight).

The timeseries columns are :data:`fms_testbed.core.timeseries.COLUMNS`.

``fms_testbed.run_scenario`` is :func:`fms_testbed.run.api.run_scenario` (imported on first use,
so ``import fms_testbed.core.units`` stays light).
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("fms-testbed")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"


def __getattr__(name: str):
    if name in ("run_scenario", "Results"):
        import fms_testbed.run as _run

        return getattr(_run, name)
    raise AttributeError(f"module 'fms_testbed' has no attribute {name!r}")


__all__ = ["__version__", "run_scenario", "Results"]
