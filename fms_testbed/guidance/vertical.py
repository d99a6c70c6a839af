"""Vertical guidance: the planned profile and the coded speed limits become targets for the
coupled law (altitude and true airspeed), within the aircraft's performance.

Altitude: the planned profile (:class:`fms_testbed.path.profile.VerticalProfile`, which already
climbs at the aircraft's gradient, levels off under 'at or below' constraints and descends at
the coded or 3° angle into each window) read ahead of the aircraft by the law's ramp lag::

    H_cmd = H_plan(s + V_g τ_H),    τ_H = 2 ξ_H T_H

(a second-order altitude loop follows a ramp with a lag of 2 ξ_H T_H; reading the plan that far
ahead removes it). Speed is also capped ahead of arcs too tight for the planned TAS within the
bank limit (:func:`.speed_plan.arc_speed_cap_mps`). In a climb phase (SID, missed approach) the target is instead the top of the
climb — the highest planned altitude of the phase capped by every 'at or below' constraint
ahead — flown at the law's level-change rate, set to the aircraft's sustained climb rate
(:func:`procedure_law`): an FMS climbs at the best rate, not along a geometric path, so 'at or
above' constraints are met as early as the aircraft can. Speed: the aircraft's planned TAS, capped by an 'at' / 'at or below' limit of
the leg being flown (coded as IAS/CAS, converted at the present altitude, aimed
:data:`SPEED_MARGIN_MPS` inside the limit) or raised to an 'at or above' one; in descent
(STAR/approach) a limit, once applied, holds for the rest of the procedure. Never below
MIN_CAS_FACTOR × the aircraft's minimum CAS.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.units import KT_MPS
from fms_testbed.core.planning import MIN_CLEAN_CAS_FACTOR as MIN_CAS_FACTOR
from fms_testbed.legs.model import approach_cas_caps

# MIN_CAS_FACTOR: the TAS target never gives a CAS below this multiple of the aircraft's minimum
# clean CAS (the planned TAS is constant, so high in a SID or STAR the CAS would otherwise fall
# toward the stall); the planner's factor, one number for both.
SPEED_MARGIN_MPS = 2.0 * KT_MPS
"""Aim inside an 'at or below' / 'at or above' speed limit by this much, m/s."""


@dataclass(frozen=True, slots=True)
class SpeedLimit:
    """A coded speed limit of one leg: CAS (m/s) and descriptor ('' or '@' at, '-' at or below,
    '+' at or above)."""

    cas_mps: float
    desc: str


def leg_speed_limits(legs) -> list[SpeedLimit | None]:
    """Speed limit of each leg record (``LegRecord.speed_limit_mps``/``speed_desc``), or None."""
    return [SpeedLimit(r.speed_limit_mps, r.speed_desc) if r.speed_limit_mps else None
            for r in legs]


def planned_limits(legs, proc_type: str, cas_min_mps: float) -> list[SpeedLimit | None]:
    """The speed limit guidance flies on each leg: the coded one, merged with the planned
    approach speed (:func:`fms_testbed.legs.model.approach_cas_caps`) as an 'at or below'
    limit where that is lower."""
    out = leg_speed_limits(legs)
    for k, cap in enumerate(approach_cas_caps(legs, proc_type, cas_min_mps)):
        lim = out[k]
        if cap is None:
            continue
        if lim is None or (lim.desc == "-" and lim.cas_mps > cap):
            out[k] = SpeedLimit(cap, "-")
    return out


def cas_band(limit: SpeedLimit | None, carried_max_cas_mps: float | None
             ) -> tuple[float | None, float | None]:
    """(lowest, highest) CAS the current leg allows, m/s (None: unbounded)."""
    lo = hi = None
    if limit is not None:
        if limit.desc in ("", "@", "-"):
            hi = limit.cas_mps - (SPEED_MARGIN_MPS if limit.desc == "-" else 0.0)
        if limit.desc in ("", "@", "+"):
            lo = limit.cas_mps + (SPEED_MARGIN_MPS if limit.desc == "+" else 0.0)
    if carried_max_cas_mps is not None:
        hi = carried_max_cas_mps if hi is None else min(hi, carried_max_cas_mps)
    return lo, hi


def tas_target_mps(tas_plan_mps: float, alt_m: float, lo_cas_mps: float | None,
                   hi_cas_mps: float | None, cas_min_mps: float, isa_dev_c: float = 0.0,
                   floor_cas_mps: float | None = None) -> float:
    """TAS target, m/s: the planned TAS moved into the allowed CAS band at altitude ``alt_m``
    (conversion on a day ``isa_dev_c`` K off the ISA), never below MIN_CAS_FACTOR ×
    ``cas_min_mps`` (clean) or, when ``floor_cas_mps`` is given (an aircraft configured for
    the approach: its Vapp), below that CAS, m/s."""
    if floor_cas_mps is not None:
        cas_min_mps = floor_cas_mps / MIN_CAS_FACTOR
    v = tas_plan_mps
    if hi_cas_mps is not None:
        v = min(v, cas_to_tas_scalar(hi_cas_mps, alt_m, isa_dev_c))
    if lo_cas_mps is not None:
        v = max(v, cas_to_tas_scalar(lo_cas_mps, alt_m, isa_dev_c))
    return max(v, cas_to_tas_scalar(MIN_CAS_FACTOR * cas_min_mps, alt_m, isa_dev_c))


def altitude_lead_s(cfg) -> float:
    """Read-ahead time of the altitude plan, 2 ξ_H T_H of the aircraft's coupled law, s."""
    g = cfg.coupled_law
    return 2.0 * g.xi_H * g.T_H_s if g is not None else 10.0


