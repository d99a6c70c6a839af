"""Figures of the envelope tuning: Nichols and Bode charts of the broken loops with the margin
goals, nonlinear steps with the old and the tuned gains, and the gain schedule.

Every function takes computed data (frequency responses, time series, tables) and only draws.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.viz.figure import subplots

LOOP_TITLES = {"throttle": "inner n_x loop at the throttle", "elevator": "inner n_y loop at the elevator",
               "nx_cmd": "coupled law, thrust channel (n_x cmd)",
               "dny_cmd": "coupled law, elevator channel (n_y cmd)",
               "aileron": "bank loop at the aileron", "bank_cmd": "path law at the bank command"}


def _nichols_xy(h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Open-loop phase (deg, unwrapped into (-360, 0]) and gain (dB) of a response."""
    ph = np.degrees(np.unwrap(np.angle(h)))
    ic = int(np.argmin(np.abs(np.abs(h) - 1.0)))      # phase in (-360, 0] at the crossover
    ph = ph - 360.0 * np.ceil(ph[ic] / 360.0)
    return ph, 20 * np.log10(np.maximum(np.abs(h), 1e-12))


def plot_nichols(freq: dict[str, dict[str, np.ndarray]], title: str, gm_db: float = 6.0,
                 pm_deg: float = 45.0) -> Figure:
    """Nichols chart per loop, every design point overlaid, with the exclusion box of the
    margin goals around (-180°, 0 dB).

    Parameters
    ----------
    freq : point label → loop name → L(jω) (complex) of the loop broken there
    title : headline;  gm_db, pm_deg : margin goals drawn (dB, deg)
    """
    loops = list(LOOP_TITLES)
    fig, axes = subplots(2, 3, figsize=(15, 8.5))
    for ax, loop in zip(axes.ravel(), loops):
        for label, resp in freq.items():
            if loop in resp:
                x, y = _nichols_xy(resp[loop])
                ax.plot(x, y, lw=0.9, label=label)
        ax.fill_between([-180 - pm_deg, -180 + pm_deg], -gm_db, gm_db, color="red", alpha=0.15,
                        label=f"excluded: GM < {gm_db:g} dB or PM < {pm_deg:g}°")
        ax.plot([-180], [0], "r+", ms=10)
        ax.set_xlim(-360, 0)
        ax.set_ylim(-40, 40)
        ax.set_xlabel("open-loop phase, deg")
        ax.set_ylabel("open-loop gain, dB")
        ax.set_title(LOOP_TITLES[loop], fontsize=10)
        ax.grid(True, alpha=0.3)
    h, lab = axes.ravel()[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="lower center", ncol=5, fontsize=7)
    fig.suptitle(title)
    fig.subplots_adjust(bottom=0.17, top=0.9, hspace=0.35, wspace=0.25)
    return fig


def plot_bode_margins(omega_rps: np.ndarray, resp: dict[str, np.ndarray], margins: pd.DataFrame,
                      title: str) -> Figure:
    """Bode magnitude and phase of every broken loop at one point, crossovers marked.

    Parameters
    ----------
    omega_rps : frequencies, rad/s;  resp : loop → L(jω)
    margins : one row per loop with columns loop, gm_db, pm_deg, wc_rps
    title : headline
    """
    fig, (am, ap) = subplots(2, 1, figsize=(10, 8), sharex=True)
    for loop, h in resp.items():
        r = margins.set_index("loop").loc[loop]
        lab = f"{loop}: GM {r.gm_db:.1f} dB, PM {r.pm_deg:.1f}°, ωc {r.wc_rps:.2f} rad/s"
        line, = am.semilogx(omega_rps, 20 * np.log10(np.abs(h)), label=lab)
        ph = np.degrees(np.unwrap(np.angle(h)))
        ic = int(np.argmin(np.abs(np.abs(h) - 1.0)))
        ap.semilogx(omega_rps, ph - 360.0 * np.ceil(ph[ic] / 360.0), color=line.get_color())
        am.axvline(r.wc_rps, color=line.get_color(), ls=":", lw=0.8)
    am.axhline(0, color="k", lw=0.8)
    ap.axhline(-180, color="k", lw=0.8)
    am.set_ylabel("|L|, dB")
    ap.set_ylabel("phase of L, deg")
    ap.set_xlabel("frequency, rad/s")
    am.set_ylim(-60, 60)
    am.legend(fontsize=7)
    am.grid(True, which="both", alpha=0.3)
    ap.grid(True, which="both", alpha=0.3)
    fig.suptitle(title)
    return fig


