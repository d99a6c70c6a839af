"""Data passed between the leg interpreter, the segmentation, the profile and the monitor.

Frozen dataclasses only; the later guidance issue flies :class:`ProcedurePath` objects: an ordered
tuple of :class:`PathSegment` (each a :class:`~fms_testbed.core.segments.Line` or
:class:`~fms_testbed.core.segments.Arc` tagged with its leg) and, per leg, a :class:`BuiltLeg` holding the
leg's kind and its termination condition as data (:class:`Termination`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.planning import (ACCEL_HEIGHT_M, DEPARTURE_ACCEL_MPS2,
                                       MIN_CLEAN_CAS_FACTOR, SPEED_LIMIT_10000FT_CAS_MPS,
                                       SPEED_LIMIT_ALT_M)
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.wind import WindProfile
from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.legs.coded import CodedPath
from fms_testbed.procedures.legrecord import LegRecord


@dataclass(frozen=True, slots=True)
class BuildParams:
    """Tunable build settings (units in names).

    bank_plan_deg: nominal bank for planned turns; bank_limit_deg: the monitor's |γ| bound (25°
    by the paper, lowered to the aircraft's ``bank_max_deg`` when that is smaller);
    manual_leg_m: length flown on FM/VM legs before the crew takes over; timed_speed_mps:
    speed for timed legs (hold legs given in minutes, the procedure turn's minute) when no
    speed limit is coded (210 kt = 3.5 NM/min); flyby_max_deg: largest track change
    flown as a fly-by turn (above it the turn is flown over the fix); climb_min_gradient: the
    3.3 % minimum climb gradient; descent_angle_deg: default descent path angle.
    """

    bank_plan_deg: float = 20.0
    bank_limit_deg: float = 25.0
    manual_leg_m: float = 5 * NM_M
    timed_speed_mps: float = 210 * KT_MPS
    flyby_max_deg: float = 120.0
    climb_min_gradient: float = 0.033
    descent_angle_deg: float = 3.0
    max_iterations: int = 5
    wind_speed_mps: float = 0.0
    wind_from_deg: float = 0.0
    """The wind the path is planned for (Danilin 2017: the desired trajectory is built for the
    current conditions): turns are planned for their ground speed, R = V_g²/(g tan γ), with
    V_g the largest ground speed over the turn's tracks (:func:`max_tailwind_mps`); m/s and
    deg true (the direction it blows from). With a ``wind_profile`` the builder sets these to
    the wind at each leg's planned altitude (:meth:`for_altitude`)."""
    wind_profile: WindProfile | None = None
    """The planned wind over altitude (None: the constant ``wind_speed_mps``/``wind_from_deg``)."""
    climb_top_m: float | None = None
    """Top of the planned climb, m (None: not known): a hold in a climb is flown up to it, so
    its wind is planned as the profile's strongest from the hold's start up to there."""
    isa_dev_c: float = 0.0
    """The planned temperature deviation from the ISA, K: planned CAS → TAS on that day
    (:func:`isa_tas_mps`), so turn radii are those of the TAS actually flown."""

    def wind_at(self, alt_m: float) -> tuple[float, float]:
        """Planned (speed m/s, from deg true) at altitude ``alt_m`` (m): the profile's, else
        the constant wind."""
        if self.wind_profile is None:
            return self.wind_speed_mps, self.wind_from_deg
        return self.wind_profile.at(alt_m)

    def for_band(self, lo_m: float, hi_m: float) -> "BuildParams":
        """These settings with the constant wind replaced by the profile's strongest between
        ``lo_m`` and ``hi_m`` (m): a leg flown through that band of altitudes (a hold climbed
        in). The same object without a profile."""
        if self.wind_profile is None:
            return self
        spd, frm = self.wind_profile.strongest_between(lo_m, hi_m)
        return replace(self, wind_speed_mps=spd, wind_from_deg=frm)

    def for_altitude(self, alt_m: float) -> "BuildParams":
        """These settings with the constant wind replaced by the profile's at ``alt_m`` (m):
        what one leg is built with (the same object without a profile)."""
        if self.wind_profile is None:
            return self
        spd, frm = self.wind_profile.at(alt_m)
        return replace(self, wind_speed_mps=spd, wind_from_deg=frm)


CEILING_MARGIN_M = 500 * FT_M
"""The planner's own choices (climb top, an uncoded arrival start) stay this far below the
service ceiling, m (a C172P SID climbing to the default 15,000 ft top, or a STAR started at
field + 10,000 ft at a 5,841 ft airport, left its 13,500 ft ceiling: envelope_exceeded)."""


@dataclass(frozen=True, slots=True)
class Performance:
    """Aircraft performance the builder uses (from ``aircraft.limits``), SI.

    tas_plan_mps: planned TAS; tas_min_mps: lowest acceptable TAS for a correction;
    climb_gradient_max: rise over run at ``tas_plan_mps``; climb_rate_max_mps;
    descent_rate_max_mps; bank_max_deg; alt_max_m: the service ceiling, m (inf: none given);
    cas_max_mps: VMO as a CAS, m/s, and mach_max: MMO (inf: none given) — the speed envelope
    every planned TAS stays inside (:meth:`tas_max_mps`).
    """

    tas_plan_mps: float
    tas_min_mps: float
    climb_gradient_max: float
    climb_rate_max_mps: float
    descent_rate_max_mps: float
    bank_max_deg: float
    alt_max_m: float = math.inf
    cas_max_mps: float = math.inf
    mach_max: float = math.inf
    departure_cas_mps: float | None = None
    """Climb-out CAS of a departure up to the acceleration height, m/s: V2 + the takeoff's
    climb-out increment, never below the lowest CAS guidance flies clean
    (:data:`~fms_testbed.core.planning.MIN_CLEAN_CAS_FACTOR` × the minimum clean CAS; None: no
    takeoff data — a departure is planned at ``tas_plan_mps`` from the runway on)."""
    accel_height_m: float = ACCEL_HEIGHT_M
    """Height above the runway where a departure starts to accelerate, m."""
    accel_mps2: float = DEPARTURE_ACCEL_MPS2
    """Acceleration a departure makes good from the acceleration height, m/s² (CAS along the
    path)."""

    def tas_max_mps(self, alt_m: float, isa_dev_c: float = 0.0) -> float:
        """Largest TAS inside the speed envelope at ``alt_m`` (m) on a day ``isa_dev_c`` (K)
        off the ISA, m/s: min(TAS(VMO), MMO · a), a = √(γ R T) the speed of sound there
        (T of :func:`~fms_testbed.core.atmosphere.isa`, the troposphere's lapse to 11 km)."""
        from fms_testbed.core.atmosphere import GAMMA, H_TROP_M, LAPSE_KPM, R_JPKGK, T0_K
        h = max(alt_m, 0.0)
        v = math.inf
        if math.isfinite(self.cas_max_mps):
            v = cas_to_tas_scalar(self.cas_max_mps, h, isa_dev_c)
        if math.isfinite(self.mach_max):
            t_k = T0_K + isa_dev_c - LAPSE_KPM * min(h, H_TROP_M)
            v = min(v, self.mach_max * math.sqrt(GAMMA * R_JPKGK * t_k))
        return v

    @property
    def alt_plan_max_m(self) -> float:
        """Highest altitude the planner chooses on its own (a climb top, an uncoded start), m:
        :data:`CEILING_MARGIN_M` below the service ceiling."""
        return self.alt_max_m - CEILING_MARGIN_M

    @classmethod
    def from_aircraft(cls, ac) -> "Performance":
        """Take the limits of an :class:`~fms_testbed.config.aircraft.AircraftConfig`."""
        lim, to, ap = ac.limits, ac.takeoff, ac.approach
        dep = None
        if to is not None:   # the takeoff flight's climb-out speed, at the reference mass
            dep = min(max(to.v2_cas_mps + to.climb_add_cas_mps,
                          MIN_CLEAN_CAS_FACTOR * lim.cas_min_mps), lim.climb_cas_mps)
        return cls(tas_plan_mps=lim.climb_cas_mps, tas_min_mps=lim.cas_min_mps,
                   climb_gradient_max=lim.climb_gradient_max,
                   climb_rate_max_mps=lim.climb_rate_max_mps,
                   descent_rate_max_mps=lim.descent_rate_max_mps, bank_max_deg=lim.bank_max_deg,
                   alt_max_m=lim.alt_max_m, cas_max_mps=lim.cas_max_mps,
                   mach_max=lim.mach_max, departure_cas_mps=dep,
                   accel_height_m=ap.acceleration_height_m if ap is not None
                   else ACCEL_HEIGHT_M,
                   accel_mps2=to.departure_accel_mps2 if to is not None
                   else DEPARTURE_ACCEL_MPS2)

    def departure_cas_at_mps(self, accel_dist_m: float | None, alt_m: float) -> float:
        """Planned CAS of a departure, m/s (the one schedule the leg builder plans turn radii
        for and guidance flies): the climb-out CAS V_c = :attr:`departure_cas_mps` up to the
        acceleration height (``accel_dist_m`` None), then what the aircraft can have reached
        ``accel_dist_m`` (m) of path after it at :attr:`accel_mps2` a,

            V = min(√(V_c² + 2 a d), V_plan, 250 kt below 10,000 ft)

        V_plan = :attr:`tas_plan_mps` (the planned terminal-area CAS); ``alt_m`` (m) is where
        the 250 kt limit is looked at. Without takeoff data: V_plan (250 kt below 10,000 ft)."""
        v = self.tas_plan_mps
        if alt_m < SPEED_LIMIT_ALT_M:
            v = min(v, SPEED_LIMIT_10000FT_CAS_MPS)
        if self.departure_cas_mps is None:
            return v
        c = self.departure_cas_mps
        d = 0.0 if accel_dist_m is None else max(accel_dist_m, 0.0)
        return min(v, math.sqrt(c * c + 2.0 * self.accel_mps2 * d))

    def climb_gradient_at(self, tas_mps: float) -> float:
        """Climb gradient capability at a TAS, rise over run: the climb rate is taken as
        constant, so the gradient scales as 1/V from ``climb_gradient_max`` at the planned TAS,
        and never exceeds ``climb_rate_max_mps / V``."""
        return min(self.climb_gradient_max * self.tas_plan_mps, self.climb_rate_max_mps) / tas_mps


@dataclass(frozen=True, slots=True)
class FlightState:
    """Where the planned aircraft is while legs are built.

    lat_deg/lon_deg: position; track_deg: true track (None before the first course is known);
    alt_m: planned altitude; flyby: the position is a fly-by fix whose corner may be cut by
    the next leg; fix_ident: the fix at the position ('' if none).
    """

    lat_deg: float
    lon_deg: float
    track_deg: float | None
    alt_m: float
    flyby: bool = False
    fix_ident: str = ""

    @property
    def pos(self) -> tuple[float, float]:
        """(lat_deg, lon_deg)."""
        return self.lat_deg, self.lon_deg


@dataclass(frozen=True, slots=True)
class Termination:
    """How a leg ends, as data for guidance.

    kind: 'fix' | 'altitude' | 'dme' | 'radial' | 'intercept' | 'manual' | 'distance' | 'time'
    | 'circuit'. Only the fields of that kind are set: ``lat_deg/lon_deg`` (fix or computed end
    point), ``alt_m`` (altitude terminations), ``dme_m`` and ``navaid_lat_deg/lon_deg`` (DME),
    ``radial_deg`` (true, with the navaid), ``distance_m``/``time_s``, ``next_leg`` (intercept);
    holds (HA/HF/HM) also give ``distance_m``, the racetrack's straight-leg length.
    """

    kind: str
    lat_deg: float | None = None
    lon_deg: float | None = None
    fix_ident: str = ""
    alt_m: float | None = None
    dme_m: float | None = None
    radial_deg: float | None = None
    navaid_lat_deg: float | None = None
    navaid_lon_deg: float | None = None
    distance_m: float | None = None
    time_s: float | None = None
    next_leg: int | None = None


@dataclass(frozen=True, slots=True)
class PathSegment:
    """One Line or Arc of a built path with its tags.

    role: 'leg' (the leg's own path), 'turn' (a transition flown from the present position onto
    the leg's path: a turn, a 45° intercept of a course, a direct-to the leg's fix, a hold
    entry), 'flyby' (fly-by transition arc, tagged with the leg it ends), 'hold' (the turns of
    the racetrack circuits), 'connector' (bridge over a discontinuity); speed_mps: planned TAS;
    bank_deg: planned bank (arcs); lead_m: turn anticipation of a fly-by arc. The path
    definition error is scored on 'leg' and 'hold' segments only.
    """

    geom: Line | Arc
    leg_index: int
    path_term: str
    fix_ident: str
    role: str = "leg"
    speed_mps: float = 0.0
    bank_deg: float = 0.0
    lead_m: float = 0.0
    """Fly-by arcs: turn anticipation, the distance from the corner to where the turn starts, m."""
    heading_deg: float | None = None
    """Heading legs (V*): the coded heading to hold, deg true; the line is the ground track that
    heading gives in the planned wind (drift predicted); None elsewhere."""


@dataclass(frozen=True, slots=True)
class Finding:
    """A monitor or builder finding: leg index (-1: procedure), category, message, branch."""

    leg_index: int
    category: str     # 'correction' | 'impossible' | 'discontinuity' | 'loop' | 'no-intercept' | 'info'
    message: str
    branch: str = ""  # paper branch: 'R', 'V,γ', 'γ', 'V,Θ', 'V,γ,φ,λ'

    @property
    def danilin_class(self) -> int:
        """Danilin's (2017) class of what forced the finding: 1 — the current conditions (speed,
        bank, climb and descent performance, wind: the monitor's corrections and the
        manoeuvres flown instead of a fly-by that does not fit); 2 — a leg combination the
        geometry has to bridge (discontinuities, intercepts that never happen, courses joined
        upstream); 3 — the coding itself (a path flown twice, a fix missing, a coded radius
        the fixes contradict) — not correctable by the monitor, for the crew to judge."""
        m = self.message
        if self.category in ("loop", "coding") or "not in the database" in m or "coded" in m and \
                "fixes give" in m or "arc angle built" in m:
            return 3
        if self.category in ("discontinuity", "no-intercept") or "joined" in m and \
                "course into" in m:
            return 2
        return 1


@dataclass(frozen=True, slots=True)
class BuiltLeg:
    """One interpreted leg: its record, where it starts and ends, its termination, and the path
    its record codes (``coded``, for the path definition error; None when the leg type has
    none, see :attr:`fms_testbed.legs.base.Leg.pde_reference`)."""

    index: int
    record: LegRecord
    path_term: str
    start: FlightState
    end: FlightState
    termination: Termination
    speed_mps: float
    seg_first: int = 0
    seg_count: int = 0
    coded: CodedPath | None = None
    resolved: object = None
    """The :class:`~fms_testbed.legs.builder.ResolvedLeg` it was built from (fixes looked up,
    course turned true, the variation used): the coded-numbers check reads the record's
    fields against its fixes from it."""
    from_fix: object = None
    """The :class:`~fms_testbed.procedures.records.Fix` the leg starts from (the previous
    leg's fix when that leg ends there), or None."""
    departure_cas_mps: float | None = None
    """The departure schedule's CAS the leg was planned under
    (:meth:`Performance.departure_cas_at_mps` at its start), m/s: guidance flies a SID's leg
    no faster (None: not a departure from a runway)."""


@dataclass(frozen=True)
class ProcedurePath:
    """A built procedure transition: segments, legs, vertical profile and monitor outcome."""

    name: str
    airport: str
    proc_type: str
    proc_id: str
    transition: str
    legs: tuple[BuiltLeg, ...]
    segments: tuple[PathSegment, ...]
    findings: tuple[Finding, ...] = ()
    profile: object = None
    status: str = "ok"
    start_kind: str = "fix"
    """Where the build started: 'runway' (departure end), 'fix', 'airport' or 'given'."""

    def length_m(self) -> float:
        """Total horizontal path length, m."""
        return math.fsum(s.geom.length_m() for s in self.segments)

    def leg_types(self) -> list[str]:
        """Path terminators in order."""
        return [lg.path_term for lg in self.legs]

    def max_plan_alt_m(self) -> float:
        """Highest planned altitude, m: of the builder's leg starts and ends and of the
        vertical profile (NaN when nothing was built)."""
        alts = [a for lg in self.legs for a in (lg.start.alt_m, lg.end.alt_m)]
        if self.profile is not None:
            alts += [float(max(self.profile.alt_m, default=-math.inf))]
        return max(alts, default=math.nan)

    def max_plan_tas_mps(self) -> float:
        """Highest planned TAS, m/s: of the legs and of the segments (fly-by corrections
        included; NaN when nothing was built)."""
        v = [lg.speed_mps for lg in self.legs] + [s.speed_mps for s in self.segments]
        return max(v, default=math.nan)


def isa_tas_mps(cas_mps: float, alt_m: float, isa_dev_c: float = 0.0) -> float:
    """TAS (m/s) for a CAS (m/s) at altitude ``alt_m`` (m, ≥ 0) on a day ``isa_dev_c`` (K) off
    the ISA: the compressible conversion guidance flies
    (:func:`fms_testbed.core.atmosphere.cas_to_tas_scalar`), so the radius R = V²/(g tan γ)
    is planned for the TAS actually flown."""
    return cas_to_tas_scalar(cas_mps, max(alt_m, 0.0), isa_dev_c)


def turn_radius_m(tas_mps: float, bank_deg: float, g_mps2: float) -> float:
    """R = V²/(g tan γ), m (Danilin 2017, turn radius from speed and bank)."""
    return tas_mps * tas_mps / (g_mps2 * math.tan(math.radians(bank_deg)))




def max_tailwind_mps(wind_speed_mps: float, wind_from_deg: float, track_deg: float | None = None,
                     sweep_deg: float | None = None) -> float:
    """Largest wind component along the track over a turn, m/s (≥ 0): the full wind speed when
    the turn's tracks (from ``track_deg`` through ``sweep_deg``, signed, + right) include the
    direction the wind blows to, else the larger end component; the full speed when the turn
    is not known (None), as for a hold's 180° turns.

    Parameters
    ----------
    wind_speed_mps : wind speed, m/s; wind_from_deg : direction it blows from, deg true
    track_deg : track at the turn's start, deg true; sweep_deg : the turn, deg
    """
    if wind_speed_mps <= 0.0:
        return 0.0
    if track_deg is None or sweep_deg is None or abs(sweep_deg) >= 180.0:
        return wind_speed_mps
    to = wind_from_deg + 180.0
    rel = ((to - track_deg) % 360.0) if sweep_deg >= 0 else ((track_deg - to) % 360.0)
    if rel <= abs(sweep_deg):
        return wind_speed_mps
    ends = (math.cos(math.radians(to - track_deg)),
            math.cos(math.radians(to - track_deg - sweep_deg)))
    return max(0.0, wind_speed_mps * max(ends))


def drift_track_deg(heading_deg: float, tas_mps: float, wind_speed_mps: float,
                    wind_from_deg: float) -> float:
    """Ground track flown on a heading in a steady wind (the wind triangle), deg true:
    V_g = V (sin ψ, cos ψ) + W (sin χ_w, cos χ_w), χ_w = wind_from + 180°.

    Parameters
    ----------
    heading_deg : heading, deg true; tas_mps : true airspeed, m/s
    wind_speed_mps : wind speed, m/s; wind_from_deg : direction it blows from, deg true
    """
    if wind_speed_mps <= 0.0:
        return heading_deg % 360.0
    h, to = math.radians(heading_deg), math.radians(wind_from_deg + 180.0)
    gx = tas_mps * math.sin(h) + wind_speed_mps * math.sin(to)
    gy = tas_mps * math.cos(h) + wind_speed_mps * math.cos(to)
    return math.degrees(math.atan2(gx, gy)) % 360.0


APPROACH_CAS_MPS = 210 * KT_MPS
"""CAS an approach is planned at, at most (the usual initial/intermediate approach speed; no
flaps are modelled yet, so the final is flown clean at it too), m/s."""


def approach_cas_caps(records, proc_type: str, cas_min_mps: float) -> list[float | None]:
    """Planned CAS cap per leg of a procedure, m/s (None: no cap): every leg of an approach
    (``proc_type`` 'F') at :data:`APPROACH_CAS_MPS` (never below 1.15 × the minimum clean CAS
    ``cas_min_mps``), other procedures uncapped. The builder plans turn radii for it and
    guidance flies it (decelerating before the first fix where it applies). A slower final at
    the approach speed needs the flap and gear model (not modelled): slowing clean to the
    minimum clean speed on the glide path leaves the aircraft high and, for the Global 5000,
    at its stall angle of attack (measured with the flight table)."""
    if proc_type != "F":
        return [None] * len(records)
    return [max(APPROACH_CAS_MPS, 1.15 * cas_min_mps)] * len(records)
