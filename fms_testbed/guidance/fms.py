"""``ProcedureGuidance``: flies a built ARINC-424 procedure through the flight loop's Guidance hook.

Every outer step (10 Hz by default) :meth:`ProcedureGuidance.update` runs a fixed sequence of
named steps, each in its own module:

1. **locate** — project the *navigation* position on the active path piece (local tangent
   plane, :mod:`.geometry`): guidance flies on the navigation solution, so NSE shows in the true
   track; enter the piece's leg;
2. **leg end** — a conditional leg (altitude, DME distance, radial) ends when its condition is
   met (:mod:`.sequencing`): earlier than planned, the rest of the procedure is rebuilt from the
   aircraft's state (:mod:`.replan`, then :mod:`.active_path` post-processes it); later, the
   leg's last line is flown on beyond its planned end until the condition is met;
3. **sequence** — pass to the next piece abeam the end of the present one (fly-by arcs are part
   of the path, so the transition points are the planned ones); an HA hold is left over its fix
   at the end of the first circuit completed with the altitude reached;
4. **lateral** — bank from the path-following law with the curvature ahead fed forward, or the
   coded heading held on the straight part of a heading leg (:mod:`.steering`);
5. **vertical** — altitude command from the planned profile (:func:`.vertical.altitude_command_m`)
   and TAS target from the speed plan (:mod:`.speed_plan`);
6. **log** — one record with units (:mod:`.step_log`): TSE, FTE, PDE (:mod:`.pde`), leg, RNP.

Truth is used only for logging, never for control.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.contracts import GuidanceOutput
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.guidance.active_path import activate
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.guidance.lateral import LateralGains
from fms_testbed.guidance.replan import (ConditionMonitor, measured_params, passed_direct_legs,
                                         rebuild_rest, rebuildable_here)
from fms_testbed.guidance.sequencing import OVERRUN_MAX_M, ConditionWatch, hold_exit_reached
from fms_testbed.guidance.speed_plan import GoAround, SpeedPlan
from fms_testbed.guidance.steering import flies_heading, steer_bank_rad
from fms_testbed.guidance.step_log import log_row
from fms_testbed.guidance.vertical import (altitude_command_m, altitude_lead_s,
                                          planned_limits)
from fms_testbed.legs.model import CEILING_MARGIN_M, BuiltLeg, PathSegment
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.plan import FlyablePath
from fms_testbed.procedures.records import Fix

HEADING_DRIFT_REBUILD_M = 100.0
"""A heading leg is rebuilt from the present position once the aircraft is this far off the
track its planned drift predicted, m (:meth:`ProcedureGuidance._heading_drifted`)."""
HEADING_DRIFT_REBUILD_S = 30.0
"""At most one such rebuild in this time, s."""
XTK_ABORT_M = 5 * NM_M
"""Cross-track beyond which the flight is declared off the procedure, m."""
CIRCLING_FLOOR_HEIGHT_M = 180.0
"""Lowest height above the airport a circling approach (one with no landing runway: ``RNV-A``,
``VOR-B``…) descends to, m: PANS-OPS (ICAO Doc 8168, Vol. II, circling) lowest OCH for a
category C aircraft, 180 m (591 ft). The CIFP codes no MDA; its circling MAP is often coded at
the field elevation, so the coded profile alone would fly into the ground."""
DEFAULT_CLIMB_TOP_M = 15000 * FT_M
"""Climb top when no procedure spec gives one, m."""


def planned_wind_mps(fp: FlyablePath, alt_m: float) -> float:
    """The wind speed the path was planned for at ``alt_m`` (m), m/s: the plan's profile there,
    else its constant wind; 0 in calm or without planning parameters. A measured wind that
    differs makes :mod:`.replan` rebuild the path for it, so this is the flight's best wind."""
    p = fp.params
    if p is None:
        return 0.0
    if p.wind_profile is not None:
        return float(p.wind_profile.at(alt_m)[0])
    return float(p.wind_speed_mps)


