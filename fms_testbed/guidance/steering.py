"""The lateral law applied to the active path: from the piece flown to a bank command.

On the straight part of a heading leg (V*) the coded heading — the built line's direction — is
held (:func:`~.lateral.heading_hold_bank_rad`) and the wind drifts the track; everywhere else
the path-following law (:func:`~.lateral.bank_command_rad`) flies the ground track with the
curvature fed forward (:func:`feedforward_curvature_1pm`): the curvature of the piece flown,
switched to the next piece's once inside the roll anticipation distance, with a triangular bank
profile on arcs too short to reach their bank.
"""

from __future__ import annotations

import math

from fms_testbed.core.units import G0_MPS2
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.guidance.lateral import (LateralGains, anticipation_m, bank_command_rad,
                                          heading_hold_bank_rad, wrap_pi)
from fms_testbed.legs.model import PathSegment
from fms_testbed.legs.types import LEG_TYPES


def flies_heading(seg: PathSegment, p: LocalPiece) -> bool:
    """True on the straight part of a heading leg's own path (V*, role 'leg'): a heading is
    held there, and the track has no defined path (no FTE/TSE)."""
    return LEG_TYPES[seg.path_term].heading_leg and seg.role == "leg" and not p.is_arc


def _short_arc_curvature(q: LocalPiece | None, d0_m: float, gs_mps: float,
                         gains: LateralGains) -> float | None:
    """Triangle-profile curvature (1/m) if ``q`` is an arc too short to reach its bank
    (``L p < V_g |φ|``), else None; ``d0_m``: distance to its start, m."""
    if q is None or not q.is_arc:
        return None
    pr = math.radians(gains.roll_rate_dps)
    v2 = max(gs_mps, 10.0) ** 2
    phi = abs(math.atan(v2 * q.curvature_1pm / G0_MPS2))
    if q.length_m * pr >= gs_mps * phi:
        return None
    t_pk = math.sqrt(q.length_m * abs(q.curvature_1pm) * gs_mps * pr / G0_MPS2)
    mid = d0_m + 0.5 * q.length_m
    lag = gs_mps * gains.roll_lag_s
    on, off = mid - gs_mps * math.atan(t_pk) / pr - lag, mid - lag
    return math.copysign(t_pk * G0_MPS2 / v2, q.curvature_1pm) if on <= 0.0 < off else 0.0


def feedforward_curvature_1pm(p: LocalPiece, along_m: float, nxt: LocalPiece | None,
                              gs_mps: float, gains: LateralGains) -> float:
    """Curvature (1/m) whose coordinated-turn bank is fed forward now.

    The curvature of the piece flown, switched to the next piece's once within the roll
    anticipation distance ``V_g (|Δφ|/(2 p) + τ)`` of the boundary
    (:func:`.lateral.anticipation_m`: the loop's rate-limited roll is centred on the
    transition). An arc too short to reach its bank (``L p < V_g |φ|``) gets instead a
    triangular bank profile with the same heading change, peak
    ``tan φ_pk = sqrt(|Δχ| V_g p / g)``, commanded from ``V_g (φ_pk / p + τ)`` before the
    arc's middle to ``V_g τ`` before it.

    Parameters
    ----------
    p : the piece flown; along_m : distance along it, m; nxt : the piece after it (None at the
        end, or while a conditional leg is flown on past its plan); gs_mps : ground speed, m/s;
    gains : lateral tuning (roll rate, deg/s; roll lag, s)
    """
    v2 = max(gs_mps, 10.0) ** 2
    k = _short_arc_curvature(p, -along_m, gs_mps, gains)
    kappa = p.curvature_1pm if k is None else k
    if nxt is None:
        return kappa
    k = _short_arc_curvature(nxt, p.length_m - along_m, gs_mps, gains)
    if k is not None:
        return k if k != 0.0 else kappa
    k2 = nxt.curvature_1pm
    if k2 != kappa:
        dphi = math.atan(v2 * k2 / G0_MPS2) - math.atan(v2 * kappa / G0_MPS2)
        if p.length_m - along_m < anticipation_m(gs_mps, dphi, gains):
            return k2
    return kappa


def steer_bank_rad(seg: PathSegment, p: LocalPiece, along_m: float, xtk_m: float,
                   desired_track_rad: float, nxt: LocalPiece | None, track_rad: float,
                   heading_rad: float, gs_mps: float, gains: LateralGains,
                   heading_kp: float) -> float:
    """Bank command for the piece flown, rad (+ right; module docstring).

    Parameters
    ----------
    seg, p : the segment and its piece flown; along_m, xtk_m : position on the piece, m;
    desired_track_rad : the piece's track at the foot point, rad true; nxt : the piece after
        it (see :func:`feedforward_curvature_1pm`); track_rad, heading_rad : navigation ground
        track and heading, rad true; gs_mps : ground speed, m/s; gains : lateral tuning;
    heading_kp : heading-hold gain, rad of bank per rad of heading error
    """
    kappa = feedforward_curvature_1pm(p, along_m, nxt, gs_mps, gains)
    if flies_heading(seg, p) and kappa == 0.0:
        # a heading leg (V*): hold the coded heading (the built line is the ground track it
        # gives in the planned wind) and let the actual wind drift the track; the leg still
        # ends at its condition/planned distance
        # the heading is held relative to the line's local direction (the planned drift,
        # heading − track, kept): on a long heading leg a constant true heading would leave
        # the geodesic as its azimuth turns (1 km over 150 km)
        drift = 0.0 if seg.heading_deg is None else math.radians(
            ((seg.heading_deg - seg.geom.start_course_deg + 180.0) % 360.0) - 180.0)
        hdg = desired_track_rad + drift
        return heading_hold_bank_rad(hdg, heading_rad, heading_kp,
                                     math.radians(gains.bank_max_deg))
    return bank_command_rad(xtk_m, wrap_pi(track_rad - desired_track_rad), gs_mps, kappa, gains)
