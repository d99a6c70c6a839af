"""Speed planning: the TAS target of each guidance step from the coded limits and the arcs ahead.

The aircraft's planned speed, flown as a CAS (its TAS at the present altitude), is capped so
every arc within the deceleration distance ahead can be flown :data:`ARC_BANK_MARGIN_DEG` below
the bank limit (:func:`arc_speed_cap_mps`, the monitor's V,γ correction applied in flight), then
moved into the CAS band the leg's coded limit allows (:func:`~.vertical.cas_band`); in descent
(STAR/approach) an 'at' or 'at or below' limit, once entered, holds for the rest of the
procedure; the 'at' / 'at or below' limit of a fix ahead is flown from the deceleration
distance before it (:meth:`SpeedPlan.limit_ahead_cap_mps`). The target is refreshed every
:data:`SPEED_UPDATE_S` and on entering a leg.

Approaches of an aircraft with approach settings also follow the planned speed profile
(:class:`~fms_testbed.path.speed_profile.SpeedProfile`: deceleration segments before coded
limits and the FAF, Vapp on the final), read :data:`SPEED_LEAD_S` ahead of the aircraft (the
speed loop's lag), with Vapp as the floor instead of the clean minimum. In the missed approach
(:class:`GoAround`) the target is Vapp + the go-around increment until the acceleration
height above the runway, then the planned (clean) speed again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.planning import ARC_BANK_MARGIN_DEG, DECEL_MPS2
from fms_testbed.core.units import G0_MPS2
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.guidance.locate import Where
from fms_testbed.guidance.vertical import SPEED_MARGIN_MPS, SpeedLimit, cas_band, tas_target_mps

DECEL_EXTRA_S = 10.0
"""Flight time added to the deceleration distance before an arc, s."""
LOOKAHEAD_M = 30000.0
"""Arcs further ahead than this are not looked at, m."""
SPEED_UPDATE_S = 1.0
"""The TAS target is recomputed this often, s."""
SPEED_LEAD_S = 10.0
"""The planned approach speed is read this far ahead of the aircraft (flight time, s): about
the coupled law's speed-channel ramp lag 2 ξ_V T_V (10.7 s for the 737)."""


def planned_wind_mps(fp, alt_m: float) -> float:
    """The wind speed the path ``fp`` (:class:`~fms_testbed.path.plan.FlyablePath`) was planned
    for at ``alt_m`` (m), m/s: the plan's profile there, else its constant wind; 0 in calm or
    without planning parameters (a measured wind that differs has the path rebuilt for it, so
    this is the flight's best wind)."""
    p = fp.params
    if p is None:
        return 0.0
    if p.wind_profile is not None:
        return float(p.wind_profile.at(alt_m)[0])
    return float(p.wind_speed_mps)


@dataclass(frozen=True)
class GoAround:
    """Speeds of the missed approach: from whole-procedure leg ``first_leg`` on, Vapp +
    ``add_cas_mps`` until ``accel_height_m`` above the runway (elevation ``runway_elev_m``),
    then the planned speed (m/s, m)."""

    first_leg: int
    vapp_cas_mps: float
    add_cas_mps: float
    accel_height_m: float
    runway_elev_m: float


def arc_speed_cap_mps(pieces: list[LocalPiece], i: int, along_m: float, v_mps: float,
                      bank_max_deg: float, wind_mps: float = 0.0) -> float:
    """Highest TAS at which every arc within the deceleration distance ahead can be flown with
    ARC_BANK_MARGIN_DEG to spare below the bank limit, m/s (inf when none): the ground speed
    sqrt(R g tan γ) less ``wind_mps`` (the wind speed the path is planned for, m/s: the
    tailwind at the arc's worst point, whatever its tracks), never below half of it.

    Parameters
    ----------
    pieces : the active path's pieces; i : the piece flown; along_m : distance along it, m
    v_mps : present speed, m/s (deceleration distance (V² − v²) / (2 a) + DECEL_EXTRA_S V,
        a = DECEL_MPS2)
    bank_max_deg : the aircraft's bank limit, deg
    wind_mps : planned wind speed, m/s (0: calm): the arc's ground-speed limit is a tailwind's
        worst case, so the TAS cap is that limit less the wind
    """
    g_tan = G0_MPS2 * math.tan(math.radians(bank_max_deg - ARC_BANK_MARGIN_DEG))
    cap = math.inf
    dist = -along_m
    for p in pieces[i:]:
        if p.is_arc:
            vg = math.sqrt(p.radius_m * g_tan)
            v = max(vg - wind_mps, 0.5 * vg)
            if dist <= max(v_mps * v_mps - v * v, 0.0) / (2 * DECEL_MPS2) + DECEL_EXTRA_S * v_mps:
                cap = min(cap, v)
        dist += p.length_m
        if dist > LOOKAHEAD_M:
            break
    return cap


