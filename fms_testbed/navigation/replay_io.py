"""Recorded IMU/GNSS files for the replay (``fms-testbed nav-replay``): the data contract,
readers that name the file, column and row of a bad value, and the writer a flight uses to
record its own sensors (``navigation.record_sensors: true``).

Frames and units: body axes x forward, y right, z down; navigation frame NED; latitude and
longitude in degrees, heights in metres above the WGS-84 ellipsoid, rates in rad/s, specific
force in m/s², increments in rad and m/s, times in s (one clock for every file).

IMU (CSV or Parquet), one of two forms:

- rates: ``t_s, gyro_x_rps, gyro_y_rps, gyro_z_rps, accel_x_mps2, accel_y_mps2, accel_z_mps2``,
  the instantaneous values at ``t_s``; the increment over (t_{k-1}, t_k] is the trapezoid
  (ω_{k-1} + ω_k) Δt / 2 (a rate linear in time, as pyins assumes);
- increments: ``t_s, dtheta_{x,y,z}_rad, dv_{x,y,z}_mps``, row k the integral over
  (t_{k-1}, t_k] (the first row only gives the start time).

GNSS: ``t_s, lat_deg, lon_deg, alt_m`` (time of validity), optionally ``vn_mps, ve_mps, vd_mps``
(NED), ``pos_sigma_m`` (horizontal 1σ), ``alt_sigma_m``, ``vel_sigma_mps`` (horizontal),
``vd_sigma_mps``; a missing σ takes the replay's declared GNSS white σ.

Init (JSON): ``t_s, lat_deg, lon_deg, alt_m, vn_mps, ve_mps, vd_mps, roll_deg, pitch_deg,
heading_deg``, ``sigma: {pos_m, vel_mps, level_deg, heading_deg}``, ``imu`` (a preset name);
optionally ``gnss`` (the scenario's ``navigation.gnss`` keys: the receiver's declared error
model and antenna lever arm) and ``alignment_s`` (the INS was aligned at rest for this long:
P0 is then the stationary-alignment map of the IMU's errors instead of the ``sigma`` block).

Truth (optional): ``t_s, lat_deg, lon_deg, alt_m, vn_mps, ve_mps, vd_mps, roll_deg, pitch_deg,
heading_deg``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from fms_testbed.core.errors import UserError

RATE_COLS = ("gyro_x_rps", "gyro_y_rps", "gyro_z_rps", "accel_x_mps2", "accel_y_mps2",
             "accel_z_mps2")
INC_COLS = ("dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps")
GNSS_COLS = ("t_s", "lat_deg", "lon_deg", "alt_m")
GNSS_OPTIONAL = ("vn_mps", "ve_mps", "vd_mps", "pos_sigma_m", "alt_sigma_m", "vel_sigma_mps",
                 "vd_sigma_mps")
PVA_COLS = ("t_s", "lat_deg", "lon_deg", "alt_m", "vn_mps", "ve_mps", "vd_mps", "roll_deg",
            "pitch_deg", "heading_deg")
SIGMA_KEYS = ("pos_m", "vel_mps", "level_deg", "heading_deg")


class ReplayInputError(UserError):
    """A bad replay input file (the message names the file, column and row)."""


def read_table(path: str | Path) -> pd.DataFrame:
    """A CSV (``.csv``) or Parquet (``.parquet``, ``.pq``) file as a DataFrame.

    Parameters
    ----------
    path : the file

    Raises
    ------
    ReplayInputError : missing, unreadable, or of another type
    """
    p = Path(path)
    if not p.is_file():
        raise ReplayInputError(f"{p}: no such file")
    try:
        if p.suffix.lower() in (".parquet", ".pq"):
            return pd.read_parquet(p)
        if p.suffix.lower() == ".csv":
            return pd.read_csv(p)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise ReplayInputError(f"{p}: cannot read: {str(exc).splitlines()[0]}") from None
    raise ReplayInputError(f"{p}: expected a .csv or .parquet file")


def _columns(df: pd.DataFrame, path, cols, optional=()) -> np.ndarray:
    """The columns ``cols`` (then those of ``optional`` present; NaN where absent) as floats
    (n, len(cols) + len(optional)), every required value finite, ``t_s`` increasing."""
    for c in cols:
        if c not in df.columns:
            raise ReplayInputError(f"{path}: column '{c}' missing (expected {', '.join(cols)})")
    if len(df) < 2:
        raise ReplayInputError(f"{path}: fewer than 2 rows")
    out = np.full((len(df), len(cols) + len(optional)), np.nan)
    for j, c in enumerate(list(cols) + list(optional)):
        if c not in df.columns:
            continue
        v = pd.to_numeric(df[c], errors="coerce").to_numpy(float)
        bad = ~np.isfinite(v)
        if j < len(cols) and bad.any():
            r = int(np.argmax(bad))
            raise ReplayInputError(f"{path}: column '{c}', row {r + 1}: not a finite number "
                                   f"({df[c].iloc[r]!r})")
        out[:, j] = v
    dt = np.diff(out[:, 0])
    if not (dt > 0).all():
        r = int(np.argmax(~(dt > 0))) + 1
        raise ReplayInputError(f"{path}: column 't_s', row {r + 1}: time does not increase "
                               f"({out[r - 1, 0]:g} -> {out[r, 0]:g} s)")
    return out


def read_imu(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(t (n,) s, increments (n-1, 6): Δθ rad, Δv m/s over (t_{k-1}, t_k]) of an IMU file in
    either form (module docstring).

    Parameters
    ----------
    path : the IMU file

    Raises
    ------
    ReplayInputError : neither form's columns, a bad value, time not increasing
    """
    df = read_table(path)
    if all(c in df.columns for c in INC_COLS):
        a = _columns(df, path, ("t_s",) + INC_COLS)
        return a[:, 0], a[1:, 1:].copy()
    if not any(c in df.columns for c in INC_COLS + RATE_COLS):
        raise ReplayInputError(f"{path}: neither the rate columns ({', '.join(RATE_COLS)}) nor "
                               f"the increment columns ({', '.join(INC_COLS)})")
    a = _columns(df, path, ("t_s",) + RATE_COLS)
    dt = np.diff(a[:, 0])[:, None]
    return a[:, 0], 0.5 * (a[:-1, 1:] + a[1:, 1:]) * dt


