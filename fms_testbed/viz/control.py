"""Plots of the coupled-law work: comparison runs, the paper's Fig. 2 layout, linear analysis.

Plotting only: every function takes computed data (DataFrames, arrays) and returns a matplotlib
Figure; the caller saves it (:func:`fms_testbed.viz.figure.save`).

Units: these are engineering plots of the control law, drawn as the paper (Danilin) draws them —
SI with speeds in km/h: speed and speed errors km/h, altitude and altitude errors m, flight-path
angle deg, load factors g, time s. (Plots of a flight — ground tracks, profiles, time histories —
use the aviation units NM, ft, kt instead: :mod:`fms_testbed.viz.run`.)
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from fms_testbed.core.units import KMH_MPS
from fms_testbed.viz.figure import subplots

KMH = 1.0 / KMH_MPS
"""m/s → km/h."""
BODE_FLOOR_DB = -120.0
"""Magnitudes below this are drawn as absent (|W| < 1e-6: rounding noise of a zero entry)."""
_LAW_STYLE = {"coupled": dict(color="C0", lw=1.8), "pi": dict(color="C3", lw=1.2),
              "tecs": dict(color="C2", lw=1.2), "ideal": dict(color="k", lw=1.0, ls="--")}
_LAW_LABEL = {"coupled": "coupled law (JSBSim)", "pi": "baseline (a): PI autothrottle (JSBSim)",
              "tecs": "baseline (b): TECS (JSBSim)",
              "ideal": "coupled law, ideal point mass"}


def _label(name: str) -> str:
    return _LAW_LABEL.get(name, name)


def _style(name: str) -> dict:
    return _LAW_STYLE.get(name, {})


def _events(ax, df: pd.DataFrame) -> None:
    """Mark command changes with thin vertical lines."""
    for col in ("cmd_alt_m", "cmd_tas_mps"):
        c = df[col].to_numpy()
        for i in np.flatnonzero(np.abs(np.diff(c)) > 1e-6):
            ax.axvline(df["t_s"].iloc[i + 1], color="0.6", lw=0.7, ls=":")


def plot_comparison(runs: dict[str, pd.DataFrame], title: str) -> Figure:
    """Speed error (km/h), altitude error (m), throttle and n_y (g) of several laws on one
    scenario.

    Parameters
    ----------
    runs : law name → timeseries (runner columns); ``"ideal"`` is drawn dashed
    title : figure title (the scenario and its headline figures)
    """
    fig, axes = subplots(4, 1, figsize=(10, 10), sharex=True)
    for name, df in runs.items():
        st = _style(name)
        t = df["t_s"]
        axes[0].plot(t, (df["tas_mps"] - df["cmd_tas_mps"]) * KMH, label=_label(name), **st)
        axes[1].plot(t, df["alt_m"] - df["cmd_alt_m"], **st)
        if name != "ideal":
            axes[2].plot(t, df["throttle"], **st)
        axes[3].plot(t, df["ny"], **st)
    axes[0].set_ylabel("speed error V - V_cmd, km/h")
    axes[1].set_ylabel("altitude error H - H_cmd, m")
    axes[2].set_ylabel("throttle, 0..1")
    axes[3].set_ylabel("normal load factor n_y, g")
    axes[3].set_xlabel("time, s")
    e = np.concatenate([(d["alt_m"] - d["cmd_alt_m"]).to_numpy() for d in runs.values()])
    e = e[np.isfinite(e)]
    if e.size:
        # the whole step and its capture (a 500 m step starts at -500 m), robust to one run
        # diverging: the 0.1-99.9 % range of every run's error, with a margin
        lo, hi = np.percentile(e, [0.1, 99.9])
        pad = max(0.05 * (hi - lo), 5.0)
        axes[1].set_ylim(min(lo, -10.0) - pad, max(hi, 10.0) + pad)
    for ax in axes:
        ax.grid(alpha=0.4)
        _events(ax, next(iter(runs.values())))
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_paper_fig2(runs: dict[str, pd.DataFrame], title: str) -> Figure:
    """The paper's Fig. 2 layout: V (km/h), H (m), θ (deg), n_xa, n_ya (g) stacked against time.

    Parameters
    ----------
    runs : law name → timeseries; the coupled law on JSBSim and its ideal point-mass response
        are expected, baselines optional
    title : figure title
    """
    fig, axes = subplots(5, 1, figsize=(9, 12), sharex=True)
    for name, df in runs.items():
        st = _style(name)
        t = df["t_s"]
        axes[0].plot(t, df["tas_mps"] * KMH, label=_label(name), **st)
        axes[1].plot(t, df["alt_m"], **st)
        axes[2].plot(t, df["gamma_deg"], **st)
        axes[3].plot(t, df["nx"], **st)
        axes[4].plot(t, df["ny"], **st)
    ref = runs.get("coupled", next(iter(runs.values())))
    axes[0].plot(ref["t_s"], ref["cmd_tas_mps"] * KMH, color="0.5", lw=0.8, ls=":",
                 label="command")
    axes[1].plot(ref["t_s"], ref["cmd_alt_m"], color="0.5", lw=0.8, ls=":")
    for ax, lab in zip(axes, ("V, km/h", "H, m", "θ (flight path), deg", "n_xa, g", "n_ya, g")):
        ax.set_ylabel(lab)
        ax.grid(alpha=0.4)
        _events(ax, ref)
    axes[-1].set_xlabel("time, s")
    axes[0].legend(loc="lower right", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_bode_coupling(omega_rps: np.ndarray, cases: dict[str, np.ndarray],
                       title: str) -> Figure:
    """Magnitudes of W(jω): diagonal and V/H cross terms for several lag cases.

    Parameters
    ----------
    omega_rps : frequencies, rad/s
    cases : label → complex W(jω) of shape (4, 2, len(ω)) (outputs V, H, θ, n_xa; inputs
        V_cmd, H_cmd)
    title : figure title
    """
    fig, axes = subplots(2, 2, figsize=(11, 7), sharex=True)
    panels = [((0, 0), "V / V_cmd, dB", 0, 0, 1.0), ((0, 1), "V / H_cmd, dB re (km/h)/m", 0, 1, KMH),
              ((1, 0), "H / V_cmd, dB re m/(km/h)", 1, 0, 1 / KMH), ((1, 1), "H / H_cmd, dB", 1, 1, 1.0)]
    notes: dict[tuple, list[str]] = {}
    for k, (label, W) in enumerate(cases.items()):
        for (r, c), _, i, j, scale in panels:
            mag = np.abs(W[i, j]) * scale
            db = 20 * np.log10(np.maximum(mag, 1e-300))
            if mag.max() < 10 ** (BODE_FLOOR_DB / 20):
                # numerical noise of an exactly-zero transfer (e.g. -320 dB): not drawn
                notes.setdefault((r, c), []).append(
                    f"{label}: |W| ≤ {mag.max():.0e} — zero to rounding, not drawn")
                axes[r, c].plot([], [], color=f"C{k}", label=label)
                continue
            axes[r, c].semilogx(omega_rps, np.where(db >= BODE_FLOOR_DB, db, np.nan),
                                color=f"C{k}", label=label)
    for (r, c), lab, *_ in panels:
        axes[r, c].set_ylabel(lab)
        axes[r, c].grid(alpha=0.4, which="both")
        axes[r, c].set_ylim(BODE_FLOOR_DB if c != r else -60, 10)
        axes[r, c].set_xscale("log")
    for (r, c), txt in notes.items():
        axes[r, c].text(0.02, 0.04, "\n".join(txt), transform=axes[r, c].transAxes, fontsize=7,
                        va="bottom")
    for c in (0, 1):
        axes[1, c].set_xlabel("frequency ω, rad/s")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_linear_steps(t_s: np.ndarray, cases: dict[str, tuple[np.ndarray, np.ndarray]],
                      dV_mps: float, dH_m: float, title: str) -> Figure:
    """Linear step responses: V and H for a speed step and for an altitude step, per lag case.

    Parameters
    ----------
    t_s : times, s
    cases : label → (speed-step outputs, altitude-step outputs), each (4, len(t)) as returned by
        :func:`fms_testbed.control.linear.step_responses`
    dV_mps, dH_m : the step sizes, m/s and m;  title : figure title
    """
    fig, axes = subplots(2, 2, figsize=(11, 7), sharex=True)
    for label, (sv, sh) in cases.items():
        axes[0, 0].plot(t_s, sv[0] * KMH, label=label)
        axes[1, 0].plot(t_s, sv[1])
        axes[0, 1].plot(t_s, sh[0] * KMH)
        axes[1, 1].plot(t_s, sh[1])
    if all(np.abs(sv[1]).max() < 1e-9 for sv, _ in cases.values()):
        axes[1, 0].text(0.02, 0.9, "ΔH ≡ 0: at θ0 = 0 speed does not enter the linearised\n"
                        "altitude dynamics; on JSBSim the n_y loop's tracking error does",
                        transform=axes[1, 0].transAxes, fontsize=8, va="top")
    axes[0, 0].set_title(f"speed step {dV_mps * KMH:.0f} km/h")
    axes[0, 1].set_title(f"altitude step {dH_m:.0f} m")
    axes[0, 0].set_ylabel("ΔV, km/h")
    axes[1, 0].set_ylabel("ΔH, m (cross term)")
    axes[0, 1].set_ylabel("ΔV, km/h (cross term)")
    axes[1, 1].set_ylabel("ΔH, m")
    for ax in axes.flat:
        ax.grid(alpha=0.4)
    for c in (0, 1):
        axes[1, c].set_xlabel("time, s")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_tuning_overlay(jsb: dict[str, pd.DataFrame], lin: dict[str, pd.DataFrame],
                        title: str, plant: str = "JSBSim") -> Figure:
    """Responses of the tuned law on a plant (JSBSim or the point mass) with the linear
    prediction overlaid.

    Parameters
    ----------
    jsb, lin : ``"alt"`` / ``"speed"`` → DataFrame with t_s, alt_m, tas_mps, cmd_alt_m,
        cmd_tas_mps (the linear one as deviations added to the same trim)
    title : figure title
    plant : legend label of ``jsb`` (the plant the law was tuned on)
    """
    fig, axes = subplots(2, 2, figsize=(11, 7), sharex=True)
    for c, key in enumerate(("alt", "speed")):
        for src, st in ((jsb, dict(color="C0", lw=1.8, label=plant)),
                        (lin, dict(color="k", lw=1.0, ls="--", label="linear prediction"))):
            d = src[key]
            axes[0, c].plot(d["t_s"], d["alt_m"] - d["cmd_alt_m"], **st)
            axes[1, c].plot(d["t_s"], (d["tas_mps"] - d["cmd_tas_mps"]) * KMH, **st)
        axes[0, c].set_title("altitude step" if key == "alt" else "speed step")
        axes[1, c].set_xlabel("time, s")
    axes[0, 0].set_ylabel("H - H_cmd, m")
    axes[1, 0].set_ylabel("V - V_cmd, km/h")
    for ax in axes.flat:
        ax.grid(alpha=0.4)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig
