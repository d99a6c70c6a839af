"""The log of procedure guidance: the columns :mod:`fms_testbed.evaluation.flight_errors` reads,
declared once with their units (:data:`LOG_COLUMNS`).

In flight guidance keeps, per logged step, only where it located the aircraft, as a tuple of
numbers (:func:`record`: which active path, which piece, along- and cross-track, leg); the
columns are computed after the flight (:func:`log_frame`), so the outer step builds no record. The true cross-track (TSE) is computed there from the true
positions the flight loop logged: guidance never reads the true state in flight.
"""

from __future__ import annotations

import math

import numpy as np

from fms_testbed.guidance.active_path import ActivePath
from fms_testbed.guidance.locate import Where
from fms_testbed.guidance.steering import flies_heading

LOG_COLUMNS: tuple[tuple[str, str], ...] = (
    ("xtk_m", "true cross-track from the path flown (TSE), right positive, m"),
    ("nav_xtk_m", "navigation cross-track from the path flown (FTE), right positive, m"),
    ("leg_index", "whole-procedure index of the leg flown"),
    ("leg_code", "path terminator of the segment flown"),
    ("seg_role", "role of the segment flown (leg, turn, flyby, hold, connector)"),
    ("along_m", "path distance along the whole flight, m"),
    ("curvature_1pm", "curvature of the piece flown, 1/m (+ right)"),
    ("straight_m", "distance to the nearest curvature change on straight flight, m (0 on arcs)"),
    ("heading_leg", "1 on the straight part of a heading leg (V*), else 0"),
    ("pde_m", "path definition error of the segment flown, m (NaN where undefined)"),
    ("rnp_m", "RNP of the leg flown, m"),
)
"""``(column, description with unit)`` of the guidance log, in this order."""


def record(path_index: int, w: Where) -> tuple:
    """The log record of the aircraft at ``w`` on the ``path_index``-th active path: (path
    index, piece index, along the piece m, navigation cross-track m, whole-procedure leg)."""
    return (path_index, w.i, w.along_m, w.xtk_m, w.leg)


def log_values(a: ActivePath, rec: tuple, true_lat_rad: float, true_lon_rad: float) -> tuple:
    """The :data:`LOG_COLUMNS` values of one logged step: its record ``rec`` on active path
    ``a`` (:func:`record`) and the true position ``true_lat_rad``, ``true_lon_rad`` (rad)."""
    _, i, along_m, xtk_m, leg = rec
    p = a.pieces[i]
    seg = a.segs[p.seg_index]
    _, true_xtk, _ = p.project(true_lat_rad, true_lon_rad)
    s_path = a.seg_cum_m[p.seg_index] + p.s0_m + along_m
    s_seg = p.s0_m + along_m
    b, f = a.flat_m[p.seg_index]
    flat = 0.0 if p.is_arc else min(b + s_seg, f + seg.geom.length_m() - s_seg)
    rnp = a.fp.rnp_m[seg.leg_index] if seg.leg_index < len(a.fp.rnp_m) else math.nan
    return (true_xtk, xtk_m, leg, seg.path_term, seg.role, a.s_base_m + s_path,
            p.curvature_1pm, flat, int(flies_heading(seg, p)), a.pde_m[p.seg_index], rnp)


def log_frame(paths: list[ActivePath], records: list[tuple | None], true_lat_rad: np.ndarray,
              true_lon_rad: np.ndarray) -> dict[str, list]:
    """The :data:`LOG_COLUMNS` of the logged steps: ``records`` (one :func:`record` per row on
    the active paths ``paths``, None where guidance located nothing: NaN) and the true position
    of each row, ``true_lat_rad``, ``true_lon_rad`` (rad)."""
    nan_row = (math.nan,) * len(LOG_COLUMNS)
    rows = [nan_row if r is None else log_values(paths[r[0]], r, float(la), float(lo))
            for r, la, lo in zip(records, true_lat_rad, true_lon_rad)]
    return {name: [r[j] for r in rows] for j, (name, _) in enumerate(LOG_COLUMNS)}


__all__ = ["LOG_COLUMNS", "log_frame", "log_values", "record"]
