"""The leg base class: what every path terminator is, as class attributes, and the table of them.

A path terminator is one subclass of :class:`Leg` with its two-letter ``code``. The class says
how the leg is built (:meth:`Leg.build`), what a CI/VI before it intercepts (:meth:`Leg.target`),
which path the record codes for the path definition error (:attr:`Leg.pde_reference`,
:meth:`Leg.coded_path`), and the properties the builder, the monitor and guidance ask about
(heading leg, conditional end, ends at its fix, hold, ...). Defining the class registers it in
:data:`LEG_TYPES` — a new leg type is one class in one place; the families live in
:mod:`.fix_legs`, :mod:`.course_legs` and :mod:`.holds`, the table is read from :mod:`.types`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

from fms_testbed.legs.model import FlightState, Termination

if TYPE_CHECKING:
    from fms_testbed.legs.builder import LegBuilder
    from fms_testbed.legs.coded import CodedPath
    from fms_testbed.procedures.legrecord import LegRecord


class LegError(Exception):
    """The leg cannot be built as coded (missing field or fix); the message says why."""


LEG_TYPES: dict[str, type["Leg"]] = {}
"""The table from path terminator to its class, filled as the classes are defined (read it
from :mod:`fms_testbed.legs.types`, which imports every family)."""


class Leg:
    """Base of the 23 path terminators: ``build(b, state) -> (state, termination)``.

    Class attributes (the defaults below hold unless a leg type says otherwise):
    """

    code: ClassVar[str] = ""
    """ARINC-424 path terminator (col. 48-49); '' on the abstract families."""
    heading_leg: ClassVar[bool] = False
    """V*: the straight part is a heading flown with the wind's drift, not a ground track (no
    FTE/TSE there)."""
    conditional: ClassVar[bool] = False
    """The end is a condition guidance checks in flight — altitude (CA/FA/VA), DME distance
    (CD/FD/VD), radial (CR/VR) — so the rest of the procedure is rebuilt where it is met."""
    altitude_terminated: ClassVar[bool] = False
    """The leg ends on reaching its altitude (CA/FA/VA, and HA over its fix): the altitude
    constraint is met by construction."""
    ends_at_fix: ClassVar[bool] = False
    """The leg ends at (over) its database fix, so a TF after it starts from that fix."""
    track_to_fix: ClassVar[bool] = False
    """A straight track into the fix from the previous one (TF/CF/DF): the same fix-to-fix track
    flown twice is a loop in the coding (Danilin 2017, Fig. 4)."""
    course_to_fix: ClassVar[bool] = False
    """CF: the leg's path is its coded course into the fix — joined before the fix or, where
    that cannot be flown, the leg is impossible (never flown direct to the fix)."""
    direct_to: ClassVar[bool] = False
    """DF: flown from wherever the aircraft is; on a rebuild a fix already behind is passed."""
    initial: ClassVar[bool] = False
    """IF: a point where the path (re)starts; no path of its own."""
    manual_end: ClassVar[bool] = False
    """FM/VM/HM: ended by the crew (vectors, a hold left on clearance); a route resumed after
    it at an IF is the coded direct-to, not a gap in the coding."""
    hold: ClassVar[bool] = False
    """HA/HF/HM: a racetrack hold at the fix."""
    course_reversal: ClassVar[bool] = False
    """Holds and PI: the path comes back over itself by design (not a doubling-back fault)."""
    arc_centre: ClassVar[str | None] = None
    """Coded arcs: 'fix' — RF about its centre fix (col. 107) at the coded radius; 'navaid' —
    AF, the DME arc about the recommended navaid at rho. None for other legs."""
    radius_tol_m: ClassVar[float | None] = None
    """Coded arcs: how far the built radius may differ from the coded one before the monitor
    reports the correction (branch R), m."""
    pde_reference: ClassVar[str | None] = None
    """How the coded path of the leg is defined for the path definition error (see
    :mod:`.coded`), or None: the record defines no path to compare with — the leg starts
    wherever the aircraft is (DF, C*/V* courses and headings from the present position),
    is a point (IF) or a manoeuvre of the aircraft's choosing (PI) — and its PDE is NaN."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.code:
            if cls.code in LEG_TYPES:
                raise TypeError(f"two leg classes for {cls.code}: {LEG_TYPES[cls.code]} and {cls}")
            LEG_TYPES[cls.code] = cls

    @classmethod
    def build(cls, b: "LegBuilder", s: FlightState) -> tuple[FlightState, Termination]:
        """Append the leg's segments to ``b`` and return its end.

        Parameters
        ----------
        b : the transition's builder; ``b.leg`` is this leg (fixes resolved, course true, deg),
            ``b.speed_mps``/``b.radius_m`` the planned TAS (m/s) and turn radius (m)
        s : planned state where the previous leg ended (deg, deg true, m)

        Returns
        -------
        (state, termination): the planned state at the leg's end and how the leg ends.

        Raises
        ------
        LegError when a field the leg needs is missing (the transition is then impossible).
        """
        raise NotImplementedError

    @classmethod
    def target(cls, leg) -> tuple | None:
        """What a CI/VI leg before this one intercepts: ('line', lat, lon, course_deg at the
        point, must_be_before_the_point) or ('circle', lat, lon, radius_m), or None."""
        return None

    @classmethod
    def coded_path(cls, b: "LegBuilder", term: Termination) -> "CodedPath | None":
        """The path the record codes (:attr:`pde_reference`), built after the leg.

        Parameters
        ----------
        b : the builder right after this leg was built (``b.leg``, ``b.prev_fixes[b.i]``,
            ``b.radius_m`` in m)
        term : the leg's termination as built

        Returns
        -------
        The coded path, or None when the leg type has none (``pde_reference is None``) or the
        record lacks a field it needs (PDE NaN).
        """
        return None

    @classmethod
    def coded_radius_m(cls, rec: "LegRecord") -> float | None:
        """Coded arcs: the radius the record gives (RF col. 57-62, AF rho col. 67-70), m."""
        return None


