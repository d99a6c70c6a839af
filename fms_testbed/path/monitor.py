"""The built-in parameter monitor (Danilin 2017, Fig. 5) and the per-procedure outcome.

The computed vector X = (φ, λ, Ω, R, V, γ, Θ) of the built path is compared with the database
and performance values: fixes where the database puts them (φ, λ), RF radius and arc angle
(R, Ω), planned speed against coded limits (V), |γ| ≤ 25° (γ), and the climb gradient window
3.3 % ≤ Θ ≤ Θ_perf. Failures are corrected in the paper's order — R; V,γ; γ; V,Θ; V,γ,φ,λ — each
with a bounded number of iterations (the fly-by branches R, V,γ and V,γ,φ,λ run while the
corners are rounded, see ``segmentation.round_corners``). If no branch succeeds the outcome is
"impossible" with the reason. The monitor also flags discontinuities, looping or duplicated
paths (the paper's Fig. 4 coding error) and intercepts that never happen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.core.geodesy import inverse, wrap180
from fms_testbed.core.segments import Arc, project
from fms_testbed.core.units import FT_M, G0_MPS2, KT_MPS, NM_M
from fms_testbed.legs.builder import CF_OFF_COURSE_DEG
from fms_testbed.legs.model import BuildParams, Finding, Performance, ProcedurePath
from fms_testbed.legs.types import LEG_TYPES
from fms_testbed.path.coding import hold_checks, record_checks
from fms_testbed.path.profile import path_climb_top_m, plan_profile, sid_join_required_alt_m
from fms_testbed.path.segmentation import planned_conditions

#: Tolerances: fly-over pass, gaps (the coded-arc radius tolerances are the leg classes'
#: ``radius_tol_m``).
FIX_TOL_M = 1.0
GAP_TOL_M = 1.0
#: Largest track change between consecutive segments not flagged as a kink, deg.
KINK_TOL_DEG = 10.0


@dataclass(frozen=True, slots=True)
class FixCheck:
    """Distance from a fix-terminated leg's end to its fix, with the allowed distance, m."""

    leg_index: int
    fix_ident: str
    miss_m: float
    allowed_m: float
    fly_over: bool


def leg_end_checks(path: ProcedurePath) -> list[FixCheck]:
    """(φ, λ) check: every leg that ends at its database fix with a 'fix' termination
    (TF/CF/DF/IF/RF/AF; holds end over their fix by construction) ends there — over it when
    fly-over, within the turn anticipation L = R tan(Ω/2) of the fly-by arc that replaces the
    corner."""
    out = []
    own: dict[int, int] = {}
    for k, seg in enumerate(path.segments):
        own[seg.leg_index] = k
    for lg in path.legs:
        if not LEG_TYPES[lg.path_term].ends_at_fix or lg.termination.kind != "fix":
            continue
        allowed = FIX_TOL_M
        k = own.get(lg.index)
        if k is None:
            end = (lg.end.lat_deg, lg.end.lon_deg)
        elif path.segments[k].role == "flyby":
            # the fillet leaves the fix's corner on one side at the lead distance (on the
            # straight, for a fillet between a coded arc and a line)
            arc = path.segments[k].geom
            allowed += path.segments[k].lead_m or \
                arc.radius_m * math.tan(math.radians(abs(arc.sweep_deg)) / 2.0)
            t = lg.termination
            out.append(FixCheck(lg.index, t.fix_ident, min(
                inverse(*arc.start, t.lat_deg, t.lon_deg)[0],
                inverse(*arc.end, t.lat_deg, t.lon_deg)[0]), allowed, lg.record.fly_over))
            continue
        else:
            end = path.segments[k].geom.end
        t = lg.termination
        miss = inverse(end[0], end[1], t.lat_deg, t.lon_deg)[0]
        out.append(FixCheck(lg.index, t.fix_ident, miss, allowed, lg.record.fly_over))
    return out