def read_gnss(path: str | Path) -> np.ndarray:
    """(n, 11) GNSS rows: t_s, lat_deg, lon_deg, alt_m, then :data:`GNSS_OPTIONAL` (NaN where
    the file has no such column or value).

    Parameters
    ----------
    path : the GNSS file

    Raises
    ------
    ReplayInputError : a required column missing, a bad value, time not increasing
    """
    a = _columns(read_table(path), path, GNSS_COLS, GNSS_OPTIONAL)
    if (np.abs(a[:, 1]) > 90).any():
        r = int(np.argmax(np.abs(a[:, 1]) > 90))
        raise ReplayInputError(f"{path}: column 'lat_deg', row {r + 1}: outside ±90 deg")
    return a


def read_truth(path: str | Path) -> np.ndarray:
    """(n, 10) truth rows in :data:`PVA_COLS` order.

    Parameters
    ----------
    path : the truth file

    Raises
    ------
    ReplayInputError : a column missing, a bad value, time not increasing
    """
    return _columns(read_table(path), path, PVA_COLS)


def read_init(path: str | Path) -> dict:
    """The init JSON (module docstring), checked: every :data:`PVA_COLS` key a finite number,
    ``sigma`` with :data:`SIGMA_KEYS` >= 0, ``imu`` a string (may be given on the command line
    instead), ``alignment_s`` > 0 when present.

    Parameters
    ----------
    path : the JSON file

    Raises
    ------
    ReplayInputError : unreadable JSON or a bad field (named)
    """
    p = Path(path)
    try:
        d = json.loads(p.read_text())
    except OSError as exc:
        raise ReplayInputError(f"{p}: cannot read: {exc.strerror}") from None
    except json.JSONDecodeError as exc:
        raise ReplayInputError(f"{p}: line {exc.lineno}: not JSON ({exc.msg})") from None
    if not isinstance(d, dict):
        raise ReplayInputError(f"{p}: expected a JSON object")
    for k in PVA_COLS:
        v = d.get(k)
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ReplayInputError(f"{p}: field '{k}': expected a finite number, got {v!r}")
    sig = d.get("sigma")
    if not isinstance(sig, dict):
        raise ReplayInputError(f"{p}: field 'sigma': expected {{{', '.join(SIGMA_KEYS)}}}")
    for k in SIGMA_KEYS:
        v = sig.get(k)
        if not isinstance(v, (int, float)) or not v >= 0 or not math.isfinite(v):
            raise ReplayInputError(f"{p}: field 'sigma.{k}': expected a number >= 0, got {v!r}")
    if "imu" in d and not isinstance(d["imu"], (str, dict)):
        raise ReplayInputError(f"{p}: field 'imu': expected a preset name (or an IMU mapping)")
    a = d.get("alignment_s")
    if a is not None and not (isinstance(a, (int, float)) and a > 0):
        raise ReplayInputError(f"{p}: field 'alignment_s': expected a number > 0 s")
    if "gnss" in d and not isinstance(d["gnss"], dict):
        raise ReplayInputError(f"{p}: field 'gnss': expected a mapping")
    return d


def write_table(df: pd.DataFrame, path: Path) -> None:
    """Write ``df`` as CSV or Parquet by the suffix of ``path``.

    Parameters
    ----------
    df : the table;  path : ``.csv`` or ``.parquet``
    """
    if path.suffix == ".csv":
        df.to_csv(path, index=False, float_format="%.17g")
    else:
        df.to_parquet(path, index=False)


__all__ = ["GNSS_COLS", "GNSS_OPTIONAL", "INC_COLS", "PVA_COLS", "RATE_COLS", "SIGMA_KEYS",
           "ReplayInputError", "read_gnss", "read_imu", "read_init", "read_table", "read_truth",
           "write_table"]
