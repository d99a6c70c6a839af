"""Plots of a flown run (plotting only; nothing here computes results).

* ``ground_track``: east/north distance from the start (NM), true and navigation tracks, with
  time marks and the start/end labelled.
* ``time_histories``: altitude, speeds, attitude, load factors and controls against time, with
  the active commands dashed.

Units of every flight plot in :mod:`fms_testbed.viz` (this module, :mod:`.procedure`,
:mod:`.path`): the aviation edge — horizontal distances in NM, altitudes in ft, air and ground
speeds in kt, vertical speed in ft/min; angles in deg, load factors in g, time in s. Path errors
(FTE, TSE, NSE, PDE) stay in m, as RNP monitoring reports them. Engineering plots of one
subsystem stay SI as their sources draw them (:mod:`.control`: the coupled law in m and km/h
like the paper; :mod:`.sins`: m and mrad).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.core.geodesy import LocalFrame
from fms_testbed.core.units import FPM_MPS, FT_M, KT_MPS, NM_M
from fms_testbed.viz.figure import subplots


def local_en_nm(lat_deg, lon_deg, lat0_deg: float, lon0_deg: float):
    """East/north offsets (NM) from a reference point in the azimuthal-equidistant plane
    (:class:`~fms_testbed.core.geodesy.LocalFrame`: exact range and azimuth from the origin).

    Parameters
    ----------
    lat_deg, lon_deg : points, deg (scalars or arrays)
    lat0_deg, lon0_deg : the origin, deg

    Returns
    -------
    (east_nm, north_nm) as arrays of the points' shape
    """
    fr = LocalFrame(float(lat0_deg), float(lon0_deg))
    la = np.atleast_1d(np.asarray(lat_deg, dtype=float))
    lo = np.atleast_1d(np.asarray(lon_deg, dtype=float))
    xy = np.full((la.size, 2), np.nan)
    for i, (a, b) in enumerate(zip(la.ravel(), lo.ravel())):
        if np.isfinite(a) and np.isfinite(b):
            xy[i] = fr.to_xy(a, b)
    e, n = xy[:, 0].reshape(la.shape) / NM_M, xy[:, 1].reshape(la.shape) / NM_M
    return (e, n) if np.ndim(lat_deg) else (e[0], n[0])


def _title(summary: dict) -> str:
    s = f"{summary.get('scenario') or 'run'} — {summary.get('aircraft')}"
    if summary.get("status") != "ok":
        s += f" — {summary.get('status', '').upper()}: {summary.get('reason')}"
    return s


def plot_ground_track(df: pd.DataFrame, summary: dict) -> Figure:
    """Ground track in east/north NM from the start; the navigation track dashed when it
    differs; the distance flown in the title."""
    lat0, lon0 = df["lat_deg"].iloc[0], df["lon_deg"].iloc[0]
    e, n = local_en_nm(df["lat_deg"].to_numpy(), df["lon_deg"].to_numpy(), lat0, lon0)
    fig, ax = subplots(figsize=(7, 6.5))
    ax.plot(e, n, lw=1.8, label="true track")
    en, nn = local_en_nm(df["nav_lat_deg"].to_numpy(), df["nav_lon_deg"].to_numpy(), lat0, lon0)
    if np.nanmax(np.hypot(en - e, nn - n)) * NM_M > 1.0:
        ax.plot(en, nn, "--", lw=1.2, label="navigation solution")
    step = max(1, len(df) // 8)
    for i in range(0, len(df), step):
        ax.plot(e[i], n[i], "k.", ms=4)
        ax.annotate(f"{df['t_s'].iloc[i]:.0f} s", (e[i], n[i]), textcoords="offset points",
                    xytext=(4, 4), fontsize=7)
    ax.plot(e[0], n[0], "go", label="start")
    ax.plot(e[-1], n[-1], "rs", label="end")
    ax.set_xlabel("east of start, NM")
    ax.set_ylabel("north of start, NM")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    dist = summary.get("metrics", {}).get("distance_flown_m")
    head = f"{dist / NM_M:.1f} NM flown in " if dist is not None else ""
    ax.set_title(_title(summary) + f"\n{head}{df['t_s'].iloc[-1] - df['t_s'].iloc[0]:.0f} s; "
                 f"start {lat0:.4f}°, {lon0:.4f}°", fontsize=10)
    fig.tight_layout()
    return fig


def plot_time_histories(df: pd.DataFrame, summary: dict) -> Figure:
    """Stacked time histories (altitude ft, speeds kt and ft/min, angles deg, load factors g,
    controls) with commands dashed; the final altitude and speed errors in the title."""
    t = df["t_s"]
    fig, axs = subplots(5, 1, figsize=(9, 12), sharex=True)
    ax = axs[0]
    ax.plot(t, df["alt_m"] / FT_M, label="altitude")
    if df["cmd_alt_m"].notna().any():
        ax.plot(t, df["cmd_alt_m"] / FT_M, "--", label="altitude target")
    ax.set_ylabel("altitude MSL, ft")
    ax.legend(fontsize=8, loc="best")
    ax = axs[1]
    ax.plot(t, df["tas_mps"] / KT_MPS, label="TAS")
    ax.plot(t, df["cas_mps"] / KT_MPS, label="CAS", alpha=0.7)
    if df["cmd_tas_mps"].notna().any():
        ax.plot(t, df["cmd_tas_mps"] / KT_MPS, "--", label="TAS target")
    ax2 = ax.twinx()
    ax2.plot(t, df["vs_mps"] / FPM_MPS, color="tab:gray", lw=0.8, label="vertical speed")
    ax2.set_ylabel("vertical speed, ft/min", color="tab:gray")
    ax.set_ylabel("speed, kt")
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
    m = summary.get("metrics", {})
    head = ""
    if m.get("alt_err_final_m") is not None and m.get("tas_err_final_mps") is not None:
        head = (f"\nfinal errors: altitude {m['alt_err_final_m'] / FT_M:+.1f} ft, "
                f"TAS {m['tas_err_final_mps'] / KT_MPS:+.2f} kt")
    axs[0].set_title(_title(summary) + head, fontsize=10)
    fig.tight_layout()
    return fig


def plot_run(df: pd.DataFrame, summary: dict) -> dict:
    """The standard figures of a run, by file stem: ``ground_track``, ``time_histories``."""
    if df.empty:
        return {}
    return {"ground_track": plot_ground_track(df, summary),
            "time_histories": plot_time_histories(df, summary)}


__all__ = ["local_en_nm", "plot_ground_track", "plot_run", "plot_time_histories"]
