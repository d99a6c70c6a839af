"""Plots of a flown run (plotting only; nothing here computes results).

* ``ground_track.png``: east/north distance from the start (km), true and navigation tracks, with
  time marks and the start/end labelled.
* ``time_histories.png``: altitude, speeds, attitude, load factors and controls against time,
  with the active commands dashed.
"""

from __future__ import annotations


from fms_testbed.viz.figure import subplots
import numpy as np
import pandas as pd

R_EARTH_M = 6371008.8


def local_en_km(lat_deg, lon_deg, lat0_deg: float, lon0_deg: float):
    """Equirectangular east/north offsets in km from a reference point (for plotting only)."""
    e = np.radians(np.asarray(lon_deg) - lon0_deg) * np.cos(np.radians(lat0_deg)) * R_EARTH_M
    n = np.radians(np.asarray(lat_deg) - lat0_deg) * R_EARTH_M
    return e / 1000.0, n / 1000.0


def _title(summary: dict) -> str:
    s = f"{summary.get('scenario') or 'run'} — {summary.get('aircraft')}"
    if summary.get("status") != "ok":
        s += f" — {summary.get('status').upper()}: {summary.get('reason')}"
    return s


def plot_ground_track(df: pd.DataFrame, summary: dict):
    """Ground track in local east/north km; navigation track dashed when it differs."""
    lat0, lon0 = df["lat_deg"].iloc[0], df["lon_deg"].iloc[0]
    e, n = local_en_km(df["lat_deg"], df["lon_deg"], lat0, lon0)
    fig, ax = subplots(figsize=(7, 6.5))
    ax.plot(e, n, lw=1.8, label="true track")
    en, nn = local_en_km(df["nav_lat_deg"], df["nav_lon_deg"], lat0, lon0)
    if np.nanmax(np.hypot(en - e, nn - n)) > 1e-3:
        ax.plot(en, nn, "--", lw=1.2, label="navigation solution")
    step = max(1, len(df) // 8)
    for i in range(0, len(df), step):
        ax.plot(e[i], n[i], "k.", ms=4)
        ax.annotate(f"{df['t_s'].iloc[i]:.0f} s", (e[i], n[i]), textcoords="offset points",
                    xytext=(4, 4), fontsize=7)
    ax.plot(e[0], n[0], "go", label="start")
    ax.plot(e[-1], n[-1], "rs", label="end")
    ax.set_xlabel("east of start, km")
    ax.set_ylabel("north of start, km")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(_title(summary) + f"\nstart {lat0:.4f}°, {lon0:.4f}°", fontsize=10)
    fig.tight_layout()
    return fig


def plot_time_histories(df: pd.DataFrame, summary: dict):
    """Stacked time histories with commands dashed."""
    t = df["t_s"]
    fig, axs = subplots(5, 1, figsize=(9, 12), sharex=True)
    ax = axs[0]
    ax.plot(t, df["alt_m"], label="altitude")
    if df["cmd_alt_m"].notna().any():
        ax.plot(t, df["cmd_alt_m"], "--", label="altitude target")
    ax.set_ylabel("altitude, m")
    ax.legend(fontsize=8, loc="best")
    ax = axs[1]
    ax.plot(t, df["tas_mps"] * 3.6, label="TAS")
    ax.plot(t, df["cas_mps"] * 3.6, label="CAS", alpha=0.7)
    if df["cmd_tas_mps"].notna().any():
        ax.plot(t, df["cmd_tas_mps"] * 3.6, "--", label="TAS target")
    ax2 = ax.twinx()
    ax2.plot(t, df["vs_mps"], color="tab:gray", lw=0.8, label="vertical speed")
    ax2.set_ylabel("vertical speed, m/s", color="tab:gray")
    ax.set_ylabel("speed, km/h")
    # one legend for both axes, on the twin axis so the vertical-speed curve cannot cross it
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax2.legend(h1 + h2, l1 + l2, fontsize=8, loc="best", framealpha=0.9)
    ax = axs[2]
    ax.plot(t, df["roll_deg"], label="roll")
    ax.plot(t, df["cmd_bank_deg"], "--", label="bank command")
    ax.plot(t, df["pitch_deg"], label="pitch")
    ax.plot(t, df["alpha_deg"], label="alpha", alpha=0.7)
    ax.set_ylabel("angle, deg")
    ax.legend(fontsize=8, loc="best", ncol=2)
    ax = axs[3]
    ax.plot(t, df["ny"], label="n_y (normal)")
    ax.plot(t, df["cmd_ny"], "--", label="n_y command")
    ax.plot(t, df["nx"], label="n_x (tangential)")
    if df["cmd_nx"].notna().any():
        ax.plot(t, df["cmd_nx"], "--", label="n_x command")
    ax.set_ylabel("load factor, g")
    ax.legend(fontsize=8, loc="best", ncol=2)
    ax = axs[4]
    for c, lab in (("throttle", "throttle"), ("elevator", "elevator"), ("aileron", "aileron"),
                   ("rudder", "rudder")):
        ax.plot(t, df[c], label=lab)
    ax.set_ylabel("control, normalised")
    ax.set_xlabel("time, s")
    ax.legend(fontsize=8, loc="best", ncol=4)
    for a in axs:
        a.grid(True, alpha=0.3)
    axs[0].set_title(_title(summary), fontsize=10)
    fig.tight_layout()
    return fig


def plot_run(df: pd.DataFrame, summary: dict) -> dict:
    """The standard figures of a run, by file stem: ``ground_track``, ``time_histories``."""
    if df.empty:
        return {}
    return {"ground_track": plot_ground_track(df, summary),
            "time_histories": plot_time_histories(df, summary)}
