"""Plots of the MEMS gyro static test, like Figs. 2-4 of Vorobyov et al. (seed 000).

Each function draws a :class:`~fms_testbed.sensors.mems.static_test.StaticTestResult` and
returns a :class:`~matplotlib.figure.Figure`; nothing is computed or saved here.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from fms_testbed.core.units import DEG_RAD
from fms_testbed.viz.figure import subplots

AXIS_COLOURS = {"x": "tab:blue", "y": "tab:orange", "z": "tab:green"}
STAGE_STYLE = {"none": ("k", "uncompensated"), "temperature": ("tab:purple", "temperature"),
               "run-to-run": ("tab:red", "+ run-to-run"), "slow-drift": ("tab:green", "+ slow drift")}
AXIS_LINES = {"x": "-", "y": "--", "z": ":"}


def plot_zero_signal_vs_temperature(res) -> Figure:
    """Calibration run: raw zero signal vs temperature with the fitted polynomial (top) and the
    residual after the temperature stage (bottom, the hysteresis loop), °/s vs °C."""
    cal = res.calibration
    if cal is None:
        raise ValueError("plot_zero_signal_vs_temperature: the run has no temperature stage")
    fig, (top, bot) = subplots(2, 1, figsize=(9, 7), sharex=True)
    t = cal.point_temp_degC
    order = np.argsort(t)
    fit = cal.zero_signal_rps(t) / DEG_RAD
    raw = cal.point_zero_rps / DEG_RAD
    for a, ax in enumerate("xyz"):
        c = AXIS_COLOURS[ax]
        top.plot(t, raw[:, a], ".", ms=3, color=c, label=f"{ax}: 100-s means")
        top.plot(t[order], fit[order, a], "-", color=c, lw=1.2, label=f"{ax}: fitted polynomial")
        bot.plot(t, raw[:, a] - fit[:, a], "-", color=c, lw=0.8, marker=".", ms=2,
                 label=f"{ax}: max {np.abs(raw[:, a] - fit[:, a]).max():.5f} °/s")
    ref = res.reference["temperature_residual_deg_per_s"]
    for sgn in (1, -1):
        bot.axhline(sgn * ref, color="0.3", ls="--", lw=1,
                    label=f"seed: ±{ref} °/s" if sgn == 1 else None)
    top.set_ylabel("zero signal, °/s")
    bot.set_ylabel("after temperature calibration, °/s")
    bot.set_xlabel("sensor temperature, °C")
    for ax in (top, bot):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=3, loc="best")
    res_max = float(np.abs(raw - fit).max())
    top.set_title(f"{res.imu} calibration run ({cal.swing_degC:.0f} °C swing): raw zero signal "
                  f"up to {np.abs(raw).max():.3f} °/s;\nresidual after temperature calibration "
                  f"{res_max:.5f} °/s (seed: {ref} °/s)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_residual_after_run_to_run(res) -> Figure:
    """Test run: window means of the zero signal after the temperature stage and after the
    run-to-run stage vs time (°/s vs min), with the sensor temperature (°C)."""
    stages = [s for s in ("temperature", "run-to-run") if s in res.window_error_deg_per_s]
    if not stages:
        raise ValueError("plot_residual_after_run_to_run: no temperature or run-to-run stage")
    fig, (ax0, ax1) = subplots(2, 1, figsize=(9, 7), sharex=True,
                               gridspec_kw={"height_ratios": [3, 1]})
    tm = res.window_t_s / 60.0
    for st in stages:
        w = res.window_error_deg_per_s[st]
        for a, ax in enumerate("xyz"):
            ax0.plot(tm, w[:, a], AXIS_LINES[ax], color=STAGE_STYLE[st][0], lw=1.1,
                     label=f"{STAGE_STYLE[st][1]}, {ax}: max {np.abs(w[:, a]).max():.5f} °/s")
    ref = res.reference["run_to_run_residual_deg_per_s"]
    for sgn in (1, -1):
        ax0.axhline(sgn * ref, color="0.3", ls="--", lw=1,
                    label=f"seed after run-to-run: ±{ref} °/s" if sgn == 1 else None)
    ax0.set_ylabel(f"zero signal ({res.window_t_s[1] - res.window_t_s[0]:.0f}-s means), °/s"
                   if res.window_t_s.size > 1 else "zero signal, °/s")
    ax0.legend(fontsize=7, ncol=2)
    ax0.grid(True, alpha=0.3)
    ax1.plot(res.profile.t_s / 60.0, res.profile.temp_degC, "k-", lw=1,
             label=f"profile {res.profile.name}")
    ax1.set_ylabel("temperature, °C")
    ax1.set_xlabel("time since switch-on, min")
    ax1.legend(fontsize=7)
    ax1.grid(True, alpha=0.3)
    parts = [f"after {st}: max {res.stage[st].residual_max_deg_per_s.max():.5f} °/s"
             for st in stages]
    ax0.set_title(f"{res.imu} static test, seed {res.seed}: " + "; ".join(parts)
                  + f"\n(seed: run-to-run error up to "
                  f"{res.reference['run_to_run_error_deg_per_s']} °/s → {ref} °/s)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_accumulated_angle(res) -> Figure:
    """Angle accumulated by the output error vs time per stage (°, h): all stages (top) and the
    final stage on its own scale (bottom), with the seed's 2-h figures."""
    fig, (top, bot) = subplots(2, 1, figsize=(9, 7), sharex=True)
    th = res.series_t_s / 3600.0
    for st, ang in res.angle_series_deg.items():
        for a, ax in enumerate("xyz"):
            top.plot(th, ang[:, a], AXIS_LINES[ax], color=STAGE_STYLE[st][0], lw=1.1,
                     label=f"{STAGE_STYLE[st][1]}, {ax}: {ang[-1, a]:.1f}°")
    last = list(res.angle_series_deg)[-1]
    for a, ax in enumerate("xyz"):
        ang = res.angle_series_deg[last][:, a]
        bot.plot(th, ang, AXIS_LINES[ax], color=AXIS_COLOURS[ax], lw=1.1,
                 label=f"{STAGE_STYLE[last][1]}, {ax}: {ang[-1]:.2f}°")
    r = res.reference
    for sgn in (1, -1):
        top.axhline(sgn * r["angle_uncompensated_deg"], color="0.3", ls="--", lw=1,
                    label=f"seed uncompensated: ±{r['angle_uncompensated_deg']:g}° in 2 h"
                    if sgn == 1 else None)
        bot.axhline(sgn * r["angle_compensated_deg"], color="0.3", ls="--", lw=1,
                    label=f"seed compensated: ±{r['angle_compensated_deg']:g}° in 2 h"
                    if sgn == 1 else None)
    top.set_ylabel("accumulated angle, °")
    bot.set_ylabel(f"accumulated angle ({STAGE_STYLE[last][1]}), °")
    bot.set_xlabel("time since switch-on, h")
    for ax in (top, bot):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=3, loc="upper left")
    first = list(res.angle_series_deg)[0]
    worst = lambda st: float(np.abs(res.angle_series_deg[st][-1]).max())  # noqa: E731
    top.set_title(f"{res.imu}, {res.duration_s / 3600:g} h static ({res.profile.name}), seed "
                  f"{res.seed}: |angle| up to {worst(first):.1f}° ({STAGE_STYLE[first][1]}) → "
                  f"{worst(last):.2f}° ({STAGE_STYLE[last][1]})\n(seed: "
                  f"{r['angle_uncompensated_deg']:g}° → {r['angle_compensated_deg']:g}° in 2 h)",
                  fontsize=10)
    fig.tight_layout()
    return fig


