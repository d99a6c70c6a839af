"""Path post-processing: from a built procedure to the path guidance flies, with what it reads.

The built path (:class:`~fms_testbed.path.plan.FlyablePath`) becomes the flown-for path:

* segments too short to fly are dropped (bridges under :data:`MIN_CONNECTOR_M`, others under
  :data:`MIN_SEGMENT_M`): the lateral law absorbs a gap that small (:func:`smooth_connectors`);
  a bridge over a discontinuity (after vectors, VM/FM) is already built by the builder as it is
  flown — a direct-to, with the fly-by at its end rounded like any other corner;
* after an in-flight rebuild, a straight run-in from the aircraft to the rebuilt path's start is
  put first (role 'leg' of the first rebuilt leg, so a heading leg keeps its heading; no PDE).

:func:`activate` then precomputes, once per path, what every guidance step reads: the local-plane
pieces (:mod:`.geometry`), each segment's start distance, its PDE (:mod:`.pde`), the straight
run before and after it, the vertical profile's nodes and climb targets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from fms_testbed.core.segments import Line
from fms_testbed.guidance.geometry import LocalPiece, local_pieces
from fms_testbed.guidance.pde import path_pde_m
from fms_testbed.guidance.vertical import climb_targets
from fms_testbed.path.plan import FlyablePath

MIN_SEGMENT_M = 1.0
"""Segments shorter than this are not flown, m."""
MIN_CONNECTOR_M = 50.0
"""Connector segments (the builder's bridges over gaps) shorter than this are not flown: their
course is meaningless and the lateral law absorbs a gap this small, m."""


@dataclass
class ActivePath:
    """The path being flown (the whole procedure, or its rest after an in-flight rebuild).

    fp: the built procedure; segs: its flown-for segments; pieces: their local-plane pieces;
    seg_cum_m: path distance at each segment's start, m; pde_m: each segment's PDE, m (NaN where
    undefined); flat_m: (straight run before, after) each segment, m (0 on arcs); prof_s /
    prof_h: the vertical profile's node distances (m, on this path) and altitudes (m);
    climb_tgt: climb target per node (m, None outside climbs); windows: coded window per node;
    s_base_m: path distance of this
    path's start along the whole flight, m; last_piece_of_leg: leg index → its last piece.
    """

    fp: FlyablePath
    segs: list
    pieces: list[LocalPiece]
    seg_cum_m: list[float]
    pde_m: list[float]
    flat_m: list[tuple[float, float]]
    prof_s: list[float]
    prof_h: list[float]
    climb_tgt: list[float | None]
    s_base_m: float
    last_piece_of_leg: dict[int, int] = field(default_factory=dict)
    windows: list[tuple[float | None, float | None]] = field(default_factory=list)
    """Per profile node, the coded altitude window (lo, hi), m (None: unbounded)."""
    piece_legs: list[int] = field(default_factory=list)
    """Per piece, its whole-procedure leg index."""
    coded_angle: list[bool] = field(default_factory=list)
    """Per profile node, True when the profile piece ending there lies on a coded vertical
    angle (a final approach path: its corners are not moved, :func:`.vertical.knees_clear_of_windows`)."""


def smooth_connectors(segs) -> list:
    """The path as flown (module docstring): segments too short to fly dropped, the others
    unchanged — the builder already built every bridge over a discontinuity as it is flown
    (a direct-to with its turns, or a gap closed in the geometry:
    :meth:`fms_testbed.legs.builder.LegBuilder.connect`), so guidance flies exactly the
    built path the map, the profile and the monitor see.

    Parameters
    ----------
    segs : the built path's segments
    """
    out = []
    for sg in segs:
        short = MIN_CONNECTOR_M if sg.role == "connector" else MIN_SEGMENT_M
        if sg.geom.length_m() < short and len(segs) > 1:
            continue  # a tiny bridge between legs: nothing to fly (the law absorbs the gap)
        out.append(sg)
    return out


def _straight_runs_m(geoms) -> list[tuple[float, float]]:
    """Per segment: straight-flight distance from the previous and to the next curvature
    change (0 on arcs), m."""
    n = len(geoms)
    is_line = [isinstance(g, Line) for g in geoms]
    before, after = [0.0] * n, [0.0] * n
    run = 0.0
    for k in range(n):
        run = run if (k > 0 and is_line[k - 1]) else 0.0
        before[k] = run if is_line[k] else 0.0
        run = run + geoms[k].length_m() if is_line[k] else 0.0
    run = 0.0
    for k in range(n - 1, -1, -1):
        run = run if (k < n - 1 and is_line[k + 1]) else 0.0
        after[k] = run if is_line[k] else 0.0
        run = run + geoms[k].length_m() if is_line[k] else 0.0
    return list(zip(before, after))


def activate(fp: FlyablePath, s_base_m: float,
             lead_from: tuple[float, float] | None = None) -> ActivePath:
    """Post-process a built procedure and precompute what guidance reads (module docstring).

    Parameters
    ----------
    fp : the built procedure (or the rest of it, rebuilt in flight)
    s_base_m : path distance flown before this path starts, m
    lead_from : (lat_deg, lon_deg) of the aircraft when the path was rebuilt in flight: a
        straight run-in from there to the path's start is flown first
    """
    segs = smooth_connectors(list(fp.path.segments))
    pde = path_pde_m(segs, fp.path.legs)
    lead_m = 0.0
    if lead_from is not None and segs:
        # the straight run-in from the aircraft to where the rebuilt path starts
        first = segs[0]
        run_in = Line(lead_from[0], lead_from[1], *first.geom.start)
        if run_in.length_m() >= MIN_SEGMENT_M:
            segs.insert(0, replace(first, geom=run_in, role="leg"))
            pde.insert(0, math.nan)  # a transition from the aircraft, not the coded path
            lead_m = run_in.length_m()
    geoms = [s.geom for s in segs]
    pieces = local_pieces(geoms)
    cum, s = [], 0.0
    for g in geoms:
        cum.append(s)
        s += g.length_m()
    prof = fp.path.profile
    last = {}
    for i, p in enumerate(pieces):
        last[segs[p.seg_index].leg_index] = i
    wins: list[tuple[float | None, float | None]] = [(None, None)] * len(prof.along_m)
    for w in prof.windows:
        if w.leg_index + 1 < len(wins):
            wins[w.leg_index + 1] = (w.lo_m, w.hi_m)
    return ActivePath(fp, segs, pieces, cum, pde, _straight_runs_m(geoms),
                      [float(x) + lead_m for x in prof.along_m],
                      [float(x) for x in prof.alt_m], climb_targets(prof), s_base_m, last,
                      wins, [fp.leg_offset + segs[p.seg_index].leg_index for p in pieces],
                      [False] + [bool(lg.record.vpa_deg) for lg in fp.path.legs])
