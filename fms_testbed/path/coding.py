"""The coded-numbers check: each record's redundant fields against its own fixes (Danilin's
class 3, wrong coding in the database).

Many leg records code numbers the fixes already fix: a TF's route distance (cols 75-78) is the
geodesic length between its two fixes and its course (71-74, magnetic + the variation the leg
uses) the initial azimuth of that geodesic; a CF from a fix codes the course of the line into
its fix; an RF's radius (57-62) is the distance from its centre fix to both its fixes, its
distance the arc length between them and its course the tangent at the end fix; an AF's rho
(67-70) is the distance from its DME to the end fix and its theta (63-66) the bearing of the fix
from the navaid; a hold codes the length of its outbound leg, as a distance or a time. Where
the coded number and the geometry disagree beyond the field's resolution the record is
suspect: a class-3 finding (category ``coding``) names the field, the coded value, the value
the fixes give and the file line. The geometry is computed here, from the database's fixes
with geographiclib (Karney 2013), not from the builder's segments or its geodesy.

Tolerances (:data:`TOL`), from the fields' resolution:

* distances (TF, CF, RF route distance; AF rho): one unit of the field, 0.1 NM (the coded
  value is rounded or truncated to 0.1 NM and the coder's geodesy may differ a little);
* courses (TF, CF, RF end tangent; AF theta): half a unit of the course field (0.05°) plus
  half a unit of the variation added to it — FAA variations are whole degrees (±0.5°),
  others tenths (±0.05°) — plus 0.05° for the fixes' own rounding over short legs;
* RF radius: 0.01 NM (ten units of the 0.001-NM field; the fixes' coordinates are rounded
  to 0.01″, 0.3 m);
* hold leg: 0.1 NM between the built outbound leg and the coded distance, or the coded time
  at the planned timed-leg speed.

A course is only compared where it is redundant: a CF whose previous leg ends at a fix and
whose course is not a course reversal (more than 90° off the line from that fix: a CF coded
back along the final of a missed approach, a teardrop), a TF whose previous leg ends at a fix.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from geographiclib.geodesic import Geodesic

from fms_testbed.core.geodesy import inverse, wrap180, wrap360
from fms_testbed.core.units import KT_MPS, NM_M
from fms_testbed.legs.model import Finding
from fms_testbed.legs.types import LEG_TYPES

_WGS84 = Geodesic.WGS84
_INV = Geodesic.DISTANCE | Geodesic.AZIMUTH


@dataclass(frozen=True, slots=True)
class Tolerances:
    """Tolerances of the coded-numbers check (module docstring).

    distance_m: route distance, rho; course_deg: course field half-unit plus the fixes'
    rounding (the variation's half-unit is added per leg, :func:`variation_tol_deg`);
    radius_m: RF radius; hold_m: hold outbound leg.
    """

    distance_m: float = 0.1 * NM_M
    course_deg: float = 0.1
    radius_m: float = 0.01 * NM_M
    hold_m: float = 0.1 * NM_M


TOL = Tolerances()
"""The tolerances the monitor uses."""

CODING_KINDS = ("distance", "course", "rf_radius", "rf_tangent", "af_rho", "af_theta",
                "hold_length")
"""Kinds of class-3 finding, the first word of each message."""


def variation_tol_deg(magvar_deg: float, course_true: bool) -> float:
    """Half a unit of the variation a magnetic course is turned true with, deg: 0.5° for a
    whole-degree variation (FAA data), 0.05° for one coded in tenths; 0 for a true course."""
    if course_true:
        return 0.0
    return 0.5 if abs(magvar_deg - round(magvar_deg)) < 1e-6 else 0.05


def geodesic(lat1_deg: float, lon1_deg: float, lat2_deg: float, lon2_deg: float
             ) -> tuple[float, float, float]:
    """(distance m, initial azimuth deg, final azimuth deg) of the WGS-84 geodesic between
    two points (geographiclib, Karney 2013)."""
    g = _WGS84.Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, _INV)
    return g["s12"], wrap360(g["azi1"]), wrap360(g["azi2"])


def fast_geodesic(lat1_deg: float, lon1_deg: float, lat2_deg: float, lon2_deg: float
                  ) -> tuple[float, float, float]:
    """(distance m, initial azimuth deg, final azimuth deg) by the package's compiled
    Vincenty inverse (within 1 mm and 1e-5° of :func:`geodesic`): the screening pass."""
    s, az1, az2 = inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg)
    return s, wrap360(az1), wrap360(az2)


SCREEN_M = 0.01
"""Screening margin on distances, m (the compiled inverse is within 1 mm of geographiclib)."""
SCREEN_DEG = 1e-4
"""Screening margin on courses, deg."""


def _finding(i: int, kind: str, leg, field: str, coded: str, geom: str, what: str) -> Finding:
    r = leg.rec
    ident = r.fix.ident if r.fix else ""
    return Finding(i, "coding", f"{kind}: {r.path_term} {ident} {field} coded {coded}, "
                   f"{what} {geom} (line {r.line})")


def _nm(x_m: float) -> str:
    return f"{x_m / NM_M:.2f} NM"


def _course_tol(leg) -> float:
    return TOL.course_deg + variation_tol_deg(leg.magvar_deg, leg.rec.course_true)


def _track_checks(i: int, leg, prev, geo=geodesic, m_m: float = 0.0, m_deg: float = 0.0
                  ) -> list[Finding]:
    """TF/CF route distance and course against the geodesic from the previous fix (``geo``;
    the tolerances less the screening margins ``m_m``, ``m_deg``)."""
    r, f = leg.rec, leg.fix
    out = []
    d, az1, az2 = geo(prev.lat_deg, prev.lon_deg, f.lat_deg, f.lon_deg)
    if d < 1.0:
        return out
    if r.distance_m is not None and abs(r.distance_m - d) > TOL.distance_m - m_m:
        out.append(_finding(i, "distance", leg, "route distance (cols 75-78)",
                            _nm(r.distance_m), _nm(d), f"fixes {prev.ident}-{f.ident} give"))
    crs = leg.course_true_deg
    if crs is not None:
        geo = az1 if r.path_term == "TF" else az2
        err = abs(wrap180(crs - geo))
        if err > _course_tol(leg) - m_deg and not (r.path_term == "CF" and err > 90.0):
            out.append(_finding(i, "course", leg, "course (cols 71-74) + variation "
                                f"{leg.magvar_deg:+.1f}°", f"{crs:.1f}° true", f"{geo:.1f}°",
                                f"the geodesic {prev.ident}-{f.ident} gives"))
    return out


def _rf_checks(i: int, leg, prev, geo=geodesic, m_m: float = 0.0, m_deg: float = 0.0
               ) -> list[Finding]:
    """RF radius against both fixes, route distance against the arc, course against the
    tangent at the end fix (``geo``, margins as :func:`_track_checks`)."""
    r, f, c = leg.rec, leg.fix, leg.centre
    out = []
    d1, a1, _ = geo(c.lat_deg, c.lon_deg, f.lat_deg, f.lon_deg)
    d0, a0, _ = geo(c.lat_deg, c.lon_deg, prev.lat_deg, prev.lon_deg)
    if r.arc_radius_m:
        for d, which in ((d0, prev.ident), (d1, f.ident)):
            if abs(d - r.arc_radius_m) > TOL.radius_m - m_m:
                out.append(_finding(i, "rf_radius", leg, "arc radius (cols 57-62)",
                                    f"{r.arc_radius_m / NM_M:.3f} NM", f"{d / NM_M:.3f} NM",
                                    f"centre {c.ident}-{which} gives"))
                break
    turn = r.turn_dir if r.turn_dir in ("L", "R") else ("R" if wrap180(a1 - a0) > 0 else "L")
    sweep = (a1 - a0) % 360.0 if turn == "R" else (a0 - a1) % 360.0
    if r.distance_m is not None:
        arc = 0.5 * (d0 + d1) * math.radians(sweep)
        if abs(r.distance_m - arc) > TOL.distance_m - m_m \
                - math.radians(2.0 * m_deg) * (d0 + d1):
            out.append(_finding(i, "distance", leg, "route distance (cols 75-78)",
                                _nm(r.distance_m), _nm(arc),
                                f"the {sweep:.1f}° arc {prev.ident}-{f.ident} gives"))
    if leg.course_true_deg is not None:
        tangent = wrap360(a1 + (90.0 if turn == "R" else -90.0))
        if abs(wrap180(leg.course_true_deg - tangent)) > _course_tol(leg) - m_deg:
            out.append(_finding(i, "rf_tangent", leg, "course (cols 71-74) + variation "
                                f"{leg.magvar_deg:+.1f}°", f"{leg.course_true_deg:.1f}° true",
                                f"{tangent:.1f}°", f"the tangent at {f.ident} is"))
    return out


def _af_checks(i: int, leg, geo=geodesic, m_m: float = 0.0, m_deg: float = 0.0
               ) -> list[Finding]:
    """AF rho and theta against the end fix's distance and bearing from the navaid's DME
    (``geo``, margins as :func:`_track_checks`)."""
    r, f, n = leg.rec, leg.fix, leg.navaid
    out = []
    lat = n.dme_lat_deg if n.dme_lat_deg is not None else n.lat_deg
    lon = n.dme_lon_deg if n.dme_lon_deg is not None else n.lon_deg
    d, az, _ = geo(lat, lon, f.lat_deg, f.lon_deg)
    if r.rho_m is not None and abs(r.rho_m - d) > TOL.distance_m - m_m:
        out.append(_finding(i, "af_rho", leg, "rho (cols 67-70)", _nm(r.rho_m), _nm(d),
                            f"{n.ident}-{f.ident} gives"))
    if r.theta_deg is not None:
        theta = wrap360(r.theta_deg + leg.magvar_deg)
        if abs(wrap180(theta - az)) > TOL.course_deg - m_deg + variation_tol_deg(
                leg.magvar_deg, False):
            out.append(_finding(i, "af_theta", leg, "theta (cols 63-66) + variation "
                                f"{leg.magvar_deg:+.1f}°", f"{theta:.1f}° true", f"{az:.1f}°",
                                f"the bearing {n.ident}-{f.ident} is"))
    return out


def record_checks(legs, prev_fixes) -> list[Finding]:
    """Class-3 findings of the coded numbers of every leg (module docstring).

    Parameters
    ----------
    legs : the resolved legs (:class:`~fms_testbed.legs.builder.ResolvedLeg`): fixes looked
        up, course turned true with the variation the leg uses (``magvar_deg``, deg east)
    prev_fixes : per leg, the fix the leg starts from (the previous leg's fix when it ends
        there), or None
    """
    out: list[Finding] = []
    for i, leg in enumerate(legs):
        prev = prev_fixes[i] if i < len(prev_fixes) else None
        pt = leg.rec.path_term
        if leg.fix is None:
            continue
        if pt in ("TF", "CF") and prev is not None:
            check, args = _track_checks, (i, leg, prev)
        elif pt == "RF" and prev is not None and leg.centre is not None:
            check, args = _rf_checks, (i, leg, prev)
        elif pt == "AF" and leg.navaid is not None:
            check, args = _af_checks, (i, leg)
        else:
            continue
        # screened with the compiled inverse at the tolerances less its margins; a leg that
        # may disagree is decided (and reported) with geographiclib
        if check(*args, fast_geodesic, SCREEN_M, SCREEN_DEG):
            out += check(*args)
    return out


def hold_checks(path, timed_speed_mps: float) -> list[Finding]:
    """Holds: the built outbound leg against the coded distance, or the coded time at the
    timed-leg speed (the coded limit's planned TAS, else ``timed_speed_mps``, m/s), within
    :attr:`Tolerances.hold_m`."""
    out = []
    for lg in path.legs:
        if not LEG_TYPES[lg.path_term].hold:
            continue
        r = lg.record
        if r.distance_m is not None:
            want, field = r.distance_m, f"leg distance (cols 75-78) {_nm(r.distance_m)}"
        elif r.time_s is not None:
            v = lg.speed_mps if r.speed_limit_mps else timed_speed_mps
            want = r.time_s * v
            field = f"leg time (cols 75-78) {r.time_s / 60.0:.1f} min at {v / KT_MPS:.0f} kt"
        else:
            continue
        built = outbound_m(path, lg.index)
        if built is not None and abs(built - want) > TOL.hold_m:
            ident = r.fix.ident if r.fix else ""
            out.append(Finding(lg.index, "coding", f"hold_length: {lg.path_term} {ident} "
                               f"{field} = {_nm(want)}, built {_nm(built)} (line {r.line})"))
    return out


def outbound_m(path, leg_index: int) -> float | None:
    """Length of a hold leg's outbound straight (the line after its first racetrack turn), m;
    None when the leg has no circuit."""
    segs = [s for s in path.segments if s.leg_index == leg_index]
    for a, b in zip(segs, segs[1:]):
        if a.role == "hold" and a.geom.kind == "arc" and b.geom.kind == "line":
            return b.geom.length_m()
    return None


def coding_kind(f: Finding) -> str:
    """The kind of a class-3 finding (:data:`CODING_KINDS`), '' for any other finding."""
    if f.category != "coding":
        return ""
    return f.message.split(":", 1)[0]
