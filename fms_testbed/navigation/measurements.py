"""Measurements of the INS/GNSS filter as plug-ins: each gives (z, H, R) from the current INS
solution, the way pyins' ``measurements.py`` does, so adding a sensor (a heading, DME/DME) is
one class.

The filter's state layout (SI; errors are *indicated minus true*)::

    0:3   δp   position error E, N, U, m          3:6   δV   velocity error E, N, U, m/s
    6:9   ε    attitude error about E, N, U, rad   9:12  b_a  accelerometer bias, body, m/s²
    12:15 b_g  gyro bias, body, rad/s              15:18 m_p  GNSS position Markov error, m
    18:21 m_v  GNSS velocity Markov error, m/s     21    b_h  baro bias, m (with a baro)

Attitude convention: C_ind = (I - [ε×]) C_true (ENU), so a body vector l resolved by the INS is
C_ind l = C l + [(C l)×] ε. A measurement is built from an INS output ``sol``
(:class:`~fms_testbed.core.state.NavSolution`, the INS's own indicated solution at the
measurement's time of validity) and the INS's measured body rate ω_eb (rad/s); it never sees
the true state.

    GNSS position (antenna at l):  z = p_INS + C l - p_GNSS,  H = [I, 0, [(C l)×], 0, 0, -I, 0]
    GNSS velocity:                 z = V_INS + C (ω×l) - V_GNSS,  H = [0, I, [(C(ω×l))×], .., -I]
    baro altitude:                 z = h_INS - h_baro,  H = [e_U, 0, ..., -1 (b_h)]
    airspeed (wind w known):       z = |V_INS - w| - TAS,  H = [0, uᵀ, 0 ...], u = (V - w)/|V - w|

R is the σ the sensor reports (GNSS: its per-fix σ) plus, for a GNSS time-tag error of declared
σ_t, σ_t² V Vᵀ (a stamp off by δt puts the fix V δt away).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.earth import radii_m
from fms_testbed.core.state import NavSolution
from fms_testbed.navigation.sins import _c_bn

N_INS = 15
POS, VEL, ATT, BA, BG = (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 15))
MP, MV = slice(15, 18), slice(18, 21)
BARO = 21


def enu_difference_m(a_lat_rad, a_lon_rad, a_alt_m, b_lat_rad, b_lon_rad, b_alt_m) -> np.ndarray:
    """Position a - b in local ENU at a, m (small differences: radii of curvature at a).

    Parameters
    ----------
    a_lat_rad, a_lon_rad, a_alt_m : point a (rad, rad, m)
    b_lat_rad, b_lon_rad, b_alt_m : point b (rad, rad, m)
    """
    rm, rn = radii_m(a_lat_rad)
    return np.array([(a_lon_rad - b_lon_rad) * (rn + a_alt_m) * math.cos(a_lat_rad),
                     (a_lat_rad - b_lat_rad) * (rm + a_alt_m), a_alt_m - b_alt_m])


def skew(a: np.ndarray) -> np.ndarray:
    """[a×] (3, 3): skew(a) @ b = a × b.

    Parameters
    ----------
    a : (3,) vector
    """
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def c_bn_enu(sol: NavSolution) -> np.ndarray:
    """C_b^n (3, 3), body (x fwd, y right, z down) → ENU, at the solution's indicated attitude.

    Parameters
    ----------
    sol : an INS output (roll, pitch, heading rad)
    """
    return _c_bn(sol.roll_rad, sol.pitch_rad, sol.heading_rad)


class Measurement:
    """Base of the filter's measurements: :meth:`matrices` gives (z, H, R) for the current INS
    solution, or None when it cannot be formed.

    Class attributes: ``name`` (the group's name in logs and events), ``reset_states`` (the
    INS states whose covariance is reset when the measurement has been rejected by the gate
    for too long). Instance attribute ``t_s``: time of validity, s.
    """

    name: str = ""
    reset_states: slice = POS
    t_s: float

    def matrices(self, sol: NavSolution, n: int, w_eb_rps: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(z (m,), H (m, n), R (m, m)) at the INS output ``sol`` for a filter of ``n``
        states; ``w_eb_rps`` (3,) the INS's measured body rate over the Earth, rad/s."""
        raise NotImplementedError


@dataclass
class GnssPosition(Measurement):
    """GNSS position of the antenna (lat/lon rad, alt m) with its reported σ (ENU, m).

    t_s : time of validity, s;  lever_arm_m : antenna from the CG, body axes, m
    time_tag_sigma_s : declared 1σ of the time-tag error, s;  v_enu_mps : the fix's velocity
    (for the time-tag term), m/s
    """

    t_s: float
    lat_rad: float
    lon_rad: float
    alt_m: float
    sigma_m: np.ndarray
    lever_arm_m: np.ndarray
    time_tag_sigma_s: float = 0.0
    v_enu_mps: np.ndarray | None = None
    name = "gnss_pos"
    reset_states = POS

    def matrices(self, sol, n, w_eb_rps):
        """(z, H, R), module docstring."""
        a = c_bn_enu(sol) @ np.asarray(self.lever_arm_m, float)
        z = enu_difference_m(sol.lat_rad, sol.lon_rad, sol.alt_m, self.lat_rad, self.lon_rad,
                             self.alt_m) + a
        H = np.zeros((3, n))
        H[:, POS] = np.eye(3)
        H[:, ATT] = skew(a)
        H[:, MP] = -np.eye(3)
        R = np.diag(np.asarray(self.sigma_m, float) ** 2)
        v = None if self.v_enu_mps is None else np.asarray(self.v_enu_mps, float)
        if self.time_tag_sigma_s > 0 and v is not None and np.all(np.isfinite(v)):
            R = R + self.time_tag_sigma_s ** 2 * np.outer(v, v)
        return z, H, R