@dataclass
class SpeedPlan:
    """The TAS target and the state it carries from leg to leg (module docstring).

    limits: coded speed limit per leg of the whole procedure; descent: STAR/approach (limits
    carry on); plan_cas_mps: the aircraft's planned speed, a CAS, m/s; cas_min_mps:
    its minimum CAS, m/s; tas_cmd_mps: the present target, m/s; carry_max_cas_mps: the lowest
    'at'/'at or below' CAS entered in descent, m/s; next_t_s: when the target is due again, s.
    """

    limits: list[SpeedLimit | None]
    descent: bool
    plan_cas_mps: float
    cas_min_mps: float
    tas_cmd_mps: float
    carry_max_cas_mps: float | None = None
    next_t_s: float = -1.0
    vapp_cas_mps: float | None = None
    """Final approach speed of the flight's mass (approach settings), m/s; None: clean."""
    go_around: GoAround | None = None
    accelerated: bool = False
    """The go-around has passed its acceleration height."""
    isa_dev_c: float = 0.0
    """The day's temperature deviation the CAS → TAS conversions use, K (the plan's; after a
    rebuild on changed conditions, the measured one)."""
    bank_max_deg: float = 25.0
    """The aircraft's bank limit (arcs ahead are flown below it), deg."""

    def enter_leg(self, k: int) -> None:
        """Leg ``k`` (whole-procedure index) is entered: in descent its 'at'/'at or below' limit
        carries on."""
        lim = self.limits[k] if k < len(self.limits) else None
        if self.descent and lim is not None and lim.desc in ("", "@", "-"):
            c = lim.cas_mps
            self.carry_max_cas_mps = c if self.carry_max_cas_mps is None else \
                min(self.carry_max_cas_mps, c)

    def due_now(self) -> None:
        """Recompute the target at the next step (a new leg is flown)."""
        self.next_t_s = -1.0

    def limit_ahead_cap_mps(self, alt_m: float, leg: int, pieces: list[LocalPiece], i: int,
                            along_m: float, v_mps: float, piece_legs: list[int]) -> float:
        """Highest TAS that still lets the aircraft slow to the 'at' / 'at or below' speed
        limit of a fix ahead (the end of a later leg) by the time it gets there, m/s (inf when
        none is in reach): the limit's TAS once the fix is within the deceleration distance
        (V² − v²) / (2 a) + DECEL_EXTRA_S V, a = DECEL_MPS2 — the deceleration is planned
        before the fix, not from the start of its leg."""
        cap = math.inf
        dist = -along_m
        for j in range(i, len(pieces)):
            dist += pieces[j].length_m
            k = piece_legs[j]
            last = j + 1 >= len(pieces) or piece_legs[j + 1] != k
            if k <= leg or not last or k >= len(self.limits):
                if dist > LOOKAHEAD_M:
                    break
                continue
            lim = self.limits[k]
            if lim is not None and lim.desc in ("", "@", "-"):
                v_lim = cas_to_tas_scalar(lim.cas_mps - (SPEED_MARGIN_MPS if lim.desc == "-"
                                                         else 0.0), alt_m, self.isa_dev_c)
                need = max(v_mps * v_mps - v_lim * v_lim, 0.0) / (2 * DECEL_MPS2) \
                    + DECEL_EXTRA_S * v_mps
                if dist <= need:
                    cap = min(cap, v_lim)
            if dist > LOOKAHEAD_M:
                break
        return cap

    def update(self, t_s: float, alt_m: float, w: Where) -> float:
        """The TAS target at time ``t_s`` (s) and navigation altitude ``alt_m`` (m) with the
        aircraft at ``w`` on the active path, m/s (recomputed every :data:`SPEED_UPDATE_S`):
        the leg's coded band, a departure leg's planned CAS (``BuiltLeg.departure_cas_mps``:
        the climb-out speed to the acceleration height, then the acceleration the plan's
        turn radii were built for), the arcs ahead (:func:`arc_speed_cap_mps` in the planned wind,
        :func:`planned_wind_mps`), the limits of fixes ahead planned before them
        (:meth:`limit_ahead_cap_mps`) and the approach's planned speeds (the profile's
        ``SpeedProfile``, read :data:`SPEED_LEAD_S` ahead)."""
        if t_s < self.next_t_s:
            return self.tas_cmd_mps
        a, leg, i, along_m, gs_mps = w.act, w.leg, w.i, w.along_m, w.gs_mps
        wind_mps = planned_wind_mps(a.fp, alt_m)
        ga = self.go_around
        if ga is not None and leg >= ga.first_leg:
            return self._go_around_update(t_s, alt_m, w, ga, wind_mps)
        lim = self.limits[leg] if leg < len(self.limits) else None
        lo, hi = cas_band(lim, self.carry_max_cas_mps if self.descent else None)
        plan_cas = self.plan_cas_mps
        if w.built.departure_cas_mps is not None:   # a departure: its planned speeds
            plan_cas = min(plan_cas, w.built.departure_cas_mps)
        plan = min(cas_to_tas_scalar(plan_cas, alt_m, self.isa_dev_c),
                   arc_speed_cap_mps(a.pieces, i, along_m, gs_mps, self.bank_max_deg, wind_mps))
        plan = min(plan, self.limit_ahead_cap_mps(alt_m, leg, a.pieces, i, along_m,
                                                  self.tas_cmd_mps, a.piece_legs))
        floor = None
        prof = a.fp.path.profile
        schedule = prof.speed
        if self.vapp_cas_mps is not None and schedule is not None:
            s_sched_m = w.s_path_m - (a.prof_s[0] - float(prof.along_m[0]))
            c = schedule.cas_at(s_sched_m + SPEED_LEAD_S * gs_mps, self.vapp_cas_mps)
            if math.isfinite(c):
                plan = min(plan, cas_to_tas_scalar(c, alt_m, self.isa_dev_c))
            floor = self.vapp_cas_mps
        self.tas_cmd_mps = tas_target_mps(plan, alt_m, lo, hi, self.cas_min_mps,
                                          self.isa_dev_c, floor)
        self.next_t_s = t_s + SPEED_UPDATE_S
        return self.tas_cmd_mps

    def _go_around_update(self, t_s: float, alt_m: float, w: Where, ga: GoAround,
                          wind_mps: float) -> float:
        """The missed approach's TAS target (:class:`GoAround`), m/s: Vapp + the increment up
        to the acceleration height above the runway, then the planned speed in the leg's coded
        band."""
        if not self.accelerated and alt_m - ga.runway_elev_m >= ga.accel_height_m:
            self.accelerated = True
        lim = self.limits[w.leg] if w.leg < len(self.limits) else None
        lo, hi = cas_band(lim, None)
        if self.accelerated:
            plan = min(cas_to_tas_scalar(self.plan_cas_mps, alt_m, self.isa_dev_c),
                       arc_speed_cap_mps(w.act.pieces, w.i, w.along_m, w.gs_mps,
                                         self.bank_max_deg, wind_mps))
        else:
            plan = cas_to_tas_scalar(ga.vapp_cas_mps + ga.add_cas_mps, alt_m, self.isa_dev_c)
            lo = hi = None
        self.tas_cmd_mps = tas_target_mps(plan, alt_m, lo, hi, self.cas_min_mps,
                                          self.isa_dev_c, ga.vapp_cas_mps)
        self.next_t_s = t_s + SPEED_UPDATE_S
        return self.tas_cmd_mps