def arc_conditions_text(tas_mps: float, wind_mps: float, isa_dev_c: float, alt_m: float,
                        radius_m: float, bank_deg: float, g_mps2: float) -> str:
    """The conditions behind a coded arc's bank or speed correction (class 1), '' in calm ISA
    air: e.g. "; at 245 kt TAS + 30 kt tailwind, ISA+20 the bank needed is 27.1° (19.4° in
    calm ISA air): forced by the conditions" — γ = atan((V + W)² / (R g)) against the
    calm-ISA γ for the same CAS (:func:`~fms_testbed.path.segmentation.conditions_text`'s
    twin for arcs of fixed radius).

    Parameters
    ----------
    tas_mps : planned TAS, m/s; wind_mps : planned wind speed (its tailwind part at worst), m/s
    isa_dev_c : planned ISA deviation, K; alt_m : the leg's planned altitude, m
    radius_m : the arc's radius, m; bank_deg : the planned bank, deg; g_mps2 : gravity, m/s²
    """
    planned = planned_conditions(tas_mps, wind_mps, isa_dev_c, alt_m)
    if planned is None:
        return ""
    cond, v_isa = planned
    g_now = math.degrees(math.atan((tas_mps + wind_mps) ** 2 / (radius_m * g_mps2)))
    g_calm = math.degrees(math.atan(v_isa ** 2 / (radius_m * g_mps2)))
    forced = ": forced by the conditions" if g_calm <= bank_deg + 1e-9 else ""
    return (f"; at {cond} the bank needed is "
            f"{g_now:.1f}° ({g_calm:.1f}° in calm ISA air){forced}")


def _arc_checks(path: ProcedurePath, perf: Performance, params: BuildParams,
                g: float) -> list[Finding]:
    """(R, Ω, γ) checks of the coded arcs (RF, AF) with the γ and V,γ corrections."""
    out = []
    for lg in path.legs:
        kind = LEG_TYPES[lg.path_term]
        if kind.arc_centre is None:
            continue
        arcs = [s for s in path.segments if s.leg_index == lg.index and isinstance(s.geom, Arc)
                and s.role == "leg"]
        if not arcs:
            continue
        arc = arcs[0].geom
        r = lg.record
        if r.turn_dir in ("L", "R") and arc.turn != r.turn_dir:
            out.append(Finding(lg.index, "impossible", f"{lg.path_term} arc turns {arc.turn}, "
                               f"coded {r.turn_dir}"))
        if kind.arc_centre == "fix" and lg.index > 0 and path.legs[lg.index - 1].record.fix \
                and path.legs[lg.index - 1].termination.kind == "fix" and r.fix is not None:
            # Ω: the angle the database's fixes subtend about the coded centre
            t0 = path.legs[lg.index - 1].termination
            _, a0, _ = inverse(arc.centre_lat_deg, arc.centre_lon_deg, t0.lat_deg, t0.lon_deg)
            _, a1, _ = inverse(arc.centre_lat_deg, arc.centre_lon_deg, lg.termination.lat_deg,
                               lg.termination.lon_deg)
            omega_k = (a1 - a0) % 360.0 if arc.turn == "R" else (a0 - a1) % 360.0
            built = sum(abs(s.geom.sweep_deg) for s in arcs)
            if abs(built - omega_k) > 1.0 and abs(built - omega_k) < 359.0:
                out.append(Finding(lg.index, "discontinuity", f"RF arc angle built "
                                   f"{built:.1f}° vs {omega_k:.1f}° between its fixes"))
        coded_r = kind.coded_radius_m(r)
        if coded_r:
            dr = arc.radius_m - coded_r
            if abs(dr) > kind.radius_tol_m:
                out.append(Finding(lg.index, "correction",
                                   f"{lg.path_term} radius coded {coded_r / NM_M:.3f} NM, fixes "
                                   f"give {arc.radius_m / NM_M:.3f} NM: path follows the fixes",
                                   "R"))
        out += _arc_bank_findings(lg, arc, perf, params, g)
    return out


