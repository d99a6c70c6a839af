"""Planned vertical profile from the coded altitude constraints and climb/descent gradients.

Nodes are the path start and every leg end (distance along the built path, m). Climb phases
(SIDs, missed approaches) climb at the aircraft's gradient, level off below every 'at or
below' constraint ahead and at the highest climb constraint still ahead (with none: the coded
transition altitude, else 18,000 ft); descent phases are planned backwards from the last constrained fix at
the coded vertical angle (else 3°), clamped into each fix's altitude window, never above
the start altitude or the highest coded altitude, and never climbing within a descent phase. One geometry feeds
both: the distances come from the same segments the map and guidance use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.units import FT_M, G0_MPS2
from fms_testbed.legs.model import ProcedurePath


@dataclass(frozen=True, slots=True)
class AltitudeWindow:
    """Altitude constraint at a leg end: lo_m ≤ alt ≤ hi_m (None = unbounded), m."""

    leg_index: int
    fix_ident: str
    along_m: float
    desc: str
    lo_m: float | None
    hi_m: float | None


@dataclass(frozen=True)
class VerticalProfile:
    """Planned altitude along the path.

    along_m, alt_m: node distances from the path start (m) and planned altitudes (m);
    climb: per node, True where the segment ending at that node is a climb phase;
    windows: the coded constraints; speed: the planned CAS of an approach with its
    deceleration segments (:class:`~fms_testbed.path.speed_profile.SpeedProfile`; None for
    other procedures and aircraft without approach settings).
    """

    along_m: np.ndarray
    alt_m: np.ndarray
    climb: np.ndarray
    windows: tuple[AltitudeWindow, ...]
    speed: object = None

    def alt_at(self, s_m: float | np.ndarray) -> float | np.ndarray:
        """Planned altitude at distance ``s_m`` (m) along the path, m."""
        return np.interp(s_m, self.along_m, self.alt_m)

    def gradients(self) -> np.ndarray:
        """Rise over run of each node-to-node piece (dimensionless; NaN for zero length)."""
        ds = np.diff(self.along_m)
        dh = np.diff(self.alt_m)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(ds > 1.0, dh / ds, np.nan)


def window(desc: str, alt1_m: float | None, alt2_m: float | None
           ) -> tuple[float | None, float | None]:
    """(lo_m, hi_m) from an ARINC-424 altitude descriptor (column 83) and its two altitudes."""
    if alt1_m is None:
        return None, None
    if desc in ("+", "H", "J", "V"):
        return alt1_m, None
    if desc in ("-", "Y"):
        return None, alt1_m
    if desc == "B" and alt2_m is not None:
        return min(alt1_m, alt2_m), max(alt1_m, alt2_m)
    if desc == "C" and alt2_m is not None:
        return alt2_m, None
    return alt1_m, alt1_m  # '', '@', 'X', 'G', 'I': at


def leg_end_distances(path: ProcedurePath) -> np.ndarray:
    """Distance along the path (m) where each built leg ends — abeam its fix: a leg that ends
    in a fly-by arc ends at the arc's middle, where the aircraft passes the fix and its
    altitude constraint is checked, not where the arc ends (one geometry for the profile, the
    monitor's gradients and guidance)."""
    ends = np.zeros(len(path.legs))
    s = 0.0
    per_leg: dict[int, float] = {}
    for seg in path.segments:
        s += seg.geom.length_m()
        per_leg[seg.leg_index] = s - (0.5 * seg.geom.length_m() if seg.role == "flyby" else 0.0)
    last = 0.0
    for k, lg in enumerate(path.legs):
        last = max(per_leg.get(lg.index, last), last)
        ends[k] = last
    return ends


DESCENT_CAP_MARGIN_M = 150 * FT_M
"""Largest margin below an 'at or below' / 'between' top a descent is planned to, m."""


def descent_cap_margin_m(lo_m: float | None, hi_m: float) -> float:
    """Margin below a window's top a descent aims at, m: a quarter of a 'between' window (at
    most :data:`DESCENT_CAP_MARGIN_M`), the whole margin under an 'at or below', none for an
    'at' (its top is its bottom)."""
    if lo_m is None:
        return DESCENT_CAP_MARGIN_M
    return min(0.25 * max(hi_m - lo_m, 0.0), DESCENT_CAP_MARGIN_M)


def arrival_join_alt_m(path: ProcedurePath, descent_angle_deg: float = 3.0,
                       cas_plan_mps: float | None = None, descent_rate_mps: float | None = None,
                       isa_dev_c: float = 0.0) -> float | None:
    """Highest altitude an arrival (STAR, approach) should start at: the descent path planned
    back from its last constraint (the coded angles, else ``descent_angle_deg``, inside every
    window; with ``cas_plan_mps`` and ``descent_rate_mps`` within the energy budget of
    :func:`plan_profile`) at its first fix, raised to that fix's own 'at or above', m (None:
    fewer than two legs). Its first coded altitude may be an 'at or below' far above what the
    aircraft can lose before the next fixes."""
    if len(path.legs) < 2:
        return None
    st0 = path.legs[0].start.alt_m
    prof = plan_profile(path, 0.0, st0, descent_angle_deg, descent_gradient_max=1e3)
    vpa = path.legs[1].record.vpa_deg
    ang = abs(vpa) if vpa else descent_angle_deg
    ds = float(prof.along_m[2] - prof.along_m[1])
    drop = math.tan(math.radians(ang)) * ds
    if cas_plan_mps is not None and descent_rate_mps and not vpa:
        # the second leg within the energy the aircraft can shed while it changes speed
        v = descent_leg_tas_mps(path, prof.alt_m[1:], cas_plan_mps, isa_dev_c)
        drop = min(drop, energy_drop_max_m(ds, v[1], v[1], v[0], descent_rate_mps))
    back = float(prof.alt_m[2]) + drop
    r0 = path.legs[0].record
    lo, _ = window(r0.alt_desc, r0.alt1_m, r0.alt2_m)
    return max(back, lo) if lo is not None else back


def sid_join_required_alt_m(path: ProcedurePath, climb_gradient: float) -> float | None:
    """Lowest altitude at which a SID joined at its first fix (not from the runway) must be
    there to make every 'at or above' climb constraint at ``climb_gradient``: the largest
    lo − gradient × distance over its windows, capped by the lowest 'at or below' one, m (None
    when nothing is coded)."""
    ends = leg_end_distances(path)
    need, cap = None, math.inf
    for k, lg in enumerate(path.legs):
        r = lg.record
        lo, hi = window(r.alt_desc, r.alt1_m, r.alt2_m)
        if hi is not None:
            cap = min(cap, hi)
        if lo is not None:
            a = lo - climb_gradient * ends[k]
            need = a if need is None else max(need, a)
    return None if need is None else min(need, cap)


PLAN_CLIMB_FRACTION = 0.75
"""The plan climbs (and, where it must descend steeply, descends) at this fraction of the
aircraft's sustained climb (descent) rate: margin for the law to catch up after turns and
speed changes."""


def energy_drop_max_m(ds_m: float, gs_mps: float, tas_mps: float, tas_prev_mps: float,
                      descent_rate_mps: float) -> float:
    """Largest altitude drop over a leg within the aircraft's energy budget, m::

        Δh ≤ (w_d / V_g) Δs + (V² − V_prev²) / (2 g)

    ``ds_m`` the leg length (m), ``gs_mps`` its ground speed, ``tas_mps`` the TAS it is flown at
    and ``tas_prev_mps`` the TAS of the leg before (a deceleration uses up part of the drop, an
    acceleration adds to it), ``descent_rate_mps`` the planned descent rate w_d; never < 0."""
    return max(descent_rate_mps / gs_mps * ds_m
               + (tas_mps ** 2 - tas_prev_mps ** 2) / (2.0 * G0_MPS2), 0.0)


def descent_leg_tas_mps(path: ProcedurePath, leg_alt_m: np.ndarray, cas_plan_mps: float,
                        isa_dev_c: float = 0.0) -> np.ndarray:
    """TAS each leg is flown at in a descent, m/s: the aircraft's planned CAS under every
    'at' / 'at or below' speed limit coded so far (a descent's limit holds for the rest of the
    procedure, as guidance flies it: :mod:`fms_testbed.guidance.vertical`) and above an 'at'
    / 'at or above' limit of the leg itself, converted from CAS at ``leg_alt_m`` (each leg's
    end altitude, m) on a day ``isa_dev_c`` K off the ISA."""
    from fms_testbed.core.atmosphere import cas_to_tas_scalar
    from fms_testbed.legs.model import approach_cas_caps

    caps = approach_cas_caps([lg.record for lg in path.legs], path.proc_type, 0.0)
    out = np.empty(len(path.legs))
    carried = math.inf
    for k, lg in enumerate(path.legs):
        r = lg.record
        lo = None
        if r.speed_limit_mps:
            if r.speed_desc in ("", "@", "-"):
                carried = min(carried, r.speed_limit_mps)
            if r.speed_desc in ("", "@", "+"):
                lo = r.speed_limit_mps
        hi = min(carried, caps[k]) if caps[k] is not None else carried
        c = min(cas_plan_mps, hi)
        if lo is not None:
            c = max(c, lo)
        out[k] = cas_to_tas_scalar(c, float(leg_alt_m[k]), isa_dev_c)
    return out


def climb_phases(records, proc_type: str, start_in_climb: bool = False) -> np.ndarray:
    """Per node (the start and every leg end), True where the leg ending there is climbed: a
    SID, or from the first missed-approach leg on (or all of it with ``start_in_climb``)."""
    climb = np.zeros(len(records) + 1, dtype=bool)
    climbing = proc_type == "D" or start_in_climb
    for k, r in enumerate(records):
        climbing = climbing or r.missed_approach_start
        climb[k + 1] = climbing
    return climb


def path_climb_top_m(proc_type: str, climb_top_m: float | None) -> float | None:
    """The climb top a path of type ``proc_type`` is planned to, m: the flight's
    ``climb_top_m`` for a SID; None for an approach (its missed approach climbs to its own
    coded altitudes, the highest of them, not to the SID climb top)."""
    return None if proc_type == "F" else climb_top_m


def climb_caps_m(records, climb: np.ndarray, climb_top_m: float | None = None,
                 alt_max_m: float = math.inf) -> np.ndarray:
    """The altitude a climb may reach at each node (the start and every leg end), m.

    A climb is capped by every 'at or below' ahead of the node and levels at the highest
    climb constraint still ahead, raised to ``climb_top_m`` when given (else, with none
    coded, the coded transition altitude, else 18,000 ft); never above ``alt_max_m`` (the
    aircraft's ceiling less its margin). The one climb planner: the leg builder (planned
    altitudes, speeds and turn radii) and :func:`plan_profile` both use it.

    Parameters
    ----------
    records : the legs' :class:`~fms_testbed.procedures.legrecord.LegRecord` in order
    climb : per node, whether it is climbed (:func:`climb_phases`)
    climb_top_m : the flight's climb top, m (None: from the records, above)
    alt_max_m : the highest altitude the plan may reach, m
    """
    n = len(records)
    cap = np.full(n + 1, np.inf)
    run = np.inf
    top = -np.inf
    trans = next((r.trans_alt_m for r in records if r.trans_alt_m), None)
    wins = [(None, None)] + [window(r.alt_desc, r.alt1_m, r.alt2_m) for r in records]
    for k in range(n, -1, -1):
        lo, hi = wins[k]
        if climb[k]:
            if hi is not None:
                run = min(run, hi)
                top = max(top, hi)
            elif lo is not None:
                top = max(top, lo)
        if climb_top_m is not None:
            level = max(top, climb_top_m)
        else:
            level = top if np.isfinite(top) else (trans if trans else 18000 * FT_M)
        cap[k] = min(run, level, alt_max_m)
    return cap


def plan_profile(path: ProcedurePath, climb_gradient: float, start_alt_m: float,
                 descent_angle_deg: float = 3.0, climb_top_m: float | None = None,
                 descent_gradient_max: float | None = None,
                 descent_rate_mps: float | None = None,
                 wind: tuple[float, float] | None = None,
                 start_in_climb: bool = False, cas_plan_mps: float | None = None,
                 isa_dev_c: float = 0.0, alt_max_m: float = math.inf) -> VerticalProfile:
    """Plan the vertical profile of a built path.

    Parameters
    ----------
    path : the built procedure transition
    climb_gradient : planned climb gradient (rise over run) for climb phases
    start_alt_m : altitude at the path start, m
    descent_angle_deg : default descent path angle where no vertical angle is coded, deg
    climb_top_m : where a climb levels off, m (:func:`climb_caps_m`; None: from the records)
    descent_gradient_max : steepest descent the aircraft can fly (drop over run; its descent
        rate over its planned speed); None: 2.5 × tan(descent_angle_deg)
    descent_rate_mps : when given, the steepest descent of each leg is this rate over the
        leg's planned ground speed (``BuiltLeg.speed_mps`` plus the ``wind`` component along
        the leg's track), m/s
    wind : (speed m/s, from deg true) the path is planned for; None: calm
    start_in_climb : the path is the rest of a missed approach (rebuilt in flight): a climb
        phase from its start
    cas_plan_mps, isa_dev_c : with ``descent_rate_mps``, the aircraft's planned CAS (m/s) and
        the day's ISA deviation (K): descents are planned within the energy the aircraft can
        shed (below)
    alt_max_m : the highest altitude the plan may reach (the aircraft's ceiling less its
        margin, :attr:`~fms_testbed.legs.model.Performance.alt_plan_max_m`), m: climbs level
        at :func:`climb_caps_m`, descents start no higher

    Notes
    -----
    Descent: backwards from the last constrained node at the coded angle (else
    ``descent_angle_deg``), clamped into every window, under the start and highest coded
    altitude; from a start above that path, down at up to ``descent_gradient_max`` until it
    is met. With ``cas_plan_mps`` a leg without a coded angle drops no more than the energy
    the aircraft can shed (Danilin: speeds from its performance, :func:`energy_drop_max_m`)::

        Δh_k ≤ (w_d / V_g,k) Δs_k + (V_k² − V_k-1²) / (2 g)
    """
    plan = _Plan(path, start_alt_m, descent_angle_deg, descent_rate_mps, wind,
                 climb_phases([lg.record for lg in path.legs], path.proc_type, start_in_climb))
    plan.ceiling = max(min(max(plan.coded(), default=-math.inf), alt_max_m), start_alt_m)
    if plan.desc_idx:
        plan.backward(None)
        if cas_plan_mps is not None and descent_rate_mps is not None:
            # the speeds at the altitudes of the geometric plan, then the plan within the
            # energy budget (one refinement: TAS changes ~2 %/1,000 ft)
            plan.backward(descent_leg_tas_mps(path, plan.alt[1:], cas_plan_mps, isa_dev_c))
        plan.forward(descent_gradient_max if descent_gradient_max is not None else
                     2.5 * math.tan(math.radians(descent_angle_deg)))
        plan.never_climb_in_descent()
    plan.climb_up(climb_caps_m([lg.record for lg in path.legs], plan.climb, climb_top_m,
                               alt_max_m), climb_gradient)
    return VerticalProfile(plan.along, plan.alt, plan.climb, tuple(plan.windows))


class _Plan:
    """The working state of :func:`plan_profile`: node distances, altitudes and windows, and
    the passes over them (each a named step)."""

    def __init__(self, path: ProcedurePath, start_alt_m: float, descent_angle_deg: float,
                 descent_rate_mps: float | None, wind, climb: np.ndarray):
        self.path, self.n = path, len(path.legs)
        self.start_alt_m, self.angle_deg = start_alt_m, descent_angle_deg
        self.rate_mps, self.wind, self.climb = descent_rate_mps, wind, climb
        ends = leg_end_distances(path)
        self.windows = []
        for k, lg in enumerate(path.legs):
            r = lg.record
            lo, hi = window(r.alt_desc, r.alt1_m, r.alt2_m)
            if lo is not None or hi is not None:
                self.windows.append(AltitudeWindow(k, r.fix.ident if r.fix else "", ends[k],
                                                   r.alt_desc, lo, hi))
        self.along = np.concatenate(([0.0], ends))
        self.alt = np.full(self.n + 1, start_alt_m)
        self.lo_at = [None] * (self.n + 1)
        self.hi_at = [None] * (self.n + 1)
        for w in self.windows:
            self.lo_at[w.leg_index + 1], self.hi_at[w.leg_index + 1] = w.lo_m, w.hi_m
        self.desc_idx = [k for k in range(1, self.n + 1) if not climb[k]]
        self.last = self.desc_idx[-1] if self.desc_idx else 0
        self.ceiling = math.inf
        self.v_leg = None

    def coded(self) -> list[float]:
        """Every coded altitude of the windows, m."""
        return [v for w in self.windows for v in (w.lo_m, w.hi_m) if v is not None]

    def ground_speed(self, k: int, v: float) -> float:
        """Planned ground speed on leg k at TAS v (a tailwind: the same descent rate is a
        shallower path; class 1: wind), m/s."""
        lg = self.path.legs[k]
        if v and self.wind is not None and lg.end.track_deg is not None:
            w = self.wind
            v = max(v + w[0] * math.cos(math.radians(w[1] + 180.0 - lg.end.track_deg)),
                    0.3 * v)
        return v

    def max_drop(self, k: int) -> float:
        """Largest drop over leg k within the energy budget, m (inf without one)."""
        if self.v_leg is None:
            return math.inf
        v = self.v_leg
        v_prev = v[k - 1] if k > 0 else v[0]
        return energy_drop_max_m(self.along[k + 1] - self.along[k],
                                 self.ground_speed(k, v[k]), v[k], v_prev, self.rate_mps)

    def backward(self, v_leg: np.ndarray | None) -> None:
        """Backward pass from the last descent node at the coded angles (else the default),
        within the energy budget of ``v_leg`` (the legs' TAS, m/s; None: none), clamped into
        every window and under the ceiling."""
        self.v_leg = v_leg
        lo_at, hi_at, alt, along = self.lo_at, self.hi_at, self.alt, self.along
        alt[self.last] = next((lo_at[k] if lo_at[k] is not None else hi_at[k]
                               for k in reversed(self.desc_idx)
                               if lo_at[k] is not None or hi_at[k] is not None),
                              self.start_alt_m)
        for k in range(self.last - 1, -1, -1):
            vpa = self.path.legs[k].record.vpa_deg if k < self.n else None
            ang = abs(vpa) if vpa else self.angle_deg
            drop = math.tan(math.radians(ang)) * (along[k + 1] - along[k])
            if not vpa and not self.climb[k + 1]:
                drop = min(drop, self.max_drop(k))
            h = min(alt[k + 1] + drop, self.ceiling)
            if hi_at[k] is not None:
                # a descent capped by a window's top aims a margin inside it: the aircraft
                # tracks a descending path a little high (:func:`descent_cap_margin_m`)
                h = min(h, hi_at[k] - descent_cap_margin_m(lo_at[k], hi_at[k]))
            if lo_at[k] is not None:
                h = max(h, lo_at[k])
            alt[k] = h if k > 0 else self.start_alt_m
        self.share_coincident_windows()

    def share_coincident_windows(self) -> None:
        """Two constraints at one point (a transition ending at the fix a final segment's IF
        codes again): the later node keeps the earlier one's altitude where its own window
        allows — no step down at the fix that the blend would fly below the first window."""
        for k in range(1, self.last):
            if self.along[k + 1] - self.along[k] < 1.0:
                a = self.alt[k]
                if self.hi_at[k + 1] is not None:
                    a = min(a, self.hi_at[k + 1])
                if self.lo_at[k + 1] is not None:
                    a = max(a, self.lo_at[k + 1])
                self.alt[k + 1] = a

    def forward(self, g_desc: float) -> None:
        """From a start above the geometric path, descend no steeper than the aircraft can
        (its descent rate over each leg's ground speed, else ``g_desc``; within the energy
        budget) until the path is met."""
        alt, hi_at = self.alt, self.hi_at
        for k in range(1, self.last + 1):
            lg = self.path.legs[k - 1]
            v = self.ground_speed(k - 1, lg.speed_mps)
            g_k = self.rate_mps / v if self.rate_mps and v else g_desc
            drop = g_k * (self.along[k] - self.along[k - 1])
            if self.v_leg is not None and not self.climb[k]:
                drop = min(drop, self.max_drop(k - 1))
            floor = alt[k - 1] - drop
            if floor > alt[k]:
                alt[k] = floor if hi_at[k] is None else min(floor, max(hi_at[k], alt[k]))

    def never_climb_in_descent(self) -> None:
        """A descent phase never climbs: after the last constraint (a STAR ending in vectors)
        the backward pass from the final node can plan above an earlier 'at' fix."""
        for k in range(1, self.n + 1):
            if not self.climb[k] and not self.climb[k - 1] and self.alt[k] > self.alt[k - 1]:
                lo = self.lo_at[k]
                self.alt[k] = max(self.alt[k - 1], lo if lo is not None else -np.inf)

    def climb_up(self, cap: np.ndarray, climb_gradient: float) -> None:
        """Climb nodes: at ``climb_gradient`` from the node before, up to ``cap`` (m)."""
        for k in range(1, self.n + 1):
            if self.climb[k]:
                base = self.alt[k - 1]
                self.alt[k] = min(base + climb_gradient * (self.along[k] - self.along[k - 1]),
                                  max(cap[k], base))
