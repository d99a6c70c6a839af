"""Planned speed along an approach: the deceleration segments of the VNAV profile.

An approach is flown at the aircraft's planned approach CAS (clean), slowed by every coded
'at' / 'at or below' speed limit (which then holds for the rest of the approach, as in
descent), and from the final approach fix (FAF: waypoint description code col. 43 'F') to the
missed-approach point at the final approach speed Vapp, configured for landing. The planned
CAS at every profile node is found by a backward pass that lets the aircraft slow at the
planned deceleration ``a`` (true airspeed, constant along the ground)::

    V_j = min(cap_j, sqrt(V_{j+1}² + 2 a (s_{j+1} − s_j)))     (TAS at the planned altitudes)

and where a node's cap binds, a deceleration segment starts ``(V_j² − V_{j+1}²) / 2a`` before
the next node (a node is inserted there): the aircraft holds its speed, then slows at ``a`` to
reach the next speed at the next node. The missed approach (from its first leg on) is not
planned here: guidance flies the go-around speeds (:mod:`fms_testbed.guidance.speed_plan`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fms_testbed.core.atmosphere import cas_to_tas_scalar, tas_to_cas


@dataclass(frozen=True)
class Deceleration:
    """One deceleration segment: from ``start_m`` to ``end_m`` along the path (m), from
    ``cas_from_mps`` to ``cas_to_mps`` (m/s)."""

    start_m: float
    end_m: float
    cas_from_mps: float
    cas_to_mps: float


@dataclass(frozen=True)
class SpeedProfile:
    """Planned CAS along the path up to the missed-approach point.

    along_m / cas_mps: node distances (m, the vertical profile's nodes plus the start of every
    deceleration segment) and the planned CAS there (m/s; between two nodes V² varies linearly:
    constant deceleration); vapp_cas_mps: the final approach speed planned with (m/s);
    faf_m / map_m: distance of the FAF and the missed-approach point along the path, m (None:
    not coded); decelerations: the deceleration segments.
    """

    along_m: np.ndarray
    cas_mps: np.ndarray
    vapp_cas_mps: float
    faf_m: float | None
    map_m: float
    decelerations: tuple[Deceleration, ...]

    def cas_at(self, s_m: float, vapp_cas_mps: float | None = None) -> float:
        """Planned CAS at path distance ``s_m`` (m), m/s (past the missed-approach point: the
        speed planned there, the landing goes on at it; the missed approach has its own
        speeds). ``vapp_cas_mps``: the Vapp of the actual mass (m/s; default the planned one):
        flown from the FAF on, never below it before."""
        v2 = float(np.interp(s_m, self.along_m, self.cas_mps ** 2))
        v = math.sqrt(max(v2, 0.0))
        if vapp_cas_mps is None or vapp_cas_mps == self.vapp_cas_mps:
            return v
        if self.faf_m is not None and s_m >= self.faf_m:
            return vapp_cas_mps
        return max(v, vapp_cas_mps) if v > self.vapp_cas_mps + 0.5 else vapp_cas_mps


def faf_leg_index(records) -> int | None:
    """Index of the leg that ends at the final approach fix (waypoint description col. 43
    'F'), None when no fix is coded as the FAF."""
    for k, r in enumerate(records):
        if r.desc[3:4] == "F" and not r.missed_approach_start:
            return k
    return None


def _cas_caps(recs, m_end: int, faf: int | None, clean_cas_mps: float,
              vapp_cas_mps: float) -> np.ndarray:
    """The CAS each node may be planned at before decelerations, m/s: the clean speed under
    every 'at' / 'at or below' limit coded so far (held for the rest of the approach), Vapp
    from the FAF on (else at the missed-approach point), never below Vapp."""
    cap = np.full(len(recs) + 1, float(clean_cas_mps))
    carry = math.inf
    for k, r in enumerate(recs[:m_end]):
        if r.speed_limit_mps and r.speed_desc in ("", "@", "-"):
            carry = min(carry, r.speed_limit_mps)
            cap[k] = min(cap[k], carry)       # the leg is flown at its limit...
        cap[k + 1] = min(cap[k + 1], carry)   # ...and it holds for the rest of the approach
    if faf is not None:
        cap[faf + 1:m_end + 1] = np.minimum(cap[faf + 1:m_end + 1], vapp_cas_mps)
    else:   # no FAF coded: Vapp at the missed-approach point
        cap[m_end] = min(cap[m_end], vapp_cas_mps)
    return np.maximum(cap, vapp_cas_mps)       # never planned below Vapp


def plan_speed_profile(path, along_m: np.ndarray, alt_m: np.ndarray, clean_cas_mps: float,
                       vapp_cas_mps: float, decel_mps2: float) -> SpeedProfile:
    """The planned CAS of an approach (module docstring).

    Parameters
    ----------
    path : the built approach (``ProcedurePath``; its leg records give the FAF, the missed
        approach start and the coded speed limits)
    along_m, alt_m : the vertical profile's nodes (m along the path) and planned altitudes, m
        (node k + 1 is the end of leg k)
    clean_cas_mps : planned CAS before any limit (the approach speed, clean), m/s
    vapp_cas_mps : final approach speed, m/s
    decel_mps2 : planned deceleration (true airspeed), m/s²
    """
    recs = [lg.record for lg in path.legs]
    m_end = next((k for k, r in enumerate(recs) if r.missed_approach_start), len(recs))
    faf = faf_leg_index(recs[:m_end])
    cap = _cas_caps(recs, m_end, faf, clean_cas_mps, vapp_cas_mps)
    s = np.asarray(along_m[:m_end + 1], dtype=float)
    h = np.asarray(alt_m[:m_end + 1], dtype=float)
    cas = cap[:m_end + 1].copy()
    nodes_s, nodes_c = [float(s[-1])], [float(cas[-1])]
    decs = []
    for j in range(m_end - 1, -1, -1):
        ds = s[j + 1] - s[j]
        vt_next = cas_to_tas_scalar(cas[j + 1], h[j + 1])
        reach = math.sqrt(vt_next ** 2 + 2.0 * decel_mps2 * ds)
        cas[j] = min(cas[j], float(tas_to_cas(reach, h[j])))
        if cas[j] > cas[j + 1] + 0.05:
            # TAS at the start of the deceleration (interpolated altitude: the first guess at
            # the node's own is close; the distance is then refined once)
            d = ds
            for _ in range(2):
                a = float(np.interp(s[j + 1] - d, s, h))
                vt0 = cas_to_tas_scalar(cas[j], a)
                d = min(max(vt0 ** 2 - vt_next ** 2, 0.0) / (2.0 * decel_mps2), ds)
            start = s[j + 1] - d
            if start > s[j] + 1.0:
                nodes_s.append(float(start))
                nodes_c.append(float(cas[j]))
            decs.append(Deceleration(float(start), float(s[j + 1]), float(cas[j]),
                                     float(cas[j + 1])))
        nodes_s.append(float(s[j]))
        nodes_c.append(float(cas[j]))
    nodes_s.reverse()
    nodes_c.reverse()
    ns, ncas = np.array(nodes_s), np.array(nodes_c)
    dec = tuple(reversed(decs))
    return SpeedProfile(ns, ncas, float(vapp_cas_mps),
                        float(s[faf + 1]) if faf is not None else None, float(s[-1]), dec)


__all__ = ["Deceleration", "SpeedProfile", "faf_leg_index", "plan_speed_profile"]
