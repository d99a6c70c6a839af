"""Lateral path-following law: curvature feed-forward plus cross-track and track-angle feedback.

Cross-track dynamics about the path (small angles, ground speed V_g, air speed V, bank φ)::

    ż = V_g sin(χ - χ_d),      ẍ ≈ V_g (χ̇ - χ̇_d),     χ̇ = g tan φ / V_g (coordinated turn in
    the ground frame, wind absorbed into the track)

With ``tan φ = tan φ_ff + u`` and the feed-forward ``tan φ_ff = V_g² κ / g`` (the bank that flies
an arc of curvature κ at the current ground speed), the error obeys ``z̈ = g u``. Choosing

    u = -(2 ζ ω V_g sin(χ - χ_d) + ω² z) / g

gives ``z̈ + 2 ζ ω ż + ω² z = 0``. Written as a track-angle loop, the cross-track term becomes a
commanded intercept angle ``Δχ_c = -asin(clip(ω z / (2 ζ V_g), ±sin 45°))`` so that a large
offset is flown back at no more than 45°, and ``u = (2 ζ ω V_g / g) sin(Δχ_c - (χ - χ_d))``.
The bank is limited to the aircraft's ``bank_max_deg``; the runner rate-limits it.

Wind is handled through the ground track χ and ground speed V_g (the navigation solution's
ground velocity), so the aircraft crabs automatically.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.units import G0_MPS2


@dataclass(frozen=True, slots=True)
class LateralGains:
    """Tuning of the path-following law.

    omega_rps: natural frequency of the cross-track error dynamics, rad/s; zeta: damping ratio;
    intercept_max_deg: largest intercept angle commanded back to the path, deg;
    bank_max_deg: bank limit, deg; roll_rate_dps: the bank-command rate limit the runner applies
    (used for bank anticipation at curvature changes), deg/s; roll_lag_s: bank-loop lag, s.
    """

    omega_rps: float = 0.10
    zeta: float = 0.9
    intercept_max_deg: float = 45.0
    bank_max_deg: float = 25.0
    roll_rate_dps: float = 5.0
    roll_lag_s: float = 1.0

    @classmethod
    def for_aircraft(cls, cfg, **overrides) -> "LateralGains":
        """Gains with the aircraft's bank limit and roll-rate limit (``cfg.limits``)."""
        kw = {"bank_max_deg": cfg.limits.bank_max_deg, "roll_rate_dps": cfg.limits.roll_rate_max_dps}
        kw.update(overrides)
        return cls(**kw)


def feedforward_bank_rad(gs_mps: float, curvature_1pm: float) -> float:
    """Bank that flies curvature κ (1/m, + right) at ground speed V_g: atan(V_g² κ / g), rad."""
    return math.atan(gs_mps * gs_mps * curvature_1pm / G0_MPS2)


def anticipation_m(gs_mps: float, bank_change_rad: float, gains: LateralGains) -> float:
    """Distance before a curvature change at which to switch the feed-forward, m.

    The runner ramps the bank at ``roll_rate``; switching half the ramp early, plus the bank
    loop's lag, centres the roll on the geometric transition point:
    ``d = V_g (|Δφ| / (2 p_max) + τ)``.
    """
    return gs_mps * (abs(bank_change_rad) / (2.0 * math.radians(gains.roll_rate_dps))
                     + gains.roll_lag_s)


def bank_command_rad(xtk_m: float, track_err_rad: float, gs_mps: float, curvature_1pm: float,
                     gains: LateralGains) -> float:
    """Bank command, rad (+ right), from the path errors.

    Parameters
    ----------
    xtk_m : cross-track error, m, positive right of the path
    track_err_rad : ground track minus desired track, rad, wrapped to (-π, π]
    gs_mps : ground speed, m/s
    curvature_1pm : path curvature at the foot point (or anticipated), 1/m, + right
    gains : tuning

    Returns
    -------
    Bank command limited to ±bank_max_deg, rad (module docstring: the law).
    """
    v = max(gs_mps, 10.0)
    w, z = gains.omega_rps, gains.zeta
    s_max = math.sin(math.radians(gains.intercept_max_deg))
    s = w * xtk_m / (2.0 * z * v)
    s = -s_max if s > s_max else (s_max if s < -s_max else -s)
    d_chi_c = math.asin(s)
    e = d_chi_c - track_err_rad
    if e > math.pi / 2:
        e = math.pi / 2
    elif e < -math.pi / 2:
        e = -math.pi / 2
    tan_phi = v * v * curvature_1pm / G0_MPS2 + 2.0 * z * w * v / G0_MPS2 * math.sin(e)
    phi = math.atan(tan_phi)
    lim = math.radians(gains.bank_max_deg)
    return lim if phi > lim else (-lim if phi < -lim else phi)


def wrap_pi(a_rad: float) -> float:
    """Angle wrapped into [-π, π), rad."""
    return (a_rad + math.pi) % (2 * math.pi) - math.pi


def heading_hold_bank_rad(heading_cmd_rad: float, heading_rad: float, kp: float,
                          bank_max_rad: float) -> float:
    """Heading hold: bank command proportional to the heading error, limited.

    Parameters
    ----------
    heading_cmd_rad : heading to hold, rad (true)
    heading_rad : current (navigation) heading, rad (true)
    kp : heading-hold gain, rad of bank per rad of heading error (aircraft file
        ``inner_loops.heading_kp``)
    bank_max_rad : bank limit, rad

    Returns
    -------
    bank command, rad (right wing down positive)
    """
    err = wrap_pi(heading_cmd_rad - heading_rad)
    return max(-bank_max_rad, min(bank_max_rad, kp * err))
