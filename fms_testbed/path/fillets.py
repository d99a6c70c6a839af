"""Fly-by fillets between a straight and a coded arc, both ways, on WGS-84.

A fly-by corner between a line and an arc (a CI/VI onto a DME arc, a non-tangent RF entry: line
→ arc; a CF, TF or DF leaving an RF/AF end fix the other way: arc → line) is rounded by a
circle of radius r = V²/(g tan γ) tangent to both: internally when both turn the same way
(|F − C| = R − r), externally otherwise (|F − C| = R + r), solved in the azimuthal-equidistant
plane about the junction and then made exact on the ellipsoid (the contact point put on the coded
arc, the fillet retargeted onto the radial through it). The arc → line case is the line → arc
case flown backwards: both segments are reversed, filleted, and the result reversed again, so
one construction serves both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fms_testbed.core.geodesy import LocalFrame, direct, inverse, wrap180, wrap360
from fms_testbed.core.segments import Arc, Line
from fms_testbed.legs.construct import turn_arc


@dataclass(frozen=True, slots=True)
class Fillet:
    """A rounded line/arc corner, in flying order.

    line: the straight, trimmed at the contact point (None when nothing of it is left);
    fillet: the fly-by arc; gap: a bridge of millimetres between the fillet and the coded arc
    (None when they meet); arc: the coded arc, trimmed at its contact point; lead_m: distance
    from the corner to the contact point on the straight, m.
    """

    line: Line | None
    fillet: Arc
    gap: Line | None
    arc: Arc
    lead_m: float


def reverse_arc(arc: Arc) -> Arc:
    """The same arc flown the other way (from its end to its start)."""
    return Arc(arc.centre_lat_deg, arc.centre_lon_deg, arc.radius_m, arc.end_radial_deg,
               -arc.sweep_deg)


def reverse_line(line: Line) -> Line:
    """The same geodesic flown the other way."""
    return Line(line.end_lat_deg, line.end_lon_deg, line.start_lat_deg, line.start_lon_deg)


def retarget_arc(arc: Arc, pt: tuple[float, float], max_change_deg: float = 5.0) -> Arc:
    """The same arc ending on the radial through ``pt``; unchanged when that would change its
    sweep by more than ``max_change_deg`` (deg)."""
    _, az, _ = inverse(arc.centre_lat_deg, arc.centre_lon_deg, pt[0], pt[1])
    if arc.sweep_deg >= 0:
        sweep = wrap360(az - arc.start_radial_deg)
        if sweep > 359.0:
            sweep -= 360.0
    else:
        sweep = -wrap360(arc.start_radial_deg - az)
        if sweep < -359.0:
            sweep += 360.0
    if abs(sweep - arc.sweep_deg) > max_change_deg:
        return arc
    return Arc(arc.centre_lat_deg, arc.centre_lon_deg, arc.radius_m, arc.start_radial_deg, sweep)


def _geo_radial(fr: LocalFrame, arc: Arc, planar_radial_deg: float) -> float:
    """Geodesic radial from the arc centre matching a radial measured in the local plane."""
    cx, cy = fr.to_xy(arc.centre_lat_deg, arc.centre_lon_deg)
    a = math.radians(planar_radial_deg)
    px, py = cx + arc.radius_m * math.sin(a), cy + arc.radius_m * math.cos(a)
    lat, lon = fr.to_latlon(px, py)
    return inverse(arc.centre_lat_deg, arc.centre_lon_deg, lat, lon)[1]


def _planar_lead(fr: LocalFrame, line: Line, arc: Arc, omega: float, r_m: float
                 ) -> tuple[float, float, float, float, float] | None:
    """The lead L of a fillet of radius ``r_m`` from ``line`` onto ``arc`` in the plane of
    ``fr`` (origin at the corner): the fillet's centre F = −L u + r n (u the line's direction,
    n its normal toward the turn) lies at |F − C| = R ∓ r from the arc's centre C — a
    quadratic in L, its least root ≥ 0. Returns (L m, F x, F y, C x, C y) or None."""
    sgn = 1.0 if omega > 0 else -1.0
    same = (arc.sweep_deg > 0) == (omega > 0)
    cx, cy = fr.to_xy(arc.centre_lat_deg, arc.centre_lon_deg)
    u = math.radians(line.end_course_deg)
    ux, uy = math.sin(u), math.cos(u)
    nx, ny = sgn * uy, -sgn * ux          # unit normal toward the turn side
    d = arc.radius_m - r_m if same else arc.radius_m + r_m
    if d <= 0:
        return None
    px, py = r_m * nx - cx, r_m * ny - cy
    bq = -(px * ux + py * uy)
    cq = px * px + py * py - d * d
    disc = bq * bq - cq
    if disc < 0:
        return None
    roots = sorted(x for x in (-bq - math.sqrt(disc), -bq + math.sqrt(disc)) if x >= 0)
    if not roots:
        return None
    lead = roots[0]
    return lead, -lead * ux + r_m * nx, -lead * uy + r_m * ny, cx, cy


def line_arc_fillet(line: Line, arc: Arc, r_m: float, avail_m: float | None = None
                    ) -> Fillet | None:
    """Round the corner from ``line`` (ending where ``arc`` starts) onto ``arc``.

    Parameters
    ----------
    line : the straight before the corner; arc : the coded arc after it
    r_m : fillet radius, m
    avail_m : how much of the line the fillet may use, m (default: all of it)

    Returns
    -------
    The rounded corner, or None when no fillet of that radius fits (the contact point would
    fall before the line's start, beyond the arc's end or more than 180° round it).
    """
    omega = wrap180(arc.start_course_deg - line.end_course_deg)
    if abs(omega) < 0.5:
        return None
    avail_m = line.length_m() if avail_m is None else avail_m
    fr = LocalFrame(*arc.start)
    got = _planar_lead(fr, line, arc, omega, r_m)
    if got is None or got[0] > avail_m:
        return None
    lead, fx, fy, cx, cy = got
    # the contact point lies on the ray from C through F (planar radial from C) ...
    radial_t2 = math.degrees(math.atan2(fx - cx, fy - cy))
    # ... and from here on the geometry is exact: the contact point on the coded arc and a
    # fillet started on the line, ended on the radial through the contact point
    t2 = direct(arc.centre_lat_deg, arc.centre_lon_deg, _geo_radial(fr, arc, radial_t2),
                arc.radius_m)[:2]
    la = line.length_m()
    t1 = line.point_at(la - lead)
    fillet = retarget_arc(turn_arc(t1[0], t1[1], line.course_at(la - lead), omega, r_m), t2,
                          max_change_deg=90.0)
    _, r2, _ = inverse(arc.centre_lat_deg, arc.centre_lon_deg, *fillet.end)
    used = (r2 - arc.start_radial_deg) % 360.0 if arc.sweep_deg > 0 else \
        (arc.start_radial_deg - r2) % 360.0
    if used >= abs(arc.sweep_deg) or used > 180.0:
        return None
    rest = Arc(arc.centre_lat_deg, arc.centre_lon_deg, arc.radius_m, r2,
               arc.sweep_deg - math.copysign(used, arc.sweep_deg))
    new_line = Line(line.start_lat_deg, line.start_lon_deg, *fillet.start)
    gap = Line(*fillet.end, *rest.start)
    return Fillet(new_line if new_line.length_m() >= 0.01 else None, fillet,
                  gap if gap.length_m() > 0.01 else None, rest, lead)


def arc_line_fillet(arc: Arc, line: Line, r_m: float, avail_m: float | None = None
                    ) -> Fillet | None:
    """Round the corner from ``arc`` (ending where ``line`` starts) onto ``line``: the
    line → arc fillet of the two flown backwards (module docstring).

    Returns
    -------
    The rounded corner, with ``arc`` trimmed at its end and ``line`` at its start (the
    ``line`` field is the rest of the straight after the fillet; ``gap``, when there is one,
    lies between the arc and the fillet), or None when no fillet fits.
    """
    back = line_arc_fillet(reverse_line(line), reverse_arc(arc), r_m, avail_m)
    if back is None:
        return None
    return Fillet(None if back.line is None else reverse_line(back.line),
                  reverse_arc(back.fillet), None if back.gap is None else reverse_line(back.gap),
                  reverse_arc(back.arc), back.lead_m)
