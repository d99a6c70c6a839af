"""The closed loops of one design point as python-control systems, and the loops broken for margins.

The blocks (python-control ``StateSpace`` with named signals; interconnected by name):

* the airframe (longitudinal: throttle, elevator → V, α, θ, q, h, γ, n_x, n_y; lateral: aileron,
  rudder → β, φ, p, r, ψ), linearised from JSBSim (:mod:`fms_testbed.sim.linearise`);
* the inner loops as the JSBSim ``<system>`` realises them (:mod:`fms_testbed.sim.inner_loops`),
  every error and damping term of the surface loops scaled by ``k_q = q̄_ref / q̄``::

      δe = k_q (k_d q - k_p e - k_i ∫e - k_ff Δn_y,cmd),   e = Δn_y,cmd - Δn_y
      δT = k_p e + k_i ∫e + k_ff n_x,cmd,                   e = n_x,cmd - Δn_x
      δa = k_q (k_p e + k_i ∫e - k_d p),                    e = φ_cmd - φ
      δr = k_d (r - g φ / V) - k_p β - k_i ∫β

* the coupled law linearised about level flight (:func:`fms_testbed.control.linear.law_ss`,
  paper eq. 19) with the flight-path angle γ for its θ;
* the lateral path law (:mod:`fms_testbed.guidance.lateral`, small angles, no intercept limit)
  about a path of curvature κ: ``ż = V e_χ``, ``ė_χ = χ̇ - V κ``, ``χ = ψ + β``,
  ``φ_cmd = V² κ / g - (2 ζ ω V e_χ + ω² z) / g``;
* an optional pure delay (second-order Padé) at each actuator: the inner-loop lag of the
  robustness check.

A loop is broken at a signal by renaming that input of its consumer to ``<signal>_in``; the loop
transfer is ``L = -T(<signal>_in → <signal>)`` with every other loop closed, so that the closed
loop is ``1 / (1 + L)`` — the convention of ``control.stability_margins``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control as ct
import numpy as np
from scipy.linalg import block_diag

from fms_testbed.control.coupled_law import CoupledLawParams
from fms_testbed.control.linear import law_ss
from fms_testbed.core.units import G0_MPS2

BREAKS = ("throttle", "elevator", "nx_cmd", "dny_cmd", "aileron", "bank_cmd")
"""Signals the loops are broken at: the inner loops at their actuators, the coupled law's
thrust (n_x) and elevator (n_y) channels, the lateral law's bank command."""
LON_BREAKS = BREAKS[:4]
LAT_BREAKS = BREAKS[4:]


@dataclass(frozen=True, slots=True)
class InnerGains:
    """Inner-loop gains at the design point (the aircraft file's, already times ``k_q`` for
    the surface loops: elevator and aileron per g or rad, throttle per g)."""

    ny_kp: float
    ny_ki: float
    ny_kd: float
    ny_kff: float
    nx_kp: float
    nx_ki: float
    nx_kff: float
    bank_kp: float
    bank_ki: float
    bank_kd: float
    yaw_kp: float
    yaw_ki: float
    yaw_kd: float


def inner_gains(cfg, qbar_ratio: float) -> InnerGains:
    """:class:`InnerGains` of an aircraft configuration at ``k_q = q̄_ref / q̄`` (clipped to
    [0.25, 4] as in the JSBSim system).

    Parameters
    ----------
    cfg : aircraft configuration (``inner_loops``);  qbar_ratio : q̄_ref / q̄
    """
    k = min(4.0, max(0.25, qbar_ratio))
    g = cfg.inner_loops
    return InnerGains(k * g.ny.kp, k * g.ny.ki, k * g.ny.kd, k * g.ny.kff, g.nx.kp, g.nx.ki,
                      g.nx.kff, k * g.bank.kp, k * g.bank.ki, k * g.bank.kd, g.yaw.kp, g.yaw.ki,
                      g.yaw.kd)


@dataclass(frozen=True, slots=True)
class LateralLaw:
    """Path-law tuning: natural frequency ω (rad/s) and damping ζ of the cross-track error."""

    omega_rps: float = 0.10
    zeta: float = 0.9


def _pi(name: str, kp: float, ki: float, inputs: list[str], out: str, weights: list[float],
        extra: np.ndarray | None = None) -> ct.StateSpace:
    """``out = kp e + ki ∫e + extra·inputs`` with ``e = weights·inputs``: one integrator state."""
    w = np.asarray(weights, float).reshape(1, -1)
    D = kp * w + (0.0 if extra is None else np.asarray(extra, float).reshape(1, -1))
    return ct.ss([[0.0]], w, [[ki]], D, inputs=inputs, outputs=[out], states=[f"{name}_int"],
                 name=name)