def _arc_bank_findings(lg, arc, perf: Performance, params: BuildParams, g: float
                       ) -> list[Finding]:
    """(γ; V,γ) of one coded arc: the bank its radius needs at the planned speed and the
    wind at the leg's planned altitude, γ = atan((V + W)² / (R g)); raised up to the limit,
    else the speed lowered to V = √(R g tan γ_max) − W, else impossible."""
    gplan = min(params.bank_plan_deg, params.bank_limit_deg, perf.bank_max_deg)
    gmax = min(params.bank_limit_deg, perf.bank_max_deg)
    v = lg.speed_mps
    # the ground speed on an arc reaches TAS + wind (class 1): the wind at the leg's
    # planned altitude
    w = params.wind_at(lg.start.alt_m)[0]
    why = arc_conditions_text(v, w, params.isa_dev_c, lg.start.alt_m, arc.radius_m, gplan, g)
    g_req = math.degrees(math.atan((v + w) ** 2 / (arc.radius_m * g)))
    if g_req <= gplan + 1e-9:
        return []
    if g_req <= gmax:
        return [Finding(lg.index, "correction", f"{lg.path_term} radius "
                        f"{arc.radius_m / NM_M:.2f} NM at {v / KT_MPS:.0f} kt: bank "
                        f"{gplan:.0f} -> {g_req:.1f}°{why}", "γ")]
    v_reg = math.sqrt(arc.radius_m * g * math.tan(math.radians(gmax))) - w
    if v_reg >= perf.tas_min_mps:
        return [Finding(lg.index, "correction", f"{lg.path_term} radius "
                        f"{arc.radius_m / NM_M:.2f} NM: speed {v / KT_MPS:.0f} -> "
                        f"{v_reg / KT_MPS:.0f} kt at bank {gmax:.0f}°{why}", "V,γ")]
    return [Finding(lg.index, "impossible", f"{lg.path_term} radius "
                    f"{arc.radius_m / NM_M:.2f} NM needs bank {g_req:.0f}° > "
                    f"{gmax:.0f}° even at the minimum speed {v_reg / KT_MPS:.0f} kt")]


def _gradient_checks(path: ProcedurePath, perf: Performance, params: BuildParams,
                     start_alt_m: float) -> tuple[list[Finding], object]:
    """Θ window: 3.3 % ≤ Θ ≤ Θ_perf in climbs, descent within the descent rate; branch V,Θ."""
    out = []
    v = perf.tas_plan_mps
    theta_perf = perf.climb_gradient_at(v)
    climbs = path.proc_type == "D" or any(lg.record.missed_approach_start for lg in path.legs)
    if climbs and theta_perf < params.climb_min_gradient:
        v_need = perf.climb_gradient_max * perf.tas_plan_mps / params.climb_min_gradient
        if v_need >= perf.tas_min_mps:
            out.append(Finding(-1, "correction", f"climb gradient {100 * theta_perf:.1f}% < 3.3%:"
                               f" speed {v / KT_MPS:.0f} -> {v_need / KT_MPS:.0f} kt", "V,Θ"))
            v = v_need
            theta_perf = perf.climb_gradient_at(v)
        else:
            out.append(Finding(-1, "impossible", f"aircraft climb gradient "
                               f"{100 * theta_perf:.1f}% below the 3.3% minimum"))
    g_desc = perf.descent_rate_max_mps / perf.tas_plan_mps
    top = path_climb_top_m(path.proc_type, params.climb_top_m)
    prof = plan_profile(path, theta_perf, start_alt_m, params.descent_angle_deg,
                        climb_top_m=top, descent_gradient_max=g_desc,
                        descent_rate_mps=perf.descent_rate_max_mps,
                        alt_max_m=perf.alt_plan_max_m)
    if path.proc_type == "D" and path.start_kind != "runway" and prof.windows:
        # joined at a fix away from the runway: the planned start must make every climb
        # constraint ahead at the aircraft's gradient; a start below that is flagged and the
        # rest checked from the altitude it needs
        a0 = sid_join_required_alt_m(path, theta_perf)
        if a0 is not None and a0 > start_alt_m + 50 * FT_M:
            name = path.legs[0].record.fix.ident if path.legs[0].record.fix else "the start"
            out.append(Finding(0, "correction", f"SID joined at {name} at "
                               f"{start_alt_m / FT_M:.0f} ft cannot make its climb constraints "
                               f"at {100 * theta_perf:.1f}%: joined at {a0 / FT_M:.0f} ft",
                               "V,Θ"))
            prof = plan_profile(path, theta_perf, a0, params.descent_angle_deg,
                                climb_top_m=top, descent_gradient_max=g_desc,
                                descent_rate_mps=perf.descent_rate_max_mps,
                                alt_max_m=perf.alt_plan_max_m)
    out += _climb_window_findings(path, perf, params, prof, v, theta_perf)
    out += _descent_findings(path, perf, prof, v)
    return out, prof


