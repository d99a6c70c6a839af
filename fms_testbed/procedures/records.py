"""ARINC-424 (v18, 132-column) record layouts: fixes, airports, runways, procedure legs.

Column numbers in this module are 1-based as in the specification (see
``shared/notes/arinc424.md``). Values are converted to SI at parse time: altitudes to metres,
distances to metres, speeds to m/s, times to seconds; angles stay in degrees (``_deg``).
A malformed field raises :class:`RecordError` naming the column and the reason; the parser
turns it into a :class:`ParseIssue` and carries on with the next record.
"""

from __future__ import annotations

from dataclasses import dataclass

FT_M = 0.3048
NM_M = 1852.0
KT_MPS = 1852.0 / 3600.0


class RecordError(ValueError):
    """A field of one record is malformed: ``column`` (1-based) and ``reason``."""

    def __init__(self, column: int, reason: str):
        super().__init__(f"column {column}: {reason}")
        self.column = column
        self.reason = reason


@dataclass(frozen=True, slots=True)
class ParseIssue:
    """One rejected record: file, 1-based line, 1-based column, reason."""

    file: str
    line: int
    column: int
    reason: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: column {self.column}: {self.reason}"


def _f(rec: str, a: int, b: int) -> str:
    """Field between 1-based columns a..b inclusive, stripped."""
    return rec[a - 1:b].strip()


def _int(rec: str, a: int, b: int, what: str, signed: bool = False) -> int | None:
    s = rec[a - 1:b].strip()
    if not s:
        return None
    try:
        v = int(s)
    except ValueError:
        raise RecordError(a, f"{what} {s!r} is not a number") from None
    if v < 0 and not signed:
        raise RecordError(a, f"{what} {s!r} is negative")
    return v


def parse_lat(rec: str, col: int) -> float:
    """Latitude 'NDDMMSSss' at ``col`` (9 chars), deg."""
    s = rec[col - 1:col + 8]
    if len(s) < 9 or s[0] not in "NS" or not s[1:].isdigit():
        raise RecordError(col, f"latitude {s!r} is not N/S DDMMSSss")
    v = int(s[1:3]) + int(s[3:5]) / 60.0 + int(s[5:9]) / 360000.0
    if v > 90.0 or int(s[3:5]) >= 60:
        raise RecordError(col, f"latitude {s!r} out of range")
    return -v if s[0] == "S" else v


def parse_lon(rec: str, col: int) -> float:
    """Longitude 'EDDDMMSSss' at ``col`` (10 chars), deg."""
    s = rec[col - 1:col + 9]
    if len(s) < 10 or s[0] not in "EW" or not s[1:].isdigit():
        raise RecordError(col, f"longitude {s!r} is not E/W DDDMMSSss")
    v = int(s[1:4]) + int(s[4:6]) / 60.0 + int(s[6:10]) / 360000.0
    if v > 180.0 or int(s[4:6]) >= 60:
        raise RecordError(col, f"longitude {s!r} out of range")
    return -v if s[0] == "W" else v


def parse_magvar(rec: str, col: int) -> float:
    """Magnetic variation 'E0127' / 'W0127' (tenths of a degree) at ``col``, deg (east +).

    'T' (true-referenced station) and blank give 0.
    """
    s = rec[col - 1:col + 4]
    if not s.strip() or s[0] == "T":
        return 0.0
    if s[0] not in "EW" or not s[1:].strip().isdigit():
        raise RecordError(col, f"magnetic variation {s!r} is not E/W + tenths of a degree")
    v = int(s[1:]) / 10.0
    return v if s[0] == "E" else -v


def parse_alt_ft(rec: str, a: int) -> float | None:
    """Altitude field (5 chars) at column ``a``: feet, 'FL180', blank or 'UNKNN' -> None; returns m."""
    s = rec[a - 1:a + 4].strip()
    if not s or s in ("UNKNN", "NESTB"):
        return None
    if s.startswith("FL"):
        if not s[2:].isdigit():
            raise RecordError(a, f"flight level {s!r} is not FLnnn")
        return int(s[2:]) * 100 * FT_M
    try:
        return int(s) * FT_M
    except ValueError:
        raise RecordError(a, f"altitude {s!r} is neither feet nor FLnnn") from None


