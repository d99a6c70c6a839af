"""``ProcedureGuidance``: flies a built ARINC-424 procedure through the flight loop's
:class:`~fms_testbed.core.contracts.Guidance` interface, on the navigation solution and the air
data — never on the true state.

Every outer step (10 Hz by default) :meth:`ProcedureGuidance.update` runs a fixed sequence of
steps, each owned by its own module:

1. **locate** — project the navigation position on the active path piece (:mod:`.locate`;
   guidance flies on the navigation solution, so NSE shows in the true track) and enter its leg;
2. **leg end** — a conditional leg (altitude, DME distance, radial) ends when its condition is
   met (:mod:`.sequencing`): earlier than planned, the rest of the procedure is rebuilt from the
   aircraft's state (:mod:`.replan`); later, the leg's last line is flown on beyond its planned
   end until the condition is met;
3. **replan** — changed conditions or a drifted heading leg rebuild the rest from the present
   position (:class:`~.replan.Replanner`: one rebuild API for every reason);
4. **sequence** — pass to the next piece abeam the end of the present one (fly-by arcs are part
   of the path, so the transition points are the planned ones); an HA hold is left over its fix
   at the end of the first circuit completed with the altitude reached;
5. **lateral** — bank from the path-following law with the curvature ahead fed forward, or the
   coded heading held on the straight part of a heading leg (:mod:`.steering`);
6. **vertical** — altitude command and TAS target (:mod:`.vnav`).

A step that changes the piece or the path (2-4) locates the aircraft again on the new one. The
log (:mod:`.step_log`) is built after the flight from where each logged step located the
aircraft.
"""

from __future__ import annotations

from fms_testbed.core.contracts import GuidanceBase, GuidanceOutput
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.core.units import NM_M
from fms_testbed.guidance.active_path import activate
from fms_testbed.guidance.lateral import LateralGains
from fms_testbed.guidance.locate import Where, locate
from fms_testbed.guidance.replan import Rebuild, Replanner
from fms_testbed.guidance.sequencing import LegSequencer
from fms_testbed.guidance.step_log import LOG_COLUMNS, log_frame, record
from fms_testbed.guidance.steering import steer_bank_rad
from fms_testbed.guidance.vnav import VerticalGuidance
from fms_testbed.path.plan import FlyablePath

XTK_ABORT_M = 5 * NM_M
"""Cross-track beyond which the flight is declared off the procedure, m."""
_DONE = GuidanceOutput(done=True)


