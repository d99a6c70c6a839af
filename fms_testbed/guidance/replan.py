"""Re-planning: the rest of the procedure rebuilt from the aircraft's state when a conditional
leg ends in flight.

An altitude, DME or radial leg ends where the aircraft meets its condition, not where the plan
assumed (:mod:`.sequencing`). The legs after it are then built again by the same builder and
monitor (:func:`fms_testbed.path.plan.rebuild_from`) from a start one roll-in anticipation
ahead on the present track, so the first turn's roll is centred on its start as for any planned
turn; DF legs whose fix is already behind are skipped first (:func:`passed_direct_legs`).

**Changed conditions.** The path is planned for a wind and a temperature (the scenario's
forecast, else the actual ones). :class:`ConditionMonitor` measures both in flight; when the
filtered wind differs from the planned one at the present altitude by more than 10 kt (vector)
or the ISA deviation by more than 5 °C (:class:`ConditionThresholds`), guidance rebuilds the
rest of the procedure — the present leg included, from the present position — for the measured
conditions (:func:`measured_params`), logs a ``rebuild`` event with the reason and draws the
rebuilt path like any other. A rebuild waits until the aircraft flies a straight part of a leg
that can be rebuilt from mid-leg (not an arc, hold or procedure turn: :func:`rebuildable_here`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.atmosphere import isa_dev_from_air_data_c
from fms_testbed.core.geodesy import direct
from fms_testbed.core.units import FT_M, G0_MPS2, KT_MPS
from fms_testbed.guidance.lateral import LateralGains, anticipation_m
from fms_testbed.guidance.sequencing import direct_fix_passed
from fms_testbed.path.plan import FlyablePath, rebuild_from

PLANNED_BANK_DEG = 20.0
"""The builder's planned bank: sets the roll-in anticipation of the rebuilt start, deg."""


def passed_direct_legs(whole: FlyablePath, first: int, lat_rad: float, lon_rad: float,
                       track_rad: float, tas_mps: float) -> list[int]:
    """Indices ``first, first + 1, ...`` of the consecutive DF legs whose fix is already passed
    (:func:`~.sequencing.direct_fix_passed`) at the navigation position (rad), track (rad) and
    planned speed (m/s)."""
    out = []
    k = first
    legs = whole.path.legs
    while k < len(whole.seq.legs) and k < len(legs) and \
            direct_fix_passed(legs[k], lat_rad, lon_rad, track_rad, tas_mps):
        out.append(k)
        k += 1
    return out


def roll_out_state(lat_deg: float, lon_deg: float, track_rad: float, gs_mps: float,
                   roll_rad: float, gains: LateralGains) -> tuple[float, float, float]:
    """Where the aircraft is, and its track, once it has rolled wings level from ``roll_rad``.

    A leg that ends on a condition can end in a turn (the previous turn's bank still on). The
    aircraft goes on turning while it rolls out at the roll rate p_max over t = |φ₀| / p_max;
    with the bank ramping linearly to zero the track changes by Δψ ≈ g tan φ₀ / V_g · t / 2
    (the mean turn rate) and the aircraft covers V_g t along a chord on the mean track
    ψ + Δψ / 2. The rebuilt path starts from there, so a roll reversal is not flown as a
    cross-track error.

    Parameters
    ----------
    lat_deg, lon_deg : position, deg; track_rad : ground track, rad true
    gs_mps : ground speed, m/s; roll_rad : bank, rad (+ right)
    gains : lateral tuning (roll rate p_max, deg/s)

    Returns
    -------
    (lat_deg, lon_deg, track_rad) after the roll-out
    """
    t_s = abs(roll_rad) / math.radians(gains.roll_rate_dps)
    if t_s <= 0.0 or gs_mps <= 0.0:
        return lat_deg, lon_deg, track_rad
    dpsi = G0_MPS2 * math.tan(roll_rad) / gs_mps * t_s / 2.0
    la, lo, _ = direct(lat_deg, lon_deg, math.degrees(track_rad + dpsi / 2.0), gs_mps * t_s)
    return la, lo, track_rad + dpsi


def rebuild_rest(db, whole: FlyablePath, spec, cfg, gains: LateralGains, next_leg: int,
                 lat_rad: float, lon_rad: float, track_rad: float, alt_m: float,
                 gs_mps: float | None = None, roll_rad: float = 0.0, params=None,
                 prev_fix=None) -> FlyablePath | None:
    """Legs ``next_leg..`` of the procedure built from the aircraft's state (module docstring).

    Parameters
    ----------
    db, whole, spec, cfg : the database, the whole built procedure, its spec and the aircraft
    gains : lateral tuning (roll rate for the anticipation distance)
    next_leg : first leg to build (index in the whole procedure)
    lat_rad, lon_rad, track_rad, alt_m : navigation position (rad), ground track (rad true),
        altitude (m)
    gs_mps : ground speed, m/s, for the roll-out and roll-in distances (default: the planned
        climb speed); roll_rad : bank at the rebuild, rad (+ right): see :func:`roll_out_state`
    params : build settings for the rest (default: the whole path's; the measured conditions
        after a change, :func:`measured_params`)
    prev_fix : the fix the leg ``next_leg`` starts from (a TF rebuilt mid-leg rejoins its track
        from it), or None

    Returns
    -------
    The rebuilt rest, or None when there is no database to build from, nothing is left or the
    rest cannot be built.
    """
    v = gs_mps if gs_mps and gs_mps > 0.0 else cfg.limits.climb_tas_mps
    la, lo, trk = roll_out_state(math.degrees(lat_rad), math.degrees(lon_rad), track_rad, v,
                                 roll_rad, gains)
    lead = anticipation_m(v, math.radians(PLANNED_BANK_DEG), gains)
    la, lo, _ = direct(la, lo, math.degrees(trk), lead)
    if db is None or spec is None:
        return None
    return rebuild_from(db, whole, spec, cfg, next_leg, la, lo, math.degrees(trk) % 360.0, alt_m,
                        params=params, prev_fix=prev_fix)


def rebuildable_here(seg, built) -> bool:
    """True when the aircraft, on segment ``seg`` of built leg ``built``, may have its path
    rebuilt from here for changed conditions: a straight part ('leg' line) of a leg that is
    not a coded arc, a hold or a procedure turn (those are rebuilt at their end instead)."""
    from fms_testbed.legs.types import LEG_TYPES

    kind = LEG_TYPES[built.path_term]
    return (seg.role == "leg" and seg.geom.kind == "line" and kind.arc_centre is None
            and not kind.hold and not kind.course_reversal and not kind.initial)


# ------------------------------------------------------------ rebuild on changed conditions

@dataclass(frozen=True, slots=True)
class ConditionThresholds:
    """When the measured conditions call for a rebuild (Danilin 2017: the desired trajectory
    is built for the current conditions; class 1 when they change), in one place.

    wind_err_mps: magnitude of the vector difference measured − planned wind at the present
    altitude, m/s (10 kt); isa_dev_err_c: |measured − planned| ISA deviation, K (5 °C);
    tau_s: time constant of the first-order filter on the measurements, s; holdoff_s: no
    rebuild this long after the start (the wind is ramped in over 20 s) or after a rebuild, s;
    nav_sigma_k: the wind threshold is at least this many σ of the wind measurement's own error
    from the navigation's heading uncertainty, k · TAS · σ_ψ (an INS whose heading is not yet
    observable — 2.8° before the first turn — "measures" a 10 kt crosswind that is not there).
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
    v_n = R_z(ψ) R_y(θ) R_x(φ) v_b (in a banked turn the α part has a horizontal component:
    ~1.7° of track at α 4°, φ 25°, which heading alone would miss)."""
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
    one — and the measured ISA deviation (K). ``params``: the active path's
    :class:`~fms_testbed.legs.model.BuildParams`; ``wind_ne_mps``: measured (north, east)
    velocity of the air, m/s."""
    from dataclasses import replace

    from fms_testbed.core.wind import WindProfile

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
    """Compares the conditions the aircraft measures with the ones its path was planned for.

    The wind is the ground velocity of the navigation solution minus the air velocity
    (:func:`air_velocity_ned_mps` from the air data — TAS, α, β — and the navigation attitude);
    the ISA deviation is the static temperature from TAS and Mach minus the ISA's
    (:func:`~fms_testbed.core.atmosphere.isa_dev_from_air_data_c`). The air data are JSBSim's
    (an ideal air-data computer: the navigation sources model no air data). Both are filtered
    (first order, ``tau_s``); :meth:`update` returns the reason for a rebuild once a filtered
    difference exceeds its threshold (:class:`ConditionThresholds`) outside the hold-off.
    """

    def __init__(self, thresholds: ConditionThresholds | None = None):
        self.th = thresholds or ConditionThresholds()
        self.wn = self.we = self.dt_c = None
        self.t_last = None
        self.quiet_until_s = None

    def measure(self, t_s: float, nav, truth) -> tuple[float, float, float]:
        """Filter in one measurement; return the filtered (wind north m/s, wind east m/s,
        ISA deviation K)."""
        an, ae, _ = air_velocity_ned_mps(truth.tas_mps, truth.alpha_rad, truth.beta_rad,
                                         nav.roll_rad, nav.pitch_rad, nav.heading_rad)
        v = nav.v_enu_mps
        wn, we = float(v[1]) - an, float(v[0]) - ae
        dev = isa_dev_from_air_data_c(truth.tas_mps, truth.mach, nav.alt_m)
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

    def update(self, t_s: float, nav, truth, params) -> str:
        """Measure and compare with ``params`` (the active path's build settings) at the
        navigation altitude; the rebuild reason ('' when none is due, or when ``truth``
        carries no air data — TAS, Mach, α, β — to measure with)."""
        if not all(hasattr(truth, k) for k in ("tas_mps", "mach", "alpha_rad", "beta_rad")) \
                or not truth.mach > 0.0:
            return ""
        wn, we, dev = self.measure(t_s, nav, truth)
        if params is None or t_s < self.quiet_until_s:
            return ""
        from fms_testbed.core.wind import WindProfile

        spd, frm = params.wind_at(nav.alt_m)
        pn, pe = WindProfile.constant(spd, frm).ned_at(0.0)
        err = math.hypot(wn - pn, we - pe)
        why = []
        if err > self.wind_threshold_mps(nav, truth):
            ms, mf = WindProfile((0.0,), (wn,), (we,)).at(0.0)
            why.append(f"wind measured {mf:03.0f}/{ms / KT_MPS:.0f} kt vs planned "
                       f"{frm:03.0f}/{spd / KT_MPS:.0f} kt at {nav.alt_m / FT_M:.0f} ft "
                       f"(vector error {err / KT_MPS:.0f} kt > "
                       f"{self.wind_threshold_mps(nav, truth) / KT_MPS:.0f} kt)")
        if abs(dev - params.isa_dev_c) > self.th.isa_dev_err_c:
            why.append(f"temperature measured ISA{dev:+.1f} vs planned "
                       f"ISA{params.isa_dev_c:+.1f} (> {self.th.isa_dev_err_c:.0f} °C)")
        return "; ".join(why)

    def wind_threshold_mps(self, nav, truth) -> float:
        """The wind-change threshold, m/s: ``wind_err_mps``, or ``nav_sigma_k`` σ of the wind
        error the navigation's heading uncertainty makes (TAS · σ_ψ across the air velocity)
        when that is larger."""
        sig = getattr(nav, "heading_sigma_rad", None)
        if sig is None or not math.isfinite(sig):
            return self.th.wind_err_mps
        return max(self.th.wind_err_mps, self.th.nav_sigma_k * truth.tas_mps * sig)

    def rebuilt(self, t_s: float) -> None:
        """A rebuild was made at ``t_s`` (s): hold off the next one."""
        self.quiet_until_s = t_s + self.th.holdoff_s

    @property
    def measured(self) -> tuple[tuple[float, float], float]:
        """((wind north, east) m/s, ISA deviation K) as filtered so far."""
        return (self.wn, self.we), self.dt_c
