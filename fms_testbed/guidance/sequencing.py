"""Sequencing: when the aircraft leaves a piece, a leg or a hold, decided in flight.

* A piece is left abeam its end (``along ≥ length``): fly-by arcs are part of the path, so the
  transition points are the planned ones.
* A conditional leg (:attr:`~fms_testbed.legs.base.Leg.conditional`: altitude, DME distance,
  radial) ends when its condition is actually met (:class:`ConditionWatch`) — earlier than
  planned, or later: its last line is then flown on beyond the planned end, up to
  :data:`OVERRUN_MAX_M`.
* A hold to an altitude (HA) is left over its fix at the end of the first circuit (after the
  entry) completed with the altitude reached (:func:`hold_exit_reached`), instead of every circuit planned.
* A DF whose fix is already behind the aircraft when the leg before it ends counts as passed
  (:func:`direct_fix_passed`): a direct-to would loop back.

:class:`LegSequencer` holds the piece and the leg flown and applies these rules step by step.

Positions: navigation latitude/longitude in rad; distances in a local plane about the reference
point with the WGS-84 radii of curvature (:func:`~.geometry.radii_m`).
"""

from __future__ import annotations

import math

from fms_testbed.core.earth import radii_m
from fms_testbed.core.planning import PLANNED_BANK_DEG
from fms_testbed.core.units import G0_MPS2, NM_M
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.guidance.locate import Where
from fms_testbed.legs.model import BuiltLeg, PathSegment, Termination
from fms_testbed.legs.types import LEG_TYPES

ALT_CAPTURE_M = 15.0
"""An HA hold's altitude counts as reached within this (the law levels off at it), m."""
OVERRUN_MAX_M = 20 * NM_M
"""A conditional leg flown this far past its planned end without the condition: give up, m."""
HOLD_FIX_M = 100.0
"""A completed piece ends over the hold fix when its end is this close to it, m."""
DF_PASSED_M = 0.3 * NM_M
"""A DF fix this close counts as passed, m."""
DF_BEHIND_DEG = 60.0
"""A DF fix more than this off the track and within a turn diameter (at the planned speed and
the planned bank, :data:`~fms_testbed.core.planning.PLANNED_BANK_DEG`) counts as passed, deg."""


class ConditionWatch:
    """Whether a conditional leg's end condition is met, from one call to the next.

    Altitude: reached when the altitude is at or above it. DME distance and radial: met when
    the signed difference (distance − DME distance, m; bearing from the navaid − radial, deg)
    changes sign between the first check on the leg and now. :meth:`reset` on entering a leg.
    """

    def __init__(self) -> None:
        self.start: float | None = None

    def reset(self) -> None:
        """Forget the first check (a new leg is flown)."""
        self.start = None

    def met(self, t: Termination, lat_rad: float, lon_rad: float, alt_m: float) -> bool:
        """True once the termination ``t`` ('altitude' | 'dme' | 'radial') is met at the
        navigation position (rad) and altitude (m)."""
        if t.kind == "altitude":
            return alt_m >= t.alt_m
        if t.navaid_lat_deg is None:
            return False
        la0, lo0 = math.radians(t.navaid_lat_deg), math.radians(t.navaid_lon_deg)
        m0, n0 = radii_m(la0)
        x = (lon_rad - lo0) * n0 * math.cos(0.5 * (lat_rad + la0))
        y = (lat_rad - la0) * m0
        if t.kind == "dme":
            d = math.hypot(x, y) - t.dme_m
        elif t.kind == "radial":
            d = ((math.degrees(math.atan2(x, y)) - t.radial_deg + 180.0) % 360.0) - 180.0
        else:
            return False
        if self.start is None:
            self.start = d
            return False
        return d * self.start <= 0.0


def hold_exit_reached(p: LocalPiece, seg: PathSegment, t: Termination, alt_m: float) -> bool:
    """HA (hold to altitude): True when the piece just completed ends over the hold fix and
    completes a circuit (not the entry, role 'turn': at least one circuit is flown) and the
    altitude is reached within :data:`ALT_CAPTURE_M`.

    Parameters
    ----------
    p : the piece just completed, of segment ``seg``; t : the HA's termination (fix position,
        deg; altitude, m); alt_m : navigation altitude, m
    """
    if t.alt_m is None or t.lat_deg is None or alt_m < t.alt_m - ALT_CAPTURE_M:
        return False
    if seg.role == "turn":
        return False  # the way to the hold and its entry end over the fix too: no circuit yet
    if p.s0_m + p.length_m < seg.geom.length_m() - 1.0:
        return False  # not the last chunk of its segment
    lat, lon = seg.geom.end
    la0, lo0 = math.radians(t.lat_deg), math.radians(t.lon_deg)
    m0, n0 = radii_m(la0)
    x = (math.radians(lon) - lo0) * n0 * math.cos(la0)
    y = (math.radians(lat) - la0) * m0
    return math.hypot(x, y) < HOLD_FIX_M