def inner_blocks(g: InnerGains, V0_mps: float) -> list[ct.StateSpace]:
    """The four inner loops as blocks (module docstring); signals in SI, load factors in g.

    Parameters
    ----------
    g : gains at the point;  V0_mps : trim TAS, m/s (coordinated-turn yaw rate)
    """
    ny = _pi("ny_loop", -g.ny_kp, -g.ny_ki, ["dny_cmd", "ny", "q"], "elevator",
             [1.0, -1.0, 0.0], extra=[-g.ny_kff, 0.0, g.ny_kd])
    nx = _pi("nx_loop", g.nx_kp, g.nx_ki, ["nx_cmd", "nx"], "throttle", [1.0, -1.0],
             extra=[g.nx_kff, 0.0])
    bank = _pi("bank_loop", g.bank_kp, g.bank_ki, ["bank_cmd", "phi", "p"], "aileron",
               [1.0, -1.0, 0.0], extra=[0.0, 0.0, -g.bank_kd])
    yaw = _pi("yaw_loop", -g.yaw_kp, -g.yaw_ki, ["beta", "r", "phi"], "rudder", [1.0, 0.0, 0.0],
              extra=[0.0, g.yaw_kd, -g.yaw_kd * G0_MPS2 / V0_mps])
    return [ny, nx, bank, yaw]


def path_block(law: LateralLaw, V0_mps: float) -> ct.StateSpace:
    """Cross-track kinematics and the path law (module docstring): inputs (psi, beta, kappa),
    outputs (bank_cmd, xtk); states (xtk_m, chi_d_rad).

    Parameters
    ----------
    law : path-law tuning;  V0_mps : ground speed = TAS (calm air), m/s
    """
    g, w, z, V = G0_MPS2, law.omega_rps, law.zeta, V0_mps
    # states z (m), chi_d (rad): z' = V (psi + beta - chi_d), chi_d' = V kappa
    A = np.array([[0.0, -V], [0.0, 0.0]])
    B = np.array([[V, V, 0.0], [0.0, 0.0, V]])
    k = 2 * z * w * V / g
    C = np.array([[-(w * w) / g, k], [1.0, 0.0]])
    D = np.array([[-k, -k, V * V / g], [0.0, 0.0, 0.0]])
    return ct.ss(A, B, C, D, inputs=["psi", "beta", "kappa"], outputs=["bank_cmd", "xtk"],
                 states=["xtk_m", "chi_d_rad"], name="path_law")


def law_block(p: CoupledLawParams, V0_mps: float) -> ct.StateSpace:
    """The linearised coupled law with its θ input fed by the flight-path angle γ, and (when
    ``p.ny_trim_tau_s`` > 0) its n_y tracking-error integrator::

        ṅ_m = (Δn_y,law - n_m) / τ_m,   ṫ = (n_m - Δn_y) / τ_t,   Δn_y,cmd = Δn_y,law + t

    with the thrust channel's cross term on the command including ``t``.

    Parameters
    ----------
    p : law tuning;  V0_mps : trim TAS, m/s
    """
    s = law_ss(p, V0_mps)
    ins = ["V_cmd", "H_cmd", "V", "gamma", "h", "nx", "ny"]
    B0 = np.hstack([np.asarray(s.B), np.zeros((1, 1))])
    D0 = np.hstack([np.asarray(s.D), np.zeros((2, 1))])
    if p.ny_trim_tau_s <= 0:
        return ct.ss(s.A, B0, s.C, D0, inputs=ins, outputs=["nx_cmd", "dny_cmd"],
                     states=["nxa_int"], name="coupled_law")
    tm, tt = max(p.ny_model_tau_s, 1e-3), p.ny_trim_tau_s
    A = np.zeros((3, 3))
    A[0, 0], A[0, 2] = float(np.asarray(s.A)[0, 0]), G0_MPS2 / V0_mps
    A[1, 1], A[2, 1] = -1.0 / tm, 1.0 / tt
    B = np.vstack([B0, D0[1] / tm, np.zeros(7)])
    B[2, 6] = -1.0 / tt
    C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    return ct.ss(A, B, C, D0, inputs=ins, outputs=["nx_cmd", "dny_cmd"],
                 states=["nxa_int", "ny_model", "ny_trim"], name="coupled_law")


GUST_INPUTS = ("w_gust", "u_gust")
"""Disturbance inputs of :func:`with_gusts`: vertical wind (up positive) and headwind, m/s."""


