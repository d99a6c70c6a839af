"""True trajectories the error model runs along: from a run's timeseries or synthetic.

A :class:`Trajectory` holds, per sample, what F needs: geodetic position, ENU velocity, Euler
angles, body rates and body specific force (SI). ``from_run_dir`` reads ``timeseries.parquet``
(columns t_s, lat_deg, lon_deg, alt_m, ve_mps, vn_mps, vu_mps, roll_deg, pitch_deg, heading_deg,
p_dps, q_dps, r_dps, fx_mps2, fy_mps2, fz_mps2); the synthetic helpers build a stationary aircraft
and a straight, level, unaccelerated flight along a great circle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fms_testbed.core.earth import earth_rate_enu, radii_m, transport_rate_enu
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import DEG_RAD
from fms_testbed.sensors.sins.model import gravity_up

REQUIRED_COLUMNS = ("t_s", "lat_deg", "lon_deg", "alt_m", "ve_mps", "vn_mps", "vu_mps",
                    "roll_deg", "pitch_deg", "heading_deg", "p_dps", "q_dps", "r_dps",
                    "fx_mps2", "fy_mps2", "fz_mps2")


@dataclass(frozen=True)
class Trajectory:
    """True motion sampled at times ``t_s`` (s), arrays of length n (or (n, 3)).

    lat_rad, lon_rad: geodetic, rad;  alt_m: m;  v_enu_mps: (n, 3) m/s;
    rpy_rad: (n, 3) roll, pitch, heading (body→NED), rad;
    w_eb_b_rps: (n, 3) body rate relative to the Earth (JSBSim p, q, r), rad/s;
    f_b_mps2: (n, 3) specific force in body FRD, m/s².
    """

    t_s: np.ndarray
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    alt_m: np.ndarray
    v_enu_mps: np.ndarray
    rpy_rad: np.ndarray
    w_eb_b_rps: np.ndarray
    f_b_mps2: np.ndarray
    label: str = ""

    def __len__(self) -> int:
        return len(self.t_s)

    def resample(self, dt_s: float) -> "Trajectory":
        """Linear interpolation onto a uniform grid of step ``dt_s`` (heading unwrapped)."""
        t = np.arange(self.t_s[0], self.t_s[-1] + 1e-9, dt_s)

        def lin(a):
            a = np.asarray(a)
            if a.ndim == 1:
                return np.interp(t, self.t_s, a)
            return np.column_stack([np.interp(t, self.t_s, a[:, i]) for i in range(a.shape[1])])

        rpy = self.rpy_rad.copy()
        rpy[:, 2] = np.unwrap(rpy[:, 2])
        return Trajectory(t, lin(self.lat_rad), lin(self.lon_rad), lin(self.alt_m),
                          lin(self.v_enu_mps), lin(rpy), lin(self.w_eb_b_rps), lin(self.f_b_mps2),
                          self.label)


def from_dataframe(df, where: str = "timeseries") -> Trajectory:
    """Trajectory from a timeseries DataFrame (see :data:`REQUIRED_COLUMNS`, units in names).

    Raises
    ------
    UserError : missing columns (named), fewer than 2 rows, or non-increasing time.
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in df.columns]
    if missing:
        raise UserError(f"{where}: missing column(s) {', '.join(missing)} needed by the SINS model")
    if len(df) < 2:
        raise UserError(f"{where}: needs at least 2 rows, has {len(df)}")
    for c in REQUIRED_COLUMNS:
        bad_rows = np.flatnonzero(~np.isfinite(df[c].to_numpy(float)))
        if bad_rows.size:
            raise UserError(f"{where}: row {bad_rows[0]}: column {c} is not a finite number "
                            f"({bad_rows.size} such rows)")
    t = df["t_s"].to_numpy(float)
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        raise UserError(f"{where}: row {bad[0] + 1}: t_s not increasing ({t[bad[0]]} -> "
                        f"{t[bad[0] + 1]})")
    d = DEG_RAD
    col = lambda *names: np.column_stack([df[n].to_numpy(float) for n in names])  # noqa: E731
    return Trajectory(
        t, df["lat_deg"].to_numpy(float) * d, df["lon_deg"].to_numpy(float) * d,
        df["alt_m"].to_numpy(float), col("ve_mps", "vn_mps", "vu_mps"),
        col("roll_deg", "pitch_deg", "heading_deg") * d, col("p_dps", "q_dps", "r_dps") * d,
        col("fx_mps2", "fy_mps2", "fz_mps2"), label=where)


