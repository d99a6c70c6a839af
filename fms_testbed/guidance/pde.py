"""PDE scoring: the path definition error of each segment of the path guidance flies.

PDE (RNP, ICAO Doc 9613) is the distance of the path flown for — the built path after
guidance's post-processing (:mod:`.active_path`) — from the path the database codes. Each
:class:`~fms_testbed.legs.model.BuiltLeg` carries its coded path (built by its leg class,
:mod:`fms_testbed.legs.coded`); a segment's PDE is the largest distance of
:data:`PDE_POINTS` points spread evenly over it (ends included) from that coded path, m.

PDE is NaN by design, never by an error, where no coded path applies: on segments that are
transitions rather than the leg's own path (fly-by arcs, turns and intercepts onto a leg,
connectors, the run-in to a rebuilt path: roles other than :data:`SCORED_ROLES`) and on legs
whose type codes no path (``pde_reference is None``: IF, DF, PI, the C*/V* courses and
headings from the present position) or whose record lacks a field the path needs.
"""

from __future__ import annotations

import math

from fms_testbed.legs.coded import path_definition_error_m
from fms_testbed.legs.model import BuiltLeg, PathSegment

PDE_POINTS = 5
"""Points per segment at which the distance from the coded path is evaluated."""
SCORED_ROLES = ("leg", "hold")
"""Segment roles that are a leg's own path (the rest are transitions onto it)."""


def segment_pde_m(seg: PathSegment, leg: BuiltLeg) -> float:
    """Path definition error of one segment of leg ``leg``, m (NaN where undefined: module
    docstring)."""
    if seg.role not in SCORED_ROLES or leg.coded is None:
        return math.nan
    g = seg.geom
    n = PDE_POINTS - 1
    pts = [g.point_at(g.length_m() * k / n) for k in range(PDE_POINTS)]
    return path_definition_error_m(leg.coded, pts)


def path_pde_m(segs: list[PathSegment], legs: tuple[BuiltLeg, ...]) -> list[float]:
    """PDE of every segment of a flown path (``segs`` tagged with indices into ``legs``), m."""
    return [segment_pde_m(s, legs[s.leg_index]) for s in segs]
