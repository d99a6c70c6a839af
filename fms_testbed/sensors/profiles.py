"""Synthetic manoeuvre profiles for the navigation tests and the Monte-Carlo runs: a sequence of
segments (turn rate, climb angle, acceleration) integrated into a kinematically consistent true
trajectory, without the flight simulator.

Each :class:`Segment` holds for ``duration_s``: turn rate ψ' (the target of a coordinated turn,
roll φ = atan(V ψ'/g); the heading follows the lagging roll, ψ' = g tan φ / V), flight-path angle γ (pitch = γ + ``alpha_rad``, a constant angle of attack) and
longitudinal acceleration V'. Kinematics (flat-Earth attitude rates, ellipsoidal position)::

    V_ENU = V (cos γ sin ψ, cos γ cos ψ, sin γ),   a_ENU = dV_ENU/dt
    f^N = a_ENU + (2 Ω_IE + Ω_EN) × V - g^N,        f^B = C_N^B f^N
    p = φ' - ψ' sin θ,  q = θ' cos φ + ψ' cos θ sin φ,  r = -θ' sin φ + ψ' cos θ cos φ

Roll and pitch change smoothly between segments (first-order lag of ``attitude_tau_s``) so the
body rates stay finite. The result is a :class:`~fms_testbed.sensors.sins.trajectory.Trajectory`;
:func:`aircraft_states` turns it into the :class:`~fms_testbed.core.state.AircraftState` stream a
navigation source's ``update`` takes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.earth import earth_rate_enu, radii_m, transport_rate_enu
from fms_testbed.core.state import AircraftState
from fms_testbed.core.units import G0_MPS2
from fms_testbed.sensors.sins.model import dcm_body_to_enu, gravity_up
from fms_testbed.sensors.sins.trajectory import Trajectory


@dataclass(frozen=True)
class Segment:
    """One manoeuvre segment: duration s, turn rate deg/s (right positive), flight-path angle
    deg, longitudinal acceleration m/s²."""

    duration_s: float
    turn_rate_dps: float = 0.0
    gamma_deg: float = 0.0
    accel_mps2: float = 0.0


def fly_profile(segments: list[Segment], dt_s: float = 0.1, lat_deg: float = 47.0,
                lon_deg: float = 8.0, alt_m: float = 3000.0, speed_mps: float = 120.0,
                heading_deg: float = 0.0, alpha_rad: float = 0.03,
                attitude_tau_s: float = 2.0, label: str = "profile") -> Trajectory:
    """Integrate ``segments`` into a true trajectory sampled every ``dt_s`` (s).

    Parameters
    ----------
    segments : the manoeuvres, in order
    lat_deg, lon_deg, alt_m, speed_mps, heading_deg : initial position (deg, m), ground speed
        (m/s) and heading (deg true)
    alpha_rad : constant angle of attack added to the flight-path angle for pitch, rad
    attitude_tau_s : time constant of the roll/pitch transitions between segments, s
    """
    n = int(round(sum(s.duration_s for s in segments) / dt_s)) + 1
    t = np.arange(n) * dt_s
    seg_end = np.cumsum([s.duration_s for s in segments])
    idx = np.minimum(np.searchsorted(seg_end, t, side="right"), len(segments) - 1)
    lat, lon, h = np.empty(n), np.empty(n), np.empty(n)
    v_enu, rpy = np.empty((n, 3)), np.empty((n, 3))
    lat[0], lon[0], h[0] = math.radians(lat_deg), math.radians(lon_deg), alt_m
    V, psi = speed_mps, math.radians(heading_deg)
    gam = math.radians(segments[0].gamma_deg)
    roll = math.atan(V * math.radians(segments[0].turn_rate_dps) / G0_MPS2)
    a = dt_s / attitude_tau_s
    for k in range(n):
        s = segments[idx[k]]
        wz = math.radians(s.turn_rate_dps)
        if k > 0:
            roll += a * (math.atan(V * wz / G0_MPS2) - roll)
            gam += a * (math.radians(s.gamma_deg) - gam)
            psi += G0_MPS2 * math.tan(roll) / V * dt_s        # coordinated with the roll
            V += s.accel_mps2 * dt_s
        v_enu[k] = V * np.array([math.cos(gam) * math.sin(psi), math.cos(gam) * math.cos(psi),
                                 math.sin(gam)])
        rpy[k] = roll, gam + alpha_rad, psi % (2 * math.pi)
        if k > 0:
            rm, rn = radii_m(lat[k - 1])
            vm = 0.5 * (v_enu[k] + v_enu[k - 1])
            lat[k] = lat[k - 1] + vm[1] / (rm + h[k - 1]) * dt_s
            lon[k] = lon[k - 1] + vm[0] / ((rn + h[k - 1]) * math.cos(lat[k - 1])) * dt_s
            h[k] = h[k - 1] + vm[2] * dt_s
    acc = np.gradient(v_enu, dt_s, axis=0)
    ang = rpy.copy()
    ang[:, 2] = np.unwrap(ang[:, 2])
    dang = np.gradient(ang, dt_s, axis=0)
    f_b, w_eb = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        w_ie = earth_rate_enu(lat[k])
        w_en = transport_rate_enu(lat[k], h[k], v_enu[k])
        g_n = np.array([0.0, 0.0, gravity_up(lat[k], h[k])[0]])
        f_n = acc[k] + np.cross(2 * w_ie + w_en, v_enu[k]) - g_n
        c_bn = dcm_body_to_enu(*rpy[k])
        f_b[k] = c_bn.T @ f_n
        ph, th = rpy[k, 0], rpy[k, 1]
        dph, dth, dps = dang[k]
        w_eb[k] = (dph - dps * math.sin(th),
                   dth * math.cos(ph) + dps * math.cos(th) * math.sin(ph),
                   -dth * math.sin(ph) + dps * math.cos(th) * math.cos(ph))
    return Trajectory(t, lat, lon, h, v_enu, rpy, w_eb, f_b, label=label)


def aircraft_states(tr: Trajectory, alpha_rad: float = 0.03) -> list[AircraftState]:
    """The :class:`AircraftState` of every sample of ``tr`` (air data filled consistently with a
    calm atmosphere: TAS = ground speed; fields a navigation source does not read are nominal)."""
    out = []
    for k in range(len(tr)):
        v = tr.v_enu_mps[k]
        gs = float(math.hypot(v[0], v[1]))
        out.append(AircraftState(
            t_s=float(tr.t_s[k]), lat_rad=float(tr.lat_rad[k]), lon_rad=float(tr.lon_rad[k]),
            alt_m=float(tr.alt_m[k]), tas_mps=float(np.linalg.norm(v)),
            cas_mps=float(np.linalg.norm(v)), gs_mps=gs, vs_mps=float(v[2]),
            v_enu_mps=np.array(v, float), roll_rad=float(tr.rpy_rad[k, 0]),
            pitch_rad=float(tr.rpy_rad[k, 1]), heading_rad=float(tr.rpy_rad[k, 2]),
            track_rad=float(math.atan2(v[0], v[1]) % (2 * math.pi)), alpha_rad=alpha_rad,
            beta_rad=0.0, gamma_rad=float(math.atan2(v[2], max(gs, 1e-9))),
            p_rps=float(tr.w_eb_b_rps[k, 0]), q_rps=float(tr.w_eb_b_rps[k, 1]),
            r_rps=float(tr.w_eb_b_rps[k, 2]), nx=0.0, ny=1.0,
            f_body_mps2=np.array(tr.f_b_mps2[k], float), mach=0.4, agl_m=float(tr.alt_m[k]),
            throttle=0.6, mass_kg=60000.0))
    return out


PROFILES = {
    "straight": [Segment(600.0)],
    "turns": [Segment(60.0), Segment(60.0, 3.0), Segment(30.0), Segment(60.0, -3.0),
              Segment(30.0), Segment(120.0, 1.5), Segment(60.0)],
    "climb_turns": [Segment(40.0), Segment(60.0, 2.0, 5.0), Segment(30.0, 0.0, 5.0),
                    Segment(60.0, -2.0, 5.0, 0.3), Segment(60.0, 0.0, 0.0, -0.3),
                    Segment(60.0, 3.0), Segment(60.0)],
}
"""Shipped manoeuvre profiles (segment lists): straight and level, a turn sequence, a climb with
turns — seed 004's flight-test manoeuvres."""


__all__ = ["PROFILES", "Segment", "aircraft_states", "fly_profile"]
