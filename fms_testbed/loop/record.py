"""What a flight loop reports about itself: the :class:`FlightRecord` (the loop's part of the run
record, ``summary.json``), its trim and its metrics. Frozen dataclasses, units in every name;
:class:`~fms_testbed.core.contracts.RecordView` gives the JSON form as a read-only mapping.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pydantic import ConfigDict

from fms_testbed.core.contracts import OMIT_NONE, RecordView
from fms_testbed.loop.takeoff import TakeoffRecord


@dataclass(frozen=True)
class TrimRecord:
    """The start condition: trimmed altitude (m), TAS (m/s), α and pitch (deg), throttle (0..1)
    and elevator (normalised); a takeoff's is the aircraft at rest on the runway."""

    __pydantic_config__ = ConfigDict(extra="forbid")

    alt_m: float
    tas_mps: float
    alpha_deg: float
    pitch_deg: float
    throttle: float
    elevator: float


def _opt():
    return field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class Metrics:
    """Extremes of the flight (the timeseries' true values; all None for an empty flight):
    altitude (m), TAS (m/s), |roll| and α (deg), n_y (g), throttle (0..1), the distance flown
    over the ground (m), and the final altitude and TAS errors against the vertical law's
    commands (m, m/s; None when it was never engaged)."""

    __pydantic_config__ = ConfigDict(extra="forbid")

    alt_min_m: float | None = _opt()
    alt_max_m: float | None = _opt()
    tas_min_mps: float | None = _opt()
    tas_max_mps: float | None = _opt()
    roll_max_abs_deg: float | None = _opt()
    alpha_max_deg: float | None = _opt()
    ny_min: float | None = _opt()
    ny_max: float | None = _opt()
    throttle_min: float | None = _opt()
    throttle_max: float | None = _opt()
    distance_flown_m: float | None = _opt()
    alt_err_final_m: float | None = _opt()
    tas_err_final_mps: float | None = _opt()

    @classmethod
    def of(cls, df: pd.DataFrame) -> "Metrics":
        """The metrics of a flight's timeseries (rounded to 4 decimals)."""
        if df.empty:
            return cls()
        out = {
            "alt_min_m": df["alt_m"].min(), "alt_max_m": df["alt_m"].max(),
            "tas_min_mps": df["tas_mps"].min(), "tas_max_mps": df["tas_mps"].max(),
            "roll_max_abs_deg": df["roll_deg"].abs().max(),
            "alpha_max_deg": df["alpha_deg"].max(),
            "ny_min": df["ny"].min(), "ny_max": df["ny"].max(),
            "throttle_min": df["throttle"].min(), "throttle_max": df["throttle"].max(),
            "distance_flown_m": float(np.sum(df["gs_mps"].to_numpy()[1:] * np.diff(df["t_s"]))),
        }
        e = df["alt_m"] - df["cmd_alt_m"]
        if e.notna().any():
            out["alt_err_final_m"] = float(e.dropna().iloc[-1])
        e = df["tas_mps"] - df["cmd_tas_mps"]
        if e.notna().any():
            out["tas_err_final_mps"] = float(e.dropna().iloc[-1])
        return cls(**{k: round(float(v), 4) for k, v in out.items()})


@dataclass(frozen=True)
class FlightRecord(RecordView):
    """The flight loop's report of one flight.

    Attributes
    ----------
    scenario, aircraft : names; aircraft_file : the aircraft file flown (None: built in Python)
    jsbsim_model : the JSBSim model
    status, reason : how the loop ended (:attr:`~fms_testbed.core.contracts.Ending.status`:
        ``ok``, ``diverged``, ``incomplete``, ``timeout``) and why; the flight's outcome adds the
        checks (:func:`fms_testbed.evaluation.outcome.decide`)
    seed, navigation_seed : the seeds actually used
    duration_s : simulated time flown, s; wall_time_s : wall time since the flight was built, s
    real_time_factor : simulated over wall time (None before any wall time)
    loop_wall_time_s : wall time in the flight loop alone, s; loop_steps_per_s : JSBSim frames
        per wall second in the loop (None before any)
    trim : the start condition; metrics : the flight's extremes
    takeoff : the takeoff of a SID started on the runway (None: an airborne start)
    """

    __pydantic_config__ = ConfigDict(extra="forbid")

    scenario: str | None
    aircraft: str
    aircraft_file: str | None
    jsbsim_model: str
    status: str
    reason: str
    seed: int
    navigation_seed: int
    duration_s: float
    wall_time_s: float
    real_time_factor: float | None
    loop_wall_time_s: float
    loop_steps_per_s: int | None
    trim: TrimRecord
    metrics: Metrics
    takeoff: TakeoffRecord | None = field(default=None, metadata=OMIT_NONE)


__all__ = ["FlightRecord", "Metrics", "TrimRecord"]
