"""A flight's own sensors in the replay format (``navigation.record_sensors: true``): unit 0's
IMU increments, the GNSS fixes as delivered, the initial state with its σ, and the truth
(:mod:`.replay_io` for the columns; heights above the WGS-84 ellipsoid, as the replay reads
them).

The IMU is recorded at the navigation step: row k holds the *raw* (uncompensated) increments
ΣΔθ, ΣΔv of the step (t_{k-1}, t_k] — the sums of the unit's per-frame measured increments,
(f̄_c + b̂) T and (ω̄_c + b̂_g) T with the compensation b̂ the filter had fed back. Replayed, the
coning and sculling inside a step are those of one increment per step, not of the frames.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fms_testbed.core.earth import ellipsoidal_height_m
from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation.replay_io import GNSS_COLS, GNSS_OPTIONAL, INC_COLS, PVA_COLS


def _pva(t_s, lat, lon, alt, v_enu, roll, pitch, hdg) -> list[float]:
    return [t_s, math.degrees(lat), math.degrees(lon), ellipsoidal_height_m(lat, alt),
            float(v_enu[1]), float(v_enu[0]), -float(v_enu[2]), math.degrees(roll),
            math.degrees(pitch), math.degrees(hdg)]


class SensorRecorder:
    """Collects one flight's sensors (module docstring).

    Parameters
    ----------
    imu_name : the IMU preset the flight's INS declares
    gnss_block : the flight's ``navigation.gnss`` mapping (the replay's declared receiver)
    """

    def __init__(self, imu_name: str, gnss_block: dict):
        self.imu_name, self.gnss_block = imu_name, gnss_block
        self.imu: list[list[float]] = []
        self.gnss: list[list[float]] = []
        self.truth: list[list[float]] = []
        self.init: dict | None = None

    def start(self, sol: NavSolution, P: np.ndarray, alignment_s: float | None) -> None:
        """The initial state: unit 0's indicated solution, its filter's P0 (σ of the position,
        velocity, level and heading blocks), the alignment's duration (s, or None)."""
        row = _pva(sol.t_s, sol.lat_rad, sol.lon_rad, sol.alt_m, sol.v_enu_mps, sol.roll_rad,
                   sol.pitch_rad, sol.heading_rad)
        sd = np.sqrt(np.diag(P))
        self.init = {**dict(zip(PVA_COLS, row)), "imu": self.imu_name, "gnss": self.gnss_block,
                     "sigma": {"pos_m": float(max(sd[:3])), "vel_mps": float(max(sd[3:6])),
                               "level_deg": math.degrees(max(sd[6:8])),
                               "heading_deg": math.degrees(sd[8])}}
        if alignment_s:
            self.init["alignment_s"] = float(alignment_s)
        self.imu.append([sol.t_s] + [0.0] * 6)

    def step(self, t_s: float, raw_f_w: np.ndarray, dt_s: float) -> None:
        """One navigation step ending at ``t_s`` (s): the raw mean specific force and rate
        ``raw_f_w`` (6,: m/s², rad/s) over ``dt_s`` (s)."""
        w = np.asarray(raw_f_w, float) * dt_s
        self.imu.append([t_s, *w[3:], *w[:3]])

    def fix(self, fix) -> None:
        """A delivered GNSS fix (:class:`~fms_testbed.sensors.gnss.GnssFix`)."""
        v, ps, vs = fix.v_enu_mps, fix.pos_sigma_m, fix.vel_sigma_mps
        self.gnss.append([fix.t_s, math.degrees(fix.lat_rad), math.degrees(fix.lon_rad),
                          ellipsoidal_height_m(fix.lat_rad, fix.alt_m), v[1], v[0], -v[2],
                          ps[0], ps[2], vs[0], vs[2]])

    def true_state(self, truth: AircraftState) -> None:
        """The true state of a step (the truth file)."""
        self.truth.append(_pva(truth.t_s, truth.lat_rad, truth.lon_rad, truth.alt_m,
                               truth.v_enu_mps, truth.roll_rad, truth.pitch_rad,
                               truth.heading_rad))

    def record(self, truth: AircraftState, prev: AircraftState | None, fixes, bank) -> None:
        """One navigation step: the truth, the delivered ``fixes`` and unit 0's raw step
        increments from ``bank`` (its compensated measured f̄, ω̄ plus the compensation it
        applied: ``comp`` of a strapdown bank, ``compensation`` of the linear one) since
        ``prev``."""
        self.true_state(truth)
        for fix in fixes:
            self.fix(fix)
        if prev is not None and truth.t_s > prev.t_s:
            f, w = bank.measured(0)
            comp = bank.comp[0] if hasattr(bank, "comp") else bank.compensation[0]
            self.step(truth.t_s, np.concatenate([f, w]) + comp, truth.t_s - prev.t_s)

    def tables(self) -> dict:
        """{"imu", "gnss", "truth": DataFrames in the replay's columns, "init": mapping}."""
        return {"imu": pd.DataFrame(self.imu, columns=("t_s",) + INC_COLS),
                "gnss": pd.DataFrame(self.gnss, columns=GNSS_COLS + GNSS_OPTIONAL),
                "truth": pd.DataFrame(self.truth, columns=PVA_COLS), "init": self.init}


__all__ = ["SensorRecorder"]
