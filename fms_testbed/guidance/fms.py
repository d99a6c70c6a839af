"""``ProcedureGuidance``: flies a built ARINC-424 procedure through the runner's Guidance hook.

Every outer step (10 Hz by default) it

1. projects the *navigation* position on the active path piece (local tangent plane, see
   :mod:`.geometry`) — guidance flies on the navigation solution, so NSE shows in the true track;
2. sequences pieces/segments/legs when the aircraft passes abeam a piece's end (fly-by arcs are
   part of the path, so the transition points are the planned ones);
3. ends a conditional leg (altitude, DME distance, radial) when the condition is actually met —
   earlier than planned: the rest of the procedure is rebuilt from the aircraft's state
   (:func:`.procedure.rebuild_from`); later: the leg's last line is flown on beyond its planned
   end until the condition is met; an HA hold is left over its fix at the end of the first
   circuit that completes with the altitude reached;
4. commands bank from :func:`.lateral.bank_command_rad` with the curvature of the piece ahead
   once inside the roll anticipation distance (on the straight part of a heading leg, V*, it
   holds the coded heading instead and lets the wind drift the track), and altitude/TAS
   targets from :mod:`.vertical`;
5. logs ``xtk_m`` (true cross-track, TSE), ``nav_xtk_m`` (FTE), ``leg_index``, ``leg_code`` and
   the other per-step quantities :mod:`fms_testbed.evaluation.flight_errors` needs.

Truth is used only for logging, never for control.
"""

from __future__ import annotations

import bisect
import logging
import math
from dataclasses import dataclass, field

from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.geodesy import direct, inverse
from fms_testbed.core.segments import Arc, Line, project
from fms_testbed.core.contracts import GuidanceOutput
from fms_testbed.guidance.geometry import LocalPiece, local_pieces, radii_m
from fms_testbed.guidance.lateral import LateralGains, anticipation_m, bank_command_rad
from fms_testbed.path.plan import FlyablePath, rebuild_from
from fms_testbed.guidance.vertical import (BLEND_S, altitude_lead_s, blended_profile, cas_band, climb_targets,
                       leg_speed_limits, profile_nodes_at_fixes, tas_target_mps)

log = logging.getLogger(__name__)

HEADING_LEGS = frozenset({"VA", "VD", "VI", "VM", "VR"})
"""Heading legs: their straight part is flown as a heading (drift allowed), not a track."""
CONDITIONAL = frozenset({"CA", "FA", "VA", "CD", "FD", "VD", "CR", "VR"})
"""Legs whose end is a condition checked in flight (HA: at the fix, see ``_ha_done``)."""
ALT_CAPTURE_M = 15.0
"""An HA hold's altitude counts as reached within this (the law levels off at it), m."""
OVERRUN_MAX_M = 20 * 1852.0
"""A conditional leg flown this far past its planned end without the condition: give up, m."""
XTK_ABORT_M = 5 * 1852.0
"""Cross-track beyond which the flight is declared off the procedure, m."""
STRAIGHT_MARGIN_M = 2000.0
MIN_SEGMENT_M = 1.0
ARC_BANK_MARGIN_DEG = 3.0
"""Arcs are flown at a speed that needs at most the bank limit minus this, deg."""
DECEL_MPS2 = 0.3
"""Deceleration assumed when slowing for an arc ahead, m/s²."""
"""Segments shorter than this are not flown, m."""
MIN_CONNECTOR_M = 50.0
"""Connector segments (the builder's bridges over gaps) shorter than this are not flown: their
course is meaningless and the lateral law absorbs a gap this small, m."""


@dataclass
class _Active:
    """The path being flown (the whole procedure, or its rest after an in-flight rebuild)."""

    fp: FlyablePath
    segs: list
    pieces: list[LocalPiece]
    seg_cum_m: list[float]
    pde_m: list[float]
    flat_m: list[tuple[float, float]]
    prof_s: list[float]
    prof_h: list[float]
    climb_tgt: list[float | None]
    s_base_m: float
    last_piece_of_leg: dict[int, int] = field(default_factory=dict)