def with_gusts(lon: ct.StateSpace, V0_mps: float) -> ct.StateSpace:
    """The longitudinal airframe ``lon`` with the wind inputs :data:`GUST_INPUTS`, m/s.

    The airframe's α and V are air-relative. An updraft w raises α by w/V₀ and the inertial
    climb rate by w (ḣ = V γ_air + w); a headwind u raises V by u. With ``x' = x - E w`` (E
    the α or V unit column scaled by 1/V₀ or 1) the state equation needs no derivative of the
    wind: ``ẋ' = A x' + (A E + e_h) w + B u`` for the updraft (``A E`` for the headwind), and
    every output sees the air-relative state: ``y = C x' + C E w + D u``, except the
    flight-path angle ``gamma`` the law reads, which is inertial (γ_air + w / V₀: the law's
    V_y is measured against the ground).

    Parameters
    ----------
    lon : longitudinal airframe (:func:`fms_testbed.sim.linearise.longitudinal_ss`)
    V0_mps : trim TAS, m/s
    """
    A, B, C, D = (np.asarray(m) for m in (lon.A, lon.B, lon.C, lon.D))
    states = list(lon.state_labels)
    ia, iV, ih = states.index("alpha_rad"), states.index("V_mps"), states.index("h_m")
    E = np.zeros((A.shape[0], 2))
    E[ia, 0], E[iV, 1] = 1.0 / V0_mps, 1.0
    Bw = A @ E
    Bw[ih, 0] += 1.0
    Dw = C @ E
    Dw[list(lon.output_labels).index("gamma"), 0] += 1.0 / V0_mps   # the law's γ is inertial
    return ct.ss(A, np.hstack([B, Bw]), C, np.hstack([D, Dw]), states=states,
                 inputs=list(lon.input_labels) + list(GUST_INPUTS),
                 outputs=list(lon.output_labels), name=lon.name)


def delay_block(signal: str, delay_s: float) -> ct.StateSpace:
    """Second-order Padé delay of ``delay_s`` seconds from ``<signal>_c`` to ``<signal>``."""
    num, den = ct.pade(delay_s, 2)
    d = ct.ss(ct.tf(num, den))
    return ct.ss(d.A, d.B, d.C, d.D, inputs=[f"{signal}_c"], outputs=[signal],
                 name=f"delay_{signal}")


def connect(blocks: list[ct.StateSpace], inputs: list[str], outputs: list[str]
            ) -> ct.StateSpace:
    """Interconnect ``blocks`` by signal name (every block input fed by the block output of the
    same name, or by the external input of that name, else 0), solving the algebraic loops of
    the direct feedthroughs: with ``u = K y + E r`` and ``y = C x + D u``,
    ``y = (I - D K)⁻¹ (C x + D E r)``.

    Parameters
    ----------
    blocks : systems with unique output names;  inputs, outputs : external signal names

    Returns
    -------
    StateSpace from ``inputs`` to ``outputs``
    """
    A = block_diag(*[np.asarray(b.A) for b in blocks])
    B = block_diag(*[np.asarray(b.B) for b in blocks])
    C = block_diag(*[np.asarray(b.C) for b in blocks])
    D = block_diag(*[np.asarray(b.D) for b in blocks])
    u_names = [n for b in blocks for n in b.input_labels]
    y_names = [n for b in blocks for n in b.output_labels]
    y_index = {n: i for i, n in enumerate(y_names)}
    K = np.zeros((len(u_names), len(y_names)))
    E = np.zeros((len(u_names), len(inputs)))
    for i, n in enumerate(u_names):
        if n in inputs:
            E[i, inputs.index(n)] = 1.0
        elif n in y_index:
            K[i, y_index[n]] = 1.0
    M = np.linalg.solve(np.eye(len(y_names)) - D @ K, np.hstack([C, D @ E]))
    Cy, Dy = M[:, :A.shape[0]], M[:, A.shape[0]:]
    sel = [y_index[n] for n in outputs]
    states = [n for b in blocks for n in b.state_labels]
    return ct.ss(A + B @ K @ Cy, B @ (K @ Dy + E), Cy[sel], Dy[sel], inputs=inputs,
                 outputs=outputs, states=states)


def _rename_input(sys: ct.StateSpace, signal: str, new: str) -> ct.StateSpace:
    if signal not in sys.input_labels:
        return sys
    ins = [new if n == signal else n for n in sys.input_labels]
    return ct.ss(sys.A, sys.B, sys.C, sys.D, inputs=ins, outputs=sys.output_labels,
                 states=sys.state_labels, name=sys.name)


def _rename_output(sys: ct.StateSpace, signal: str, new: str) -> ct.StateSpace:
    if signal not in sys.output_labels:
        return sys
    outs = [new if n == signal else n for n in sys.output_labels]
    return ct.ss(sys.A, sys.B, sys.C, sys.D, inputs=sys.input_labels, outputs=outs,
                 states=sys.state_labels, name=sys.name)