@dataclass(frozen=True, slots=True)
class Fix:
    """A point a leg can refer to (waypoint, navaid, runway threshold, airport reference point).

    ``section`` is the two-letter ARINC section/subsection ('EA', 'PC', 'D ', 'DB', 'PN', 'PG',
    'PA', 'PI'); ``magvar_deg`` east-positive (station declination for VHF navaids);
    ``elev_m`` elevation (runways: threshold), ``dme_*`` the DME antenna when it is elsewhere.
    """

    ident: str
    region: str
    section: str
    lat_deg: float
    lon_deg: float
    magvar_deg: float = 0.0
    elev_m: float | None = None
    airport: str = ""
    dme_lat_deg: float | None = None
    dme_lon_deg: float | None = None
    bearing_deg: float | None = None   # runway: magnetic bearing, deg
    length_m: float | None = None      # runway: length, m
    line: int = 0


def parse_waypoint(rec: str, line: int) -> Fix:
    """Enroute (EA) or terminal (PC / heliport HC) waypoint."""
    sec = "EA" if rec[4] == "E" else "PC"
    return Fix(ident=_f(rec, 14, 18), region=_f(rec, 20, 21), section=sec,
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 75), airport=_f(rec, 7, 10) if sec == "PC" else "",
               line=line)


def parse_vhf(rec: str, line: int) -> Fix:
    """VHF navaid (section D, subsection blank): VOR position, or the DME when VOR-less."""
    dme_lat = parse_lat(rec, 56) if rec[55].strip() else None
    dme_lon = parse_lon(rec, 65) if rec[64].strip() else None
    if rec[32].strip():
        lat, lon = parse_lat(rec, 33), parse_lon(rec, 42)
    elif dme_lat is not None and dme_lon is not None:
        lat, lon = dme_lat, dme_lon
    else:
        raise RecordError(33, "VHF navaid without VOR or DME position")
    elev = _int(rec, 80, 84, "DME elevation", signed=True)
    return Fix(ident=_f(rec, 14, 17), region=_f(rec, 20, 21), section="D ",
               lat_deg=lat, lon_deg=lon, magvar_deg=parse_magvar(rec, 75),
               elev_m=None if elev is None else elev * FT_M, airport=_f(rec, 7, 10),
               dme_lat_deg=dme_lat, dme_lon_deg=dme_lon, line=line)


def parse_ndb(rec: str, line: int) -> Fix:
    """NDB: enroute (DB) or terminal (PN)."""
    sec = "PN" if rec[4] == "P" else "DB"
    return Fix(ident=_f(rec, 14, 17), region=_f(rec, 20, 21), section=sec,
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 75), airport=_f(rec, 7, 10), line=line)


def parse_airport(rec: str, line: int) -> Fix:
    """Airport (PA) or heliport (HA) reference point; magvar at 52, elevation at 57."""
    elev = _int(rec, 57, 61, "airport elevation", signed=True)
    return Fix(ident=_f(rec, 7, 10), region=_f(rec, 11, 12), section="PA",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 52), elev_m=None if elev is None else elev * FT_M,
               airport=_f(rec, 7, 10), line=line)


def parse_runway(rec: str, line: int) -> Fix:
    """Runway threshold (PG): bearing (magnetic, tenths) at 28, threshold elevation at 67."""
    brg = _int(rec, 28, 31, "runway bearing")
    length = _int(rec, 23, 27, "runway length")
    elev = _int(rec, 67, 71, "threshold elevation", signed=True)
    return Fix(ident=_f(rec, 14, 18), region=_f(rec, 11, 12), section="PG",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               elev_m=None if elev is None else elev * FT_M, airport=_f(rec, 7, 10),
               bearing_deg=None if brg is None else brg / 10.0,
               length_m=None if length is None else length * FT_M, line=line)


def parse_localizer(rec: str, line: int) -> Fix:
    """Localizer/glide slope (PI): localizer antenna at 33, bearing at 52, declination at 91."""
    return Fix(ident=_f(rec, 14, 17), region=_f(rec, 11, 12), section="PI",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 91), airport=_f(rec, 7, 10), line=line)
