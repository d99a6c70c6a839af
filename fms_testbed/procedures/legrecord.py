"""The procedure leg record (PD/PE/PF, heliport HD/HE/HF): one primary record per leg.

Columns follow ``shared/notes/arinc424.md``. Altitudes are returned in metres, distances in
metres, times in seconds, speeds in m/s; courses stay in degrees with a flag saying whether
they are true or magnetic (turned true later with the station/airport variation).
"""

from __future__ import annotations

from dataclasses import dataclass

from fms_testbed.procedures.records import FT_M, KT_MPS, NM_M, RecordError, _int, parse_alt_ft

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


def _ref(rec: str, a: int, ident_len: int, reg: int, sec: int) -> FixRef | None:
    ident = rec[a - 1:a - 1 + ident_len].strip()
    if not ident:
        return None
    return FixRef(ident, rec[reg - 1:reg + 1].strip(), rec[sec - 1:sec + 1].upper())


def parse_leg(rec: str, line: int) -> LegRecord:
    """Parse one primary procedure record (132 columns) into a :class:`LegRecord`.

    Raises
    ------
    RecordError
        naming the 1-based column and the reason when a field is malformed.
    """
    if len(rec) < 120:
        raise RecordError(len(rec) + 1, f"record has {len(rec)} columns, expected 132")
    pt = rec[47:49]
    if pt not in _PT_SET:
        raise RecordError(48, f"unknown path terminator {pt!r}")
    seq = _int(rec, 27, 29, "sequence number")
    if seq is None:
        raise RecordError(27, "missing sequence number")
    crs_s = rec[70:74]
    course, course_true = None, False
    if crs_s.strip():
        if crs_s[3] == "T":
            course_true = True
            crs_s = crs_s[:3] + "0"
            digits = crs_s[:3]
            if not digits.strip().isdigit():
                raise RecordError(71, f"course {rec[70:74]!r} is not tenths of a degree")
            course = float(int(digits))
        else:
            if not crs_s.strip().isdigit():
                raise RecordError(71, f"course {crs_s!r} is not tenths of a degree")
            course = int(crs_s) / 10.0
        if course > 360.0:
            raise RecordError(71, f"course {course} deg above 360")
    dist_s = rec[74:78]
    distance_m = time_s = None
    if dist_s.strip():
        if dist_s[0] == "T":
            if not dist_s[1:].strip().isdigit():
                raise RecordError(75, f"time {dist_s!r} is not T + tenths of a minute")
            time_s = int(dist_s[1:]) * 6.0
        else:
            if not dist_s.strip().isdigit():
                raise RecordError(75, f"distance {dist_s!r} is not tenths of a NM")
            distance_m = int(dist_s) / 10.0 * NM_M
    arc_r = _int(rec, 57, 62, "arc radius")
    theta = _int(rec, 63, 66, "theta")
    rho = _int(rec, 67, 70, "rho")
    spd = _int(rec, 100, 102, "speed limit")
    vpa = _int(rec, 103, 106, "vertical angle", signed=True)
    rnp_s = rec[44:47].strip()
    rnp = None
    if rnp_s:
        if not rnp_s.isdigit() or len(rnp_s) != 3:
            raise RecordError(45, f"RNP {rnp_s!r} is not 3 digits")
        rnp = int(rnp_s[:2]) * 10.0 ** (-int(rnp_s[2]))
    turn = rec[43]
    if turn not in "LRE ":
        raise RecordError(44, f"turn direction {turn!r} is not L, R or E")
    sub = rec[12]
    return LegRecord(
        airport=rec[6:10].strip(), proc_type=sub, proc_id=rec[13:19].strip(),
        route_type=rec[19], transition=rec[20:25].strip(), seq=seq,
        fix=_ref(rec, 30, 5, 35, 37), desc=rec[39:43], turn_dir=turn.strip(),
        rnp_nm=rnp, path_term=pt, turn_dir_valid=rec[49] == "Y",
        navaid=_ref(rec, 51, 4, 55, 79),
        arc_radius_m=None if arc_r is None else arc_r / 1000.0 * NM_M,
        theta_deg=None if theta is None else theta / 10.0,
        rho_m=None if rho is None else rho / 10.0 * NM_M,
        course_deg=course, course_true=course_true, distance_m=distance_m, time_s=time_s,
        alt_desc=rec[82].strip(), alt1_m=parse_alt_ft(rec, 85), alt2_m=parse_alt_ft(rec, 90),
        trans_alt_m=None if (t := _int(rec, 95, 99, "transition altitude")) is None else t * FT_M,
        speed_limit_mps=None if spd is None else spd * KT_MPS, speed_desc=rec[117].strip(),
        vpa_deg=None if vpa is None else vpa / 100.0,
        centre=_ref(rec, 107, 5, 113, 115), heliport=rec[4] == "H", line=line)
