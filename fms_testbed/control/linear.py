"""Linear analysis of the coupled law with python-control (paper eq. 13-18).

The point-mass plant (eq. 1) linearised about level flight at V0 (θ0 = 0, n_x0 = 0, n_y0 = 1)::

    δV' = g (n_x - θ),   θ' = (g / V0) Δn_y,   δH' = V0 θ

with optional first-order lags between the commanded and the realised load factors, is closed
with the linearised law (eq. 19 with ΔH inside the ±limit)::

    Δn_ya = -(2 ξ_H / (g T_H)) V0 θ - ΔH / (g T_H²)
    n_xa' = (g / V0) Δn_ya - (2 ξ_V / T_V)(n_x - θ) - ΔV / (g T_V²)

Both are built as python-control state-space systems and joined with ``control.interconnect``;
the result is the closed-loop transfer matrix W(p) from (V_cmd, H_cmd) to (V, H, θ, n_xa). Without
lags its V/H off-diagonal entries vanish and its poles are the roots of T² p² + 2 ξ T p + 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from fms_testbed.control.coupled_law import CoupledLawParams
from fms_testbed.core.units import G0_MPS2

OUTPUTS = ("V", "H", "theta", "nxa")
"""Closed-loop outputs: airspeed (m/s), altitude (m), flight-path angle (rad), n_xa command (g)."""
INPUTS = ("V_cmd", "H_cmd")
"""Closed-loop inputs: speed command (m/s) and altitude command (m)."""


def plant_ss(V0_mps: float, tau_nx_s: float = 0.0, tau_ny_s: float = 0.0) -> ct.StateSpace:
    """Linearised point-mass plant (eq. 1) with optional load-factor lags.

    Parameters
    ----------
    V0_mps : trim airspeed, m/s
    tau_nx_s, tau_ny_s : first-order lags of the n_x and n_y realisation, s (0: none)

    Returns
    -------
    StateSpace with inputs (nx_cmd, dny_cmd) in g and outputs (V, theta, H, nx) in m/s, rad, m, g.
    """
    g = G0_MPS2
    # states: V, theta, H, [nx], [dny]
    names = ["V", "theta", "H"]
    lag_x, lag_y = tau_nx_s > 0, tau_ny_s > 0
    if lag_x:
        names.append("nx_act")
    if lag_y:
        names.append("dny_act")
    n = len(names)
    ix = {s: i for i, s in enumerate(names)}
    A = np.zeros((n, n))
    B = np.zeros((n, 2))
    A[ix["V"], ix["theta"]] = -g
    A[ix["H"], ix["theta"]] = V0_mps
    if lag_x:
        A[ix["V"], ix["nx_act"]] = g
        A[ix["nx_act"], ix["nx_act"]] = -1.0 / tau_nx_s
        B[ix["nx_act"], 0] = 1.0 / tau_nx_s
    else:
        B[ix["V"], 0] = g
    if lag_y:
        A[ix["theta"], ix["dny_act"]] = g / V0_mps
        A[ix["dny_act"], ix["dny_act"]] = -1.0 / tau_ny_s
        B[ix["dny_act"], 1] = 1.0 / tau_ny_s
    else:
        B[ix["theta"], 1] = g / V0_mps
    C = np.zeros((4, n))
    D = np.zeros((4, 2))
    C[0, ix["V"]] = C[1, ix["theta"]] = C[2, ix["H"]] = 1.0
    if lag_x:
        C[3, ix["nx_act"]] = 1.0
    else:
        D[3, 0] = 1.0
    return ct.ss(A, B, C, D, inputs=["nx_cmd", "dny_cmd"], outputs=["V", "theta", "H", "nx"],
                 states=names, name="plant")


def law_ss(p: CoupledLawParams, V0_mps: float, use_measured_nx: bool | None = None
           ) -> ct.StateSpace:
    """Linearised coupled law (eq. 19), one state: the n_xa integrator.

    Parameters
    ----------
    p : law tuning (T_V, ξ_V, T_H, ξ_H); ``p.use_measured_nx`` unless overridden
    V0_mps : trim airspeed, m/s

    Returns
    -------
    StateSpace with inputs (V_cmd, H_cmd, V, theta, H, nx) and outputs (nx_cmd, dny_cmd).
    """
    g = G0_MPS2
    meas = p.use_measured_nx if use_measured_nx is None else use_measured_nx
    a_d, a_p = 2 * p.xi_H / (g * p.T_H_s), 1.0 / (g * p.T_H_s ** 2)
    b_d, b_p = 2 * p.xi_V / p.T_V_s, 1.0 / (g * p.T_V_s ** 2)
    # dny = -a_d V0 theta - a_p (H - Hc)      (inputs: Vc, Hc, V, theta, H, nx)
    dny_row = np.array([0.0, a_p, 0.0, -a_d * V0_mps, -a_p, 0.0])
    # xi' = (g/V0) dny - b_d (nxa - theta) - b_p (V - Vc)
    row = (g / V0_mps) * dny_row + np.array([b_p, 0.0, -b_p, b_d, 0.0, -b_d if meas else 0.0])
    A = np.array([[0.0 if meas else -b_d]])
    B = row.reshape(1, 6)
    C = np.array([[1.0], [0.0]])
    D = np.vstack([np.zeros(6), dny_row])
    return ct.ss(A, B, C, D, inputs=["V_cmd", "H_cmd", "V", "theta", "H", "nx"],
                 outputs=["nx_cmd", "dny_cmd"], states=["nxa_int"], name="law")


def closed_loop(p: CoupledLawParams, V0_mps: float, tau_nx_s: float = 0.0, tau_ny_s: float = 0.0,
                use_measured_nx: bool | None = None) -> ct.StateSpace:
    """Closed-loop MIMO system W(p): (V_cmd, H_cmd) → (V, H, θ, n_xa) (paper eq. 15-18).

    Parameters
    ----------
    p : law tuning;  V0_mps : trim airspeed, m/s
    tau_nx_s, tau_ny_s : inner-loop/engine lags, s (0 = the paper's lag-free case)
    use_measured_nx : damping term on the measured n_x (default: ``p.use_measured_nx``)
    """
    plant = plant_ss(V0_mps, tau_nx_s, tau_ny_s)
    law = law_ss(p, V0_mps, use_measured_nx)
    return ct.interconnect(
        [plant, law], inputs=list(INPUTS), outputs=["V", "H", "theta", "nxa"],
        connections=[["plant.nx_cmd", "law.nx_cmd"], ["plant.dny_cmd", "law.dny_cmd"],
                     ["law.V", "plant.V"], ["law.theta", "plant.theta"], ["law.H", "plant.H"],
                     ["law.nx", "plant.nx"]],
        outlist=["plant.V", "plant.H", "plant.theta", "law.nx_cmd"],
        name="coupled closed loop")


@dataclass(frozen=True, slots=True)
class DecouplingReport:
    """Decoupling and pole placement of a closed loop.

    off_V_from_H : max over ω of |W_V,Hcmd(jω)| / max over ω of |W_V,Vcmd(jω)| (m/s per m scaled)
    off_H_from_V : max over ω of |W_H,Vcmd(jω)| / max over ω of |W_H,Hcmd(jω)|
    dc_gain : 2×2 DC gain of (V, H) from (V_cmd, H_cmd)
    poles : closed-loop poles, rad/s
    desired_poles : roots of T_V² p² + 2 ξ_V T_V p + 1 and T_H² p² + 2 ξ_H T_H p + 1, rad/s
    pole_error : max distance from each desired pole to the nearest closed-loop pole, rad/s
    """

    off_V_from_H: float
    off_H_from_V: float
    dc_gain: np.ndarray
    poles: np.ndarray
    desired_poles: np.ndarray
    pole_error: float


def frequency_response(sys: ct.StateSpace, omega_rps: np.ndarray) -> np.ndarray:
    """Complex frequency response W(jω) = C (jωI - A)⁻¹ B + D.

    Parameters
    ----------
    sys : state-space system (e.g. :func:`closed_loop`)
    omega_rps : frequencies ω, rad/s

    Returns
    -------
    array of shape (outputs, inputs, len(ω))
    """
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    out = np.empty((C.shape[0], B.shape[1], len(omega_rps)), dtype=complex)
    for k, w in enumerate(omega_rps):
        out[:, :, k] = C @ np.linalg.solve(1j * w * np.eye(n) - A, B) + D
    return out


def desired_poles(p: CoupledLawParams) -> np.ndarray:
    """Roots of T_V² p² + 2 ξ_V T_V p + 1 and of T_H² p² + 2 ξ_H T_H p + 1, rad/s."""
    return np.concatenate([np.roots([p.T_V_s ** 2, 2 * p.xi_V * p.T_V_s, 1.0]),
                           np.roots([p.T_H_s ** 2, 2 * p.xi_H * p.T_H_s, 1.0])])


def decoupling_report(sys: ct.StateSpace, p: CoupledLawParams,
                      omega_rps: np.ndarray | None = None) -> DecouplingReport:
    """Measure the V/H cross-transfer of a closed loop and compare its poles with (T, ξ).

    Parameters
    ----------
    sys : closed loop from :func:`closed_loop`
    p : the law tuning it was built with
    omega_rps : frequency grid, rad/s (default 1e-3 … 1e2, 400 points)
    """
    w = np.logspace(-3, 2, 400) if omega_rps is None else omega_rps
    W = np.abs(frequency_response(sys, w))
    iV, iH = OUTPUTS.index("V"), OUTPUTS.index("H")
    off_v = W[iV, 1].max() / W[iV, 0].max()
    off_h = W[iH, 0].max() / W[iH, 1].max()
    dc = np.real(frequency_response(sys, np.array([0.0]))[[iV, iH]][:, :, 0])
    poles = np.linalg.eigvals(np.asarray(sys.A))
    want = desired_poles(p)
    err = max(np.min(np.abs(poles - d)) for d in want)
    return DecouplingReport(float(off_v), float(off_h), dc, poles, want, float(err))


def step_responses(sys: ct.StateSpace, t_s: np.ndarray, dV_mps: float, dH_m: float):
    """Responses of ``sys`` to a speed step ``dV_mps`` (m/s) and, separately, an altitude step
    ``dH_m`` (m) at times ``t_s`` (s).

    Returns
    -------
    (speed_step, alt_step): arrays of shape (4, len(t)) with outputs (V, H, θ, n_xa) as deviations
    from trim in m/s, m, rad, g.
    """
    rv = ct.forced_response(sys, t_s, np.vstack([np.full_like(t_s, dV_mps), np.zeros_like(t_s)]))
    rh = ct.forced_response(sys, t_s, np.vstack([np.zeros_like(t_s), np.full_like(t_s, dH_m)]))
    return np.asarray(rv.outputs), np.asarray(rh.outputs)


def siso_tf(sys: ct.StateSpace, output: str, inp: str) -> ct.TransferFunction:
    """One entry of W(p) as a minimal transfer function, e.g. ``siso_tf(sys, "V", "H_cmd")``.

    Parameters
    ----------
    sys : closed loop from :func:`closed_loop`
    output : one of :data:`OUTPUTS`;  inp : one of :data:`INPUTS`
    """
    i, j = OUTPUTS.index(output), INPUTS.index(inp)
    sub = ct.ss(sys.A, sys.B[:, [j]], sys.C[[i], :], sys.D[[i]][:, [j]])
    return ct.minreal(ct.ss2tf(sub), verbose=False)
