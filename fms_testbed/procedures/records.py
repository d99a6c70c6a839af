"""ARINC-424 (v18, 132-column) record layouts: fixes, airports, runways, procedure legs.

Column numbers in this module are 1-based as in the specification (see
``shared/notes/arinc424.md``). Values are converted to SI at parse time: altitudes to metres,
distances to metres, speeds to m/s, times to seconds; angles stay in degrees (``_deg``).
A malformed field raises :class:`~.fields.FieldError` naming the columns, the field and the
reason (formats and ranges in :mod:`.fields`); the loader turns it into a
:class:`~.fields.RecordError` and carries on with the next record.
"""

from __future__ import annotations

from dataclasses import dataclass

from fms_testbed.core.units import FT_M, KT_MPS, NM_M  # noqa: F401 (re-exported)
from fms_testbed.procedures.fields import (FieldError, RecordError, parse_alt_ft,  # noqa: F401
                                           parse_lat, parse_lon, parse_magvar, read_ident,
                                           read_int)

ParseIssue = RecordError
"""Former name of :class:`~.fields.RecordError` (one rejected record)."""


def _f(rec: str, a: int, b: int) -> str:
    """Field between 1-based columns a..b inclusive, stripped."""
    return rec[a - 1:b].strip()


def _int(rec: str, a: int, b: int, what: str, signed: bool = False,
         rng: str | None = None) -> int | None:
    """:func:`~.fields.read_int` (blank -> None; ASCII digits; range ``RANGES[rng or what]``)."""
    return read_int(rec, a, b, what, signed, rng)


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
    name: str = ""                     # airport/heliport: name (cols 94-123)
    tch_m: float | None = None         # runway: threshold crossing height (cols 76-77), m


def parse_waypoint(rec: str, line: int) -> Fix:
    """Enroute (EA) or terminal (PC / heliport HC) waypoint."""
    sec = "EA" if rec[4] == "E" else "PC"
    return Fix(ident=read_ident(rec, 14, 18, "waypoint ident", required=True),
               region=read_ident(rec, 20, 21, "ICAO region"), section=sec,
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 75),
               airport=read_ident(rec, 7, 10, "airport ident") if sec == "PC" else "",
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
        raise FieldError(33, "VOR/DME position", "VHF navaid without VOR or DME position", 74)
    elev = _int(rec, 80, 84, "DME elevation", signed=True, rng="elevation")
    return Fix(ident=read_ident(rec, 14, 17, "navaid ident", required=True),
               region=read_ident(rec, 20, 21, "ICAO region"), section="D ",
               lat_deg=lat, lon_deg=lon, magvar_deg=parse_magvar(rec, 75),
               elev_m=None if elev is None else elev * FT_M,
               airport=read_ident(rec, 7, 10, "airport ident"), dme_lat_deg=dme_lat,
               dme_lon_deg=dme_lon, line=line)


def parse_ndb(rec: str, line: int) -> Fix:
    """NDB: enroute (DB) or terminal (PN)."""
    sec = "PN" if rec[4] == "P" else "DB"
    return Fix(ident=read_ident(rec, 14, 17, "NDB ident", required=True),
               region=read_ident(rec, 20, 21, "ICAO region"), section=sec,
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 75), airport=read_ident(rec, 7, 10, "airport ident"),
               line=line)


def parse_airport(rec: str, line: int) -> Fix:
    """Airport (PA) or heliport (HA) reference point; magvar at 52, elevation at 57."""
    elev = _int(rec, 57, 61, "airport elevation", signed=True, rng="elevation")
    return Fix(ident=read_ident(rec, 7, 10, "airport ident", required=True),
               region=read_ident(rec, 11, 12, "ICAO region"), section="PA",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 52), elev_m=None if elev is None else elev * FT_M,
               airport=_f(rec, 7, 10), line=line, name=_f(rec, 94, 123))


def parse_runway(rec: str, line: int) -> Fix:
    """Runway threshold (PG): bearing (magnetic, tenths) at 28, threshold elevation at 67,
    threshold crossing height (ft) at 76-77."""
    brg = _int(rec, 28, 31, "runway bearing")
    # lenient: a blank or non-numeric TCH leaves the threshold usable (no TCH known)
    tch_txt = _f(rec, 76, 77)
    tch = int(tch_txt) if tch_txt.isascii() and tch_txt.isdigit() else None
    length = _int(rec, 23, 27, "runway length")
    elev = _int(rec, 67, 71, "threshold elevation", signed=True, rng="elevation")
    return Fix(ident=read_ident(rec, 14, 18, "runway ident", required=True),
               region=read_ident(rec, 11, 12, "ICAO region"), section="PG",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               elev_m=None if elev is None else elev * FT_M,
               airport=read_ident(rec, 7, 10, "airport ident", required=True),
               bearing_deg=None if brg is None else brg / 10.0,
               length_m=None if length is None else length * FT_M, line=line,
               tch_m=None if tch is None else tch * FT_M)


def parse_localizer(rec: str, line: int) -> Fix:
    """Localizer/glide slope (PI): localizer antenna at 33, bearing at 52, declination at 91."""
    return Fix(ident=read_ident(rec, 14, 17, "localizer ident", required=True),
               region=read_ident(rec, 11, 12, "ICAO region"), section="PI",
               lat_deg=parse_lat(rec, 33), lon_deg=parse_lon(rec, 42),
               magvar_deg=parse_magvar(rec, 91),
               airport=read_ident(rec, 7, 10, "airport ident", required=True), line=line)