@dataclass
class GnssVelocity(Measurement):
    """GNSS velocity of the antenna (ENU, m/s) with its reported σ (m/s).

    t_s : time of validity, s;  lever_arm_m : antenna from the CG, body axes, m
    """

    t_s: float
    v_enu_mps: np.ndarray
    sigma_mps: np.ndarray
    lever_arm_m: np.ndarray
    name = "gnss_vel"
    reset_states = VEL

    def matrices(self, sol, n, w_eb_rps):
        """(z, H, R), module docstring."""
        b = c_bn_enu(sol) @ np.cross(np.asarray(w_eb_rps, float),
                                     np.asarray(self.lever_arm_m, float))
        z = np.asarray(sol.v_enu_mps, float) + b - np.asarray(self.v_enu_mps, float)
        H = np.zeros((3, n))
        H[:, VEL] = np.eye(3)
        H[:, ATT] = skew(b)
        H[:, MV] = -np.eye(3)
        return z, H, np.diag(np.asarray(self.sigma_mps, float) ** 2)


@dataclass
class BaroAltitude(Measurement):
    """Baro altitude (m, the package's sea-level datum) with its white σ (m); the filter's
    state 21 carries its bias.

    t_s : time of validity, s
    """

    t_s: float
    alt_m: float
    sigma_m: float
    name = "baro"
    reset_states = slice(2, 3)

    def matrices(self, sol, n, w_eb_rps):
        """(z, H, R), module docstring (None for a filter without the baro state)."""
        if n <= BARO:
            return None
        H = np.zeros((1, n))
        H[0, 2], H[0, BARO] = 1.0, -1.0
        return np.array([sol.alt_m - self.alt_m]), H, np.array([[self.sigma_m ** 2]])


@dataclass
class Airspeed(Measurement):
    """True airspeed (m/s) from the air data, against the INS velocity less a known wind.

    t_s : time of validity, s;  tas_mps : measured TAS, m/s;  sigma_mps : its 1σ plus the
    wind's uncertainty along the air path, m/s;  wind_enu_mps : (3,) wind (towards), m/s
    """

    t_s: float
    tas_mps: float
    sigma_mps: float
    wind_enu_mps: np.ndarray
    name = "airspeed"
    reset_states = VEL

    def matrices(self, sol, n, w_eb_rps):
        """(z, H, R), module docstring (None below 1 m/s of air-relative speed)."""
        va = np.asarray(sol.v_enu_mps, float) - np.asarray(self.wind_enu_mps, float)
        s = float(np.linalg.norm(va))
        if s < 1.0:
            return None
        H = np.zeros((1, n))
        H[0, VEL] = va / s
        return np.array([s - self.tas_mps]), H, np.array([[self.sigma_mps ** 2]])


def gnss_measurements(fix, lever_arm_m, time_tag_sigma_s: float = 0.0,
                      default_sigma: np.ndarray | None = None) -> list[Measurement]:
    """The position and velocity measurements of one GNSS fix (its reported σ, or
    ``default_sigma`` (6,) [m, m/s] when the fix reports none).

    Parameters
    ----------
    fix : a :class:`~fms_testbed.sensors.gnss.GnssFix` (t_s, lat/lon rad, alt m, v_enu_mps,
        pos_sigma_m, vel_sigma_mps)
    lever_arm_m : (3,) antenna position from the CG, body axes, m
    time_tag_sigma_s : declared 1σ of the receiver's time-tag error, s
    default_sigma : (6,) σ [position ENU m, velocity ENU m/s] for a fix without its own
    """
    ps = fix.pos_sigma_m if fix.pos_sigma_m is not None else default_sigma[:3]
    out: list[Measurement] = [GnssPosition(fix.t_s, fix.lat_rad, fix.lon_rad, fix.alt_m, ps,
                                           lever_arm_m, time_tag_sigma_s, fix.v_enu_mps)]
    if fix.v_enu_mps is not None and np.all(np.isfinite(fix.v_enu_mps)):
        vs = fix.vel_sigma_mps if fix.vel_sigma_mps is not None else default_sigma[3:]
        out.append(GnssVelocity(fix.t_s, fix.v_enu_mps, vs, lever_arm_m))
    return out


__all__ = ["ATT", "Airspeed", "BA", "BARO", "BG", "BaroAltitude", "GnssPosition", "GnssVelocity",
           "MP", "MV", "Measurement", "N_INS", "POS", "VEL", "c_bn_enu", "enu_difference_m",
           "gnss_measurements", "skew"]