def _climb_window_findings(path: ProcedurePath, perf: Performance, params: BuildParams,
                           prof, v: float, theta_perf: float) -> list[Finding]:
    """(V,Θ) of every 'at or above' window of a climb the profile misses at the gradient
    ``theta_perf``: the speed lowered (bounded iterations) until the aircraft's gradient
    there makes it, else impossible. ``v``: the planned TAS, m/s."""
    out = []
    for w in prof.windows:
        k = w.leg_index + 1
        if not prof.climb[k] or w.lo_m is None or prof.alt_m[k] >= w.lo_m - 1.0:
            continue
        kind = LEG_TYPES[path.legs[w.leg_index].path_term]
        if kind.altitude_terminated or kind.hold:
            continue  # altitude-terminated or reached in the hold: met by construction
        nxt = path.legs[w.leg_index + 1] if w.leg_index + 1 < len(path.legs) else None
        if nxt is not None and LEG_TYPES[nxt.path_term].hold and nxt.record.fix \
                and nxt.record.fix.ident == w.fix_ident:
            continue  # climb in the hold that follows at the same fix
        # find the last node where the climb was free to start from
        j = k - 1
        ds = prof.along_m[k] - prof.along_m[j]
        while j > 0 and prof.climb[j] and ds < 1.0:
            j -= 1
            ds = prof.along_m[k] - prof.along_m[j]
        need = (w.lo_m - prof.alt_m[j]) / max(prof.along_m[k] - prof.along_m[0], 1.0) \
            if j == 0 else (w.lo_m - prof.alt_m[j]) / max(ds, 1.0)
        need = max(need, (w.lo_m - prof.alt_m[0]) / max(prof.along_m[k], 1.0))
        name = w.fix_ident or f"the end of {path.legs[w.leg_index].path_term}"
        ok = False
        vv = v
        for _ in range(params.max_iterations):
            vv = max(perf.tas_min_mps, vv * min(theta_perf / need, 0.97))
            if perf.climb_gradient_at(vv) >= need:
                ok = True
                break
        if ok:
            out.append(Finding(w.leg_index, "correction", f"{name} at or above "
                               f"{w.lo_m / FT_M:.0f} ft needs {100 * need:.1f}% climb: speed "
                               f"{v / KT_MPS:.0f} -> {vv / KT_MPS:.0f} kt", "V,Θ"))
        else:
            out.append(Finding(w.leg_index, "impossible", f"{name} at or above "
                               f"{w.lo_m / FT_M:.0f} ft needs {100 * need:.2f}% climb, aircraft "
                               f"max {100 * perf.climb_gradient_at(perf.tas_min_mps):.2f}% at "
                               "minimum speed"))
    return out


def _descent_findings(path: ProcedurePath, perf: Performance, prof, v: float
                      ) -> list[Finding]:
    """(V,Θ) of every descent piece steeper than the descent rate allows at ``v`` (m/s):
    V = w_d / gradient when that is above the minimum speed, else impossible."""
    out = []
    grads = prof.gradients()
    for k in range(1, len(prof.alt_m)):
        if prof.climb[k] or not grads[k - 1] < 0:
            continue
        need = -grads[k - 1]
        cap = perf.descent_rate_max_mps / v
        if need <= cap * 1.005:
            continue
        v_reg = perf.descent_rate_max_mps / need
        lg = path.legs[k - 1]
        ident = lg.record.fix.ident if lg.record.fix else lg.path_term
        if v_reg >= perf.tas_min_mps:
            out.append(Finding(k - 1, "correction", f"descent to {ident} needs "
                               f"{100 * need:.1f}%: speed {v / KT_MPS:.0f} -> {v_reg / KT_MPS:.0f} kt",
                               "V,Θ"))
        else:
            out.append(Finding(k - 1, "impossible", f"descent to {ident} needs "
                               f"{100 * need:.1f}% (> {100 * perf.descent_rate_max_mps / perf.tas_min_mps:.1f}% "
                               "at minimum speed)"))
    return out


LONG_WAY_TURN_DEG = 270.0
"""A TF or CF whose coded turn direction makes it turn more than this (deg) is reported: the
short way round is less than 90°, so the coded direction is more likely a coding error than a
design (Danilin's class 3; the leg is flown as coded)."""