@dataclass(frozen=True, slots=True)
class _Where:
    """Step 1's answer: the piece flown (of segment ``seg``, of built leg ``built``) and the
    aircraft's place on it (navigation solution).

    along_m / xtk_m: along the piece and cross-track, m; dtrk_rad: the piece's track there,
    rad; gs_mps / trk_rad: ground speed (m/s) and track (rad); leg: whole-procedure leg index.
    """

    p: LocalPiece
    seg: PathSegment
    built: BuiltLeg
    along_m: float
    xtk_m: float
    dtrk_rad: float
    gs_mps: float
    trk_rad: float
    leg: int


_MOVED = object()
"""Step 2/3 result: the active piece or path changed; locate again."""


class ProcedureGuidance:
    """Guidance that flies a :class:`~fms_testbed.path.plan.FlyablePath` (implements the
    ``Guidance`` protocol of :mod:`fms_testbed.core.contracts`:
    ``update(dt_s, nav, truth) -> GuidanceOutput``).

    Parameters
    ----------
    fp : the built procedure
    cfg : aircraft configuration (bank limit, roll rate, minimum speed, coupled-law timing)
    db : the database it came from (in-flight rebuilds); spec : its ProcedureSpec
    gains : lateral tuning (default: :meth:`LateralGains.for_aircraft`)
    log_every : build the log only every this many calls — the loop's logging cadence
        (``round(outer_rate_hz / log_rate_hz)``, logging at calls 0, n, 2n, ...); 1 = always

    Attributes
    ----------
    events : list of dicts (t_s, kind 'leg' | 'rebuild' | 'condition' | 'abort', leg, detail)
    legs_sequenced : global leg indices in the order they became active
    abort_reason : why guidance stopped early ('' when it did not)
    rebuilt : the paths rebuilt in flight (rest of the procedure), in order
    act : the active path (:class:`~.active_path.ActivePath`); i : its piece flown; leg : the
        whole-procedure leg flown
    """

    def __init__(self, fp: FlyablePath, cfg, db=None, spec=None, gains: LateralGains | None = None,
                 log_every: int = 1):
        self.whole = fp
        self.cfg, self.db, self.spec = cfg, db, spec
        self.gains = gains or LateralGains.for_aircraft(cfg)
        self.act = activate(fp, 0.0, cfg.limits.climb_tas_mps)
        self.i = 0
        self.leg = -1
        self.events: list[dict] = []
        self.legs_sequenced: list[int] = []
        self.abort_reason = ""
        self.lead_s = altitude_lead_s(cfg)
        self.heading_kp = cfg.inner_loops.heading_kp
        top = spec.climb_top_ft * FT_M if spec is not None else DEFAULT_CLIMB_TOP_M
        top = min(top, cfg.limits.alt_max_m - CEILING_MARGIN_M)   # below the ceiling
        los = [w.lo_m for w in (fp.path.profile.windows if fp.path.profile else ())
               if w.lo_m is not None]
        self.top_m = max([top] + los)
        self.t2_s2 = cfg.coupled_law.T_H_s ** 2 if cfg.coupled_law is not None else 0.0
        self.approach = fp.path.proc_type == "F"
        self.speed = SpeedPlan(planned_limits(fp.seq.legs, fp.path.proc_type,
                                              cfg.limits.cas_min_mps),
                               fp.path.proc_type in ("E", "F"),
                               cfg.limits.climb_tas_mps, cfg.limits.cas_min_mps,
                               cfg.limits.climb_tas_mps)
        self.speed.isa_dev_c = fp.params.isa_dev_c if fp.params is not None else 0.0
        self._approach_speeds(fp, cfg, db)
        self.floor_m = self._circling_floor_m(fp, db)
        self.watch = ConditionWatch()
        self.done = False
        self.calls = 0
        self.log_every = max(1, int(log_every))
        self.rebuilt: list[FlyablePath] = []
        self.conditions = ConditionMonitor()
        """Measured vs planned wind and temperature (:mod:`.replan`): a rebuild when they differ."""
        self._drift_rebuilt_s = -math.inf
        """When a heading leg was last rebuilt for its drift, s."""

    def _circling_floor_m(self, fp: FlyablePath, db) -> float:
        """Lowest altitude command, m: for a circling approach the airport elevation plus
        :data:`CIRCLING_FLOOR_HEIGHT_M`, else −inf."""
        from fms_testbed.path.runway import approach_runway

        if not self.approach or db is None or approach_runway(db, fp.seq) is not None:
            return -math.inf
        apt = db.airports.get(fp.seq.airport)
        if apt is None or apt.elev_m is None:
            return -math.inf
        return apt.elev_m + CIRCLING_FLOOR_HEIGHT_M

    def _approach_speeds(self, fp: FlyablePath, cfg, db) -> None:
        """Vapp and the go-around speeds of an approach flown by an aircraft with approach
        settings (:mod:`.speed_plan`); ``go_around_leg``: the first missed-approach leg flown
        (None: the missed approach is not flown)."""
        from fms_testbed.path.runway import approach_runway

        self.go_around_leg = None
        ap = cfg.approach
        if not self.approach or ap is None:
            return
        self.speed.vapp_cas_mps = ap.vapp_cas_mps_at(None)
        first = next((k for k, r in enumerate(fp.seq.legs) if r.missed_approach_start), None)
        if first is None:
            return
        rw = approach_runway(db, fp.seq) if db is not None else None
        elev = rw.elev_m if rw is not None and rw.elev_m is not None else \
            float(fp.path.profile.alt_m[first]) if fp.path.profile is not None else 0.0
        self.go_around_leg = first
        self.speed.go_around = GoAround(first, ap.vapp_cas_mps_at(None), ap.go_around_add_cas_mps,
                                        ap.acceleration_height_m, float(elev))

    def set_mass(self, mass_kg: float) -> None:
        """The gross weight the FMS flies with (kg): Vapp is scaled to it (approach settings)."""
        ap = self.cfg.approach
        if ap is None or self.speed.vapp_cas_mps is None:
            return
        self.speed.vapp_cas_mps = ap.vapp_cas_mps_at(mass_kg)
        if self.speed.go_around is not None:
            from dataclasses import replace
            self.speed.go_around = replace(self.speed.go_around,
                                           vapp_cas_mps=self.speed.vapp_cas_mps)

    @property
    def go_around_active(self) -> bool:
        """True once the missed approach is flown (its first leg entered)."""
        return self.go_around_leg is not None and self.leg >= self.go_around_leg

    # ------------------------------------------------------------------ the step
    def update(self, dt_s: float, nav, truth) -> GuidanceOutput:
        """One guidance step: bank command, altitude and TAS targets, done flag, log (module
        docstring: locate → leg end → sequence → lateral → vertical → log)."""
        while not self.done:
            w = self._locate(nav)
            out = self._leg_end(w, nav)
            if out is _MOVED:
                continue
            if out is not None:
                return out
            if self._conditions_changed(w, nav, truth):
                continue
            hold = self._held_past_plan(w, nav)
            out = self._sequence(w, nav, truth, hold)
            if out is _MOVED:
                continue
            if out is not None:
                return out
            if abs(w.xtk_m) > XTK_ABORT_M:
                return self._abort(nav.t_s, f"off the procedure: cross-track "
                                   f"{w.xtk_m / NM_M:.1f} NM on leg {w.leg + 1} "
                                   f"({w.built.path_term})")
            bank = self._lateral(w, nav, hold)
            s_path = self._s_path_m(w)
            a = self.act
            ps, ph, ct, win, va = a.prof_s, a.prof_h, a.climb_tgt, a.windows, a.coded_angle
            if self.go_around_leg is not None and not self.go_around_active:
                # before the go-around the final approach path goes on through the MAP (no
                # blend into the missed-approach climb before it): the profile up to the MAP
                j = self.go_around_leg - a.fp.leg_offset + 1
                if 1 < j < len(ps):
                    ps, ph, ct, win, va = ps[:j], ph[:j], ct[:j], win[:j], va[:j]
            alt_cmd = max(altitude_command_m(ps, ph, ct, s_path, w.gs_mps, self.lead_s,
                                             self.t2_s2, self.top_m, self.approach, win, va,
                                             getattr(truth, "tas_mps", None)),
                          self.floor_m)
            prof = self.act.fp.path.profile
            sched = getattr(prof, "speed", None)
            s_sched = s_path - (self.act.prof_s[0] - float(prof.along_m[0])) \
                if sched is not None else None
            tas_cmd = self.speed.update(nav.t_s, nav.alt_m, w.leg, self.act.pieces, self.i,
                                        w.along_m, w.gs_mps, self.gains.bank_max_deg,
                                        self.act.piece_legs, sched, s_sched,
                                        planned_wind_mps(self.act.fp, nav.alt_m))
            return GuidanceOutput(bank_rad=bank, alt_m=alt_cmd, tas_mps=tas_cmd,
                                  log=self._log_due(w, truth, s_path))
        return GuidanceOutput(done=True)

    # ------------------------------------------------------------------ 1. locate
    def _locate(self, nav) -> _Where:
        """Project the navigation position on the active piece and enter its leg."""
        a = self.act
        v = nav.v_enu_mps
        ve, vn = float(v[0]), float(v[1])
        p = a.pieces[self.i]
        along, xtk, dtrk = p.project(nav.lat_rad, nav.lon_rad)
        seg = a.segs[p.seg_index]
        leg = a.fp.leg_offset + seg.leg_index
        self._enter_leg(nav.t_s, leg)
        return _Where(p, seg, a.fp.path.legs[seg.leg_index], along, xtk, dtrk,
                      math.hypot(ve, vn), math.atan2(ve, vn), leg)

    def _enter_leg(self, t_s: float, g: int) -> None:
        """Make whole-procedure leg ``g`` the active one; every leg up to it is entered once,
        in order (events, speed limits carried in descent)."""
        if g == self.leg:
            return
        for k in range(self.leg + 1, g + 1):
            self.legs_sequenced.append(k)
            self.events.append({"t_s": t_s, "kind": "leg", "leg": k,
                                "code": self.whole.seq.legs[k].path_term})
            self.speed.enter_leg(k)
        self.leg = g
        self.watch.reset()
        self.speed.due_now()

    # ------------------------------------------------------------------ 2. leg end
    def _leg_end(self, w: _Where, nav):
        """A conditional leg whose condition is met: rebuild the rest from here, else pass to
        the leg's next piece. Returns _MOVED, a final output, or None (leg goes on)."""
        if not LEG_TYPES[w.built.path_term].conditional or \
                not self.watch.met(w.built.termination, nav.lat_rad, nav.lon_rad, nav.alt_m):
            return None
        self._event(nav.t_s, "condition", w.leg, f"{w.built.termination.kind} condition met")
        if self._rebuild(nav.t_s, w, nav):
            return _MOVED
        return self._past_leg(w)

    def _rebuild(self, t_s: float, w: _Where, nav) -> bool:
        """Rebuild the rest of the procedure from the aircraft's state (:mod:`.replan`); DF legs
        whose fix is already behind are passed first. True when a rebuilt path is active."""
        nxt = w.leg + 1
        v = self.cfg.limits.climb_tas_mps
        for k in passed_direct_legs(self.whole, nxt, nav.lat_rad, nav.lon_rad, w.trk_rad, v):
            self._event(t_s, "condition", k, "DF fix already passed when the previous leg ended")
            self._enter_leg(t_s, k)
            nxt = k + 1
        if nxt >= len(self.whole.seq.legs) or not self._rebuild_rest(w, nav, self.act.fp.params,
                                                                     leg=nxt):
            return False
        self._event(t_s, "rebuild", nxt, f"rest of the procedure rebuilt from the aircraft "
                                          f"state ({len(self.act.fp.path.segments)} segments)")
        return True

    def _conditions_changed(self, w: _Where, nav, truth) -> bool:
        """Step 2b: the measured wind or temperature differs from the planned one beyond its
        threshold (:class:`~.replan.ConditionMonitor`): the rest of the procedure, the present
        leg included, rebuilt from the present position for the measured conditions. True when
        a rebuilt path is active."""
        why = self.conditions.update(nav.t_s, nav, truth, self.act.fp.params)
        if not why or not rebuildable_here(w.seg, w.built) or self.db is None:
            return self._heading_drifted(w, nav)
        (wn, we), dev = self.conditions.measured
        params = measured_params(self.act.fp.params, nav.alt_m, (wn, we), dev)
        self.conditions.rebuilt(nav.t_s)
        kept = (self.act, self.i, len(self.rebuilt))
        if not self._rebuild_rest(w, nav, params):
            self._event(nav.t_s, "condition", w.leg, f"conditions changed ({why}); the rest "
                                                     "could not be rebuilt: the plan is kept")
            return False
        broken = [f for f in self.act.fp.path.findings
                  if f.category in ("discontinuity", "loop", "no-intercept")]
        if broken:
            # a rebuilt rest that is not continuous is worse than the plan for the old
            # conditions (KBFI H14RZ from mid-TF in a 12 kt wind: the RF joined 127° off its
            # tangent and flown as two 360° loops): keep the plan
            self.act, self.i = kept[0], kept[1]
            del self.rebuilt[kept[2]:]
            self._event(nav.t_s, "condition", w.leg,
                        f"conditions changed ({why}); the rebuilt rest is not continuous "
                        f"(leg {broken[0].leg_index + w.leg}: {broken[0].message}): the plan "
                        "is kept")
            return False
        self.speed.isa_dev_c = params.isa_dev_c
        self._event(nav.t_s, "rebuild", w.leg, f"conditions changed: {why}; rest of the "
                                               f"procedure rebuilt from the present position "
                                               f"({len(self.act.fp.path.segments)} segments)")
        return True

    def _heading_drifted(self, w: _Where, nav) -> bool:
        """Step 2c: on the straight part of a heading leg (V*) the aircraft is more than
        :data:`HEADING_DRIFT_REBUILD_M` off the track its planned drift predicted (the wind
        ramped in after a still-air trim, a TAS or wind a little off the plan): the rest of
        the procedure, the heading leg included, is rebuilt from the present position, so the
        intercept or turn at the leg's end starts where the aircraft is — as an FMS computes a
        heading leg's intercept from the present position. At most once every
        :data:`HEADING_DRIFT_REBUILD_S`. True when a rebuilt path is active."""
        if (self.db is None or not flies_heading(w.seg, w.p)
                or abs(w.xtk_m) < HEADING_DRIFT_REBUILD_M
                or not rebuildable_here(w.seg, w.built)
                or nav.t_s - self._drift_rebuilt_s < HEADING_DRIFT_REBUILD_S):
            return False
        self._drift_rebuilt_s = nav.t_s
        off = w.xtk_m
        if not self._rebuild_rest(w, nav, self.act.fp.params):
            return False
        self._event(nav.t_s, "rebuild", w.leg, f"heading leg {off:+.0f} m off its predicted "
                                               f"track; rest of the procedure rebuilt from the "
                                               f"present position "
                                               f"({len(self.act.fp.path.segments)} segments)")
        return True

    def _rebuild_rest(self, w: _Where, nav, params, leg: int | None = None) -> bool:
        """Rebuild the rest of the procedure from the present position for ``params`` and make
        it the active path: from the present leg (its previous fix kept as the leg's origin),
        or from ``leg`` on (a conditional leg that ended); False when it cannot be built."""
        k = w.leg if leg is None else leg
        prev = None
        if leg is None and k > 0:
            t = self.whole.path.legs[k - 1].termination
            if t.kind == "fix" and t.lat_deg is not None:
                prev = Fix(ident=t.fix_ident, region="", section="", lat_deg=t.lat_deg,
                           lon_deg=t.lon_deg)
        v = nav.v_enu_mps
        gs = math.hypot(float(v[0]), float(v[1]))
        fp = rebuild_rest(self.db, self.whole, self.spec, self.cfg, self.gains, k,
                          nav.lat_rad, nav.lon_rad, w.trk_rad, nav.alt_m, gs, nav.roll_rad,
                          params=params, prev_fix=prev)
        if fp is None:
            return False
        a = self.act
        s_now = a.s_base_m + a.seg_cum_m[w.p.seg_index] + w.p.s0_m + w.along_m
        self.act = activate(fp, s_now, self.cfg.limits.climb_tas_mps,
                            lead_from=(math.degrees(nav.lat_rad), math.degrees(nav.lon_rad)))
        self.rebuilt.append(fp)
        self.i = 0
        return True

    def _past_leg(self, w: _Where):
        """Go to the first piece after the present leg's; done when there is none."""
        nxt = self.act.last_piece_of_leg[w.seg.leg_index] + 1
        if nxt >= len(self.act.pieces):
            self.done = True
            return GuidanceOutput(done=True)
        self.i = nxt
        return _MOVED

    def _held_past_plan(self, w: _Where, nav) -> bool:
        """True while a conditional leg is flown on past its planned end, waiting for its
        condition (up to OVERRUN_MAX_M past the plan)."""
        if not LEG_TYPES[w.built.path_term].conditional:
            return False
        hold = self.i == self.act.last_piece_of_leg[w.seg.leg_index]
        if hold and w.along_m > w.p.length_m + OVERRUN_MAX_M:
            self._event(nav.t_s, "condition", w.leg, f"{w.built.termination.kind} condition "
                        f"not met {OVERRUN_MAX_M / NM_M:.0f} NM past the plan")
            return False
        return hold

    # ------------------------------------------------------------------ 3. sequence
    def _sequence(self, w: _Where, nav, truth, hold: bool):
        """Abeam the end of the piece: the next piece (or the end of an HA hold, or the end of
        the procedure). Returns _MOVED, a final output, or None (piece goes on)."""
        if w.along_m < w.p.length_m or hold:
            return None
        if self.i + 1 >= len(self.act.pieces):
            self.done = True
            return GuidanceOutput(done=True, log=self._log(w, truth, self._s_path_m(w)))
        kind = LEG_TYPES[w.built.path_term]
        if kind.hold and kind.altitude_terminated and \
                hold_exit_reached(w.p, w.seg, w.built.termination, nav.alt_m):
            self._event(nav.t_s, "condition", w.leg, "HA altitude reached: hold left over the fix")
            return self._past_leg(w)
        self.i += 1
        return _MOVED

    # ------------------------------------------------------------------ 4. lateral
    def _lateral(self, w: _Where, nav, hold: bool) -> float:
        """Bank command, rad (:func:`.steering.steer_bank_rad`); no curvature ahead while a
        conditional leg is flown on past its plan."""
        a = self.act
        nxt = a.pieces[self.i + 1] if self.i + 1 < len(a.pieces) and not hold else None
        return steer_bank_rad(w.seg, w.p, w.along_m, w.xtk_m, w.dtrk_rad, nxt, w.trk_rad,
                              nav.heading_rad, w.gs_mps, self.gains, self.heading_kp)

    # ------------------------------------------------------------------ 6. log, helpers
    def _s_path_m(self, w: _Where) -> float:
        """Distance along the active path, m."""
        return self.act.seg_cum_m[w.p.seg_index] + w.p.s0_m + w.along_m

    def _log(self, w: _Where, truth, s_path: float) -> dict:
        _, true_xtk, _ = w.p.project(truth.lat_rad, truth.lon_rad)
        return log_row(self.act, w.p, w.along_m, w.xtk_m, true_xtk, w.seg, w.leg, s_path)

    def _log_due(self, w: _Where, truth, s_path: float) -> dict:
        """The log record at the loop's logging cadence (``log_every``), else {}."""
        self.calls += 1
        due = (self.calls - 1) % self.log_every == 0
        return self._log(w, truth, s_path) if due else {}

    def _event(self, t_s: float, kind: str, leg: int, detail: str) -> None:
        self.events.append({"t_s": t_s, "kind": kind, "leg": leg, "detail": detail})

    def _abort(self, t_s: float, why: str) -> GuidanceOutput:
        self.abort_reason = why
        self._event(t_s, "abort", self.leg, why)
        self.done = True
        return GuidanceOutput(done=True)
