"""Baseline vertical laws the coupled law is compared against, tuned from the same (T, ξ).

(a) :class:`SeparateChannelsLaw` — the paper's "separate channels": a PI autothrottle on ΔV
    designed for (T_V, ξ_V) on the simplified speed dynamics V' = g n_x::

        n_x = n_x0 - (2 ξ_V / (g T_V)) ΔV - (1 / (g T_V²)) ∫ ΔV dt

    (closed loop on V' = g n_x: T_V² ΔV'' + 2 ξ_V T_V ΔV' + ΔV = 0), feeding the same n_x inner
    loop; the elevator channel is the coupled law's (eq. 7 with the ±dH limit). No cross terms.

(b) :class:`TecsLaw` — a total-energy control law (Lambregts; ArduPilot ``AP_TECS`` / PX4 TECS
    structure). Outer loops turn the errors into a flight-path and an acceleration demand::

        γ_c = clip(-ΔH, ±dH_lim) / (2 ξ_H T_H V),      V'_c / g = -ΔV / (2 ξ_V T_V g)

    Thrust closes the specific total-energy rate (γ + V'/g ≈ n_x), elevator the energy
    distribution rate (γ - V'/g)::

        n_x  = (γ_c + V'_c/g) + k_T E_err + k_TI ∫ E_err,     E_err = (γ_c + V'_c/g) - (γ + V'/g)
        Δn_y = (V / g) [k_L L_err + k_LI ∫ L_err],             L_err = (γ_c - V'_c/g) - (γ - V'/g)

    with the TECS defaults k_T = 0.5 (throttle damping) and k_TI = 0.3 1/s (integrator gain), and
    an elevator PI of time constant τ_E = min(T_V, T_H) / 2: k_L = 1/τ_E, k_LI = 1/(4 τ_E²).
    As in AP_TECS the demands are rate limited: γ_c slews at most ``0.1 g / V`` rad/s.
    Integrators freeze at throttle / n_y limits (anti-windup).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import G0_MPS2
from fms_testbed.control.coupled_law import (CoupledLawParams, altitude_channel_ny, clip_altitude_error,
                          gravity_ratio, params_from_config)


@dataclass(slots=True)
class _IntegratorState:
    engaged: bool = False
    i1: float = 0.0
    i2: float = 0.0


class SeparateChannelsLaw:
    """Baseline (a): PI autothrottle on ΔV + the coupled law's elevator channel, no cross terms.

    Parameters
    ----------
    aircraft_cfg : aircraft configuration (T_V, ξ_V, T_H, ξ_H, limits), or ``None`` with params
    params : explicit tuning
    """

    name = "pi"

    def __init__(self, aircraft_cfg: AircraftConfig | None = None,
                 params: CoupledLawParams | None = None):
        self.params = params if params is not None else params_from_config(aircraft_cfg)
        self.state = _IntegratorState()

    def engage(self, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float) -> None:
        """Initialise the integral term to the measured n_x (no bump)."""
        self.state = _IntegratorState(engaged=True, i1=float(state.nx))

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:
        """Return ``(nx_cmd, ny_cmd)`` in g (PI on ΔV; eq. 7 elevator channel)."""
        p, st = self.params, self.state
        if not st.engaged:
            self.engage(state, alt_cmd_m, tas_cmd_mps)
        V = max(float(state.tas_mps), 1.0)
        dV = V - tas_cmd_mps
        sat_hi = state.throttle >= p.throttle_max - 0.005
        sat_lo = state.throttle <= p.throttle_min + 0.005
        di = -dV / (G0_MPS2 * p.T_V_s ** 2)
        if not ((sat_hi and di > 0) or (sat_lo and di < 0)):
            st.i1 += di * dt_s
        nx = st.i1 - 2.0 * p.xi_V / (G0_MPS2 * p.T_V_s) * dV
        dH = clip_altitude_error(float(state.alt_m) - alt_cmd_m, p.dH_limit_m)
        gr = gravity_ratio(float(state.lat_rad), float(state.alt_m), float(state.v_enu_mps[0]),
                           float(state.v_enu_mps[1]))
        ny = altitude_channel_ny(p, dH, V, float(state.gamma_rad), float(state.nx), gr)
        return nx, min(max(ny, p.ny_min), p.ny_max)


class TecsLaw:
    """Baseline (b): total-energy control (thrust ↔ energy rate, elevator ↔ energy balance).

    Parameters
    ----------
    aircraft_cfg : aircraft configuration (T_V, ξ_V, T_H, ξ_H, limits), or ``None`` with params
    params : explicit tuning
    tau_E_s : energy-loop time constant, s (default ``min(T_V, T_H) / 2``)
    """

    name = "tecs"

    def __init__(self, aircraft_cfg: AircraftConfig | None = None,
                 params: CoupledLawParams | None = None, tau_E_s: float | None = None):
        self.params = params if params is not None else params_from_config(aircraft_cfg)
        self.tau_E_s = tau_E_s if tau_E_s is not None else min(self.params.T_V_s,
                                                               self.params.T_H_s) / 2.0
        self.k_T, self.k_TI_ps = 0.5, 0.3
        self.state = _IntegratorState()

    def engage(self, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float) -> None:
        """Start with zero integrators and the measured γ: the feed-forward carries the trim."""
        self.state = _IntegratorState(engaged=True)
        self.gamma_c_rad = float(state.gamma_rad)

    def demands(self, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
                ) -> tuple[float, float]:
        """Outer loops: flight-path demand γ_c (rad) and acceleration demand V'_c/g (g)."""
        p = self.params
        V = max(float(state.tas_mps), 1.0)
        dH = clip_altitude_error(float(state.alt_m) - alt_cmd_m, p.dH_limit_m)
        gamma_c = math.asin(max(-0.3, min(0.3, -dH / (2.0 * p.xi_H * p.T_H_s * V))))
        acc_c = -(V - tas_cmd_mps) / (2.0 * p.xi_V * p.T_V_s * G0_MPS2)
        return gamma_c, acc_c

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:
        """Return ``(nx_cmd, ny_cmd)`` in g: demands → energy errors → thrust → elevator."""
        p, st = self.params, self.state
        if not st.engaged:
            self.engage(state, alt_cmd_m, tas_cmd_mps)
        V = max(float(state.tas_mps), 1.0)
        gam = float(state.gamma_rad)
        gr = gravity_ratio(float(state.lat_rad), float(state.alt_m), float(state.v_enu_mps[0]),
                           float(state.v_enu_mps[1]))
        acc = float(state.nx) - gr * math.sin(gam)     # V'/g0 from the measured n_x
        gamma_c, acc_c = self.demands(state, alt_cmd_m, tas_cmd_mps)
        step = 0.1 * G0_MPS2 / V * dt_s
        gamma_c = self.gamma_c_rad = min(max(gamma_c, self.gamma_c_rad - step),
                                         self.gamma_c_rad + step)
        e_err = (gamma_c + acc_c) - (gam + acc)
        l_err = (gamma_c - acc_c) - (gam - acc)
        k, ki = 1.0 / self.tau_E_s, 1.0 / (4.0 * self.tau_E_s ** 2)
        sat_hi = state.throttle >= p.throttle_max - 0.005
        sat_lo = state.throttle <= p.throttle_min + 0.005
        if not ((sat_hi and e_err > 0) or (sat_lo and e_err < 0)):
            st.i1 += self.k_TI_ps * e_err * dt_s
        nx = math.sin(gamma_c) + acc_c + self.k_T * e_err + st.i1
        dny = (V / G0_MPS2) * (k * l_err + st.i2)
        ny = gr * math.cos(gam) + dny
        ny_c = min(max(ny, p.ny_min), p.ny_max)
        if ny_c == ny:
            st.i2 += ki * l_err * dt_s
        return nx, ny_c