def _long_way_turns(path: ProcedurePath) -> list[Finding]:
    """TF/CF legs with a coded turn direction flown more than :data:`LONG_WAY_TURN_DEG` round.

    The turn is the summed sweep of the leg's own turn and fly-by arcs, reported when its net
    track change is under 360° − that limit (a course reversal, 180° either way, is a design
    and not reported); legs whose design turns
    far (RF, AF, holds, procedure turns, direct-tos and heading legs after a runway climb) are
    not checked."""
    out = []
    for lg in path.legs:
        if lg.path_term not in ("TF", "CF") or lg.record.turn_dir not in ("L", "R"):
            continue
        arcs = [sg.geom for sg in path.segments if sg.leg_index == lg.index
                and sg.geom.kind == "arc" and sg.role in ("turn", "flyby")]
        sweep = sum(abs(a.sweep_deg) for a in arcs)
        if sweep <= LONG_WAY_TURN_DEG:
            continue
        net = abs(wrap180(arcs[-1].end_course_deg - arcs[0].start_course_deg))
        if net <= 360.0 - LONG_WAY_TURN_DEG:   # the short way was under 90°
            side = {"L": "left", "R": "right"}[lg.record.turn_dir]
            ident = lg.record.fix.ident if lg.record.fix else lg.path_term
            out.append(Finding(lg.index, "loop", f"leg {lg.index + 1} ({lg.path_term} {ident}): "
                               f"the coded {side} turn is flown {sweep:.0f}° round for a "
                               f"{net:.0f}° track change (turn direction coded against the "
                               f"short way?)"))
    return out


def _topology_checks(path: ProcedurePath) -> list[Finding]:
    """Gaps between segments, duplicated/looping paths (Fig. 4) and doubled-back legs."""
    out = []
    segs = path.segments
    for k in range(1, len(segs)):
        a, b = segs[k - 1], segs[k]
        gap = inverse(*a.geom.end, *b.geom.start)[0]
        if gap > GAP_TOL_M:
            out.append(Finding(b.leg_index, "discontinuity",
                               f"gap of {gap:.1f} m before leg {b.leg_index + 1}"))
        elif "connector" not in (a.role, b.role) and a.geom.length_m() > 1.0 \
                and b.geom.length_m() > 1.0:
            jump = abs(wrap180(b.geom.start_course_deg - a.geom.end_course_deg))
            if jump > KINK_TOL_DEG:
                out.append(Finding(b.leg_index, "discontinuity", f"track jumps by {jump:.0f}° "
                                   f"in leg {b.leg_index + 1} ({b.path_term})"))
    seen: dict[tuple[str, str], int] = {}
    prev_fix = ""
    for lg in path.legs:
        r = lg.record
        f = r.fix.ident if r.fix else ""
        if LEG_TYPES[lg.path_term].track_to_fix and prev_fix and f:
            key = (prev_fix, f)
            if key in seen:
                out.append(Finding(lg.index, "loop", f"path {prev_fix}->{f} flown twice "
                                   f"(legs {seen[key] + 1} and {lg.index + 1})"))
            seen.setdefault(key, lg.index)
        prev_fix = f if lg.termination.kind == "fix" else ""
    out += _long_way_turns(path)
    lines = [s for s in segs if s.geom.kind == "line" and s.role == "leg"
             and s.geom.length_m() > 100.0]
    for a, b in zip(lines, lines[1:]):
        if b.leg_index == a.leg_index + 1 and \
                abs(wrap180(b.geom.start_course_deg - a.geom.end_course_deg)) > 175.0 and \
                not LEG_TYPES[a.path_term].course_reversal and \
                not LEG_TYPES[b.path_term].course_reversal:
            mid = b.geom.point_at(0.5 * b.geom.length_m())
            along, xtk, _, _ = project(a.geom, *mid)
            if abs(xtk) < 100.0 and -100.0 < along < a.geom.length_m() + 100.0:
                out.append(Finding(b.leg_index, "loop", f"leg {b.leg_index + 1} doubles back "
                                   f"over leg {a.leg_index + 1}"))
    return out


CF_AGAINST_COURSE_DEG = 90.0
"""A CF's own straight more than this off its coded course is flown against it, deg."""


