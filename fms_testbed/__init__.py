"""fms-testbed: a flight-management-system testbed on JSBSim.

Data contract
=============

Units and frames
----------------
* SI inside the package: metres, seconds, radians for computation, m/s, kg. Public names carry
  their unit as a suffix: ``alt_m``, ``tas_mps``, ``bank_deg``, ``rate_dps``, ``bias_dph``.
* Angles at the API are degrees where the name says ``_deg`` and radians where it says ``_rad``.
* Aviation units (ft, kt, NM, FL) appear only at the edges: ARINC-424 records, scenario files where
  the key says so (``alt_ft``, ``cas_kt``), the CLI, and plot labels.
* Geodetic coordinates are WGS-84 latitude/longitude in degrees and altitude above mean sea level
  in metres. The navigation frame is local ENU (east, north, up); body axes are forward,
  right, down (JSBSim's).
* Load factors are in g and dimensionless: ``nx`` (tangential, along the air-relative velocity,
  ``(T - D)/(m g)`` plus the weight component cancelled, i.e. what an accelerometer along the
  velocity reads divided by g) and ``ny`` (normal, the lift-axis load factor: 1 in level flight).

Timeseries (``timeseries.parquet``), one row per logged step, index-free columns
--------------------------------------------------------------------------------
See :data:`fms_testbed.timeseries.COLUMNS` for the authoritative list with units; the README
reproduces it.
"""

__version__ = "0.1.0"
