"""Check of the JSBSim linearisation against the nonlinear JSBSim model, and the comparison with
the point-mass approximation (``fms-testbed analyse --plant jsbsim``).

The nonlinear reference: from the trim, inner loops off, an elevator pulse (+0.02 for 1 s)
with the other controls held; the free response is flown for 150 s, minus the same run
without the pulse (the trim's own drift). A damped sinusoid
``y = a e^{-σ t} cos(ω_d t + φ) + b + c t`` is fitted (scipy ``curve_fit``) to the pitch rate
over 2-10 s (short period) and to the airspeed over 10-150 s (phugoid); their ω_n = sqrt(σ² +
ω_d²) and ζ = σ / ω_n are compared with the eigenvalues of the linear model, and the linear
model's response to the same pulse is overlaid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit

from fms_testbed.control.coupled_law import CoupledLawParams
from fms_testbed.control.linear import closed_loop
from fms_testbed.core.units import KMH_MPS
from fms_testbed.evaluation.envelope_points import (DH_STEP_M, DV_STEP_FRAC, linear_goals,
                                                    point_loops, step_outputs)
from fms_testbed.sim.linearise import DesignPoint, Mode, linearise, longitudinal_modes, trim_point

PULSE = 0.02
"""Elevator pulse, normalised."""
PULSE_S = (1.0, 2.0)
"""Pulse start and end, s."""
DURATION_S = 150.0


def _free_run(cfg, point: DesignPoint, pulse: float) -> np.ndarray:
    """t_s, q_rps, tas_mps, alpha_rad of a free run from the trim with an elevator pulse."""
    ac, tr = trim_point(cfg, point)
    fdm = ac.fdm
    fdm["fms/ap/master"] = 0.0
    for i in range(ac.n_engines):
        fdm[f"fcs/throttle-cmd-norm[{i}]"] = tr.throttle
    n = int(DURATION_S / ac.dt_s)
    out = np.empty((n, 4))
    for k in range(n):
        t = (k + 1) * ac.dt_s
        fdm["fcs/elevator-cmd-norm"] = tr.elevator + (pulse if PULSE_S[0] <= t < PULSE_S[1] else 0.0)
        fdm.run()
        st = ac.state()
        out[k] = (t, st.q_rps, st.tas_mps, st.alpha_rad)
    return out


def nonlinear_pulse(cfg, point: DesignPoint) -> np.ndarray:
    """Response of aircraft ``cfg`` at design point ``point`` to the elevator pulse on the
    nonlinear JSBSim model (inner loops off): the run
    with the pulse minus the run without it (which removes the trim's own slow drift).

    Returns
    -------
    array (time × 4): t_s, q_rps, tas_mps, alpha_rad (differences except t)
    """
    a, b = _free_run(cfg, point, PULSE), _free_run(cfg, point, 0.0)
    d = a - b
    d[:, 0] = a[:, 0]
    return d


def linear_pulse(model, t_s: np.ndarray) -> np.ndarray:
    """The linear ``model``'s response to the same pulse at times ``t_s`` (s): columns q_rps,
    V_mps, alpha_rad."""
    import control as ct

    u = np.zeros((2, len(t_s)))
    u[1] = np.where((t_s >= PULSE_S[0]) & (t_s < PULSE_S[1]), PULSE, 0.0)
    r = ct.forced_response(model.lon, t_s, u)
    y = np.asarray(r.outputs)
    names = list(model.lon.output_labels)
    return np.column_stack([y[names.index("q")], y[names.index("V")], y[names.index("alpha")]])


def _damped(t, a, s, w, ph, b, c):
    return a * np.exp(-s * t) * np.cos(w * t + ph) + b + c * t


def fit_mode(t_s: np.ndarray, y: np.ndarray, w_guess_rps: float) -> Mode:
    """ω_n and ζ of a damped sinusoid fitted to ``y`` at times ``t_s`` (s; module docstring),
    from a start at ``w_guess_rps`` (rad/s)."""
    t = t_s - t_s[0]
    p0 = [float(np.ptp(y)) / 2 or 1e-3, 0.1 * w_guess_rps, w_guess_rps, 0.0, 0.0, 0.0]
    p, _ = curve_fit(_damped, t, y, p0=p0, maxfev=20000)
    s, w = abs(p[1]), abs(p[2])
    wn = math.hypot(s, w)
    return Mode(wn, s / wn)


MODE_TOL_REL = 0.05
"""The linearisation agrees with JSBSim when the short-period frequency and the phugoid period
are within this fraction of the fitted ones."""


@dataclass(frozen=True)
class LinearCheck:
    """Outcome of :func:`compare_point`: report lines, whether the modes agree, and the figure
    data (time s, nonlinear and linear responses, headline)."""

    lines: list[str]
    ok: bool
    t_s: np.ndarray
    nonlinear: np.ndarray
    linear: np.ndarray
    title: str


def compare_point(cfg, alt_m: float, tas_mps: float, law: CoupledLawParams) -> LinearCheck:
    """The ``analyse --plant jsbsim`` check: report lines and whether the linear modes agree
    with the nonlinear fit (:data:`MODE_TOL_REL`), with the pulse responses for the figure.

    Parameters
    ----------
    cfg : aircraft;  alt_m, tas_mps : operating point (m, m/s);  law : coupled-law tuning
    """
    pt = DesignPoint(alt_m, tas_mps)
    model = linearise(cfg, pt)
    sp, ph = longitudinal_modes(model)
    nl = nonlinear_pulse(cfg, pt)
    t = nl[:, 0]
    lin = linear_pulse(model, t)
    i_sp = (t >= 2.0) & (t <= 10.0)
    i_ph = t >= 10.0
    sp_nl = fit_mode(t[i_sp], nl[i_sp, 1], sp.wn_rps)
    ph_nl = fit_mode(t[i_ph], nl[i_ph, 2], ph.wn_rps)
    err_q = float(np.sqrt(np.mean((lin[:, 0] - nl[:, 1])[t < 10] ** 2)) / np.abs(nl[t < 10, 1]).max())
    title = (f"{cfg.name} at {alt_m:.0f} m / {tas_mps:.1f} m/s: elevator pulse {PULSE:g} for 1 s, "
             f"inner loops off\nshort period ω_n {sp.wn_rps:.3f} (linear) vs {sp_nl.wn_rps:.3f} "
             f"rad/s (JSBSim fit); phugoid period {ph.period_s:.1f} vs {ph_nl.period_s:.1f} s")
    lines = [f"trim: alpha {model.trim.alpha_deg:.2f} deg, throttle {model.trim.throttle:.3f}, "
             f"mass {model.mass_kg:.0f} kg, q̄ {model.qbar_pa:.0f} Pa, engine lag "
             f"{model.engine_lag_s:.2f} s (63 % of a 0.05 throttle step)",
             "| mode | linear (FGLinearization, speed column by central differences) ω_n rad/s, ζ "
             "| nonlinear JSBSim fit ω_n, ζ |",
             "|---|---|---|",
             f"| short period | {sp.wn_rps:.3f}, {sp.zeta:.3f} | {sp_nl.wn_rps:.3f}, {sp_nl.zeta:.3f} |",
             f"| phugoid | {ph.wn_rps:.4f}, {ph.zeta:.3f} (T {ph.period_s:.1f} s) | "
             f"{ph_nl.wn_rps:.4f}, {ph_nl.zeta:.3f} (T {ph_nl.period_s:.1f} s) |",
             f"pitch-rate response, first 10 s: RMS(linear - JSBSim) / peak = {err_q:.3f}"]
    ok = (abs(sp_nl.wn_rps / sp.wn_rps - 1) <= MODE_TOL_REL
          and abs(ph_nl.period_s / ph.period_s - 1) <= MODE_TOL_REL)
    lines.append(f"modes agree within {MODE_TOL_REL:.0%}: {'yes' if ok else 'NO'}")
    return LinearCheck(lines + _pointmass_lines(cfg, model, law), ok, t, nl, lin, title)


def _pointmass_lines(cfg, model, law: CoupledLawParams) -> list[str]:
    """The closed loop on the JSBSim linearisation against the point-mass model with lags."""
    g = linear_goals(point_loops(cfg, model, law))
    V0 = model.trim.tas_mps
    out = []
    for tau_nx, tau_ny, what in ((0.0, 0.0, "point mass, no lags (paper)"),
                                 (model.engine_lag_s, 0.5, f"point mass, lags n_x "
                                  f"{model.engine_lag_s:.2f} s, n_y 0.5 s")):
        sys = closed_loop(law, V0, tau_nx, tau_ny)
        yh = step_outputs(sys, np.array([0.0, DH_STEP_M]))
        yv = step_outputs(sys, np.array([DV_STEP_FRAC * V0, 0.0]))
        out.append(f"| {what} | {np.abs(yh[:, 0]).max() / KMH_MPS:.3f} | "
                   f"{np.abs(yv[:, 1]).max():.3f} | — | — |")
    return ["", f"Closed loop (coupled law T_V {law.T_V_s} s, ξ_V {law.xi_V}, T_H {law.T_H_s} s, "
            f"ξ_H {law.xi_H}): +{DH_STEP_M:g} m and +{DV_STEP_FRAC:.0%} TAS steps",
            "| plant | max|ΔV| km/h | max|ΔH| m | min GM dB | min PM deg |", "|---|---|---|---|---|",
            *out, f"| JSBSim linearisation + inner loops | {g.max_dv_kmh:.3f} | {g.max_dh_m:.3f} | "
            f"{g.gm_db:.1f} | {g.pm_deg:.1f} |"]
