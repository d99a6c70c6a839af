"""Re-planning: the rest of the procedure rebuilt from the aircraft's state, one API for every
reason to rebuild.

A :class:`Rebuild` says why and from where; :meth:`Replanner.build` builds it and returns the
new active path. The reasons (:attr:`Rebuild.kind`):

* ``leg_end`` — an altitude, DME or radial leg ended where the aircraft met its condition, not
  where the plan assumed (:mod:`.sequencing`): the legs after it are built again, DF legs whose
  fix is already behind skipped first (:func:`passed_direct_legs`);
* ``conditions`` — the measured wind or temperature differ from the planned ones
  (:mod:`.conditions`): the rest, the present leg included, is built from the present position
  for the measured conditions (:func:`~.conditions.measured_params`); a rebuilt rest that is not
  continuous (a discontinuity, a loop or an intercept not found) is refused and the plan kept,
  since the plan for the old conditions is still a flyable path;
* ``heading_drift`` — on the straight part of a heading leg the aircraft is more than
  :data:`HEADING_DRIFT_REBUILD_M` off the track its planned drift predicted (the wind ramped in
  after a still-air trim, a TAS or wind a little off the plan): the rest, the heading leg
  included, is built from the present position — as an FMS computes a heading leg's intercept
  from the present position — at most once every :data:`HEADING_DRIFT_REBUILD_S`.

Every rebuild is made by the same builder and monitor (:func:`fms_testbed.path.plan.rebuild_from`)
from a start one roll-in anticipation ahead on the present track after the roll-out
(:func:`roll_out_state`), so the first turn's roll is centred on its start as for any planned
turn. A rebuild from the present position waits until the aircraft flies a straight part of a
leg that can be rebuilt from mid-leg (not an arc, hold or procedure turn: :func:`rebuildable_here`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.geodesy import direct
from fms_testbed.core.planning import PLANNED_BANK_DEG
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.core.units import G0_MPS2
from fms_testbed.guidance.active_path import ActivePath, activate
from fms_testbed.guidance.conditions import ConditionMonitor, ConditionThresholds, measured_params
from fms_testbed.guidance.lateral import LateralGains, anticipation_m
from fms_testbed.guidance.locate import Where
from fms_testbed.guidance.sequencing import direct_fix_passed
from fms_testbed.guidance.steering import flies_heading
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.plan import FlyablePath, rebuild_from
from fms_testbed.procedures.records import Fix

HEADING_DRIFT_REBUILD_M = 100.0
"""A heading leg is rebuilt from the present position once the aircraft is this far off the
track its planned drift predicted, m."""
HEADING_DRIFT_REBUILD_S = 30.0
"""At most one such rebuild in this time, s."""
BROKEN_FINDINGS = ("discontinuity", "loop", "no-intercept")
"""Monitor findings that make a rebuilt rest not continuous."""


def passed_direct_legs(whole: FlyablePath, first: int, lat_rad: float, lon_rad: float,
                       track_rad: float, tas_mps: float) -> list[int]:
    """Indices ``first, first + 1, ...`` of the consecutive DF legs of the whole procedure
    ``whole`` whose fix is already passed (:func:`~.sequencing.direct_fix_passed`) at the
    navigation position ``lat_rad``, ``lon_rad`` (rad), track ``track_rad`` (rad) and planned
    speed ``tas_mps`` (m/s)."""
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

    The aircraft goes on turning while it rolls out at the roll rate p_max over
    t = |φ₀| / p_max; with the bank ramping linearly to zero the track changes by
    Δψ ≈ g tan φ₀ / V_g · t / 2 (the mean turn rate) and the aircraft covers V_g t along a chord
    on the mean track ψ + Δψ / 2.

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
    params : build settings for the rest (default: the whole path's)
    prev_fix : the fix the leg ``next_leg`` starts from (a TF rebuilt mid-leg rejoins its track
        from it), or None

    Returns
    -------
    The rebuilt rest, or None when there is no database to build from, nothing is left or the
    rest cannot be built.
    """
    v = gs_mps if gs_mps and gs_mps > 0.0 else cfg.limits.climb_cas_mps
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
    rebuilt from here: a straight part ('leg' line) of a leg that is not a coded arc, a hold or
    a procedure turn (those are rebuilt at their end instead)."""
    kind = LEG_TYPES[built.path_term]
    return (seg.role == "leg" and seg.geom.kind == "line" and kind.arc_centre is None
            and not kind.hold and not kind.course_reversal and not kind.initial)


@dataclass(frozen=True)
class Rebuild:
    """A reason to rebuild the rest of the procedure (module docstring).

    Attributes
    ----------
    kind : 'leg_end', 'conditions' or 'heading_drift'
    first_leg : whole-procedure index of the first leg rebuilt
    from_here : the first leg is the one flown, rebuilt from the present position (its
        previous fix kept as its origin); False: the legs after a leg that ended
    params : build settings of the rest (:class:`~fms_testbed.legs.model.BuildParams`)
    why : the measured conditions that differ ('conditions'), the heading leg's offset
        ('heading_drift'), '' ('leg_end')
    keep_plan_if_broken : refuse a rest that is not continuous (:data:`BROKEN_FINDINGS`)
    """

    kind: str
    first_leg: int
    from_here: bool
    params: object
    why: str = ""
    keep_plan_if_broken: bool = False

    def done_text(self, n_segments: int) -> str:
        """The ``rebuild`` event's detail once built."""
        if self.kind == "leg_end":
            return f"rest of the procedure rebuilt from the aircraft state ({n_segments} segments)"
        head = (f"conditions changed: {self.why}" if self.kind == "conditions"
                else f"heading leg {self.why} off its predicted track")
        return (f"{head}; rest of the procedure rebuilt from the present position "
                f"({n_segments} segments)")


