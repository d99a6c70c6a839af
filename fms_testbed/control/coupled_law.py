"""The multi-coupled thrust/elevator law tracking altitude and speed (Kulikov et al., 2017).

The law imposes second-order error dynamics on speed and altitude (paper eq. 2 and 5)::

    T_V² ΔV'' + 2 ξ_V T_V ΔV' + ΔV = 0,      ΔV = V - V_cmd
    T_H² ΔH'' + 2 ξ_H T_H ΔH' + ΔH = 0,      ΔH = H - H_cmd

on the point-mass plant (eq. 1) ``V' = g (n_xa - sin θ)``, ``θ' = (g/V)(n_ya - cos θ)``,
``H' = V sin θ``. Solving for the two load factors gives (eq. 7/8)::

    n_ya  = cos θ - (n_xa - sin θ) tan θ - 2 ξ_H V sin θ / (g T_H cos θ) - ΔH_lim / (g T_H² cos θ)
    n_xa' = (g/V) cos θ (n_ya - cos θ) - (2 ξ_V / T_V)(n_xa - sin θ) - ΔV / (g T_V²)

The thrust channel commands the *derivative* of n_xa, so it carries an integrator initialised from
the measured state on engagement (no bump). ``(g/V) cos θ (n_ya - cos θ)`` and the ``sin θ`` terms
are the cross-couplings that make the closed-loop transfer matrix from (V_cmd, H_cmd) to (V, H)
diagonal. ``ΔH_lim = clip(ΔH, ±dH_limit_m)`` turns a large step into a constant-V_y level change
followed by a second-order capture. ``form="paper"`` uses the small-angle law of eq. 19 instead.

Realisation on a 6-DoF aircraft (each addition measured on JSBSim; see the README section on
the coupled law):

* the damping term uses the measured n_xa (``(n_xa - sin θ) = V'/g``), so n_x tracking error of
  the inner loop does not turn into ΔV;
* g is the apparent gravity (:func:`gravity_ratio`: normal gravity at latitude and height minus
  the Eötvös and curvature terms) — load factors are forces over m·g0, and level flight east at
  47° N reads n_y = 0.9978;
* an n_y tracking-error integrator (``ny_trim_tau_s``) compensates the slow n_y disturbance
  (lift growing with speed) that the static altitude channel would otherwise pass into ΔH.

Limits. n_ya is clipped to the aircraft's ``[ny_min, ny_max]``; the thrust-channel cross term uses
the clipped value. When the throttle sits at a limit the n_xa integrator stops moving in the
unachievable direction and is pulled back to the measured n_xa (back-calculation), so there is no
wind-up at the top of a climb. With the throttle saturated and the speed on the losing side, a
latched speed protection limits the flight path to what the available thrust can fly at constant
speed (:func:`speed_protection_limit`) and keeps the throttle at the limit: no overspeed in an idle
descent and no speed decay in a thrust-limited climb.

Tuning (:class:`CoupledLawParams`, frozen) is apart from state (:class:`CoupledLawState`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.earth import A_M, OMEGA_IE_RPS, normal_gravity_mps2
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import G0_MPS2
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.atmosphere import isa
from fms_testbed.control.schedule import (REFRESH_REL, GainSchedule, qbar_from_state,
                                          schedule_from_config)

_SAT_EPS = 0.005
"""Throttle within this of a limit counts as saturated (normalised throttle)."""


@dataclass(frozen=True, slots=True)
class CoupledLawParams:
    """Tuning of the coupled law (units in names; load factors in g).

    Attributes
    ----------
    T_V_s, xi_V : speed-channel time constant (s) and damping ratio (eq. 2)
    T_H_s, xi_H : altitude-channel time constant (s) and damping ratio (eq. 5)
    dH_limit_m : altitude-error limit of the level-change mode, m
    ny_min, ny_max : normal-load-factor command limits, g
    throttle_min, throttle_max : throttle range of the n_x inner loop (saturation detection)
    form : ``"exact"`` (eq. 7/8, nonlinear, uses θ) or ``"paper"`` (eq. 19, small angles, V_y)
    use_measured_nx : use the measured n_xa in the damping term (n_xa - sin θ) = V'/g instead of
        the integrator's command; makes the law insensitive to n_x tracking error
    speed_protection : limit the flight path when the throttle is saturated
    anti_windup : stop/back-calculate the n_xa integrator at throttle limits (off only to show
        the wind-up it prevents)
    gamma_tau_s : time constant with which speed protection pulls θ to its limit, s
    ny_trim_tau_s : time constant of the n_y tracking-error integrator, s (0 = off). The
        altitude channel is static in n_y, so an inner-loop tracking error (lift change with speed,
        thrust pitching moment) goes straight into ΔH; this integrator adds
        ``∫ (lag(n_ya_law) - n_y_meas) dt / ny_trim_tau_s`` to the command, bounded to ±0.1 g —
        the altitude-channel counterpart of ``use_measured_nx``
    ny_model_tau_s : first-order model of the n_y inner loop, s: the integrator compares the
        measurement with the law's command passed through it, so the loop's normal lag during a
        manoeuvre is not mistaken for a tracking error
    """

    T_V_s: float
    xi_V: float
    T_H_s: float
    xi_H: float
    dH_limit_m: float = 100.0
    ny_min: float = 0.0
    ny_max: float = 2.0
    throttle_min: float = 0.0
    throttle_max: float = 1.0
    form: str = "exact"
    use_measured_nx: bool = True
    speed_protection: bool = True
    anti_windup: bool = True
    gamma_tau_s: float = 2.0
    ny_trim_tau_s: float = 2.0
    ny_model_tau_s: float = 0.5

    def __post_init__(self):
        for name in ("T_V_s", "xi_V", "T_H_s", "xi_H", "dH_limit_m", "gamma_tau_s"):
            if not getattr(self, name) > 0:
                raise ValueError(f"CoupledLawParams.{name} must be > 0, got {getattr(self, name)}")
        if self.form not in ("exact", "paper"):
            raise ValueError(f"CoupledLawParams.form must be 'exact' or 'paper', got {self.form!r}")
        if not self.ny_min < 1.0 < self.ny_max:
            raise ValueError("CoupledLawParams needs ny_min < 1 < ny_max")

    @property
    def vy_limit_mps(self) -> float:
        """Steady climb/descent rate of the level-change mode, ``dH_limit / (2 ξ_H T_H)``, m/s."""
        return self.dH_limit_m / (2.0 * self.xi_H * self.T_H_s)


def params_from_config(cfg: AircraftConfig, **overrides) -> CoupledLawParams:
    """Build :class:`CoupledLawParams` from an aircraft's ``coupled_law`` block and limits.

    Parameters
    ----------
    cfg : aircraft configuration; its ``coupled_law`` block must be present
    **overrides : any :class:`CoupledLawParams` field (e.g. ``T_V_s=8.0``)
    """
    gains = cfg.coupled_law
    if gains is None:
        raise ConfigError(f"{cfg.source_file or cfg.name}: no 'coupled_law' block (T_V_s, xi_V, "
                          "T_H_s, xi_H) — run `fms-testbed tune` or add one")
    p = CoupledLawParams(
        T_V_s=gains.T_V_s, xi_V=gains.xi_V, T_H_s=gains.T_H_s, xi_H=gains.xi_H,
        dH_limit_m=gains.dH_limit_m, ny_min=cfg.limits.ny_min, ny_max=cfg.limits.ny_max,
        throttle_min=cfg.inner_loops.throttle_min, throttle_max=cfg.inner_loops.throttle_max)
    return replace(p, **overrides) if overrides else p


@dataclass(slots=True)
class CoupledLawState:
    """Run-time state of the law.

    nxa_cmd: n_xa integrator (the tangential load-factor command), g
    engaged: whether :meth:`CoupledLaw.engage` has been called
    sat_hi, sat_lo: throttle at max / idle at the last update
    protect_mode: speed protection: +1 climb limited at max throttle, -1 descent limited at
        idle, 0 off (latched until the altitude channel asks for less than the limit)
    dny: last Δn_ya = n_ya - 1 command, g
    ny_trim: n_y tracking-error integrator, g
    ny_model: the law's n_y command through the inner-loop model, g
    """

    nxa_cmd: float = 0.0
    engaged: bool = False
    sat_hi: bool = False
    sat_lo: bool = False
    protect_mode: int = 0
    dny: float = 0.0
    ny_trim: float = 0.0
    ny_model: float = 1.0


# --- the law's steps as pure functions -----------------------------------------------------

def gravity_ratio(lat_rad: float, alt_m: float, ve_mps: float = 0.0, vn_mps: float = 0.0
                  ) -> float:
    """Apparent gravity over standard gravity, g_eff / g0, dimensionless.

    Parameters
    ----------
    lat_rad : geodetic latitude, rad;  alt_m : altitude, m
    ve_mps, vn_mps : ground velocity east / north, m/s (Eötvös and path-curvature terms)

    Notes
    -----
    Normal gravity γ(φ, h) (:func:`fms_testbed.core.earth.normal_gravity_mps2`: WGS-84 Somigliana
    with the second-order height term, NIMA TR8350.2 eq. 4-1, 4-3), minus the Eötvös term
    2 Ω v_E cos φ and the curvature term v² / (a + h). Load factors are forces over m·g0, so
    level flight reads n_y = g_eff / g0, not 1 (0.99901 at 3000 m, 45° N, at rest;
    0.9978 flying east at 400 km/h at 47° N). Ignoring it leaves a steady altitude offset
    ΔH = (1 - g_eff/g0) g0 T_H² (0.8 m for T_H = 8 s). The normal-gravity part matches JSBSim's
    trimmed n_y to 1e-5 (measured at 0/45/70° and 1000/3000/10000 m).
    """
    g = normal_gravity_mps2(lat_rad, alt_m)
    g -= 2.0 * OMEGA_IE_RPS * ve_mps * math.cos(lat_rad) + (ve_mps ** 2 + vn_mps ** 2) / (
        A_M + alt_m)
    return g / G0_MPS2


def clip_altitude_error(dH_m: float, limit_m: float) -> float:
    """``ΔH_lim = clip(ΔH, -limit, +limit)`` (level-change mode, eq. 19), m.

    Parameters
    ----------
    dH_m : altitude error H - H_cmd, m
    limit_m : the limit (``dH_limit_m``), m
    """
    return min(max(dH_m, -limit_m), limit_m)


def altitude_channel_ny(p: CoupledLawParams, dH_lim_m: float, tas_mps: float, gamma_rad: float,
                        nxa: float, g_ratio: float = 1.0) -> float:
    """Normal load-factor command n_ya (g) giving the altitude error dynamics of eq. 5.

    Parameters
    ----------
    p : law tuning
    dH_lim_m : limited altitude error H - H_cmd, m
    tas_mps : airspeed V, m/s
    gamma_rad : flight-path angle θ, rad
    nxa : tangential load factor used for the V' sin θ term, g
    g_ratio : local gravity over g0 (:func:`gravity_ratio`); 1 reproduces the paper

    Returns
    -------
    n_ya (g), unclipped. ``exact``: eq. 7 with weight terms scaled by g/g0;
    ``paper``: g/g0 + Δn_ya of eq. 19 with V_y = V θ.
    """
    kd = 2.0 * p.xi_H / (G0_MPS2 * p.T_H_s)
    kp = 1.0 / (G0_MPS2 * p.T_H_s ** 2)
    if p.form == "paper":
        return g_ratio - kd * tas_mps * gamma_rad - kp * dH_lim_m
    s, c = math.sin(gamma_rad), math.cos(gamma_rad)
    return g_ratio * c - (nxa - g_ratio * s) * s / c - (kd * tas_mps * s + kp * dH_lim_m) / c


def thrust_channel_rate(p: CoupledLawParams, dV_mps: float, tas_mps: float, gamma_rad: float,
                        nxa: float, ny_cmd: float, g_ratio: float = 1.0) -> float:
    """Rate of the n_xa command, g/s, giving the speed error dynamics of eq. 2 (eq. 8 / 19).

    Parameters
    ----------
    p : law tuning
    dV_mps : speed error V - V_cmd, m/s
    tas_mps : airspeed V, m/s
    gamma_rad : flight-path angle θ, rad
    nxa : tangential load factor in the damping term (measured or commanded), g
    ny_cmd : the (limited) normal load-factor command of the elevator channel, g
    g_ratio : local gravity over g0 (:func:`gravity_ratio`)

    Returns
    -------
    dn_xa/dt, g/s. The first term is the cross-coupling that cancels the elevator's effect on V.
    """
    if p.form == "paper":
        cross = (G0_MPS2 / tas_mps) * (ny_cmd - g_ratio)
        damp = nxa - gamma_rad
    else:
        c = g_ratio * math.cos(gamma_rad)
        cross = (G0_MPS2 / tas_mps) * c * (ny_cmd - c)
        damp = nxa - g_ratio * math.sin(gamma_rad)
    return cross - (2.0 * p.xi_V / p.T_V_s) * damp - dV_mps / (G0_MPS2 * p.T_V_s ** 2)


def speed_protection_limit(p: CoupledLawParams, side: int, dV_mps: float, tas_mps: float,
                           gamma_rad: float, nx_meas: float, g_ratio: float = 1.0) -> float:
    """n_ya limit (g) at which the available thrust still holds the speed (throttle at a limit).

    With the throttle at a limit, V' = g (n_x - sin θ) is set by θ alone. Demanding
    V' = -ΔV / τ with τ = T_V / (2 ξ_V) gives the flight-path limit
    ``sin θ_lim = n_x + ΔV / (g τ)``, bounded to θ_lim ≥ 0 at max throttle and θ_lim ≤ 0 at idle
    (the protection gives up the climb or the descent, never trades altitude the other way).
    The limit is ``cos θ + (V / g)(θ_lim - θ) / gamma_tau_s``: a ceiling at max throttle
    (``side`` = +1, no speed decay in a climb), a floor at idle (``side`` = -1, no overspeed in
    a descent).

    Parameters
    ----------
    p : law tuning;  side : +1 max throttle (ceiling), -1 idle (floor)
    dV_mps : speed error V - V_cmd, m/s;  tas_mps : airspeed, m/s
    gamma_rad : flight-path angle, rad;  nx_meas : measured tangential load factor, g
    g_ratio : apparent gravity over g0 (:func:`gravity_ratio`)
    """
    tau = p.T_V_s / (2.0 * p.xi_V)
    s_lim = min(max((nx_meas + dV_mps / (G0_MPS2 * tau)) / g_ratio, -0.5), 0.5)
    s_lim = max(s_lim, 0.0) if side > 0 else min(s_lim, 0.0)
    return g_ratio * math.cos(gamma_rad) + (tas_mps / G0_MPS2) * (
        math.asin(s_lim) - gamma_rad) / p.gamma_tau_s


class CoupledLaw:
    """The coupled thrust/elevator law as a vertical law (``engage`` / ``update``).

    Parameters
    ----------
    aircraft_cfg : aircraft configuration (gains from its ``coupled_law`` block), or ``None``
        when ``params`` is given
    params : explicit tuning (overrides the config)
    """

    name = "coupled"

    def __init__(self, aircraft_cfg: AircraftConfig | None = None,
                 params: CoupledLawParams | None = None, schedule: GainSchedule | None = None):
        if params is None:
            if aircraft_cfg is None:
                raise ValueError("CoupledLaw needs an aircraft config or params")
            params = params_from_config(aircraft_cfg)
            schedule = schedule or schedule_from_config(aircraft_cfg)
        self.params = params
        self.schedule = schedule
        self.state = CoupledLawState()

    def _follow_schedule(self, state: AircraftState) -> None:
        """Take the scheduled (T_V, ξ_V, T_H, ξ_H, τ_ny-trim) at the measured q̄ and mass when one of
        them moved by more than ``REFRESH_REL`` (:mod:`fms_testbed.control.schedule`)."""
        ps, ts = float(state.p_static_pa), float(state.t_static_k)
        if not (math.isfinite(ps) and math.isfinite(ts)):
            ts, ps, _ = isa(float(state.alt_m))
        want = self.schedule.values(qbar_from_state(float(state.tas_mps), ps, ts),
                                    float(state.mass_kg))
        p = self.params
        if any(abs(v - getattr(p, k)) > REFRESH_REL * abs(getattr(p, k)) for k, v in want.items()):
            self.params = replace(p, **want)

    def reset(self) -> None:
        """Forget the run-time state (the next update re-engages)."""
        self.state = CoupledLawState()

    def engage(self, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float) -> None:
        """Take over: initialise the n_xa integrator from the measured n_xa (no bump).

        Parameters
        ----------
        state : measured aircraft state (``nx``, g, is used)
        alt_cmd_m, tas_cmd_mps : targets, m and m/s (unused; part of the protocol)
        """
        self.state = CoupledLawState(nxa_cmd=float(state.nx), engaged=True,
                                     ny_model=float(state.ny) * math.cos(state.roll_rad))

    def update(self, dt_s: float, state: AircraftState, alt_cmd_m: float, tas_cmd_mps: float
               ) -> tuple[float, float]:
        """One outer-loop step: return ``(nx_cmd, ny_cmd)`` in g.

        Steps: saturation → altitude channel (eq. 7) → n_y limits → speed protection →
        n_y tracking-error integrator → thrust channel (eq. 8) → anti-windup → integrate.

        Parameters
        ----------
        dt_s : step, s
        state : measured aircraft state (tas_mps, alt_m, gamma_rad, nx, throttle; ny and roll_rad
            for the n_y trim: the law uses the vertical-plane component n_y cos φ)
        alt_cmd_m : altitude target, m;  tas_cmd_mps : true-airspeed target, m/s
        """
        if self.schedule is not None:
            self._follow_schedule(state)
        p, st = self.params, self.state
        if not st.engaged:
            self.engage(state, alt_cmd_m, tas_cmd_mps)
        V = max(float(state.tas_mps), 1.0)
        gam = float(state.gamma_rad)
        nx_meas = float(state.nx)
        st.sat_hi = state.throttle >= p.throttle_max - _SAT_EPS
        st.sat_lo = state.throttle <= p.throttle_min + _SAT_EPS
        nxa = nx_meas if p.use_measured_nx else st.nxa_cmd
        dV = V - tas_cmd_mps
        dH_lim = clip_altitude_error(float(state.alt_m) - alt_cmd_m, p.dH_limit_m)
        v = state.v_enu_mps
        gr = gravity_ratio(float(state.lat_rad), float(state.alt_m), float(v[0]), float(v[1]))

        ny = altitude_channel_ny(p, dH_lim, V, gam, nxa, gr)
        ny = min(max(ny, p.ny_min), p.ny_max)
        ny = self._protect(ny, dV, V, gam, nx_meas, gr)
        ny = min(max(ny, p.ny_min), p.ny_max)

        if p.ny_trim_tau_s > 0:
            ny = self._ny_trim(ny, dt_s, state)

        if st.protect_mode:
            # flight path holds the speed; keep the throttle at its limit
            st.nxa_cmd = nx_meas + 0.02 * st.protect_mode
        else:
            rate = thrust_channel_rate(p, dV, V, gam, nxa, ny, gr)
            # anti-windup: no motion into an unachievable command; back-calculate to the
            # measurement
            if st.sat_hi and p.anti_windup:
                rate = min(rate, 0.0)
                st.nxa_cmd = min(st.nxa_cmd, nx_meas + 0.01)
            if st.sat_lo and p.anti_windup:
                rate = max(rate, 0.0)
                st.nxa_cmd = max(st.nxa_cmd, nx_meas - 0.01)
            st.nxa_cmd += rate * dt_s
        st.dny = ny - 1.0
        return st.nxa_cmd, ny

    def _ny_trim(self, ny_law: float, dt_s: float, state: AircraftState) -> float:
        """n_y tracking-error integrator (``ny_trim_tau_s``): the command plus the trim, the
        model of the inner loop advanced, the trim integrated unless the command is clipped."""
        p, st = self.params, self.state
        ny = min(max(ny_law + st.ny_trim, p.ny_min), p.ny_max)
        a = min(dt_s / p.ny_model_tau_s, 1.0) if p.ny_model_tau_s > 0 else 1.0
        st.ny_model += a * (ny_law - st.ny_model)
        if p.ny_min < ny < p.ny_max:
            # measured n_y, vertical-plane component (the law works in the vertical plane)
            ny_meas = float(state.ny) * math.cos(state.roll_rad)
            st.ny_trim += (st.ny_model - ny_meas) * dt_s / p.ny_trim_tau_s
            st.ny_trim = min(max(st.ny_trim, -0.1), 0.1)
        return ny

    def _protect(self, ny: float, dV: float, V: float, gam: float, nx_meas: float,
                 gr: float) -> float:
        """Speed protection with a latch (see :func:`speed_protection_limit`).

        Enters when the throttle is at a limit, the speed is on the losing side (below target at
        max throttle, above at idle) and the altitude channel asks for more climb (descent) than
        the thrust can fly at constant speed (by 0.005 g); leaves when the altitude channel's
        own demand falls back inside the limit by 0.005 g (e.g. the capture of the target
        altitude) or the speed error changes sign.
        """
        p, st = self.params, self.state
        if not p.speed_protection:
            st.protect_mode = 0
            return ny
        if st.protect_mode == 0:
            side = 1 if st.sat_hi else -1 if st.sat_lo else 0
            if side:
                lim = speed_protection_limit(p, side, dV, V, gam, nx_meas, gr)
                if (ny - lim) * side > 0.005 and dV * side < 0:
                    st.protect_mode = side
        if st.protect_mode:
            side = st.protect_mode
            lim = speed_protection_limit(p, side, dV, V, gam, nx_meas, gr)
            if (ny - lim) * side <= -0.005 or dV * side > 0:
                st.protect_mode = 0
            else:
                ny = lim
        return ny