LEAD_NAMES = ("T_H_s", "xi_H")
"""Scheduled coupled-law parameters the altitude read-ahead uses."""


def scheduled_lead(schedule, tas_mps: float, p_static_pa: float, t_static_k: float,
                   mass_kg: float) -> tuple[float, float] | None:
    """The read-ahead terms (2 ξ_H T_H in s, T_H² in s²) of the coupled law's gain schedule
    ``schedule`` (:class:`~.vertical_schedule.GainSchedule`) at the measured air data — TAS
    ``tas_mps`` (m/s), static pressure ``p_static_pa`` (Pa) and temperature ``t_static_k`` (K),
    q̄ = ½ ρ V², ρ = p_s / (R T_s) — and mass ``mass_kg`` (kg): the values the law flies there.
    None when the air data are not finite (the caller keeps its terms)."""
    from fms_testbed.guidance.vertical_schedule import qbar_from_state

    if not (math.isfinite(p_static_pa) and math.isfinite(t_static_k) and math.isfinite(tas_mps)):
        return None
    v = schedule.values(qbar_from_state(tas_mps, p_static_pa, t_static_k), mass_kg, LEAD_NAMES)
    return 2.0 * v["xi_H"] * v["T_H_s"], v["T_H_s"] ** 2


BLEND_S = 6.0
"""Each slope change of the planned profile is blended over ±BLEND_S seconds of flight."""


def _slope(ps: list[float], ph: list[float], k: int, extend: bool) -> float:
    """Slope of profile piece ``k`` (between nodes k-1 and k); 0 before the first node, the last
    piece's (``extend``) or 0 after the last."""
    n = len(ps)
    if k <= 0:
        return 0.0
    if k >= n:
        if not extend:
            return 0.0
        k = n - 1
        if k <= 0:
            return 0.0
    d = ps[k] - ps[k - 1]
    return (ph[k] - ph[k - 1]) / d if d > 1e-6 else 0.0


