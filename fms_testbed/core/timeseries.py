"""The timeseries contract: one row per logged step, columns with units in their names.

:data:`COLUMNS` is the authoritative list (name, description); the README reproduces it.
Further columns may follow these: the navigation model's error components (``nse_*``, ``bias_*``)
and the procedure guidance's (``xtk_m``, ``leg_index`` ...).
"""

from __future__ import annotations



#: (column, description with unit) — in this order in ``timeseries.parquet``.
COLUMNS: tuple[tuple[str, str], ...] = (
    ("t_s", "simulation time, s"),
    ("lat_deg", "true geodetic latitude (WGS-84), deg"),
    ("lon_deg", "true longitude, deg"),
    ("alt_m", "true altitude above mean sea level, m"),
    ("tas_mps", "true airspeed, m/s"),
    ("cas_mps", "calibrated airspeed, m/s"),
    ("gs_mps", "ground speed, m/s"),
    ("vs_mps", "vertical speed, up positive, m/s"),
    ("ve_mps", "ground velocity east, m/s"),
    ("vn_mps", "ground velocity north, m/s"),
    ("vu_mps", "ground velocity up, m/s"),
    ("heading_deg", "true heading, deg [0, 360)"),
    ("track_deg", "true ground track, deg [0, 360)"),
    ("pitch_deg", "pitch angle, deg"),
    ("roll_deg", "roll (bank) angle, right wing down positive, deg"),
    ("alpha_deg", "angle of attack, deg"),
    ("beta_deg", "sideslip angle, deg"),
    ("gamma_deg", "air-relative flight-path angle, deg"),
    ("p_dps", "body roll rate, deg/s"),
    ("q_dps", "body pitch rate, deg/s"),
    ("r_dps", "body yaw rate, deg/s"),
    ("fx_mps2", "specific force, body x (forward), m/s^2"),
    ("fy_mps2", "specific force, body y (right), m/s^2"),
    ("fz_mps2", "specific force, body z (down), m/s^2"),
    ("nx", "tangential (wind-axis) load factor, g"),
    ("ny", "normal (lift-axis) load factor, g"),
    ("mach", "Mach number"),
    ("throttle", "throttle command after limits, 0..1"),
    ("elevator", "elevator command, normalised -1..1 (positive trailing edge down)"),
    ("aileron", "aileron command, normalised -1..1 (positive rolls right)"),
    ("rudder", "rudder command, normalised -1..1 (positive yaws left)"),
    ("cmd_bank_deg", "bank-angle command to the bank-hold loop, deg"),
    ("cmd_heading_deg", "heading-hold target, deg (NaN when not in heading hold)"),
    ("cmd_nx", "tangential load-factor command, g (NaN in direct-throttle mode)"),
    ("cmd_ny", "normal load-factor command (lift axis), g"),
    ("cmd_throttle", "direct throttle command, 0..1 (NaN when the n_x loop is engaged)"),
    ("cmd_alt_m", "altitude target of the vertical law, m (NaN when not engaged)"),
    ("cmd_tas_mps", "true-airspeed target of the vertical law, m/s (NaN when not engaged)"),
    ("nav_lat_deg", "navigation-solution latitude, deg"),
    ("nav_lon_deg", "navigation-solution longitude, deg"),
    ("nav_alt_m", "navigation-solution altitude, m"),
    ("nav_heading_deg", "navigation-solution true heading, deg"),
    ("nav_roll_deg", "navigation-solution roll, deg"),
    ("nav_pitch_deg", "navigation-solution pitch, deg"),
)

#: What the runner logs per row besides the raw JSBSim read, in this order (None = inactive).
LOG_FIELDS = ("cmd_bank_rad", "cmd_heading_rad", "cmd_nx", "cmd_ny", "cmd_throttle", "cmd_alt_m",
              "cmd_tas_mps", "nav_lat_rad", "nav_lon_rad", "nav_alt_m", "nav_heading_rad",
              "nav_roll_rad", "nav_pitch_rad")


def column_doc_markdown() -> str:
    """The column table as Markdown (for the README)."""
    lines = ["| column | meaning, unit |", "|---|---|"]
    lines += [f"| `{c}` | {d} |" for c, d in COLUMNS]
    return "\n".join(lines)


__all__ = ["COLUMNS", "LOG_FIELDS", "column_doc_markdown"]