def _pde(db, fp: FlyablePath, seg, prev_leg) -> float:
    """Path definition error of one built segment: largest distance of 5 points of it from the
    ideal coded path (TF: geodesic between the fixes; CF: the coded course line through the fix;
    RF: the coded centre and radius), m; NaN where not defined (other legs, transitions)."""
    if seg.role != "leg":
        return float("nan")
    lg = fp.path.legs[seg.leg_index]
    t = lg.termination
    g = seg.geom
    pts = [g.point_at(g.length_m() * k / 4.0) for k in range(5)]
    if lg.path_term == "TF" and prev_leg is not None and prev_leg.termination.kind == "fix" \
            and isinstance(g, Line):
        pt = prev_leg.termination
        ideal = Line(pt.lat_deg, pt.lon_deg, t.lat_deg, t.lon_deg)
        return max(abs(project(ideal, *p)[1]) for p in pts)
    if lg.path_term == "RF" and isinstance(g, Arc) and lg.record.arc_radius_m and db is not None:
        c = db.find_fix(lg.record.centre, fp.seq.airport)
        if c is None:
            return float("nan")
        return max(abs(inverse(c.lat_deg, c.lon_deg, *p)[0] - lg.record.arc_radius_m)
                   for p in pts)
    if lg.path_term == "CF" and isinstance(g, Line) and lg.record.course_deg is not None:
        from fms_testbed.core.geodesy import direct
        coded = (lg.record.course_deg if lg.record.course_true else
                 lg.record.course_deg + _magvar(db, fp, lg))
        back = direct(t.lat_deg, t.lon_deg, coded + 180.0, max(g.length_m(), 1000.0))
        ideal = Line(back[0], back[1], t.lat_deg, t.lon_deg)
        del crs
        return max(abs(project(ideal, *p)[1]) for p in pts)
    return float("nan")


def _magvar(db, fp, lg) -> float:
    nav = db.find_fix(lg.record.navaid, fp.seq.airport) if db is not None else None
    if nav is not None and nav.section in ("D ", "PI"):
        return nav.magvar_deg
    apt = db.airports.get(fp.seq.airport) if db is not None else None
    return apt.magvar_deg if apt else 0.0


def smooth_connectors(segs, tas_mps: float, bank_deg: float = 20.0) -> list:
    """The path as flown: a 'connector' line the builder put across a discontinuity (e.g.
    after vectors, VM/FM) that starts with a track change is flown as a direct-to — straight on
    for the roll-in anticipation distance, a turn at the planned radius, then a line to the
    connector's end — as an FMS does after a discontinuity is cleared; segments shorter than MIN_SEGMENT_M
    (connectors: MIN_CONNECTOR_M) are dropped; other segments unchanged."""
    from dataclasses import replace as _replace

    from fms_testbed.legs.construct import direct_to_arc
    from fms_testbed.core.geodesy import wrap180

    r = tas_mps * tas_mps / (9.80665 * math.tan(math.radians(bank_deg)))
    lead_m = anticipation_m(tas_mps, math.radians(bank_deg), LateralGains())
    out = []
    for k, sg in enumerate(segs):
        short = MIN_CONNECTOR_M if sg.role == "connector" else MIN_SEGMENT_M
        if sg.geom.length_m() < short and len(segs) > 1:
            continue  # a tiny bridge between legs: nothing to fly (the law absorbs the gap)
        if sg.role == "connector" and out and isinstance(sg.geom, Line):
            prev = out[-1].geom
            trk = prev.end_course_deg
            if abs(wrap180(sg.geom.start_course_deg - trk)) > 2.0:
                lat0, lon0 = sg.geom.start
                tlat, tlon = sg.geom.end
                # run straight on for the roll-in anticipation, then turn direct to the end
                lat, lon, _ = direct(lat0, lon0, trk, lead_m)
                arc, ok = direct_to_arc(lat, lon, trk, tlat, tlon, None, r)
                if ok and arc is not None:
                    out.append(_replace(sg, geom=Line(lat0, lon0, lat, lon), role="connector"))
                    out.append(_replace(sg, geom=arc, role="turn"))
                    out.append(_replace(sg, geom=Line(*arc.end, tlat, tlon)))
                    continue
        out.append(sg)
    return out


