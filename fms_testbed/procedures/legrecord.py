"""The procedure leg record (PD/PE/PF, heliport HD/HE/HF): one primary record per leg.

Columns follow ``shared/notes/arinc424.md``. Altitudes are returned in metres, distances in
metres, times in seconds, speeds in m/s; courses stay in degrees with a flag saying whether
they are true or magnetic (turned true later with the station/airport variation).
"""

from __future__ import annotations

from dataclasses import dataclass

from fms_testbed.core.units import FT_M, KT_MPS, NM_M
from fms_testbed.procedures.fields import (FieldError, check_record, in_range, parse_alt_ft,
                                           read_code, read_ident, read_int)

#: The 23 ARINC-424 path terminators.
PATH_TERMINATORS = ("IF", "TF", "CF", "DF", "FA", "FC", "FD", "FM", "CA", "CD", "CI", "CR",
                    "RF", "AF", "VA", "VD", "VI", "VM", "VR", "HA", "HF", "HM", "PI")
_PT_SET = frozenset(PATH_TERMINATORS)

PROC_TYPES = {"D": "SID", "E": "STAR", "F": "APPROACH"}


@dataclass(frozen=True, slots=True)
class FixRef:
    """Reference from a leg to a fix: ident, ICAO region, two-letter section ('EA', 'PC', ...)."""

    ident: str
    region: str
    section: str


@dataclass(frozen=True, slots=True)
class LegRecord:
    """One procedure leg as coded.

    Attributes (units in names): ``course_deg`` with ``course_true``; ``distance_m`` or
    ``time_s`` (hold leg length / FC / PI outbound distance / DME distance for CD-FD-VD);
    ``theta_deg`` and ``rho_m`` from the recommended navaid; ``arc_radius_m`` (RF);
    ``alt_desc`` (col 83) with ``alt1_m``/``alt2_m``; ``speed_limit_mps`` with ``speed_desc``
    ('+', '-', or '' = at); ``vpa_deg`` vertical angle (negative descending); ``turn_dir``
    'L'/'R'/'E'/''; ``fly_over`` from the waypoint description code.
    """

    airport: str
    proc_type: str          # 'D' SID, 'E' STAR, 'F' approach
    proc_id: str
    route_type: str
    transition: str
    seq: int
    fix: FixRef | None
    desc: str               # waypoint description code, 4 chars (cols 40-43)
    turn_dir: str
    rnp_nm: float | None
    path_term: str
    turn_dir_valid: bool
    navaid: FixRef | None
    arc_radius_m: float | None
    theta_deg: float | None
    rho_m: float | None
    course_deg: float | None
    course_true: bool
    distance_m: float | None
    time_s: float | None
    alt_desc: str
    alt1_m: float | None
    alt2_m: float | None
    trans_alt_m: float | None
    speed_limit_mps: float | None
    speed_desc: str
    vpa_deg: float | None
    centre: FixRef | None
    heliport: bool
    line: int

    @property
    def fly_over(self) -> bool:
        """Fly-over fix (waypoint description col 41 'Y' or 'B'), runway fixes excepted."""
        return self.desc[1:2] in ("Y", "B") and self.desc[0:1] != "G"

    @property
    def missed_approach_start(self) -> bool:
        """First leg of the missed approach (description col 42 'M')."""
        return self.desc[2:3] == "M"

    @property
    def key(self) -> tuple[str, str, str, str, str]:
        """(airport, type, procedure, route type, transition): the sequence this leg belongs to."""
        return self.airport, self.proc_type, self.proc_id, self.route_type, self.transition


#: Section codes a leg's fix (cols 37-38) or RF centre (cols 115-116) may refer to.
FIX_SECTIONS = frozenset({"PC", "EA", "D ", "DB", "PN", "PG", "PA", "PI", "HC", "HA", "HG"})
#: Section codes of a recommended navaid (cols 79-80).
NAVAID_SECTIONS = frozenset({"D ", "DB", "PN", "PI"})
#: Altitude descriptors (col 83) :func:`fms_testbed.path.profile.window` knows.
ALT_DESCRIPTORS = frozenset(" +-@BCGHIJVXY")
#: Waypoint description code (cols 40-43), allowed characters per position (ARINC-424 5.17).
DESC_CODES = (frozenset(" ACEFGHNPRTUV"), frozenset(" BEUY"), frozenset(" ABCGMPRS"),
              frozenset(" ABCDEFHIMNPS"))
_ROUTE_TYPES = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789")
_TURNS, _TDV, _SPEED_DESC = frozenset("LRE "), frozenset("Y "), frozenset(" +-")
_PRIMARY, _SECTIONS, _SUBSECTIONS = frozenset("01"), frozenset({"P ", "H "}), frozenset("DEF")