def plot_steps(runs: dict[str, dict[str, dict[str, np.ndarray]]], title: str) -> Figure:
    """Nonlinear altitude and speed steps, old and tuned gains, with the cross deviations.

    Parameters
    ----------
    runs : point label → ``"old"``/``"new"`` → ``"alt"``/``"speed"`` → array (t_s, alt_m,
        tas_mps, throttle)
    title : headline
    """
    fig, axes = subplots(2, 2, figsize=(13, 8), sharex=True)
    for label, pair in runs.items():
        for key, ls in (("old", "--"), ("new", "-")):
            a, s = pair[key]["alt"], pair[key]["speed"]
            name = f"{label} ({'file gains' if key == 'old' else 'schedule'})"
            axes[0, 0].plot(a[:, 0], a[:, 1] - a[0, 1], ls, label=name)
            axes[1, 0].plot(a[:, 0], (a[:, 2] - a[0, 2]) * 3.6, ls, label=name)
            axes[0, 1].plot(s[:, 0], (s[:, 2] - s[0, 2]) * 3.6, ls, label=name)
            axes[1, 1].plot(s[:, 0], s[:, 1] - s[0, 1], ls, label=name)
    for ax, (t, y) in zip(axes.ravel(), (("altitude step", "ΔH, m"), ("speed step", "ΔV, km/h"),
                                         ("altitude step: speed deviation", "ΔV, km/h"),
                                         ("speed step: altitude deviation", "ΔH, m"))):
        ax.set_title(t, fontsize=10)
        ax.set_ylabel(y)
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time, s")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(title)
    return fig


def plot_schedule(points: pd.DataFrame, curves: dict[str, pd.DataFrame], title: str) -> Figure:
    """Tuned values at the design points and the fitted schedule, against dynamic pressure.

    Parameters
    ----------
    points : rows with qbar_pa, mass_kg, config and tuned_<param>
    curves : parameter → table with columns qbar_pa, mass_kg, value (the schedule's lines)
    title : headline
    """
    fig, axes = subplots(1, len(curves), figsize=(4.2 * len(curves), 4.5))
    for ax, (name, cur) in zip(np.atleast_1d(axes), curves.items()):
        for m, grp in cur.groupby("mass_kg"):
            line, = ax.plot(grp.qbar_pa / 1000, grp.value, label=f"schedule, {m / 1000:.1f} t")
            sel = points[np.isclose(points.mass_kg, m, rtol=0.02)]
            for cfg_name, mk in (("clean", "o"), ("approach", "^")):
                s = sel[sel.config == cfg_name]
                ax.plot(s.qbar_pa / 1000, s[f"tuned_{name}"], mk, color=line.get_color(),
                        label=f"tuned, {m / 1000:.1f} t {cfg_name}")
        ax.set_xlabel("dynamic pressure, kPa")
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[0].legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_linear_check(t_s: np.ndarray, nonlinear: np.ndarray, linear: np.ndarray,
                      title: str) -> Figure:
    """Pitch rate and airspeed after an elevator pulse: nonlinear JSBSim against the linear model.

    Parameters
    ----------
    t_s : time, s;  nonlinear : columns t_s, q_rps, tas_mps, alpha_rad (deviations)
    linear : columns q_rps, V_mps, alpha_rad;  title : headline
    """
    fig, (aq, av) = subplots(2, 1, figsize=(10, 7))
    short = t_s <= 15.0
    aq.plot(t_s[short], np.degrees(nonlinear[short, 1]), label="JSBSim (nonlinear)")
    aq.plot(t_s[short], np.degrees(linear[short, 0]), "--", label="linear model (FGLinearization, speed column by central differences)")
    aq.set_xlabel("time, s")
    aq.set_ylabel("pitch rate deviation, deg/s")
    av.plot(t_s, nonlinear[:, 2], label="JSBSim (nonlinear)")
    av.plot(t_s, linear[:, 1], "--", label="linear model (FGLinearization, speed column by central differences)")
    av.set_xlabel("time, s")
    av.set_ylabel("airspeed deviation, m/s")
    for ax in (aq, av):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return fig


def plot_campaign_shift(runs: dict[str, pd.DataFrame], metrics, title: str) -> Figure:
    """Empirical distributions of per-flight error metrics for each run of a campaign check.

    Parameters
    ----------
    runs : run label → flights table (regress rows);  metrics : columns to draw (unit in the
        name: ``_m`` metres, ``_kt`` knots);  title : headline
    """
    fig, axes = subplots(1, len(metrics), figsize=(5 * len(metrics), 4.5))
    for ax, m in zip(np.atleast_1d(axes), metrics):
        for label, df in runs.items():
            v = np.sort(df[m].dropna().to_numpy())
            if len(v):
                ax.step(v, np.arange(1, len(v) + 1) / len(v), where="post",
                        label=f"{label} (median {np.median(v):.3g})")
        unit = "m" if m.endswith("_m") else "kt"
        ax.set_xlabel(f"{m.rsplit('_', 1)[0]}, {unit}")
        ax.set_ylabel("fraction of flights")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig
