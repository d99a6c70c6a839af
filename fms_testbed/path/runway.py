"""The runway an approach leads to: threshold position, elevation, threshold crossing height
(TCH) and the coded vertical path angle (VPA), with the airport's elevation.

The threshold is the runway record (PG) of the missed-approach point when the MAP is the
runway fix (as RNAV and ILS approaches are coded), else the runway named by the approach
ident (``I16R``, ``R16RY``, ``V26`` → RW16R, RW16R, RW26); circling-only approaches
(``VOR-A``) have none. TCH: the runway record (cols. 76-77); where the MAP is the runway fix
and codes an 'at' altitude, that altitude minus the threshold elevation (the coded TCH of the
approach). VPA: the vertical angle coded on the MAP record, else on the FAF's.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from fms_testbed.path.speed_profile import faf_leg_index


@dataclass(frozen=True)
class ApproachRunway:
    """Where an approach ends.

    ident: runway ident ('RW16R'); lat_deg / lon_deg: threshold (landing threshold point),
    deg; elev_m: threshold elevation, m; tch_m: threshold crossing height, m (None: not coded);
    vpa_deg: coded vertical path angle, deg, positive (None: not coded); map_is_threshold:
    the missed-approach point is this runway's threshold; map_leg: index of the MAP leg in the
    sequence; airport_elev_m: airport reference elevation, m (None: no airport record).
    """

    ident: str
    lat_deg: float
    lon_deg: float
    elev_m: float | None
    tch_m: float | None
    vpa_deg: float | None
    map_is_threshold: bool
    map_leg: int
    airport_elev_m: float | None


_RWY = re.compile(r"^[A-Z](\d{2}[LRC]?)")


def runway_of_ident(proc_id: str) -> str | None:
    """'RWnn[LRC]' named by an approach ident, None for a circling approach ('VOR-A')."""
    m = _RWY.match(proc_id)
    return f"RW{m.group(1)}" if m else None


def map_leg_index(legs) -> int:
    """Index of the missed-approach point's leg: the one before the first missed-approach
    leg (the last leg when no missed approach is coded)."""
    k = next((i for i, r in enumerate(legs) if r.missed_approach_start), len(legs))
    return max(k - 1, 0)


def approach_runway(db, seq) -> ApproachRunway | None:
    """The runway of approach sequence ``seq`` in database ``db`` (module docstring); None
    for a non-approach or when no threshold record is found."""
    if seq.proc_type != "F" or not seq.legs:
        return None
    legs = seq.legs
    k = map_leg_index(legs)
    rec = legs[k]
    thr = None
    on_rwy = rec.fix is not None and rec.fix.section == "PG"
    if on_rwy:
        thr = db.find_fix(rec.fix, seq.airport)
    if thr is None or thr.section != "PG":
        ident = runway_of_ident(seq.proc_id)
        cands = db.terminal.get((seq.airport, ident), []) if ident else []
        thr = next((f for f in cands if f.section == "PG"), None)
        on_rwy = False
    if thr is None:
        return None
    tch = thr.tch_m
    if on_rwy and rec.alt_desc in ("", "@") and rec.alt1_m is not None and \
            thr.elev_m is not None:
        tch = rec.alt1_m - thr.elev_m
    vpa = rec.vpa_deg
    if not vpa:
        f = faf_leg_index(legs)
        vpa = legs[f].vpa_deg if f is not None else None
    apt = db.airports.get(seq.airport)
    return ApproachRunway(thr.ident, thr.lat_deg, thr.lon_deg, thr.elev_m, tch,
                          abs(vpa) if vpa else None, on_rwy, k,
                          apt.elev_m if apt is not None else None)


def terrain_elevation_m(db, seq) -> float:
    """Terrain elevation a flight of ``seq`` is flown over, m: for an approach its runway
    threshold's elevation (height above the terrain is then height above the threshold: at
    Denver the airport reference elevation is 5,434 ft but the RW16R threshold 5,322 ft, so
    its 55 ft TCH would lie under the airport elevation), otherwise the airport's reference
    elevation (CIFP airport record), else 0 (mean sea level)."""
    if db is None:
        return 0.0
    rw = approach_runway(db, seq)
    if rw is not None and rw.elev_m is not None:
        return float(rw.elev_m)
    apt = db.airports.get(seq.airport)
    if apt is not None and apt.elev_m is not None:
        return float(apt.elev_m)
    return 0.0


__all__ = ["ApproachRunway", "approach_runway", "map_leg_index", "runway_of_ident",
           "terrain_elevation_m"]