def blended_profile(ps: list[float], ph: list[float], s_m: float, w_m: float,
                    extend: bool) -> tuple[float, float, float]:
    """Planned altitude at path distance ``s_m`` with every slope change blended by a parabola
    over ±``w_m`` (constant vertical acceleration), and its first and second derivatives along
    the path: (h m, dh/ds, d²h/ds² 1/m). The blend lies on the outside of each corner (above a
    descent-to-level knee). ``extend``: the last slope continues past the last node (the final
    approach path goes on to the runway); otherwise the profile is flat beyond its ends.

    Guidance commands ``H_cmd = h + 2 ξ_H T_H V dh/ds + T_H² V² d²h/ds²``, the inverse of the
    coupled law's altitude dynamics ``T_H² Ḧ + 2 ξ_H T_H Ḣ + H = H_cmd`` along the smooth profile,
    so the aircraft flies the profile itself without lag."""
    n = len(ps)
    if n == 1:
        return ph[0], 0.0, 0.0
    j = bisect.bisect_right(ps, s_m)
    m = _slope(ps, ph, j, extend)
    if j <= 0:
        h = ph[0]
    elif j >= n:
        h = ph[-1] + m * (s_m - ps[-1])
    else:
        h = ph[j - 1] + m * (s_m - ps[j - 1])
    dh, ddh = m, 0.0
    if w_m <= 0:
        return h, dh, ddh
    for k in range(max(j - 2, 0), min(j + 2, n)):
        sk = ps[k]
        if abs(s_m - sk) >= w_m:
            continue
        delta = _slope(ps, ph, k + 1, extend) - _slope(ps, ph, k, extend)
        if delta == 0.0:
            continue
        u = s_m - sk + w_m
        after = 1.0 if s_m > sk else 0.0
        h += delta * u * u / (4.0 * w_m) - delta * (s_m - sk) * after
        dh += delta * u / (2.0 * w_m) - delta * after
        ddh += delta / (2.0 * w_m)
    return h, dh, ddh


def climb_targets(prof) -> list[float | None]:
    """Per profile node j: in a climb phase (``prof.climb[j]``), the altitude to climb to at
    the law's level-change rate while flying toward node j — the highest planned altitude of the
    rest of that climb phase, capped by every 'at or below'/'at' constraint ahead in it, m
    (None outside climb phases, where the planned profile itself is flown)."""
    n = len(prof.along_m)
    hi = [None] * n
    for w in prof.windows:
        if w.hi_m is not None and w.leg_index + 1 < n:
            hi[w.leg_index + 1] = w.hi_m
    out: list[float | None] = [None] * n
    run_max, run_cap = -math.inf, math.inf
    for j in range(n - 1, -1, -1):
        if not bool(prof.climb[j]):
            run_max, run_cap = -math.inf, math.inf
            continue
        run_max = max(run_max, float(prof.alt_m[j]))
        if hi[j] is not None:
            run_cap = min(run_cap, hi[j])
        out[j] = min(run_max, run_cap)
    return out


def knees_clear_of_windows(prof_s: list[float], prof_h: list[float],
                           climb_tgt: list[float | None],
                           windows: list[tuple[float | None, float | None]],
                           w_m: float, coded_angle: list[bool] | None = None
                           ) -> tuple[list[float], list[float]]:
    """The profile nodes (distances m, altitudes m) with every slope change at a constrained
    fix of a descent moved ``w_m`` (at most half the leg it moves into) along the piece on the
    side where its blend cannot cross the fix's window.

    :func:`blended_profile` blends a corner over ±w on its outside, so at the fix the blended
    profile is off the node's altitude by |Δγ| w / 4 (30 ft for a 3° descent that levels, at
    250 kt with w = 6 s of flight):

    - a corner the blend lies above (the descent flattens: γ_out > γ_in) at a fix with a top
      ('at', 'at or below', 'between' planned at the top) moves back along the outgoing
      piece, to (s − w, h − γ_out w): the blend ends at the fix, on the planned altitude;
    - a corner the blend lies below (the descent steepens: γ_out < γ_in) at a fix with a floor
      ('at', 'at or above') moves on along the incoming piece, to (s + w, h + γ_in w): the
      blend starts at the fix.

    The profile then passes every such fix at its planned altitude; the piece on the other
    side of the moved corner is a little steeper or shallower — never a piece on a coded
    vertical angle (``coded_angle[j]``: the piece ending at node j; a final approach path keeps
    its angle to the runway, and its FAF the plain blend)."""
    fixed = coded_angle if coded_angle is not None else [False] * len(prof_s)
    out_s, out_h = list(prof_s), list(prof_h)
    for j in range(1, len(prof_s) - 1):
        if j >= len(windows) or climb_tgt[j] is not None:
            continue
        lo, top = windows[j]
        d_in, d_out = prof_s[j] - prof_s[j - 1], prof_s[j + 1] - prof_s[j]
        if d_in <= 1e-6 or d_out <= 1e-6:
            continue
        g_in = (prof_h[j] - prof_h[j - 1]) / d_in
        g_out = (prof_h[j + 1] - prof_h[j]) / d_out
        if not (g_in < -1e-4 or g_out < -1e-4):
            continue
        if g_out > g_in + 1e-4 and top is not None and prof_h[j] >= top - 1.0 \
                and not fixed[j]:
            d = min(w_m, 0.5 * (out_s[j] - out_s[j - 1]))
            out_s[j], out_h[j] = prof_s[j] - d, prof_h[j] - g_out * d
        elif g_out < g_in - 1e-4 and lo is not None and prof_h[j] <= lo + 1.0 \
                and not fixed[j + 1]:
            d = min(w_m, 0.5 * d_out)
            out_s[j], out_h[j] = prof_s[j] + d, prof_h[j] + g_in * d
    return out_s, out_h