def _activate(fp: FlyablePath, db, s_base_m: float, tas_mps: float = 118.0,
              lead_from: tuple[float, float] | None = None) -> _Active:
    segs = smooth_connectors(list(fp.path.segments), tas_mps)
    lead_m = 0.0
    if lead_from is not None and segs:
        # the straight run-in from the aircraft to where the rebuilt path starts
        from dataclasses import replace as _replace
        first = segs[0]
        run_in = Line(lead_from[0], lead_from[1], *first.geom.start)
        if run_in.length_m() >= MIN_SEGMENT_M:
            segs.insert(0, _replace(first, geom=run_in, role="leg"))
            lead_m = run_in.length_m()
    geoms = [s.geom for s in segs]
    pieces = local_pieces(geoms)
    cum, s = [], 0.0
    for g in geoms:
        cum.append(s)
        s += g.length_m()
    pde = []
    for k, sg in enumerate(segs):
        prev = fp.path.legs[sg.leg_index - 1] if sg.leg_index > 0 else None
        try:
            pde.append(_pde(db, fp, sg, prev))
        except Exception:  # noqa: BLE001 - a PDE that cannot be evaluated is undefined, not fatal
            pde.append(float("nan"))
    # straight-flight distance from the previous and to the next curvature change, per segment
    is_line = [isinstance(g, Line) for g in geoms]
    before, after = [0.0] * len(segs), [0.0] * len(segs)
    run = 0.0
    for k in range(len(segs)):
        run = run if (k > 0 and is_line[k - 1]) else 0.0
        before[k] = run if is_line[k] else 0.0
        run = run + geoms[k].length_m() if is_line[k] else 0.0
    run = 0.0
    for k in range(len(segs) - 1, -1, -1):
        run = run if (k < len(segs) - 1 and is_line[k + 1]) else 0.0
        after[k] = run if is_line[k] else 0.0
        run = run + geoms[k].length_m() if is_line[k] else 0.0
    prof = fp.path.profile
    climb_tgt = climb_targets(prof)
    last = {}
    for i, p in enumerate(pieces):
        last[segs[p.seg_index].leg_index] = i
    return _Active(fp, segs, pieces, cum, pde, list(zip(before, after)),
                   [x + lead_m for x in profile_nodes_at_fixes(fp.path, prof)],
                   [float(x) for x in prof.alt_m], climb_tgt, s_base_m, last)


