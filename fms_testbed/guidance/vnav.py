"""The vertical step of procedure guidance: the altitude command from the planned profile and
the TAS target from the speed plan, for the aircraft located on the active path.

Altitude (:func:`.vertical.altitude_command_m`, compiled: :mod:`.profile_kernel`): the blended planned profile read ahead by the
coupled law's lag, ``H_cmd = h + 2 ξ_H T_H V dh/ds + T_H² V_g² d²h/ds²`` with V the TAS from the
air data, or in a climb phase the climb target of the node ahead, never above the climb top and
never below the circling floor (:data:`CIRCLING_FLOOR_HEIGHT_M` above the airport of a circling
approach). Before the go-around the final approach path goes on through the MAP (the profile is
cut after the MAP: no blend into the missed-approach climb before it). Speed: :mod:`.speed_plan`.
"""

from __future__ import annotations

import math
from dataclasses import replace

from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.core.units import FT_M
from fms_testbed.guidance.active_path import ActivePath
from fms_testbed.guidance.locate import Where
from fms_testbed.guidance.speed_plan import GoAround, SpeedPlan
from fms_testbed.guidance.profile_kernel import ProfileNodes, altitude_command_fast_m
from fms_testbed.guidance.vertical import altitude_lead_s, planned_limits, scheduled_lead
from fms_testbed.guidance.vertical_schedule import schedule_from_config
from fms_testbed.legs.model import CEILING_MARGIN_M
from fms_testbed.path.plan import FlyablePath

CIRCLING_FLOOR_HEIGHT_M = 180.0
"""Lowest height above the airport a circling approach (one with no landing runway: ``RNV-A``,
``VOR-B``…) descends to, m: PANS-OPS (ICAO Doc 8168, Vol. II, circling) lowest OCH for a
category C aircraft, 180 m (591 ft). The CIFP codes no MDA and may code a circling MAP at the
field elevation, so the coded profile alone could lead into the ground."""
DEFAULT_CLIMB_TOP_M = 15000 * FT_M
"""Climb top when no procedure spec gives one, m."""


def circling_floor_m(fp: FlyablePath, db) -> float:
    """Lowest altitude command of a flight of ``fp`` (database ``db``), m: for a circling
    approach the airport elevation plus :data:`CIRCLING_FLOOR_HEIGHT_M`, else −inf."""
    from fms_testbed.path.runway import approach_runway

    if fp.path.proc_type != "F" or db is None or approach_runway(db, fp.seq) is not None:
        return -math.inf
    apt = db.airports.get(fp.seq.airport)
    if apt is None or apt.elev_m is None:
        return -math.inf
    return apt.elev_m + CIRCLING_FLOOR_HEIGHT_M


def climb_top_m(fp: FlyablePath, cfg, spec) -> float:
    """The climb top of a flight of ``fp`` by aircraft ``cfg``, m: the ``spec``'s (else
    :data:`DEFAULT_CLIMB_TOP_M`) below the aircraft's ceiling less its margin, raised to every
    'at or above' bound of the profile."""
    top = spec.climb_top_ft * FT_M if spec is not None else DEFAULT_CLIMB_TOP_M
    top = min(top, cfg.limits.alt_max_m - CEILING_MARGIN_M)
    los = [w.lo_m for w in (fp.path.profile.windows if fp.path.profile else ())
           if w.lo_m is not None]
    return max([top] + los)