def from_run_dir(run_dir: str | Path) -> Trajectory:
    """Trajectory from ``RUN_DIR/timeseries.parquet`` (a run's output folder)."""
    import pandas as pd

    path = Path(run_dir) / "timeseries.parquet"
    if not path.is_file():
        raise UserError(f"{run_dir}: no timeseries.parquet (not a run directory)")
    import pyarrow as pa

    try:
        df = pd.read_parquet(path)
    except (OSError, ValueError, pa.ArrowException) as exc:  # what a damaged file raises
        raise UserError(f"{path}: cannot read parquet: {exc}") from None
    return from_dataframe(df, where=str(path))


def _level_specific_force(lat_rad, alt_m, v_enu, heading_rad):
    """Specific force (body FRD) keeping a level, constant-velocity flight: f = -g + Coriolis."""
    w_ie = earth_rate_enu(lat_rad)
    w_en = transport_rate_enu(lat_rad, alt_m, v_enu)
    g = np.array([0.0, 0.0, gravity_up(lat_rad, alt_m)[0]])
    f_n = np.cross(2 * w_ie + w_en, v_enu) - g
    ch, sh = math.cos(heading_rad), math.sin(heading_rad)
    c_nb = np.array([[sh, ch, 0.0], [ch, -sh, 0.0], [0.0, 0.0, -1.0]])  # ENU → FRD, level
    return c_nb @ f_n, c_nb


def straight_level(duration_s: float, dt_s: float = 0.1, lat_deg: float = 45.0,
                   lon_deg: float = 0.0, alt_m: float = 3000.0, speed_mps: float = 0.0,
                   heading_deg: float = 0.0) -> Trajectory:
    """Wings-level flight at constant ground speed and heading (speed 0: stationary aircraft).

    Position is propagated with the ENU kinematics; attitude is level with the given heading
    (kept constant, a rhumb-line approximation fine for the error model), the body rate keeps
    the body level (−transport rate), and the specific force balances gravity and Coriolis.
    """
    n = int(round(duration_s / dt_s)) + 1
    t = np.arange(n) * dt_s
    hdg = math.radians(heading_deg)
    v = np.array([speed_mps * math.sin(hdg), speed_mps * math.cos(hdg), 0.0])
    lat = np.empty(n)
    lon = np.empty(n)
    lat[0], lon[0] = math.radians(lat_deg), math.radians(lon_deg)
    for k in range(1, n):
        rm, rn = radii_m(lat[k - 1])
        lat[k] = lat[k - 1] + v[1] / (rm + alt_m) * dt_s
        lon[k] = lon[k - 1] + v[0] / ((rn + alt_m) * math.cos(lat[k - 1])) * dt_s
    f_b = np.empty((n, 3))
    w_eb = np.empty((n, 3))
    for k in range(n):
        f_b[k], c_nb = _level_specific_force(lat[k], alt_m, v, hdg)
        w_eb[k] = c_nb @ transport_rate_enu(lat[k], alt_m, v)
    label = "stationary" if speed_mps == 0 else f"straight-level {speed_mps:g} m/s hdg {heading_deg:g}"
    return Trajectory(t, lat, lon, np.full(n, float(alt_m)), np.tile(v, (n, 1)),
                      np.tile([0.0, 0.0, hdg], (n, 1)), w_eb, f_b, label=label)