class Replanner:
    """Builds the rest of the procedure for a :class:`Rebuild` and decides when one is due.

    Parameters
    ----------
    fp : the whole built procedure; cfg : the aircraft; db, spec : where it was built from
        (None: no in-flight rebuild is possible)
    gains : lateral tuning (roll rate: roll-out and roll-in distances)
    thresholds : when changed conditions call for a rebuild (:class:`~.conditions.ConditionThresholds`)

    Attributes
    ----------
    conditions : the :class:`~.conditions.ConditionMonitor`
    rebuilt : the rests built in flight and flown, in order
    """

    def __init__(self, fp: FlyablePath, cfg, db, spec, gains: LateralGains,
                 thresholds: ConditionThresholds | None = None):
        self.whole, self.cfg, self.db, self.spec, self.gains = fp, cfg, db, spec, gains
        self.conditions = ConditionMonitor(thresholds)
        self.rebuilt: list[FlyablePath] = []
        self._drift_rebuilt_s = -math.inf

    def leg_ended(self, w: Where, nav: NavSolution) -> tuple[list[int], Rebuild | None]:
        """The conditional leg flown ended: (the DF legs after it already passed — judged on
        the turn diameter at the present ground speed, at most the climb CAS, the speed the
        aircraft turns at — the rebuild of the legs after those; None when nothing is left)."""
        v = min(self.cfg.limits.climb_cas_mps, math.hypot(*nav.v_enu_mps[:2]))
        passed = passed_direct_legs(self.whole, w.leg + 1, nav.lat_rad, nav.lon_rad, w.trk_rad,
                                    v)
        nxt = (passed[-1] if passed else w.leg) + 1
        if nxt >= len(self.whole.seq.legs):
            return passed, None
        return passed, Rebuild("leg_end", nxt, False, w.act.fp.params)

    def due(self, w: Where, nav: NavSolution, air: AirData) -> Rebuild | None:
        """A rebuild from the present position that is due now: changed conditions (measured
        every call), else a heading leg drifted off its predicted track; None."""
        params = w.act.fp.params
        why = self.conditions.update(nav.t_s, nav, air, params)
        if why and rebuildable_here(w.seg, w.built) and self.db is not None:
            (wn, we), dev = self.conditions.measured
            self.conditions.rebuilt(nav.t_s)
            return Rebuild("conditions", w.leg, True,
                           measured_params(params, nav.alt_m, (wn, we), dev), why, True)
        if (self.db is None or not flies_heading(w.seg, w.p)
                or abs(w.xtk_m) < HEADING_DRIFT_REBUILD_M
                or not rebuildable_here(w.seg, w.built)
                or nav.t_s - self._drift_rebuilt_s < HEADING_DRIFT_REBUILD_S):
            return None
        self._drift_rebuilt_s = nav.t_s
        return Rebuild("heading_drift", w.leg, True, params, f"{w.xtk_m:+.0f} m")

    def build(self, r: Rebuild, w: Where, nav: NavSolution) -> tuple[ActivePath | None, str]:
        """Build ``r`` from the aircraft at ``w`` (navigation solution ``nav``): (the new active
        path, '') or (None, why it is refused: '' when it cannot be built, the first finding
        that breaks it when :attr:`Rebuild.keep_plan_if_broken`)."""
        k = r.first_leg
        prev = None
        if r.from_here and k > 0:
            t = self.whole.path.legs[k - 1].termination
            if t.kind == "fix" and t.lat_deg is not None:
                prev = Fix(ident=t.fix_ident, region="", section="", lat_deg=t.lat_deg,
                           lon_deg=t.lon_deg)
        v = nav.v_enu_mps
        gs = math.hypot(float(v[0]), float(v[1]))
        fp = rebuild_rest(self.db, self.whole, self.spec, self.cfg, self.gains, k, nav.lat_rad,
                          nav.lon_rad, w.trk_rad, nav.alt_m, gs, nav.roll_rad, params=r.params,
                          prev_fix=prev)
        if fp is None:
            return None, ""
        if r.keep_plan_if_broken:
            broken = [f for f in fp.path.findings if f.category in BROKEN_FINDINGS]
            if broken:
                return None, f"leg {broken[0].leg_index + w.leg}: {broken[0].message}"
        self.rebuilt.append(fp)
        return activate(fp, w.s_flight_m,
                        lead_from=(math.degrees(nav.lat_rad), math.degrees(nav.lon_rad))), ""


__all__ = ["BROKEN_FINDINGS", "HEADING_DRIFT_REBUILD_M", "HEADING_DRIFT_REBUILD_S", "Rebuild",
           "Replanner", "passed_direct_legs", "rebuild_rest", "rebuildable_here",
           "roll_out_state"]