class ProcedureGuidance:
    """Guidance that flies a :class:`~.procedure.FlyablePath` (implements the runner's
    ``Guidance`` protocol: ``update(dt_s, nav, truth) -> GuidanceOutput``).

    Parameters
    ----------
    fp : the built procedure
    cfg : aircraft configuration (bank limit, roll rate, minimum speed, coupled-law timing)
    db : the database it came from (in-flight rebuilds, PDE); spec : its ProcedureSpec
    gains : lateral tuning (default: :meth:`LateralGains.for_aircraft`)
    log_every : build the log only every this many calls — the runner's logging cadence
        (``round(outer_rate_hz / log_rate_hz)``, logging at calls 0, n, 2n, ...); 1 = always

    Attributes
    ----------
    events : list of dicts (t_s, kind 'leg' | 'rebuild' | 'condition' | 'abort', leg, detail)
    legs_sequenced : global leg indices in the order they became active
    abort_reason : why guidance stopped early ('' when it did not)
    rebuilt : the paths rebuilt in flight (rest of the procedure), in order
    """

    def __init__(self, fp: FlyablePath, cfg, db=None, spec=None, gains: LateralGains | None = None,
                 log_every: int = 1):
        self.whole = fp
        self.cfg, self.db, self.spec = cfg, db, spec
        self.gains = gains or LateralGains.for_aircraft(cfg)
        self.act = _activate(fp, db, 0.0, cfg.limits.climb_tas_mps)
        self.i = 0
        self.leg = -1
        self.events: list[dict] = []
        self.legs_sequenced: list[int] = []
        self.abort_reason = ""
        self.lead_s = altitude_lead_s(cfg)
        self.heading_kp = cfg.inner_loops.heading_kp
        top = spec.climb_top_ft * 0.3048 if spec is not None else 4572.0
        los = [w.lo_m for w in (fp.path.profile.windows if fp.path.profile else ())
               if w.lo_m is not None]
        self.top_m = max([top] + los)
        self.t2_s2 = cfg.coupled_law.T_H_s ** 2 if cfg.coupled_law is not None else 0.0
        self.limits = leg_speed_limits(fp.seq.legs)
        self.carry_max_cas: float | None = None
        self.descent = fp.path.proc_type in ("E", "F")
        self.approach = fp.path.proc_type == "F"
        self.tas_cmd = cfg.limits.climb_tas_mps
        self.next_speed_t = -1.0
        self.cond_start: tuple | None = None
        self.done = False
        self.calls = 0
        self.log_every = max(1, int(log_every))
        self.rebuilt: list[FlyablePath] = []

    # ------------------------------------------------------------------ helpers
    def _global_leg(self, piece_i: int) -> int:
        a = self.act
        return a.fp.leg_offset + a.segs[a.pieces[piece_i].seg_index].leg_index

    def _enter_leg(self, t_s: float, g: int) -> None:
        if g == self.leg:
            return
        for k in range(self.leg + 1, g + 1):  # every leg entered once, in order
            self.legs_sequenced.append(k)
            self.events.append({"t_s": t_s, "kind": "leg", "leg": k,
                                "code": self.whole.seq.legs[k].path_term})
            lim = self.limits[k] if k < len(self.limits) else None
            if self.descent and lim is not None and lim.desc in ("", "@", "-"):
                c = lim.cas_mps
                self.carry_max_cas = c if self.carry_max_cas is None else min(self.carry_max_cas, c)
        self.leg = g
        self.cond_start = None
        self.next_speed_t = -1.0

    def _condition(self, bl, lat: float, lon: float, alt_m: float) -> bool:
        t = bl.termination
        if t.kind == "altitude":
            return alt_m >= t.alt_m
        if t.navaid_lat_deg is None:
            return False
        la0, lo0 = math.radians(t.navaid_lat_deg), math.radians(t.navaid_lon_deg)
        m0, n0 = radii_m(la0)
        x = (lon - lo0) * n0 * math.cos(0.5 * (lat + la0))
        y = (lat - la0) * m0
        if t.kind == "dme":
            d = math.hypot(x, y) - t.dme_m
        elif t.kind == "radial":
            d = ((math.degrees(math.atan2(x, y)) - t.radial_deg + 180.0) % 360.0) - 180.0
        else:
            return False
        if self.cond_start is None:
            self.cond_start = (d,)
            return False
        return d * self.cond_start[0] <= 0.0

    def _ha_done(self, p: LocalPiece, seg, bl, alt_m: float) -> bool:
        """HA (hold to altitude): True when the piece just completed ends over the hold fix
        (a circuit is complete) and the altitude is reached — the hold is left there instead
        of flying the rest of the circuits the plan assumed."""
        t = bl.termination
        if t.alt_m is None or t.lat_deg is None or alt_m < t.alt_m - ALT_CAPTURE_M:
            return False
        if p.s0_m + p.length_m < seg.geom.length_m() - 1.0:
            return False  # not the last chunk of its segment
        lat, lon = seg.geom.end
        la0, lo0 = math.radians(t.lat_deg), math.radians(t.lon_deg)
        m0, n0 = radii_m(la0)
        x = (math.radians(lon) - lo0) * n0 * math.cos(la0)
        y = (math.radians(lat) - la0) * m0
        return math.hypot(x, y) < 100.0

    def _df_fix_passed(self, k: int, lat: float, lon: float, trk: float) -> bool:
        """True when leg ``k`` is a DF whose fix is behind or abeam the aircraft within a turn
        diameter, or within 0.3 NM: a direct-to would loop back; the fix counts as passed."""
        legs = self.whole.path.legs
        if k >= len(legs) or legs[k].path_term != "DF" or legs[k].termination.lat_deg is None:
            return False
        t = legs[k].termination
        la0, lo0 = math.radians(t.lat_deg), math.radians(t.lon_deg)
        m0, n0 = radii_m(la0)
        x = (lo0 - lon) * n0 * math.cos(0.5 * (lat + la0))
        y = (la0 - lat) * m0
        d = math.hypot(x, y)
        rel = abs((math.atan2(x, y) - trk + math.pi) % (2 * math.pi) - math.pi)
        v = self.cfg.limits.climb_tas_mps
        r = v * v / (9.80665 * math.tan(math.radians(20.0)))
        return d < 0.3 * 1852.0 or (rel > math.radians(60.0) and d < 2.0 * r)

    def _rebuild(self, t_s: float, g_leg: int, lat: float, lon: float, trk: float, alt: float,
                 s_now: float) -> bool:
        nxt = g_leg + 1
        while nxt < len(self.whole.seq.legs) and self._df_fix_passed(nxt, lat, lon, trk):
            self.events.append({"t_s": t_s, "kind": "condition", "leg": nxt,
                                "detail": "DF fix already passed when the previous leg ended"})
            self._enter_leg(t_s, nxt)
            nxt += 1
        if nxt >= len(self.whole.seq.legs):
            return False
        fp = None
        # start the rebuilt path one roll-in anticipation ahead on the present track, so the
        # first turn's roll is centred on its start as for any planned turn
        v = self.cfg.limits.climb_tas_mps
        phi = math.radians(20.0)  # the builder's planned bank
        lead = anticipation_m(v, phi, self.gains)
        la, lo, _ = direct(math.degrees(lat), math.degrees(lon), math.degrees(trk), lead)
        if self.db is not None and self.spec is not None:
            fp = rebuild_from(self.db, self.whole, self.spec, self.cfg, nxt, la, lo,
                              math.degrees(trk) % 360.0, alt)
        if fp is None:
            return False
        self.act = _activate(fp, self.db, s_now, v,
                             lead_from=(math.degrees(lat), math.degrees(lon)))
        self.rebuilt.append(fp)
        self.i = 0
        self.events.append({"t_s": t_s, "kind": "rebuild", "leg": nxt,
                            "detail": f"rest of the procedure rebuilt from the aircraft state "
                                      f"({len(fp.path.segments)} segments)"})
        return True

    def _feedforward_curvature(self, p: LocalPiece, along: float, nxt: LocalPiece | None,
                               gs: float) -> float:
        """Curvature (1/m) whose coordinated-turn bank is fed forward now.

        The curvature of the piece flown, switched to the next piece's once within the roll
        anticipation distance ``V_g (|Δφ|/(2 p) + τ)`` of the boundary
        (:func:`.lateral.anticipation_m`: the runner's rate-limited roll is centred on the
        transition). An arc too short to reach its bank (``L p < V_g |φ|``) gets instead a
        triangular bank profile with the same heading change, peak
        ``tan φ_pk = sqrt(|Δχ| V_g p / g)``, commanded from ``V_g (φ_pk / p + τ)`` before the
        arc's middle to ``V_g τ`` before it.
        """
        g = self.gains
        pr = math.radians(g.roll_rate_dps)
        lag = gs * g.roll_lag_s
        v2 = max(gs, 10.0) ** 2

        def short_arc(q: LocalPiece, d0: float) -> float | None:
            """Triangle-profile curvature if q is a short arc (d0: distance to its start)."""
            if q is None or not q.is_arc:
                return None
            phi = abs(math.atan(v2 * q.curvature_1pm / 9.80665))
            if q.length_m * pr >= gs * phi:
                return None
            t_pk = math.sqrt(q.length_m * abs(q.curvature_1pm) * gs * pr / 9.80665)
            mid = d0 + 0.5 * q.length_m
            on, off = mid - gs * math.atan(t_pk) / pr - lag, mid - lag
            return math.copysign(t_pk * 9.80665 / v2, q.curvature_1pm) if on <= 0.0 < off \
                else 0.0

        k = short_arc(p, -along)
        kappa = p.curvature_1pm if k is None else k
        if nxt is None:
            return kappa
        k = short_arc(nxt, p.length_m - along)
        if k is not None:
            return k if k != 0.0 else kappa
        k2 = nxt.curvature_1pm
        if k2 != kappa:
            dphi = math.atan(v2 * k2 / 9.80665) - math.atan(v2 * kappa / 9.80665)
            if p.length_m - along < anticipation_m(gs, dphi, g):
                return k2
        return kappa

    def _arc_speed_cap(self, along: float, v_mps: float) -> float:
        """Highest TAS at which every arc within the deceleration distance ahead can be flown
        with ARC_BANK_MARGIN_DEG to spare below the bank limit, m/s: v = sqrt(R g tan γ)
        (the monitor's V,γ correction, applied in flight). Deceleration distance:
        (V² - v²) / (2 a) + 10 s of flight, a = DECEL_MPS2."""
        a = self.act
        g_tan = 9.80665 * math.tan(math.radians(self.gains.bank_max_deg - ARC_BANK_MARGIN_DEG))
        cap = math.inf
        dist = -along
        for p in a.pieces[self.i:]:
            if p.is_arc:
                v = math.sqrt(p.radius_m * g_tan)
                if dist <= max(v_mps * v_mps - v * v, 0.0) / (2 * DECEL_MPS2) + 10.0 * v_mps:
                    cap = min(cap, v)
            dist += p.length_m
            if dist > 30000.0:
                break
        return cap

    def _abort(self, t_s: float, why: str) -> GuidanceOutput:
        self.abort_reason = why
        self.events.append({"t_s": t_s, "kind": "abort", "leg": self.leg, "detail": why})
        self.done = True
        return GuidanceOutput(done=True)

    # ------------------------------------------------------------------ the step
    def update(self, dt_s: float, nav, truth) -> GuidanceOutput:
        """One guidance step: bank command, altitude and TAS targets, done flag, log (module
        docstring)."""
        if self.done:
            return GuidanceOutput(done=True)
        a = self.act
        lat, lon = nav.lat_rad, nav.lon_rad
        v = nav.v_enu_mps
        ve, vn = float(v[0]), float(v[1])
        gs = math.hypot(ve, vn)
        trk = math.atan2(ve, vn)
        p = a.pieces[self.i]
        along, xtk, dtrk = p.project(lat, lon)
        g_leg = self._global_leg(self.i)
        self._enter_leg(nav.t_s, g_leg)
        # conditional leg: ended in flight when the condition is met
        seg = a.segs[p.seg_index]
        bl = a.fp.path.legs[seg.leg_index]
        if bl.path_term in CONDITIONAL:
            if self._condition(bl, lat, lon, nav.alt_m):
                self.events.append({"t_s": nav.t_s, "kind": "condition", "leg": g_leg,
                                    "detail": f"{bl.termination.kind} condition met"})
                s_now = a.s_base_m + a.seg_cum_m[p.seg_index] + p.s0_m + along
                if self._rebuild(nav.t_s, g_leg, lat, lon, trk, nav.alt_m, s_now):
                    return self.update(dt_s, nav, truth)
                nxt = a.last_piece_of_leg[seg.leg_index] + 1
                if nxt >= len(a.pieces):
                    self.done = True
                    return GuidanceOutput(done=True)
                self.i = nxt
                return self.update(dt_s, nav, truth)
            hold = self.i == a.last_piece_of_leg[seg.leg_index]
            if hold and along > p.length_m + OVERRUN_MAX_M:
                self.events.append({"t_s": nav.t_s, "kind": "condition", "leg": g_leg,
                                    "detail": f"{bl.termination.kind} condition not met "
                                              f"{OVERRUN_MAX_M / 1852:.0f} NM past the plan"})
                hold = False
        else:
            hold = False
        # sequencing: abeam the end of the piece
        if along >= p.length_m and not hold:
            if self.i + 1 >= len(a.pieces):
                self.done = True
                s_end = a.seg_cum_m[p.seg_index] + p.s0_m + along
                return GuidanceOutput(done=True, log=self._log(p, along, xtk, None, seg, nav,
                                                               truth, g_leg, s_end))
            if bl.path_term == "HA" and self._ha_done(p, seg, bl, nav.alt_m):
                self.events.append({"t_s": nav.t_s, "kind": "condition", "leg": g_leg,
                                    "detail": "HA altitude reached: hold left over the fix"})
                nxt = a.last_piece_of_leg[seg.leg_index] + 1
                if nxt >= len(a.pieces):
                    self.done = True
                    return GuidanceOutput(done=True)
                self.i = nxt
                return self.update(dt_s, nav, truth)
            self.i += 1
            return self.update(dt_s, nav, truth)
        if abs(xtk) > XTK_ABORT_M:
            return self._abort(nav.t_s, f"off the procedure: cross-track {xtk / 1852:.1f} NM "
                               f"on leg {g_leg + 1} ({bl.path_term})")
        # lateral
        nxt = a.pieces[self.i + 1] if self.i + 1 < len(a.pieces) and not hold else None
        kappa = self._feedforward_curvature(p, along, nxt, gs)
        if seg.path_term in HEADING_LEGS and seg.role == "leg" and not p.is_arc \
                and kappa == 0.0:
            # a heading leg (V*): fly the coded heading — the built line's direction — and let
            # the wind drift the track; the leg still ends at its condition/planned distance
            herr = (dtrk - nav.heading_rad + math.pi) % (2 * math.pi) - math.pi
            lim = math.radians(self.gains.bank_max_deg)
            bank = max(-lim, min(lim, self.heading_kp * herr))
        else:
            terr = (trk - dtrk + math.pi) % (2 * math.pi) - math.pi
            bank = bank_command_rad(xtk, terr, gs, kappa, self.gains)
        # vertical
        s_path = a.seg_cum_m[p.seg_index] + p.s0_m + along
        ps = a.prof_s
        h, dh, ddh = blended_profile(ps, a.prof_h, s_path, gs * BLEND_S, self.approach)
        alt_cmd = h + self.lead_s * gs * dh + self.t2_s2 * gs * gs * ddh
        jn = bisect.bisect_right(ps, s_path)
        if 0 < jn < len(ps) and a.climb_tgt[jn] is not None:  # climb: at the law's rate
            alt_cmd = min(max(alt_cmd, a.climb_tgt[jn]), self.top_m)
        if nav.t_s >= self.next_speed_t:
            lim = self.limits[g_leg] if g_leg < len(self.limits) else None
            lo, hi = cas_band(lim, self.carry_max_cas if self.descent else None)
            plan = min(cas_to_tas_scalar(self.cfg.limits.climb_tas_mps, nav.alt_m),
                       self._arc_speed_cap(along, gs))  # the planned speed is flown as a CAS
            self.tas_cmd = tas_target_mps(plan, nav.alt_m, lo, hi, self.cfg.limits.cas_min_mps)
            self.next_speed_t = nav.t_s + 1.0
        self.calls += 1
        due = (self.calls - 1) % self.log_every == 0
        return GuidanceOutput(bank_rad=bank, alt_m=alt_cmd, tas_mps=self.tas_cmd,
                              log=self._log(p, along, xtk, None, seg, nav, truth, g_leg, s_path)
                              if due else {})

    def _log(self, p: LocalPiece, along: float, nav_xtk: float, true_xtk, seg, nav, truth,
             g_leg: int, s_path: float) -> dict:
        a = self.act
        if true_xtk is None:
            _, true_xtk, _ = p.project(truth.lat_rad, truth.lon_rad)
        s_seg = p.s0_m + along
        b, f = a.flat_m[p.seg_index]
        flat = 0.0 if p.is_arc else min(
            b + s_seg, f + a.segs[p.seg_index].geom.length_m() - s_seg)
        return {"xtk_m": true_xtk, "nav_xtk_m": nav_xtk, "leg_index": g_leg,
                "leg_code": seg.path_term, "seg_role": seg.role,
                "along_m": a.s_base_m + s_path,
                "curvature_1pm": p.curvature_1pm, "straight_m": flat,
                "heading_leg": int(seg.path_term in HEADING_LEGS and seg.role == "leg"
                                   and not p.is_arc),
                "pde_m": a.pde_m[p.seg_index], "rnp_m": a.fp.rnp_m[seg.leg_index]
                if seg.leg_index < len(a.fp.rnp_m) else float("nan")}
