"""The flight log: which outer steps are logged (the cadence, in one place), what the loop keeps
of each, and the timeseries built from it once, vectorised, at the end.

Per logged step the loop keeps what it already has as tuples of numbers, converted once at the
end: the raw JSBSim read (:meth:`~fms_testbed.sim.jsbsim_core.JSBSimAircraft.read_raw`, JSBSim
units), the commands and the navigation solution (:data:`~fms_testbed.core.timeseries.LOG_FIELDS`),
the navigation source's error record (the dict it returned, not copied) and the guidance's log
record (a tuple, turned into its columns by the guidance after the flight). Tuples of numbers
and dicts of numbers are not tracked by the garbage collector, so a long log adds nothing to
its walks (a list or an object per row would: a full collection walks every one of them). The
columns, with their units:

* :data:`~fms_testbed.core.timeseries.COLUMNS` (the contract), then :data:`EXTRA_COLUMNS`;
* the navigation source's error components (``nse_*``, ``bias_*`` …; their names carry units);
* the guidance's :attr:`~fms_testbed.core.contracts.Guidance.log_columns`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fms_testbed.core.timeseries import COLUMNS, LOG_FIELDS
from fms_testbed.core.units import DEG_RAD
from fms_testbed.sim.jsbsim_core import RAW, raw_to_si

EXTRA_COLUMNS: tuple[tuple[str, str], ...] = (
    ("flap_pos_norm", "flap position, normalised 0 up .. 1 fully extended"),
    ("gear_pos_norm", "gear position, normalised 0 up .. 1 down"),
    ("agl_m", "height above the terrain (the procedure's runway or airport), m"),
)
"""Columns after :data:`~fms_testbed.core.timeseries.COLUMNS` (configuration and height above
the terrain, for the approach evaluation)."""

_NAN = math.nan


def log_every(log_rate_hz: float, dt_outer_s: float) -> int:
    """Outer steps between two logged rows: ``round(1 / (log_rate_hz · dt_outer_s))``, at least
    1 (log rate Hz, outer-loop period s)."""
    return max(1, int(round(1.0 / (log_rate_hz * dt_outer_s))))


class FlightLog:
    """The log of one flight (module docstring).

    Parameters
    ----------
    every : log every this many outer steps (:func:`log_every`)
    guidance : the flight's guidance (its log records and columns), or None
    """

    def __init__(self, every: int, guidance=None):
        self.every = int(every)
        self.guidance = guidance
        self.raw: list[tuple] = []
        self.cmds: list[tuple] = []
        self.errors: list[dict] = []
        self.records: list = []

    def due(self, k: int) -> bool:
        """True when outer step ``k`` (0 at the flight's start) is logged."""
        return k % self.every == 0

    def add(self, raw: list[float], fields: tuple, nav, record=None) -> None:
        """Log one step: the raw read, the :data:`~fms_testbed.core.timeseries.LOG_FIELDS`
        (commands and navigation solution; NaN where inactive), the navigation solution's error
        record and the guidance's record (a tuple of numbers; None: no guidance this step).
        The flight loop appends the same four itself."""
        self.raw.append(tuple(raw))
        self.cmds.append(fields)
        self.errors.append(nav.errors)
        self.records.append(record)

    def __len__(self) -> int:
        return len(self.raw)

    def columns(self) -> tuple[tuple[str, str], ...]:
        """``(column, description with unit)`` of the fixed columns and the guidance's (the
        navigation errors follow the fixed ones, named by the source)."""
        g = self.guidance.log_columns if self.guidance is not None else ()
        return COLUMNS + EXTRA_COLUMNS + g

    def frame(self) -> pd.DataFrame:
        """The timeseries (module docstring), one row per logged step."""
        names = [c for c, _ in COLUMNS]
        if not self.raw:
            return pd.DataFrame({c: pd.Series(dtype=float) for c in names})
        raw = np.array(self.raw, dtype=float)
        r = raw_to_si(raw)
        lg = np.array(self.cmds, dtype=float)
        cols = _base_columns(r, {f: lg[:, j] for j, f in enumerate(LOG_FIELDS)})
        df = pd.DataFrame({**{c: cols[c] for c in names},
                           **{c: r[c] for c, _ in EXTRA_COLUMNS}})
        extra = self._extra_columns(raw)
        return pd.concat([df, pd.DataFrame(extra)], axis=1) if extra else df

    def _extra_columns(self, raw: np.ndarray) -> dict[str, list]:
        """The navigation-error and guidance columns (NaN where a row has none)."""
        out: dict[str, list] = {}
        errors = self.errors
        if any(errors):
            for k in dict.fromkeys(k for e in errors for k in e):
                out[k] = [e.get(k, _NAN) for e in errors]
        if self.guidance is not None and any(rec is not None for rec in self.records):
            lat = raw[:, RAW["lat_deg"]] * DEG_RAD
            lon = raw[:, RAW["lon_deg"]] * DEG_RAD
            out.update(self.guidance.log_frame(self.records, lat, lon))
        return out


def _base_columns(r: dict, lg: dict) -> dict[str, np.ndarray]:
    """The :data:`COLUMNS` from the raw reads in SI (``r``, :func:`raw_to_si`) and the logged
    fields ``lg`` (:data:`LOG_FIELDS`)."""
    deg = np.degrees
    m = r["mass_kg"]
    return {
        "t_s": r["t_s"], "lat_deg": r["lat_deg"], "lon_deg": r["lon_deg"], "alt_m": r["alt_m"],
        "tas_mps": r["tas_mps"], "cas_mps": r["cas_mps"], "gs_mps": r["gs_mps"],
        "vs_mps": r["vs_mps"], "ve_mps": r["ve"], "vn_mps": r["vn"], "vu_mps": -r["vd"],
        "heading_deg": deg(r["heading_rad"]) % 360.0, "track_deg": deg(r["track_rad"]) % 360.0,
        "pitch_deg": deg(r["pitch_rad"]), "roll_deg": deg(r["roll_rad"]),
        "alpha_deg": deg(r["alpha_rad"]), "beta_deg": deg(r["beta_rad"]),
        "gamma_deg": deg(r["gamma_rad"]), "p_dps": deg(r["p_rps"]), "q_dps": deg(r["q_rps"]),
        "r_dps": deg(r["r_rps"]), "fx_mps2": r["fx"] / m, "fy_mps2": r["fy"] / m,
        "fz_mps2": r["fz"] / m, "nx": r["nx"], "ny": r["ny"], "mach": r["mach"],
        "throttle": r["throttle"], "elevator": r["elevator"], "aileron": r["aileron"],
        "rudder": r["rudder"],
        "cmd_bank_deg": deg(lg["cmd_bank_rad"]),
        "cmd_heading_deg": deg(lg["cmd_heading_rad"]) % 360.0,
        "cmd_nx": lg["cmd_nx"], "cmd_ny": lg["cmd_ny"], "cmd_throttle": lg["cmd_throttle"],
        "cmd_alt_m": lg["cmd_alt_m"], "cmd_tas_mps": lg["cmd_tas_mps"],
        "nav_lat_deg": deg(lg["nav_lat_rad"]), "nav_lon_deg": deg(lg["nav_lon_rad"]),
        "nav_alt_m": lg["nav_alt_m"], "nav_heading_deg": deg(lg["nav_heading_rad"]) % 360.0,
        "nav_roll_deg": deg(lg["nav_roll_rad"]), "nav_pitch_deg": deg(lg["nav_pitch_rad"]),
    }


__all__ = ["EXTRA_COLUMNS", "FlightLog", "log_every"]
