"""Re-planning: the rest of the procedure rebuilt from the aircraft's state when a conditional
leg ends in flight.

An altitude, DME or radial leg ends where the aircraft meets its condition, not where the plan
assumed (:mod:`.sequencing`). The legs after it are then built again by the same builder and
monitor (:func:`fms_testbed.path.plan.rebuild_from`) from a start one roll-in anticipation
ahead on the present track, so the first turn's roll is centred on its start as for any planned
turn; DF legs whose fix is already behind are skipped first (:func:`passed_direct_legs`).
"""

from __future__ import annotations

import math

from fms_testbed.core.geodesy import direct
from fms_testbed.guidance.lateral import LateralGains, anticipation_m
from fms_testbed.guidance.sequencing import direct_fix_passed
from fms_testbed.path.plan import FlyablePath, rebuild_from

PLANNED_BANK_DEG = 20.0
"""The builder's planned bank: sets the roll-in anticipation of the rebuilt start, deg."""


def passed_direct_legs(whole: FlyablePath, first: int, lat_rad: float, lon_rad: float,
                       track_rad: float, tas_mps: float) -> list[int]:
    """Indices ``first, first + 1, ...`` of the consecutive DF legs whose fix is already passed
    (:func:`~.sequencing.direct_fix_passed`) at the navigation position (rad), track (rad) and
    planned speed (m/s)."""
    out = []
    k = first
    legs = whole.path.legs
    while k < len(whole.seq.legs) and k < len(legs) and \
            direct_fix_passed(legs[k], lat_rad, lon_rad, track_rad, tas_mps):
        out.append(k)
        k += 1
    return out


def rebuild_rest(db, whole: FlyablePath, spec, cfg, gains: LateralGains, next_leg: int,
                 lat_rad: float, lon_rad: float, track_rad: float, alt_m: float
                 ) -> FlyablePath | None:
    """Legs ``next_leg..`` of the procedure built from the aircraft's state (module docstring).

    Parameters
    ----------
    db, whole, spec, cfg : the database, the whole built procedure, its spec and the aircraft
    gains : lateral tuning (roll rate for the anticipation distance)
    next_leg : first leg to build (index in the whole procedure)
    lat_rad, lon_rad, track_rad, alt_m : navigation position (rad), ground track (rad true),
        altitude (m)

    Returns
    -------
    The rebuilt rest, or None when there is no database to build from, nothing is left or the
    rest cannot be built.
    """
    v = cfg.limits.climb_tas_mps
    lead = anticipation_m(v, math.radians(PLANNED_BANK_DEG), gains)
    la, lo, _ = direct(math.degrees(lat_rad), math.degrees(lon_rad), math.degrees(track_rad),
                       lead)
    if db is None or spec is None:
        return None
    return rebuild_from(db, whole, spec, cfg, next_leg, la, lo,
                        math.degrees(track_rad) % 360.0, alt_m)