# --------------------------------------------------------------------------- record fields
def course_of(b: "LegBuilder") -> float:
    """The leg's coded course, deg true; LegError when not coded."""
    c = b.leg.course_true_deg
    if c is None:
        raise LegError(f"{b.leg.pt} leg without a course (column 71)")
    return c


def fix_of(b: "LegBuilder"):
    """The leg's fix; LegError when not coded."""
    f = b.leg.fix
    if f is None:
        raise LegError(f"{b.leg.pt} leg without a fix (column 30)")
    return f


def navaid_of(b: "LegBuilder"):
    """The leg's recommended navaid; LegError when not coded."""
    n = b.leg.navaid
    if n is None:
        raise LegError(f"{b.leg.pt} leg without a recommended navaid (column 51)")
    return n


def fix_course(leg) -> tuple[float, float, float] | None:
    """(fix lat deg, fix lon deg, course deg true) of a resolved leg, None when the record
    lacks either."""
    if leg.fix is None or leg.course_true_deg is None:
        return None
    return leg.fix.lat_deg, leg.fix.lon_deg, leg.course_true_deg


def dme_position(n) -> tuple[float, float]:
    """Where a navaid's DME is (its own position when not given separately), deg."""
    if n.dme_lat_deg is not None and n.dme_lon_deg is not None:
        return n.dme_lat_deg, n.dme_lon_deg
    return n.lat_deg, n.lon_deg


def altitude_of(b: "LegBuilder") -> float:
    """The leg's termination altitude (altitude 1), m; LegError when not coded."""
    a = b.leg.rec.alt1_m
    if a is None:
        raise LegError(f"{b.leg.pt} leg without a termination altitude (column 85)")
    return a


def fix_termination(f) -> Termination:
    """A 'fix' termination at a fix."""
    return Termination("fix", f.lat_deg, f.lon_deg, fix_ident=f.ident)
