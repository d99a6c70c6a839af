"""The conditions the path was planned for, measured in flight: wind and temperature.

The path is planned for a wind and a temperature (the scenario's forecast, else the actual
ones). :class:`ConditionMonitor` measures both from the air data and the navigation solution:

* the wind is the navigation ground velocity minus the air velocity,
  ``w = v_g − R_z(ψ) R_y(θ) R_x(φ) · V (cos α cos β, sin β, sin α cos β)`` (air data: TAS, α,
  β; attitude from the navigation solution), :func:`air_velocity_ned_mps`;
* the ISA deviation is the static temperature from TAS and Mach, ``T = (TAS / M)² / (γ R)``,
  minus the ISA temperature at the navigation altitude
  (:func:`~fms_testbed.core.atmosphere.isa_dev_from_air_data_c`).

Both are filtered (first order, ``tau_s``). When the filtered wind differs from the planned one
at the present altitude by more than its threshold (vector difference; at least
``nav_sigma_k`` σ of the wind error the navigation's heading uncertainty makes) or the ISA
deviation by more than ``isa_dev_err_c`` (:class:`ConditionThresholds`), :meth:`~ConditionMonitor.update`
gives the reason for a rebuild (Danilin 2017: the desired trajectory is built for the current
conditions); :func:`measured_params` are the build settings for what was measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.core.atmosphere import isa_dev_from_air_data_c
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.core.wind import WindProfile


@dataclass(frozen=True, slots=True)
class ConditionThresholds:
    """When the measured conditions call for a rebuild, in one place.

    wind_err_mps: magnitude of the vector difference measured − planned wind at the present
    altitude, m/s (10 kt); isa_dev_err_c: |measured − planned| ISA deviation, K (5 °C);
    tau_s: time constant of the first-order filter on the measurements, s; holdoff_s: no
    rebuild this long after the start (the wind is ramped in after a trim) or after a rebuild,
    s; nav_sigma_k: the wind threshold is at least this many σ of the wind measurement's own
    error from the navigation's heading uncertainty, k · TAS · σ_ψ.
    """

    wind_err_mps: float = 10.0 * KT_MPS
    nav_sigma_k: float = 3.0
    isa_dev_err_c: float = 5.0
    tau_s: float = 15.0
    holdoff_s: float = 60.0


def air_velocity_ned_mps(tas_mps: float, alpha_rad: float, beta_rad: float, roll_rad: float,
                         pitch_rad: float, heading_rad: float) -> tuple[float, float, float]:
    """Velocity of the aircraft relative to the air, NED, m/s: the air-data vector
    V (cos α cos β, sin β, sin α cos β) in body axes turned to NED by the attitude,
    v_n = R_z(ψ) R_y(θ) R_x(φ) v_b (in a banked turn the α part has a horizontal component,
    which the heading alone would miss).

    Parameters
    ----------
    tas_mps : true airspeed V, m/s; alpha_rad, beta_rad : angle of attack and sideslip, rad
    roll_rad, pitch_rad, heading_rad : attitude φ, θ, ψ (heading true), rad
    """
    ca, sa, cb, sb = math.cos(alpha_rad), math.sin(alpha_rad), math.cos(beta_rad), math.sin(beta_rad)
    u, v, w = tas_mps * ca * cb, tas_mps * sb, tas_mps * sa * cb
    cf, sf = math.cos(roll_rad), math.sin(roll_rad)
    ct, st = math.cos(pitch_rad), math.sin(pitch_rad)
    cp, sp = math.cos(heading_rad), math.sin(heading_rad)
    v1, w1 = cf * v - sf * w, sf * v + cf * w            # R_x(φ)
    u2, w2 = ct * u + st * w1, -st * u + ct * w1         # R_y(θ)
    return cp * u2 - sp * v1, sp * u2 + cp * v1, w2      # R_z(ψ)


def measured_params(params, alt_m: float, wind_ne_mps: tuple[float, float], isa_dev_c: float):
    """Build settings for the measured conditions: the planned wind profile shifted by the
    measured − planned wind at ``alt_m`` (m) — a constant planned wind becomes the measured
    one — and the measured ISA deviation ``isa_dev_c`` (K). ``params``: the active path's
    :class:`~fms_testbed.legs.model.BuildParams`; ``wind_ne_mps``: measured (north, east)
    velocity of the air, m/s."""
    spd, frm = params.wind_at(alt_m)
    plan = WindProfile.constant(spd, frm).ned_at(0.0)
    dn, de = wind_ne_mps[0] - plan[0], wind_ne_mps[1] - plan[1]
    prof = params.wind_profile
    if prof is not None:
        prof = WindProfile(prof.alt_m, tuple(n + dn for n in prof.north_mps),
                           tuple(e + de for e in prof.east_mps))
        w0 = prof.at(prof.alt_m[0])
    else:
        w0 = WindProfile((0.0,), (wind_ne_mps[0],), (wind_ne_mps[1],)).at(0.0)
    return replace(params, wind_profile=prof, wind_speed_mps=w0[0], wind_from_deg=w0[1],
                   isa_dev_c=float(isa_dev_c))


class ConditionMonitor:
    """Compares the conditions the aircraft measures with the ones its path was planned for
    (module docstring).

    Parameters
    ----------
    thresholds : when a difference calls for a rebuild (default :class:`ConditionThresholds`)
    """

    def __init__(self, thresholds: ConditionThresholds | None = None):
        self.th = thresholds or ConditionThresholds()
        self.wn = self.we = self.dt_c = None
        self.t_last = None
        self.quiet_until_s = None
        self._planned = (None, 0.0, 0.0)     # (params of a constant wind, north, east m/s)

    def measure(self, t_s: float, nav: NavSolution, air: AirData) -> tuple[float, float, float]:
        """Filter in one measurement; return the filtered (wind north m/s, wind east m/s,
        ISA deviation K)."""
        an, ae, _ = air_velocity_ned_mps(air.tas_mps, air.alpha_rad, air.beta_rad,
                                         nav.roll_rad, nav.pitch_rad, nav.heading_rad)
        v = nav.v_enu_mps
        wn, we = float(v[1]) - an, float(v[0]) - ae
        dev = isa_dev_from_air_data_c(air.tas_mps, air.mach, nav.alt_m)
        if self.wn is None:
            self.wn, self.we, self.dt_c = wn, we, dev
            self.quiet_until_s = t_s + self.th.holdoff_s
        else:
            k = min(1.0, (t_s - self.t_last) / self.th.tau_s)
            self.wn += k * (wn - self.wn)
            self.we += k * (we - self.we)
            self.dt_c += k * (dev - self.dt_c)
        self.t_last = t_s
        return self.wn, self.we, self.dt_c

    def planned_wind_ne_mps(self, params, alt_m: float) -> tuple[float, float]:
        """The planned (north, east) velocity of the air at ``alt_m`` (m), m/s (a constant
        planned wind is converted once per build settings)."""
        if params.wind_profile is None and self._planned[0] is params:
            return self._planned[1], self._planned[2]
        spd, frm = params.wind_at(alt_m)
        pn, pe = WindProfile.constant(spd, frm).ned_at(0.0)
        if params.wind_profile is None:
            self._planned = (params, pn, pe)
        return pn, pe

    def update(self, t_s: float, nav: NavSolution, air: AirData, params) -> str:
        """Measure and compare with ``params`` (the active path's build settings) at the
        navigation altitude; the rebuild reason ('' when none is due, or when the air data are
        not valid)."""
        if not air.valid or not air.mach > 0.0:
            return ""
        wn, we, dev = self.measure(t_s, nav, air)
        if params is None or t_s < self.quiet_until_s:
            return ""
        pn, pe = self.planned_wind_ne_mps(params, nav.alt_m)
        err = math.hypot(wn - pn, we - pe)
        why = []
        limit = self.wind_threshold_mps(nav, air)
        if err > limit:
            spd, frm = params.wind_at(nav.alt_m)
            ms, mf = WindProfile((0.0,), (wn,), (we,)).at(0.0)
            why.append(f"wind measured {mf:03.0f}/{ms / KT_MPS:.0f} kt vs planned "
                       f"{frm:03.0f}/{spd / KT_MPS:.0f} kt at {nav.alt_m / FT_M:.0f} ft "
                       f"(vector error {err / KT_MPS:.0f} kt > {limit / KT_MPS:.0f} kt)")
        if abs(dev - params.isa_dev_c) > self.th.isa_dev_err_c:
            why.append(f"temperature measured ISA{dev:+.1f} vs planned "
                       f"ISA{params.isa_dev_c:+.1f} (> {self.th.isa_dev_err_c:.0f} °C)")
        return "; ".join(why)

    def wind_threshold_mps(self, nav: NavSolution, air: AirData) -> float:
        """The wind-change threshold, m/s: ``wind_err_mps``, or ``nav_sigma_k`` σ of the wind
        error the navigation's heading uncertainty makes (TAS · σ_ψ across the air velocity)
        when that is larger."""
        sig = nav.heading_sigma_rad
        if sig is None or not math.isfinite(sig):
            return self.th.wind_err_mps
        return max(self.th.wind_err_mps, self.th.nav_sigma_k * air.tas_mps * sig)

    def rebuilt(self, t_s: float) -> None:
        """A rebuild was made at ``t_s`` (s): hold off the next one."""
        self.quiet_until_s = t_s + self.th.holdoff_s

    @property
    def measured(self) -> tuple[tuple[float, float], float]:
        """((wind north, east) m/s, ISA deviation K) as filtered so far."""
        return (self.wn, self.we), self.dt_c


__all__ = ["ConditionMonitor", "ConditionThresholds", "air_velocity_ned_mps",
           "measured_params"]