class VerticalGuidance:
    """The vertical step (module docstring): :meth:`update` gives (altitude command m, TAS
    target m/s) for the aircraft at a :class:`~.locate.Where`.

    Parameters
    ----------
    fp : the whole built procedure; cfg : the aircraft (coupled-law timing, limits, approach
        settings); spec : its ProcedureSpec (climb top); db : its database (runway, airport)
    bank_max_deg : the bank limit arcs ahead are slowed for, deg (default: the aircraft's)

    Attributes
    ----------
    speed : the :class:`~.speed_plan.SpeedPlan`
    go_around_leg : whole-procedure index of the first missed-approach leg flown (None: the
        missed approach is not flown); floor_m : lowest altitude command, m
    """

    def __init__(self, fp: FlyablePath, cfg, spec=None, db=None,
                 bank_max_deg: float | None = None):
        lim = cfg.limits
        self.cfg = cfg
        self.lead_s = altitude_lead_s(cfg)
        self.t2_s2 = cfg.coupled_law.T_H_s ** 2 if cfg.coupled_law is not None else 0.0
        # with a gain schedule the read-ahead follows the scheduled ξ_H, T_H (set_mass)
        self.lead_schedule = (schedule_from_config(cfg) if cfg.coupled_law is not None
                              else None)
        self.mass_kg: float | None = None
        self.top_m = climb_top_m(fp, cfg, spec)
        self.approach = fp.path.proc_type == "F"
        self.speed = SpeedPlan(planned_limits(fp.seq.legs, fp.path.proc_type, lim.cas_min_mps),
                               fp.path.proc_type in ("E", "F"), lim.climb_cas_mps,
                               lim.cas_min_mps, lim.climb_cas_mps,
                               isa_dev_c=fp.params.isa_dev_c if fp.params is not None else 0.0,
                               bank_max_deg=lim.bank_max_deg if bank_max_deg is None
                               else bank_max_deg)
        self.go_around_leg = self._approach_speeds(fp, cfg, db)
        self.floor_m = circling_floor_m(fp, db)
        self._cut: tuple = (None, None, None)     # (active path, node count, profile lists)

    def _approach_speeds(self, fp: FlyablePath, cfg, db) -> int | None:
        """Set Vapp and the go-around speeds of an approach flown by an aircraft with approach
        settings; return the first missed-approach leg flown (None: not flown)."""
        from fms_testbed.path.runway import approach_runway

        ap = cfg.approach
        if not self.approach or ap is None:
            return None
        self.speed.vapp_cas_mps = ap.vapp_cas_mps_at(None)
        first = next((k for k, r in enumerate(fp.seq.legs) if r.missed_approach_start), None)
        if first is None:
            return None
        rw = approach_runway(db, fp.seq) if db is not None else None
        elev = rw.elev_m if rw is not None and rw.elev_m is not None else \
            float(fp.path.profile.alt_m[first]) if fp.path.profile is not None else 0.0
        self.speed.go_around = GoAround(first, ap.vapp_cas_mps_at(None), ap.go_around_add_cas_mps,
                                        ap.acceleration_height_m, float(elev))
        return first

    def go_around_active(self, leg: int) -> bool:
        """True once whole-procedure leg ``leg`` is in the missed approach flown."""
        return self.go_around_leg is not None and leg >= self.go_around_leg

    def set_mass(self, mass_kg: float) -> None:
        """The gross weight the FMS flies with (kg): Vapp is scaled to it (approach settings),
        and with a coupled-law gain schedule the altitude read-ahead follows the schedule at it."""
        self.mass_kg = mass_kg
        ap = self.cfg.approach
        if ap is None or self.speed.vapp_cas_mps is None:
            return
        self.speed.vapp_cas_mps = ap.vapp_cas_mps_at(mass_kg)
        if self.speed.go_around is not None:
            self.speed.go_around = replace(self.speed.go_around,
                                           vapp_cas_mps=self.speed.vapp_cas_mps)

    def _nodes(self, a: ActivePath, leg: int) -> ProfileNodes:
        """The profile nodes flown now (packed once per path), cut after the MAP before the
        go-around."""
        j = len(a.prof_s)
        if self.go_around_leg is not None and not self.go_around_active(leg):
            cut = self.go_around_leg - a.fp.leg_offset + 1
            if 1 < cut < j:
                j = cut
        if self._cut[0] is not a or self._cut[1] != j:
            self._cut = (a, j, ProfileNodes.of(a.prof_s[:j], a.prof_h[:j], a.climb_tgt[:j],
                                               a.windows[:j], a.coded_angle[:j]))
        return self._cut[2]

    def update(self, w: Where, nav: NavSolution, air: AirData) -> tuple[float, float]:
        """(altitude command m, TAS target m/s) at ``w`` (module docstring)."""
        if self.lead_schedule is not None and self.mass_kg is not None:
            lead = scheduled_lead(self.lead_schedule, air.tas_mps, air.p_static_pa,
                                  air.t_static_k, self.mass_kg)
            if lead is not None:
                self.lead_s, self.t2_s2 = lead
        alt_cmd = max(altitude_command_fast_m(self._nodes(w.act, w.leg), w.s_path_m, w.gs_mps,
                                              self.lead_s, self.t2_s2, self.top_m,
                                              self.approach, air.tas_mps),
                      self.floor_m)
        return alt_cmd, self.speed.update(nav.t_s, nav.alt_m, w)


__all__ = ["CIRCLING_FLOOR_HEIGHT_M", "DEFAULT_CLIMB_TOP_M", "VerticalGuidance",
           "circling_floor_m", "climb_top_m"]