def _ref(rec: str, a: int, ident_len: int, reg: int, sec: int, what: str,
         sections: frozenset, section_optional: bool = False,
         lone_region: bool = False) -> FixRef | None:
    """A fix reference (ident at ``a``, region at ``reg``, section at ``sec``), checked: the
    ident and region are letters and digits, the section one of ``sections`` (or blank when
    ``section_optional``); a blank ident has a blank section, and a blank region unless
    ``lone_region`` (the FAA CIFP 2301 leaves a region without its RF centre twice, a section
    off a recommended navaid three times)."""
    ident = read_ident(rec, a, a + ident_len - 1, f"{what} ident")
    region = read_ident(rec, reg, reg + 1, f"{what} region")
    section = rec[sec - 1:sec + 1]
    if not ident:
        if section.strip() or (region and not lone_region):
            raise FieldError(a, f"{what} ident", f"blank, but its region/section "
                                                 f"{region!r}/{section!r} are coded", sec + 1)
        return None
    if section.strip() or not section_optional:
        read_code(rec, sec, sec + 1, f"{what} section", sections)
    return FixRef(ident, region, section)


def _course(rec: str) -> tuple[float | None, bool]:
    """Course (cols 71-74), deg, and whether it is true ('DDDT') rather than magnetic."""
    raw = rec[70:74]
    if not raw.strip():
        return None, False
    if raw[3] == "T":
        if not raw[:3].isascii() or not raw[:3].isdigit():
            raise FieldError(71, "course", f"{raw!r} is not DDDT (true) in ASCII digits", 74)
        return float(in_range(int(raw[:3]), "true course", 71, 74, raw, "course")), True
    if not raw.isascii() or not raw.isdigit():
        raise FieldError(71, "course", f"{raw!r} is not tenths of a degree in 4 ASCII digits",
                         74)
    return in_range(int(raw), "course", 71, 74, raw) / 10.0, False


def _distance_time(rec: str) -> tuple[float | None, float | None]:
    """Distance (cols 75-78, tenths of a NM) in m, or time ('T' + tenths of a minute) in s."""
    raw = rec[74:78]
    if not raw.strip():
        return None, None
    if raw[0] == "T":
        if not raw[1:].isascii() or not raw[1:].isdigit():
            raise FieldError(75, "time", f"{raw!r} is not T + tenths of a minute in 3 ASCII "
                                         "digits", 78)
        return None, in_range(int(raw[1:]), "time", 75, 78, raw) * 6.0
    if not raw.isascii() or not raw.isdigit():
        raise FieldError(75, "distance", f"{raw!r} is not tenths of a NM in 4 ASCII digits", 78)
    return in_range(int(raw), "distance", 75, 78, raw) / 10.0 * NM_M, None


def _rnp(rec: str) -> float | None:
    """RNP (cols 45-47): two digits of mantissa and one of negative exponent, NM (> 0)."""
    raw = rec[44:47]
    if not raw.strip():
        return None
    if not raw.isascii() or not raw.isdigit():
        raise FieldError(45, "RNP", f"{raw!r} is not 3 ASCII digits", 47)
    if int(raw[:2]) == 0:
        raise FieldError(45, "RNP", f"{raw!r} codes an RNP of 0 NM", 47)
    return int(raw[:2]) * 10.0 ** (-int(raw[2]))


#: Fields of a procedure record, (first column, last column, name) 1-based, for naming the
#: field a bad character is in.
LEG_FIELDS = ((1, 1, "record type"), (2, 4, "area"), (5, 6, "section"), (7, 10, "airport ident"),
              (11, 12, "ICAO region"), (13, 13, "subsection"), (14, 19, "procedure ident"),
              (20, 20, "route type"), (21, 25, "transition ident"), (27, 29, "sequence number"),
              (30, 34, "fix ident"), (35, 36, "fix region"), (37, 38, "fix section"),
              (39, 39, "continuation number"), (40, 43, "waypoint description"),
              (44, 44, "turn direction"), (45, 47, "RNP"), (48, 49, "path terminator"),
              (50, 50, "turn direction valid"), (51, 54, "navaid ident"),
              (55, 56, "navaid region"), (57, 62, "arc radius"), (63, 66, "theta"),
              (67, 70, "rho"), (71, 74, "course"), (75, 78, "distance"),
              (79, 80, "navaid section"), (83, 83, "altitude descriptor"),
              (85, 89, "altitude 1"), (90, 94, "altitude 2"), (95, 99, "transition altitude"),
              (100, 102, "speed limit"), (103, 106, "vertical angle"),
              (107, 111, "centre fix ident"), (113, 114, "centre fix region"),
              (115, 116, "centre fix section"), (118, 118, "speed limit descriptor"),
              (124, 128, "file record number"), (129, 132, "cycle date"))


def check_leg_record(rec: str) -> None:
    """:func:`~.fields.check_record` for a procedure record: a bad character is reported
    under the field it is in (e.g. 'course', columns 71-74)."""
    try:
        check_record(rec)
    except FieldError as exc:
        if exc.field != "character set":
            raise
        for a, b, name in LEG_FIELDS:
            if a <= exc.column <= b:
                raise FieldError(exc.column, name, exc.reason) from None
        raise


