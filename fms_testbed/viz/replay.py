"""Plots of a navigation replay against its truth (``fms-testbed nav-replay --truth``).

Plotting never computes: it draws the error table of
:func:`fms_testbed.navigation.replay.error_table` and the solution's σ columns
(:data:`fms_testbed.navigation.replay.SIGMA_COLS`) and returns matplotlib Figures.

Units: engineering plots, SI — position errors m, velocity errors m/s, attitude errors deg,
time s since the start.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from fms_testbed.viz.figure import subplots

_ROWS = (("err_north_m", "nav_north_sigma_m", "north error, m"),
         ("err_east_m", "nav_east_sigma_m", "east error, m"),
         ("err_alt_m", "nav_alt_sigma_m", "height error, m"),
         ("err_vn_mps", "nav_vn_sigma_mps", "north velocity error, m/s"),
         ("err_roll_deg", "nav_roll_sigma_deg", "roll error, deg"),
         ("err_heading_deg", "nav_heading_sigma_deg", "heading error, deg"))


def plot_errors(err, sigma, title: str = "") -> Figure:
    """Solution - truth with the filter's ±3σ, one panel per quantity.

    Parameters
    ----------
    err : the error table (``t_s`` and ``err_*`` columns)
    sigma : the solution's σ at the same times (``nav_*_sigma_*`` columns, same rows as err)
    title : figure headline
    """
    fig, axes = subplots(len(_ROWS), 1, figsize=(9, 11), sharex=True)
    t = err["t_s"].to_numpy() - float(err["t_s"].iloc[0])
    for ax, (e, s, label) in zip(axes, _ROWS):
        ax.plot(t, err[e].to_numpy(), "b-", lw=0.8, label="solution - truth")
        sd = sigma[s].to_numpy()
        ax.plot(t, 3 * sd, "k--", lw=1.0, label="±3σ of the filter")
        ax.plot(t, -3 * sd, "k--", lw=1.0)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time since start, s")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_track(sol, truth=None, title: str = "") -> Figure:
    """The solution's track (and the truth's), longitude/latitude in degrees.

    Parameters
    ----------
    sol : the solution table (``nav_lat_deg``, ``nav_lon_deg``)
    truth : (m, ≥3) truth rows (t_s, lat_deg, lon_deg, ...) or None
    title : figure headline
    """
    fig, ax = subplots(1, 1, figsize=(7, 6))
    if truth is not None:
        ax.plot(truth[:, 2], truth[:, 1], "k-", lw=2.0, alpha=0.4, label="truth")
    ax.plot(sol["nav_lon_deg"], sol["nav_lat_deg"], "b-", lw=0.8, label="replayed solution")
    ax.set_xlabel("longitude, deg")
    ax.set_ylabel("latitude, deg")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


__all__ = ["plot_errors", "plot_track"]
