"""The departure speed plan of a SID flown from its runway, as the leg builder applies it.

The schedule itself is :meth:`~fms_testbed.legs.model.Performance.departure_cas_at_mps` (the
climb-out CAS to the acceleration height, then the aircraft's acceleration, 250 kt below
10,000 ft); here: where along the planned climb the acceleration height is passed
(:func:`departure_cas_mps`), which CF legs are planned again at the climb-out speed the
aircraft can have held (:func:`held_speed_helps` during the build, :func:`cf_legs_to_hold`
after the corners are rounded), and the slow-down of the legs before such a leg
(:func:`departure_slowdowns`); and the altitude a SID joined at a fix is planned at
(:func:`sid_join_alt_m`).
"""

from __future__ import annotations

import math
from dataclasses import replace

from fms_testbed.core.geodesy import inverse
from fms_testbed.core.planning import DECEL_MPS2
from fms_testbed.core.units import FT_M
from fms_testbed.legs.builder import LegBuilder
from fms_testbed.legs.model import BuiltLeg, PathSegment, Performance, ProcedurePath, isa_tas_mps
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.profile import window
from fms_testbed.procedures.database import Database, Sequence


def departure_cas_mps(b: LegBuilder, alt_m: float) -> float | None:
    """The departure schedule's CAS at the start of the leg being planned from ``alt_m`` (m),
    m/s (None: not a departure from a runway). The path distance where the planned climb
    passed the acceleration height is interpolated between the leg starts around it (the
    climb is linear in distance between them); a rebuild that starts above it counts back
    along the climb at the climb-out speed's gradient, d = Δh / Θ(V_c)."""
    if b.dep_elev_m is None:
        return None
    perf = b.perf
    h = alt_m - b.dep_elev_m
    s = b.flown_before_m + math.fsum(sg.geom.length_m() for sg in b.segments)
    if b.dep_accel_s_m is None and h >= perf.accel_height_m:
        prev = b.dep_prev
        if prev is None or prev[1] >= h:
            v_c = isa_tas_mps(perf.departure_cas_mps or perf.tas_plan_mps, alt_m,
                              b.params0.isa_dev_c)
            b.dep_accel_s_m = s - (h - perf.accel_height_m) / perf.climb_gradient_at(v_c)
        else:
            b.dep_accel_s_m = prev[0] + (s - prev[0]) * (perf.accel_height_m - prev[1]) \
                / (h - prev[1])
    b.dep_prev = (s, h)
    d = None if b.dep_accel_s_m is None else s - b.dep_accel_s_m
    return perf.departure_cas_at_mps(d, alt_m)


def held_speed_helps(b: LegBuilder, n_findings: int, proc_type: str) -> bool:
    """True when the leg just built (its findings from index ``n_findings``) is a departure
    leg planned faster than the climb-out speed whose course could not be flown as coded (the
    fix reached direct, or no room even at the minimum speed): it is built again at the
    climb-out speed, which the aircraft can have held since the acceleration height."""
    perf = b.perf
    if proc_type != "D" or perf.departure_cas_mps is None or \
            not LEG_TYPES[b.leg.pt].course_to_fix:
        return False
    if b.dep_cas_mps is not None and b.dep_cas_mps <= perf.departure_cas_mps + 0.5:
        return False
    return any(f.category == "impossible" or "flown direct to the fix" in f.message
               or "joined at the minimum speed" in f.message
               for f in b.findings[n_findings:])


def cf_legs_to_hold(path: ProcedurePath, perf: Performance) -> frozenset[int]:
    """The CF legs of a departure planned faster than its climb-out speed whose course was
    not flown as coded: a fly-by onto the course flown over (branch V,γ,φ,λ naming it), or
    an 'impossible' finding on the leg; empty for other procedures."""
    if path.proc_type != "D" or perf.departure_cas_mps is None:
        return frozenset()
    out = set()
    for lg in path.legs:
        if not LEG_TYPES[lg.path_term].course_to_fix or lg.departure_cas_mps is None or \
                lg.departure_cas_mps <= perf.departure_cas_mps + 0.5:
            continue
        ident = lg.record.fix.ident if lg.record.fix else ""
        if any(f.leg_index == lg.index and f.category == "impossible" or
               f.branch == "V,γ,φ,λ" and f"CF {ident}" in f.message
               and f.leg_index in (lg.index - 1, lg.index) for f in path.findings):
            out.add(lg.index)
    return frozenset(out)


