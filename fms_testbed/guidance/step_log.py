"""The per-step log of procedure guidance: one record with units, the columns
:mod:`fms_testbed.evaluation.flight_errors` reads.

``xtk_m`` true cross-track (TSE), ``nav_xtk_m`` navigation cross-track (FTE), ``leg_index``
(whole procedure), ``leg_code``, ``seg_role``, ``along_m`` path distance along the whole
flight, ``curvature_1pm`` of the piece, ``straight_m`` distance to the nearest curvature change
on straight flight (0 on arcs), ``heading_leg`` (1 on the straight part of a V* leg), ``pde_m``
of the segment (NaN where undefined), ``rnp_m`` of the leg.
"""

from __future__ import annotations

import math

from fms_testbed.guidance.active_path import ActivePath
from fms_testbed.guidance.geometry import LocalPiece
from fms_testbed.guidance.steering import flies_heading


def log_row(a: ActivePath, p: LocalPiece, along_m: float, nav_xtk_m: float, true_xtk_m: float,
            seg, leg: int, s_path_m: float) -> dict:
    """One log record (module docstring).

    Parameters
    ----------
    a : the active path; p : the piece flown, of segment ``seg``; along_m : distance along the
        piece, m; nav_xtk_m / true_xtk_m : navigation / true cross-track, m; leg : whole-
        procedure leg index; s_path_m : distance along the active path, m
    """
    s_seg = p.s0_m + along_m
    b, f = a.flat_m[p.seg_index]
    flat = 0.0 if p.is_arc else min(
        b + s_seg, f + a.segs[p.seg_index].geom.length_m() - s_seg)
    return {"xtk_m": true_xtk_m, "nav_xtk_m": nav_xtk_m, "leg_index": leg,
            "leg_code": seg.path_term, "seg_role": seg.role,
            "along_m": a.s_base_m + s_path_m,
            "curvature_1pm": p.curvature_1pm, "straight_m": flat,
            "heading_leg": int(flies_heading(seg, p)),
            "pde_m": a.pde_m[p.seg_index], "rnp_m": a.fp.rnp_m[seg.leg_index]
            if seg.leg_index < len(a.fp.rnp_m) else math.nan}
