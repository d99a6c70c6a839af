"""The flight log: the raw JSBSim reads and commands the loop keeps per logged step, turned into
the timeseries (:data:`fms_testbed.core.timeseries.COLUMNS`) once, vectorised, at the end."""

from __future__ import annotations

import numpy as np
import pandas as pd

from fms_testbed.core.timeseries import COLUMNS, LOG_FIELDS
from fms_testbed.sim.jsbsim_core import raw_to_si


def build_frame(raw_log, log_rows: list[tuple]) -> pd.DataFrame:
    """The timeseries in :data:`COLUMNS` order from the rows the runner logged.

    The flight loop only keeps what it already has: the :meth:`JSBSimAircraft.read_raw` values
    (JSBSim units, appended row after row to a flat float buffer ``raw_log``, or a list of rows)
    and a tuple of :data:`LOG_FIELDS` per row; the unit conversions run here, vectorised, once per
    run (:func:`~fms_testbed.sim.jsbsim_core.raw_to_si`, the twin of the state the laws see).
    """
    names = [c for c, _ in COLUMNS]
    if not len(raw_log):
        return pd.DataFrame({c: pd.Series(dtype=float) for c in names})
    r = raw_to_si(np.asarray(raw_log, dtype=float))
    lg = pd.DataFrame.from_records(log_rows, columns=LOG_FIELDS).astype(float)
    deg = np.degrees
    m = r["mass_kg"]
    cols = {
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
        "cmd_bank_deg": deg(lg["cmd_bank_rad"].to_numpy()),
        "cmd_heading_deg": deg(lg["cmd_heading_rad"].to_numpy()) % 360.0,
        "cmd_nx": lg["cmd_nx"].to_numpy(), "cmd_ny": lg["cmd_ny"].to_numpy(),
        "cmd_throttle": lg["cmd_throttle"].to_numpy(), "cmd_alt_m": lg["cmd_alt_m"].to_numpy(),
        "cmd_tas_mps": lg["cmd_tas_mps"].to_numpy(),
        "nav_lat_deg": deg(lg["nav_lat_rad"].to_numpy()),
        "nav_lon_deg": deg(lg["nav_lon_rad"].to_numpy()), "nav_alt_m": lg["nav_alt_m"].to_numpy(),
        "nav_heading_deg": deg(lg["nav_heading_rad"].to_numpy()) % 360.0,
        "nav_roll_deg": deg(lg["nav_roll_rad"].to_numpy()),
        "nav_pitch_deg": deg(lg["nav_pitch_rad"].to_numpy()),
    }
    out = {c: cols[c] for c in names}
    # after the COLUMNS contract: configuration and height above the terrain (runway), for
    # the approach evaluation (normalised 0 up .. 1 fully down/extended; m)
    out["flap_pos_norm"], out["gear_pos_norm"] = r["flap_pos_norm"], r["gear_pos_norm"]
    out["agl_m"] = r["agl_m"]
    return pd.DataFrame(out)