def departure_slowdowns(built: list[BuiltLeg], segs: list[PathSegment]) -> list[BuiltLeg]:
    """A departure leg planned slower than the schedule (a course joined at the minimum
    speed) is flown at that speed from its start: the legs before it are capped, backwards,
    so the aircraft can slow down over them at the planned deceleration a,
    V_k ≤ √(V_k+1² + 2 a L_k) (CAS, L_k the leg's length, m)."""
    if all(lg.departure_cas_mps is None for lg in built):
        return built
    length = [0.0] * len(built)
    pos = {lg.index: k for k, lg in enumerate(built)}
    for sg in segs:
        k = pos.get(sg.leg_index)
        if k is not None:
            length[k] += sg.geom.length_m()
    out = list(built)
    for k in range(len(out) - 2, -1, -1):
        v, v_next = out[k].departure_cas_mps, out[k + 1].departure_cas_mps
        if v is None or v_next is None:
            continue
        cap = math.sqrt(v_next * v_next + 2.0 * DECEL_MPS2 * length[k])
        if cap < v:
            out[k] = replace(out[k], departure_cas_mps=cap)
    return out


SID_JOIN_CAP_M = 18000 * FT_M
"""A SID joined at a fix away from the runway is never planned above this, m."""


def sid_join_alt_m(db: Database, seq: Sequence, fix, elev_m: float,
                   perf: Performance | None) -> float:
    """Altitude at which a SID joined at ``fix`` (not from its runway: the runway part is
    vectors or was not asked for) is planned to be there: 35 ft above the field plus a climb at
    the aircraft's gradient over the distance from the airport to the fix, capped by every 'at
    or below', 'at' or 'between' constraint of the transition (the top of its window) and by
    :data:`SID_JOIN_CAP_M`, and raised into the first fix's own window, m — not the field
    elevation (issue 12, class H: a start thousands of feet below the climb windows), nor
    above an 'at' first fix (KAPA ECHOO1: joined at 18,000 ft over BAPME coded at 8,000 ft)."""
    alt = elev_m + 35 * FT_M
    apt = db.airports.get(seq.airport)
    if perf is not None and apt is not None and fix is not None:
        d = inverse(apt.lat_deg, apt.lon_deg, fix.lat_deg, fix.lon_deg)[0]
        alt += perf.climb_gradient_at(perf.tas_plan_mps) * d
    # capped by the top of every window ('at or below', 'at', 'between': an 'at 8,000 ft' at
    # the first fix is a cap too), and inside the first fix's own window
    wins = [window(r.alt_desc, r.alt1_m, r.alt2_m) for r in seq.legs]
    caps = [hi for _, hi in wins if hi is not None]
    alt = min([alt, SID_JOIN_CAP_M] + caps)
    lo_first = wins[0][0] if wins else None
    return alt if lo_first is None else max(alt, lo_first)


def departure_elev_m(db: Database, seq: Sequence, kind: str, rwy) -> float | None:
    """Elevation of the runway a SID is planned from, m, when its departure speeds apply
    (:meth:`~fms_testbed.legs.model.Performance.departure_cas_at_mps`): a build from the
    runway (start kind 'runway'), or the rest of a SID flown from its runway rebuilt in
    flight ('given'); None otherwise (a SID joined at a fix, arrivals). ``rwy``: the runway
    record of its runway part (:func:`~fms_testbed.path.segmentation.runway_record`), or None."""
    if seq.proc_type != "D" or kind not in ("runway", "given"):
        return None
    if rwy is None:
        return None
    apt = db.airports.get(seq.airport)
    elev = rwy.elev_m if rwy.elev_m is not None else (apt.elev_m if apt else None)
    return elev if elev is not None else 0.0