def plot_allan(res) -> Figure:
    """Overlapping Allan deviation per axis with the fitted N, F, K model (°/h vs s)."""
    fit = res.allan
    if fit is None:
        raise ValueError("plot_allan: the run has no Allan fit (run with allan=True)")
    fig, ax = subplots(1, 1, figsize=(8, 6))
    to_dph = 1.0 / DEG_RAD * 3600.0
    for a, axn in enumerate("xyz"):
        c = AXIS_COLOURS[axn]
        ax.loglog(fit.tau_s, fit.adev_rps[:, a] * to_dph, "o", ms=3, color=c,
                  label=f"{axn}: overlapping ADEV")
        ax.loglog(fit.tau_s, fit.model_adev_rps(fit.tau_s)[:, a] * to_dph, "-", color=c, lw=1,
                  label=f"{axn}: fit ARW {fit.arw_deg_per_sqrt_h[a]:.4f} °/√h, "
                        f"BI {fit.bias_instability_deg_per_h[a]:.3f} °/h")
    p = res.preset_allan
    ax.axhline(p["bias_instability_deg_per_h"], color="0.3", ls="--", lw=1,
               label=f"preset bias instability {p['bias_instability_deg_per_h']} °/h")
    tau = fit.tau_s
    ax.loglog(tau, p["arw_deg_per_sqrt_h"] * 60.0 / np.sqrt(tau), ":", color="0.3", lw=1,
              label=f"preset ARW {p['arw_deg_per_sqrt_h']} °/√h (N/√τ)")
    ax.set_xlabel("averaging time τ, s")
    ax.set_ylabel("Allan deviation, °/h")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"{res.imu} Allan deviation ({res.allan_signal} output, "
                 f"{fit.record_s / 3600:g} h at {res.rate_hz:g} Hz)\nARW "
                 f"{fit.arw_deg_per_sqrt_h.mean():.4f} °/√h, BI "
                 f"{fit.bias_instability_deg_per_h.mean():.3f} °/h (mean of axes); "
                 f"preset {p['arw_deg_per_sqrt_h']} °/√h, {p['bias_instability_deg_per_h']} °/h",
                 fontsize=10)
    fig.tight_layout()
    return fig