def direct_fix_passed(leg: BuiltLeg, lat_rad: float, lon_rad: float, track_rad: float,
                      tas_mps: float) -> bool:
    """True when ``leg`` is a direct-to (DF) whose fix is behind or abeam the aircraft within a
    turn diameter, or within :data:`DF_PASSED_M`: a direct-to would loop back.

    Parameters
    ----------
    leg : the built leg; lat_rad, lon_rad : navigation position, rad; track_rad : ground
        track, rad true; tas_mps : planned speed (turn diameter 2 V²/(g tan φ_plan)), m/s
    """
    t = leg.termination
    if not LEG_TYPES[leg.path_term].direct_to or t.lat_deg is None:
        return False
    la0, lo0 = math.radians(t.lat_deg), math.radians(t.lon_deg)
    m0, n0 = radii_m(la0)
    x = (lo0 - lon_rad) * n0 * math.cos(0.5 * (lat_rad + la0))
    y = (la0 - lat_rad) * m0
    d = math.hypot(x, y)
    rel = abs((math.atan2(x, y) - track_rad + math.pi) % (2 * math.pi) - math.pi)
    r = tas_mps * tas_mps / (G0_MPS2 * math.tan(math.radians(PLANNED_BANK_DEG)))
    return d < DF_PASSED_M or (rel > math.radians(DF_BEHIND_DEG) and d < 2.0 * r)


class LegSequencer:
    """The piece and the leg flown, moved on by the rules of the module docstring.

    Parameters
    ----------
    leg_codes : path terminator of every leg of the whole procedure (for the leg events)
    enter_leg : called with each whole-procedure leg index as it is entered (speed limits)
    events : the guidance's event list (``t_s``, ``kind``, ``leg``, ``code`` | ``detail``)

    Attributes
    ----------
    i : the piece flown (index into the active path's pieces)
    leg : the whole-procedure leg flown (-1 before the first)
    legs_sequenced : whole-procedure leg indices in the order they became active
    """

    def __init__(self, leg_codes: list[str], enter_leg, events: list[dict]):
        self.codes, self.on_enter, self.events = leg_codes, enter_leg, events
        self.i, self.leg = 0, -1
        self.legs_sequenced: list[int] = []
        self.watch = ConditionWatch()

    def restart(self) -> None:
        """A new active path is flown from its first piece."""
        self.i = 0

    def enter(self, t_s: float, g: int) -> bool:
        """Make whole-procedure leg ``g`` the active one; every leg up to it is entered once, in
        order. True when a leg was entered."""
        if g == self.leg:
            return False
        for k in range(self.leg + 1, g + 1):
            self.legs_sequenced.append(k)
            self.events.append({"t_s": t_s, "kind": "leg", "leg": k, "code": self.codes[k]})
            self.on_enter(k)
        self.leg = g
        self.watch.reset()
        return True

    def condition_met(self, w: Where, t_s: float, lat_rad: float, lon_rad: float,
                      alt_m: float) -> bool:
        """True (and a ``condition`` event) when the conditional leg flown has met its end
        condition at the navigation position (rad) and altitude (m)."""
        if not LEG_TYPES[w.built.path_term].conditional or \
                not self.watch.met(w.built.termination, lat_rad, lon_rad, alt_m):
            return False
        self._event(t_s, w.leg, f"{w.built.termination.kind} condition met")
        return True

    def held_past_plan(self, w: Where, t_s: float) -> bool:
        """True while a conditional leg is flown on past its planned end, waiting for its
        condition (up to :data:`OVERRUN_MAX_M` past the plan; then an event and False)."""
        if not LEG_TYPES[w.built.path_term].conditional:
            return False
        hold = w.last_piece_of_leg
        if hold and w.along_m > w.p.length_m + OVERRUN_MAX_M:
            self._event(t_s, w.leg, f"{w.built.termination.kind} condition not met "
                                    f"{OVERRUN_MAX_M / NM_M:.0f} NM past the plan")
            return False
        return hold

    def passed(self, w: Where, t_s: float, alt_m: float) -> bool:
        """The aircraft is abeam the end of its piece: go on to the next piece (or, at the end
        of an HA hold's circuit with the altitude reached, past the hold). False when the path
        ends here (nothing is left to fly)."""
        if w.i + 1 >= len(w.act.pieces):
            return False
        kind = LEG_TYPES[w.built.path_term]
        if kind.hold and kind.altitude_terminated and \
                hold_exit_reached(w.p, w.seg, w.built.termination, alt_m):
            self._event(t_s, w.leg, "HA altitude reached: hold left over the fix")
            return self.past_leg(w)
        self.i += 1
        return True

    def past_leg(self, w: Where) -> bool:
        """Go to the first piece after the leg flown; False when there is none."""
        nxt = w.act.last_piece_of_leg[w.seg.leg_index] + 1
        if nxt >= len(w.act.pieces):
            return False
        self.i = nxt
        return True

    def _event(self, t_s: float, leg: int, detail: str) -> None:
        self.events.append({"t_s": t_s, "kind": "condition", "leg": leg, "detail": detail})