class ProcedureGuidance(GuidanceBase):
    """Guidance that flies a :class:`~fms_testbed.path.plan.FlyablePath` (module docstring).

    Parameters
    ----------
    fp : the built procedure
    cfg : aircraft configuration (bank limit, roll rate, minimum speed, coupled-law timing)
    db : the database it came from (in-flight rebuilds); spec : its ProcedureSpec
    gains : lateral tuning (default: :meth:`LateralGains.for_aircraft`)

    Attributes
    ----------
    events : list of dicts (t_s, kind 'leg' | 'rebuild' | 'condition' | 'abort', leg, detail)
    abort_reason : why guidance stopped early ('' when it did not)
    act : the active path (:class:`~.active_path.ActivePath`)
    seq : the :class:`~.sequencing.LegSequencer` (piece and leg flown)
    replan : the :class:`~.replan.Replanner` (its ``rebuilt``: the rests built in flight)
    vnav : the :class:`~.vnav.VerticalGuidance`
    """

    log_columns = LOG_COLUMNS

    def __init__(self, fp: FlyablePath, cfg, db=None, spec=None,
                 gains: LateralGains | None = None):
        super().__init__()
        self.whole, self.cfg = fp, cfg
        self.gains = gains or LateralGains.for_aircraft(cfg)
        self.heading_kp = cfg.inner_loops.heading_kp
        self.act = activate(fp, 0.0)
        self.paths = [self.act]
        """Every path made active, in order (the log records name them by index)."""
        self.vnav = VerticalGuidance(fp, cfg, spec, db, self.gains.bank_max_deg)
        self.seq = LegSequencer([r.path_term for r in fp.seq.legs], self.vnav.speed.enter_leg,
                                self.events)
        self.replan = Replanner(fp, cfg, db, spec, self.gains)
        self.done = False
        self._last: tuple | None = None

    # ------------------------------------------------------------------ the Guidance interface
    @property
    def go_around_active(self) -> bool:
        """True once the missed approach is flown (its first leg entered)."""
        return self.vnav.go_around_active(self.seq.leg)

    def set_mass(self, mass_kg: float) -> None:
        """The gross weight the FMS flies with (kg): Vapp is scaled to it (approach settings)."""
        self.vnav.set_mass(mass_kg)

    def position_text(self) -> str:
        """'leg k of n' (whole procedure)."""
        return f"leg {self.seq.leg + 1} of {len(self.whole.seq.legs)}"

    def log_record(self) -> tuple | None:
        """Where the last :meth:`update` located the aircraft (:func:`~.step_log.record`; None:
        nowhere)."""
        return self._last

    def log_frame(self, records, true_lat_rad, true_lon_rad) -> dict[str, list]:
        """The guidance columns (:data:`~.step_log.LOG_COLUMNS`) of the logged records."""
        return log_frame(self.paths, records, true_lat_rad, true_lon_rad)

    def update(self, dt_s: float, nav: NavSolution, air: AirData) -> GuidanceOutput:
        """One guidance step: bank command, altitude and TAS targets, done flag (module
        docstring: locate → leg end → replan → sequence → lateral → vertical)."""
        seq, t = self.seq, nav.t_s
        self._last = None
        while not self.done:
            w = locate(self.act, seq.i, nav)
            if seq.enter(t, w.leg):
                self.vnav.speed.due_now()
            if seq.condition_met(w, t, nav.lat_rad, nav.lon_rad, nav.alt_m):
                if self._leg_ended(w, nav) or seq.past_leg(w):
                    continue
                return self._finish(None)
            if self._rebuild(self.replan.due(w, nav, air), w, nav):
                continue
            hold = seq.held_past_plan(w, t)
            if w.along_m >= w.p.length_m and not hold:
                if seq.passed(w, t, nav.alt_m):
                    continue
                return self._finish(w if w.i + 1 >= len(w.act.pieces) else None)
            if abs(w.xtk_m) > XTK_ABORT_M:
                return self._abort(t, f"off the procedure: cross-track {w.xtk_m / NM_M:.1f} NM "
                                      f"on leg {w.leg + 1} ({w.built.path_term})")
            self._last = record(len(self.paths) - 1, w)
            nxt = None if hold else w.next_piece
            bank = steer_bank_rad(w.seg, w.p, w.along_m, w.xtk_m, w.dtrk_rad, nxt, w.trk_rad,
                                  nav.heading_rad, w.gs_mps, self.gains, self.heading_kp)
            alt_cmd, tas_cmd = self.vnav.update(w, nav, air)
            return GuidanceOutput(bank, alt_cmd, tas_cmd)
        return _DONE

    # ------------------------------------------------------------------ the steps
    def _leg_ended(self, w: Where, nav: NavSolution) -> bool:
        """The conditional leg flown has ended: DF legs already passed are entered, the rest
        rebuilt from the aircraft's state. True when a rebuilt path is active."""
        passed, r = self.replan.leg_ended(w, nav)
        for k in passed:
            self.events.append({"t_s": nav.t_s, "kind": "condition", "leg": k,
                                "detail": "DF fix already passed when the previous leg ended"})
            if self.seq.enter(nav.t_s, k):
                self.vnav.speed.due_now()
        return self._rebuild(r, w, nav)

    def _rebuild(self, r: Rebuild | None, w: Where, nav: NavSolution) -> bool:
        """Build ``r`` (:meth:`.replan.Replanner.build`) and fly it; the events say what was
        done. True when a rebuilt path is active."""
        if r is None:
            return False
        act, refused = self.replan.build(r, w, nav)
        if act is None:
            if r.kind == "conditions":
                why = ("the rest could not be rebuilt" if not refused else
                       f"the rebuilt rest is not continuous ({refused})")
                self._event(nav.t_s, "condition", w.leg,
                            f"conditions changed ({r.why}); {why}: the plan is kept")
            return False
        self.act = act
        self.paths.append(act)
        self.seq.restart()
        if r.kind == "conditions":
            self.vnav.speed.isa_dev_c = r.params.isa_dev_c
        self._event(nav.t_s, "rebuild", r.first_leg, r.done_text(len(act.fp.path.segments)))
        return True

    def _finish(self, w: Where | None) -> GuidanceOutput:
        """The path has been flown to its end (``w``: where, for the last log record)."""
        self.done = True
        self._last = None if w is None else record(len(self.paths) - 1, w)
        return _DONE

    def _event(self, t_s: float, kind: str, leg: int, detail: str) -> None:
        self.events.append({"t_s": t_s, "kind": kind, "leg": leg, "detail": detail})

    def _abort(self, t_s: float, why: str) -> GuidanceOutput:
        self.abort_reason = why
        self._event(t_s, "abort", self.seq.leg, why)
        self.done = True
        return _DONE

    # ------------------------------------------------------------------ read-outs
    @property
    def leg(self) -> int:
        """The whole-procedure leg flown (-1 before the first)."""
        return self.seq.leg


__all__ = ["ProcedureGuidance", "XTK_ABORT_M"]
