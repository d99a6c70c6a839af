"""Locating the aircraft on the active path: the navigation position projected on the piece flown.

The projection is the piece's local-plane one (:meth:`.geometry.LocalPiece.project`, mid-latitude
equirectangular about the piece's origin): along-piece distance, cross-track (right of the path
positive) and the desired track at the foot point; the ground speed and track come from the
navigation solution's ENU ground velocity, ``V_g = √(v_e² + v_n²)``, ``χ = atan2(v_e, v_n)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.state import NavSolution
from fms_testbed.guidance.active_path import ActivePath
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.legs.model import BuiltLeg, PathSegment


@dataclass(slots=True)
class Where:
    """The aircraft on the active path (navigation solution); treat as immutable.

    Attributes
    ----------
    act : the active path; i : index of the piece flown in ``act.pieces``
    p : that piece, of segment ``seg`` of built leg ``built``
    along_m, xtk_m : along the piece (from its start) and cross-track (right positive), m
    dtrk_rad : the piece's desired track at the foot point, rad true
    gs_mps, trk_rad : navigation ground speed (m/s) and ground track (rad true)
    leg : whole-procedure index of the leg flown
    """

    act: ActivePath
    i: int
    p: LocalPiece
    seg: PathSegment
    built: BuiltLeg
    along_m: float
    xtk_m: float
    dtrk_rad: float
    gs_mps: float
    trk_rad: float
    leg: int

    @property
    def s_path_m(self) -> float:
        """Distance along the active path, m."""
        return self.act.seg_cum_m[self.p.seg_index] + self.p.s0_m + self.along_m

    @property
    def s_flight_m(self) -> float:
        """Distance along the whole flight (paths flown before a rebuild included), m."""
        a = self.act
        return a.s_base_m + a.seg_cum_m[self.p.seg_index] + self.p.s0_m + self.along_m

    @property
    def last_piece_of_leg(self) -> bool:
        """True on the last piece of the leg flown."""
        return self.i == self.act.last_piece_of_leg[self.seg.leg_index]

    @property
    def next_piece(self) -> LocalPiece | None:
        """The piece after this one (None at the end of the path)."""
        pieces = self.act.pieces
        return pieces[self.i + 1] if self.i + 1 < len(pieces) else None


def locate(act: ActivePath, i: int, nav: NavSolution) -> Where:
    """The navigation position on piece ``i`` of the active path ``act`` (module docstring)."""
    v = nav.v_enu_mps
    ve, vn = float(v[0]), float(v[1])
    p = act.pieces[i]
    along, xtk, dtrk = p.project(nav.lat_rad, nav.lon_rad)
    seg = act.segs[p.seg_index]
    return Where(act, i, p, seg, act.fp.path.legs[seg.leg_index], along, xtk, dtrk,
                 math.hypot(ve, vn), math.atan2(ve, vn), act.fp.leg_offset + seg.leg_index)


__all__ = ["Where", "locate"]