@dataclass(frozen=True)
class PointLoops:
    """Everything needed to build the loops of one design point.

    Attributes
    ----------
    lon, lat : airframe systems (:mod:`fms_testbed.sim.linearise` signal names)
    gains : inner loops at the point;  law : coupled-law tuning;  lateral : path-law tuning
    V0_mps : trim TAS, m/s;  actuator_delay_s : extra pure delay at each actuator, s
    """

    lon: ct.StateSpace
    lat: ct.StateSpace
    gains: InnerGains
    law: CoupledLawParams
    lateral: LateralLaw
    V0_mps: float
    actuator_delay_s: float = 0.0

    def blocks(self, axis: str) -> list[ct.StateSpace]:
        """Blocks of the ``"lon"`` or ``"lat"`` axis (delays inserted at the actuators)."""
        ny, nx, bank, yaw = inner_blocks(self.gains, self.V0_mps)
        if axis == "lon":
            out = [self.lon, ny, nx, law_block(self.law, self.V0_mps)]
            acts = ("throttle", "elevator")
        else:
            out = [self.lat, bank, yaw, path_block(self.lateral, self.V0_mps)]
            acts = ("aileron", "rudder")
        if self.actuator_delay_s > 0:
            for a in acts:
                out = [_rename_output(b, a, f"{a}_c") for b in out]
            out += [delay_block(a, self.actuator_delay_s) for a in acts]
        return out

    def closed(self, axis: str, inputs: list[str], outputs: list[str]) -> ct.StateSpace:
        """All loops of ``axis`` closed, from ``inputs`` to ``outputs`` (signal names)."""
        return connect(self.blocks(axis), inputs, outputs)

    def loop(self, signal: str) -> ct.StateSpace:
        """Loop transfer ``L`` broken at ``signal`` (one of :data:`BREAKS`), others closed."""
        axis = "lon" if signal in LON_BREAKS else "lat"
        blocks = [_rename_input(b, signal, f"{signal}_in") for b in self.blocks(axis)]
        return -connect(blocks, [f"{signal}_in"], [signal])


@dataclass(frozen=True, slots=True)
class Margins:
    """Stability margins of one broken loop.

    gm_db : gain margin, dB (inf: no phase crossover);  pm_deg : phase margin, deg
    delay_margin_s : phase margin over the crossover frequency, s
    disk_margin : disk margin α (balanced, skew 0: ±6 dB ↔ α = 0.67);  disk_gm_db, disk_pm_deg : the gain (dB)
        and phase (deg) variations it guarantees;  wc_rps : gain-crossover frequency, rad/s
    """

    gm_db: float
    pm_deg: float
    delay_margin_s: float
    disk_margin: float
    disk_gm_db: float
    disk_pm_deg: float
    wc_rps: float


GM_NONE_DB = 100.0
"""A gain margin above this (numerical crossings where |L| is negligible) counts as none: inf."""
OMEGA_RPS = np.logspace(-3, 2.5, 600)
"""Frequency grid of the margin computations, rad/s."""


def margins(L: ct.StateSpace, omega_rps: np.ndarray = OMEGA_RPS) -> Margins:
    """Gain, phase, delay and disk margins of a loop transfer ``L`` (closed loop 1/(1+L)).

    Gain margin is the smallest over every phase crossover (either side of 1), phase margin the
    smallest over every gain crossover; the delay margin is the smallest PM_i / ω_i.

    Parameters
    ----------
    L : SISO loop transfer;  omega_rps : frequency grid for the disk margin, rad/s
    """
    gm, pm, _, wpc, wgc, _ = ct.stability_margins(L, returnall=True)
    gms = [abs(20 * math.log10(g)) for g in np.atleast_1d(gm) if g > 0 and math.isfinite(g)]
    gms = [g for g in gms if g < GM_NONE_DB]
    pms = list(np.atleast_1d(pm))
    wgs = list(np.atleast_1d(wgc))
    gm_db = min(gms) if gms else math.inf
    pm_deg = min(pms) if pms else math.inf
    dm = [math.radians(p) / w for p, w in zip(pms, wgs) if w > 0 and p > 0]
    delay = min(dm) if dm else (math.inf if not pms else 0.0)
    wc = float(wgs[int(np.argmin(pms))]) if pms else math.nan
    DM, DGM, DPM = ct.disk_margins(L, omega_rps)
    return Margins(float(gm_db), float(pm_deg), float(delay), float(DM),
                   float(DGM), float(DPM), wc)


def closed_loop_damping(pl: PointLoops, axis: str) -> tuple[float, float]:
    """(smallest damping ratio of the oscillatory closed-loop poles, largest real part (1/s)) of
    the loops ``pl`` on ``axis`` (``"lon"`` or ``"lat"``)."""
    sys = pl.closed(axis, ["V_cmd", "H_cmd"] if axis == "lon" else ["kappa"],
                    ["V", "h"] if axis == "lon" else ["xtk"])
    ev = np.linalg.eigvals(np.asarray(sys.A))
    osc = [e for e in ev if abs(e.imag) > 1e-6]
    zeta = min((-e.real / abs(e) for e in osc), default=1.0)
    return float(zeta), float(max(ev.real))