def is_procedure_record(rec: str) -> bool:
    """Section/subsection (cols 5-6, 13) say SID, STAR or approach (airport or heliport)."""
    return rec[4:6] in ("P ", "H ") and rec[12:13] in ("D", "E", "F")


def read_key(rec: str) -> tuple[str, str, str, str, str]:
    """The transition a procedure record belongs to, checked: (airport, type 'D'/'E'/'F',
    procedure ident, route type, transition ident), as :attr:`LegRecord.key`.

    Raises
    ------
    FieldError
        when one of the key's fields (cols 5-25) is malformed.
    """
    if len(rec) < 29:
        raise FieldError(len(rec) + 1, "record length",
                         f"record has {len(rec)} columns, too few for its key (cols 5-29)")
    read_code(rec, 5, 6, "section", _SECTIONS)
    sub = read_code(rec, 13, 13, "subsection", _SUBSECTIONS)
    return (read_ident(rec, 7, 10, "airport ident", required=True), sub,
            read_ident(rec, 14, 19, "procedure ident", procedure=True, required=True),
            read_code(rec, 20, 20, "route type", _ROUTE_TYPES),
            read_ident(rec, 21, 25, "transition ident"))


def parse_leg(rec: str, line: int) -> LegRecord:
    """Parse one primary procedure record (132 columns) into a :class:`LegRecord`.

    Every field the testbed reads is checked for its format and range (:mod:`.fields`):
    the key (cols 5-29), fix, description code, turn direction, RNP, path terminator, navaid,
    arc radius, theta, rho, course, distance/time, altitude descriptor and altitudes,
    transition altitude, speed limit and its descriptor, vertical angle, RF centre.

    Raises
    ------
    FieldError
        naming the 1-based columns, the field and the reason when a field is malformed.
    """
    check_leg_record(rec)
    airport, sub, proc_id, route_type, transition = read_key(rec)
    read_code(rec, 39, 39, "continuation number", _PRIMARY)
    read_ident(rec, 11, 12, "ICAO region")
    seq = read_int(rec, 27, 29, "sequence number")
    if seq is None:
        raise FieldError(27, "sequence number", "is blank", 29)
    pt = read_code(rec, 48, 49, "path terminator", _PT_SET)
    desc = rec[39:43]
    for k, allowed in enumerate(DESC_CODES):
        if desc[k] not in allowed:
            read_code(rec, 40 + k, 40 + k, f"waypoint description {k + 1}", allowed)
    turn = read_code(rec, 44, 44, "turn direction", _TURNS)
    tdv = read_code(rec, 50, 50, "turn direction valid", _TDV)
    course, course_true = _course(rec)
    distance_m, time_s = _distance_time(rec)
    arc_r = read_int(rec, 57, 62, "arc radius")
    theta = read_int(rec, 63, 66, "theta")
    rho = read_int(rec, 67, 70, "rho")
    alt_desc = read_code(rec, 83, 83, "altitude descriptor", ALT_DESCRIPTORS)
    alt1, alt2 = parse_alt_ft(rec, 85, "altitude 1"), parse_alt_ft(rec, 90, "altitude 2")
    trans_alt = read_int(rec, 95, 99, "transition altitude")
    spd = read_int(rec, 100, 102, "speed limit")
    vpa = read_int(rec, 103, 106, "vertical angle", signed=True)
    speed_desc = read_code(rec, 118, 118, "speed limit descriptor", _SPEED_DESC)
    return LegRecord(
        airport=airport, proc_type=sub, proc_id=proc_id, route_type=route_type,
        transition=transition, seq=seq,
        fix=_ref(rec, 30, 5, 35, 37, "fix", FIX_SECTIONS), desc=desc, turn_dir=turn.strip(),
        rnp_nm=_rnp(rec), path_term=pt, turn_dir_valid=tdv == "Y",
        navaid=_ref(rec, 51, 4, 55, 79, "navaid", NAVAID_SECTIONS, section_optional=True),
        arc_radius_m=None if arc_r is None else arc_r / 1000.0 * NM_M,
        theta_deg=None if theta is None else theta / 10.0,
        rho_m=None if rho is None else rho / 10.0 * NM_M,
        course_deg=course, course_true=course_true, distance_m=distance_m, time_s=time_s,
        alt_desc=alt_desc.strip(), alt1_m=alt1, alt2_m=alt2,
        trans_alt_m=None if trans_alt is None else trans_alt * FT_M,
        speed_limit_mps=None if spd is None else spd * KT_MPS, speed_desc=speed_desc.strip(),
        vpa_deg=None if vpa is None else vpa / 100.0,
        centre=_ref(rec, 107, 5, 113, 115, "centre fix", FIX_SECTIONS, lone_region=True),
        heliport=rec[4] == "H",
        line=line)