def altitude_command_m(prof_s: list[float], prof_h: list[float], climb_tgt: list[float | None],
                       s_path_m: float, gs_mps: float, lead_s: float, t2_s2: float,
                       top_m: float, approach: bool,
                       windows: list[tuple[float | None, float | None]] | None = None,
                       coded_angle: list[bool] | None = None,
                       lead_speed_mps: float | None = None) -> float:
    """Altitude command at path distance ``s_path_m``, m.

    Along the blended planned profile (:func:`blended_profile`, blend ±``gs BLEND_S``) the
    command inverts the coupled law's altitude dynamics,
    ``H_cmd = h + 2 ξ_H T_H V dh/ds + T_H² V² d²h/ds²``; in a climb phase it is instead the
    climb target of the node ahead (:func:`climb_targets`: capped by every 'at or below'
    constraint ahead), never above ``top_m``.

    Parameters
    ----------
    prof_s, prof_h : profile node distances (m, on the active path) and altitudes (m)
    climb_tgt : climb target per node, m (None outside climbs)
    s_path_m : distance along the active path, m; gs_mps : ground speed, m/s
    lead_s : read-ahead time 2 ξ_H T_H, s (:func:`altitude_lead_s`); t2_s2 : T_H², s²
    lead_speed_mps : the speed of the lead term, m/s (None: ``gs_mps``). Guidance gives the
        TAS from the air data: the coupled law's ramp lag is air-relative, 2 ξ_H T_H V_TAS dh/ds
        (measured in ``docs/flying.md``)
    top_m : the flight's climb top, m; approach : the last slope continues to the runway
    windows : coded (lo, hi) window per node, m: outside climbs the blended profile stays
        above the lower bound of the node ahead until it is passed (the blend of a
        level-to-descent knee at an 'at or above' fix would otherwise cut below it), and its
        corners at constrained fixes are moved clear of their windows
        (:func:`knees_clear_of_windows`; ``coded_angle``: per node, the piece ending there is
        on a coded vertical angle and keeps it)
    """
    w_m = gs_mps * BLEND_S
    bs, bh = (knees_clear_of_windows(prof_s, prof_h, climb_tgt, windows, w_m, coded_angle)
              if windows else (prof_s, prof_h))
    h, dh, ddh = blended_profile(bs, bh, s_path_m, w_m, approach)
    jn = bisect.bisect_right(prof_s, s_path_m)
    if windows is not None and 0 < jn < len(windows) and climb_tgt[jn] is None:
        # the blend of a knee at an 'at or above' (or 'at') fix ahead never cuts below it
        lo = windows[jn][0]
        if lo is not None and h < lo:
            h, dh, ddh = lo, 0.0, 0.0
    v_lead = gs_mps if lead_speed_mps is None else lead_speed_mps
    alt_cmd = h + lead_s * v_lead * dh + t2_s2 * gs_mps * gs_mps * ddh
    if 0 < jn < len(prof_s) and climb_tgt[jn] is not None:
        # climb: to the target of the node ahead at the law's rate — never above it, so an
        # 'at or below' cap holds until its fix is passed (the profile's read-ahead and blend
        # would lift it early)
        alt_cmd = min(climb_tgt[jn], top_m)
    return alt_cmd
