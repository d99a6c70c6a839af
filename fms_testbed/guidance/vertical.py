"""Vertical guidance: the planned profile and the coded speed limits become targets for the
coupled law (altitude and true airspeed), within the aircraft's performance.

Altitude: the planned profile (``arinc424.profile.VerticalProfile``, which already climbs at the
aircraft's gradient, levels off under 'at or below' constraints and descends at the coded or
3° angle into each window) read ahead of the aircraft by the law's ramp lag::

    H_cmd = H_plan(s + V_g τ_H),    τ_H = 2 ξ_H T_H

(a second-order altitude loop follows a ramp with a lag of 2 ξ_H T_H; reading the plan that far
ahead removes it). Speed is also capped ahead of arcs too tight for the planned TAS within the
bank limit (``fms.ProcedureGuidance._arc_speed_cap``). In a climb phase (SID, missed approach) the target is instead the top of the
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

from dataclasses import dataclass

from ..atmosphere import cas_to_tas

KT_MPS = 1852.0 / 3600.0
MIN_CAS_FACTOR = 1.15
"""The TAS target never gives a CAS below this multiple of the aircraft's minimum clean CAS
(the planned TAS is constant, so high in a SID or STAR the CAS would otherwise fall toward the
stall)."""
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
                   hi_cas_mps: float | None, cas_min_mps: float) -> float:
    """TAS target, m/s: the planned TAS moved into the allowed CAS band at altitude ``alt_m``
    (ISA conversion), never below MIN_CAS_FACTOR × ``cas_min_mps``."""
    v = tas_plan_mps
    if hi_cas_mps is not None:
        v = min(v, float(cas_to_tas(hi_cas_mps, alt_m)))
    if lo_cas_mps is not None:
        v = max(v, float(cas_to_tas(lo_cas_mps, alt_m)))
    return max(v, float(cas_to_tas(MIN_CAS_FACTOR * cas_min_mps, alt_m)))


def altitude_lead_s(cfg) -> float:
    """Read-ahead time of the altitude plan, 2 ξ_H T_H of the aircraft's coupled law, s."""
    g = cfg.coupled_law
    return 2.0 * g.xi_H * g.T_H_s if g is not None else 10.0


LAW_CLIMB_FRACTION = 1.0
"""The coupled law's level-change rate is set to this fraction of the aircraft's sustained
climb rate (above the planned rate, so the law can catch up with the plan)."""


def procedure_law(cfg):
    """The coupled law for procedure flights: the aircraft's tuning with the level-change
    altitude-error limit raised so that its climb rate ``dH_limit / (2 ξ_H T_H)`` is
    LAW_CLIMB_FRACTION × ``limits.climb_rate_max_mps`` (never below the configured limit)."""
    from ..control import CoupledLaw, params_from_config

    g = cfg.coupled_law
    dh = max(g.dH_limit_m, LAW_CLIMB_FRACTION * cfg.limits.climb_rate_max_mps
             * 2.0 * g.xi_H * g.T_H_s)
    return CoupledLaw(params=params_from_config(cfg, dH_limit_m=dh))