def cf_course_checks(path: ProcedurePath) -> list[Finding]:
    """Every straight a CF leg flies as its own path (role 'leg') against its coded course
    (from the record, turned true with the leg's variation).

    More than :data:`CF_AGAINST_COURSE_DEG` off (the course flown backwards): the transition
    is impossible, with the reason. More than :data:`CF_OFF_COURSE_DEG` off (the fix reached
    direct where the course cannot be joined at the planned radius, the corner flown over
    and the fix rejoined): a correction of branch V,γ,φ,λ (the position changed, class 1)
    that says the coded course is not flown. The turns and intercepts onto the course (roles
    'turn', 'flyby') are transitions and not checked, nor is a CF the builder found
    impossible already (its finding gives the reason)."""
    out = []
    done = {f.leg_index for f in path.findings if f.category == "impossible"}
    for lg in path.legs:
        if not LEG_TYPES[lg.path_term].course_to_fix or lg.resolved is None \
                or lg.resolved.course_true_deg is None or lg.index in done:
            continue
        crs = lg.resolved.course_true_deg
        offs = [max(abs(wrap180(s.geom.start_course_deg - crs)),
                    abs(wrap180(s.geom.end_course_deg - crs))) for s in path.segments
                if s.leg_index == lg.index and s.role == "leg" and s.geom.kind == "line"
                and s.geom.length_m() >= 1.0]
        off = max(offs, default=0.0)
        if off <= CF_OFF_COURSE_DEG:
            continue
        ident = lg.record.fix.ident if lg.record.fix else ""
        what = (f"CF {ident} built {off:.0f}° off its coded course {crs:.1f}° "
                f"(line {lg.record.line})")
        if off > CF_AGAINST_COURSE_DEG:
            out.append(Finding(lg.index, "impossible", f"{what}: flown against the course"))
        else:
            out.append(Finding(lg.index, "correction", f"{what}: the fix is reached without "
                               "flying the coded course", "V,γ,φ,λ"))
    return out


STATUSES = ("ok", "corrected", "coding_suspect", "impossible")
"""The monitor's outcomes of a transition, from best to worst (:func:`outcome`)."""


def outcome(findings) -> str:
    """The monitor's outcome (:data:`STATUSES`) from its findings.

    'impossible' if a finding says so or the built path is not continuous (a
    ``discontinuity``: a gap bridged or a track jump, the path is not the coded one);
    'coding_suspect' if a record's coded numbers disagree with its fixes (category
    ``coding``, :mod:`.coding`) or the path loops or is flown twice (``loop``, Danilin's
    Fig. 4): class 3, the database's coding; 'corrected' if the plan was changed to fly it
    (``correction``, ``no-intercept``); else 'ok'.
    """
    cats = {f.category for f in findings}
    if cats & {"impossible", "discontinuity"}:
        return "impossible"
    if cats & {"coding", "loop"}:
        return "coding_suspect"
    if cats & {"correction", "no-intercept"}:
        return "corrected"
    return "ok"


def coding_findings(path: ProcedurePath, params: BuildParams) -> list[Finding]:
    """Class-3 findings of the coded numbers (:mod:`.coding`) of the legs built from
    resolved records, and of the holds' built leg lengths.

    Parameters
    ----------
    path : the built transition; params : build settings (the timed-leg speed, m/s)
    """
    legs = [lg for lg in path.legs if lg.resolved is not None]
    if len(legs) != len(path.legs):
        return []
    out = record_checks([lg.resolved for lg in legs], [lg.from_fix for lg in legs])
    return out + hold_checks(path, params.timed_speed_mps)


def check_path(path: ProcedurePath, perf: Performance, params: BuildParams | None = None,
               g_mps2: float = G0_MPS2) -> ProcedurePath:
    """Run the monitor on a built path; return it with findings, profile and status.

    Parameters
    ----------
    path : built procedure transition (``segmentation.build_sequence``)
    perf : aircraft performance; params : build settings; g_mps2 : local gravity, m/s²
    """
    params = params or BuildParams()
    if not path.legs:
        return replace(path, status=outcome(path.findings) if path.findings else "impossible")
    findings = list(path.findings)
    for fc in leg_end_checks(path):
        if fc.miss_m > fc.allowed_m:
            findings.append(Finding(fc.leg_index, "impossible", f"path misses {fc.fix_ident} by "
                                    f"{fc.miss_m:.1f} m (allowed {fc.allowed_m:.1f} m)"))
    findings += _arc_checks(path, perf, params, g_mps2)
    grad, prof = _gradient_checks(path, perf, params, path.legs[0].start.alt_m)
    findings += grad
    findings += _topology_checks(path)
    findings += coding_findings(path, params)
    findings += cf_course_checks(path)
    return replace(path, findings=tuple(findings), profile=prof, status=outcome(findings))
