"""Writers of synthetic ARINC-424 records (132 columns) for tests and worked examples.

They write the same columns the parser reads, so a test can state a procedure in aviation
units (ft, kt, NM, tenths of a degree), write it to a file, load it with
:func:`~.database.load_database` and check what the builder makes of it. Leg types that never
occur in FAA data (FD, CR) are tested this way.
"""

from __future__ import annotations

from pathlib import Path

from fms_testbed.core.geodesy import direct
from fms_testbed.core.units import NM_M


def _put(buf: list[str], col: int, text: str) -> None:
    """Write ``text`` starting at 1-based column ``col``."""
    for k, ch in enumerate(text):
        buf[col - 1 + k] = ch


def _blank(area: str = "USA") -> list[str]:
    buf = [" "] * 132
    _put(buf, 1, "S" + area)
    return buf


def fmt_lat(lat_deg: float) -> str:
    """'NDDMMSSss' (hundredths of a second)."""
    h = "N" if lat_deg >= 0 else "S"
    v = round(abs(lat_deg) * 360000)
    d, r = divmod(v, 360000)
    m, cs = divmod(r, 6000)
    return f"{h}{d:02d}{m:02d}{cs:04d}"


def fmt_lon(lon_deg: float) -> str:
    """'EDDDMMSSss' (hundredths of a second)."""
    h = "E" if lon_deg >= 0 else "W"
    v = round(abs(lon_deg) * 360000)
    d, r = divmod(v, 360000)
    m, cs = divmod(r, 6000)
    return f"{h}{d:03d}{m:02d}{cs:04d}"


def fmt_var(var_deg: float) -> str:
    """'E0127' style magnetic variation (tenths of a degree)."""
    return f"{'E' if var_deg >= 0 else 'W'}{round(abs(var_deg) * 10):04d}"


def airport_record(ident: str, lat: float, lon: float, var_deg: float = 0.0,
                   elev_ft: int = 0, region: str = "K1") -> str:
    """Airport reference point (PA)."""
    b = _blank()
    _put(b, 5, "P ")
    _put(b, 7, f"{ident:<4}")
    _put(b, 11, region)
    _put(b, 13, "A")
    _put(b, 22, "0")
    _put(b, 33, fmt_lat(lat))
    _put(b, 42, fmt_lon(lon))
    _put(b, 52, fmt_var(var_deg))
    _put(b, 57, f"{elev_ft:05d}")
    return "".join(b)


def runway_record(airport: str, ident: str, lat: float, lon: float, bearing_deg: float,
                  length_ft: int = 8000, elev_ft: int = 0, region: str = "K1",
                  tch_ft: int | None = None) -> str:
    """Runway threshold (PG); ``bearing_deg`` magnetic; ``tch_ft`` threshold crossing height
    (cols. 76-77), ft."""
    b = _blank()
    _put(b, 5, "P ")
    _put(b, 7, f"{airport:<4}")
    _put(b, 11, region)
    _put(b, 13, "G")
    _put(b, 14, f"{ident:<5}")
    _put(b, 22, "0")
    _put(b, 23, f"{length_ft:05d}")
    _put(b, 28, f"{round(bearing_deg * 10):04d}")
    _put(b, 33, fmt_lat(lat))
    _put(b, 42, fmt_lon(lon))
    _put(b, 67, f"{elev_ft:05d}")
    if tch_ft is not None:
        _put(b, 76, f"{tch_ft:02d}")
    return "".join(b)


def waypoint_record(ident: str, lat: float, lon: float, region: str = "K1",
                    airport: str | None = None) -> str:
    """Terminal waypoint (PC, with ``airport``) or enroute waypoint (EA)."""
    b = _blank()
    if airport:
        _put(b, 5, "P ")
        _put(b, 7, f"{airport:<4}")
        _put(b, 11, region)
        _put(b, 13, "C")
    else:
        _put(b, 5, "EA")
        _put(b, 7, "ENRT")
    _put(b, 14, f"{ident:<5}")
    _put(b, 20, region)
    _put(b, 22, "0")
    _put(b, 33, fmt_lat(lat))
    _put(b, 42, fmt_lon(lon))
    _put(b, 75, fmt_var(0.0))
    return "".join(b)


def vor_record(ident: str, lat: float, lon: float, var_deg: float = 0.0,
               region: str = "K1") -> str:
    """VOR/DME (section D) with co-located DME."""
    b = _blank()
    _put(b, 5, "D ")
    _put(b, 14, f"{ident:<4}")
    _put(b, 20, region)
    _put(b, 22, "0")
    _put(b, 23, "11370")
    _put(b, 28, "VDHW ")
    _put(b, 33, fmt_lat(lat))
    _put(b, 42, fmt_lon(lon))
    _put(b, 56, fmt_lat(lat))
    _put(b, 65, fmt_lon(lon))
    _put(b, 75, fmt_var(var_deg))
    return "".join(b)


def _put_numbers(b: list[str], arc_radius_nm, theta_deg, rho_nm, course_deg, distance_nm,
                 time_min) -> None:
    """The numeric fields of a leg record, cols 57-78 (each left blank when None): radius
    (thousandths of NM), theta and rho (tenths), course (tenths of a degree), distance (tenths
    of NM) or time ('T' + tenths of a minute)."""
    if arc_radius_nm is not None:
        _put(b, 57, f"{round(arc_radius_nm * 1000):06d}")
    if theta_deg is not None:
        _put(b, 63, f"{round(theta_deg * 10):04d}")
    if rho_nm is not None:
        _put(b, 67, f"{round(rho_nm * 10):04d}")
    if course_deg is not None:
        _put(b, 71, f"{round(course_deg * 10) % 3600:04d}")
    if distance_nm is not None:
        _put(b, 75, f"{round(distance_nm * 10):04d}")
    elif time_min is not None:
        _put(b, 75, f"T{round(time_min * 10):03d}")


def leg_record(airport: str, proc: str, pt: str, seq: int, *, proc_type: str = "F",
               transition: str = "", route_type: str = "R", fix: str = "",
               fix_section: str = "EA", region: str = "K1", desc: str = "E   ",
               turn: str = " ", navaid: str = "", navaid_section: str = "D ",
               arc_radius_nm: float | None = None, theta_deg: float | None = None,
               rho_nm: float | None = None, course_deg: float | None = None,
               distance_nm: float | None = None, time_min: float | None = None,
               alt_desc: str = " ", alt1_ft: int | None = None, alt2_ft: int | None = None,
               speed_kt: int | None = None, speed_desc: str = " ", centre: str = "",
               centre_section: str = "EA", vpa_deg: float | None = None) -> str:
    """One primary procedure leg record (PD/PE/PF) in ARINC-424 columns (``vpa_deg``: the
    vertical angle, col. 103-106, negative descending, deg)."""
    b = _blank()
    _put(b, 5, "P ")
    _put(b, 7, f"{airport:<4}")
    _put(b, 11, region)
    _put(b, 13, proc_type)
    _put(b, 14, f"{proc:<6}")
    _put(b, 20, route_type)
    _put(b, 21, f"{transition:<5}")
    _put(b, 27, f"{seq:03d}")
    if fix:
        _put(b, 30, f"{fix:<5}")
        _put(b, 35, region)
        _put(b, 37, fix_section)
    _put(b, 39, "0")
    _put(b, 40, f"{desc:<4}")
    _put(b, 44, turn)
    _put(b, 48, pt)
    if navaid:
        _put(b, 51, f"{navaid:<4}")
        _put(b, 55, region)
        _put(b, 79, navaid_section)
    _put_numbers(b, arc_radius_nm, theta_deg, rho_nm, course_deg, distance_nm, time_min)
    _put(b, 83, alt_desc)
    if alt1_ft is not None:
        _put(b, 85, f"{alt1_ft:05d}")
    if alt2_ft is not None:
        _put(b, 90, f"{alt2_ft:05d}")
    if speed_kt is not None:
        _put(b, 100, f"{speed_kt:03d}")
    if vpa_deg is not None:
        v = round(vpa_deg * 100)
        _put(b, 103, f"-{-v:03d}" if v < 0 else f"{v:04d}")
    if centre:
        _put(b, 107, f"{centre:<5}")
        _put(b, 113, region)
        _put(b, 115, centre_section)
    _put(b, 118, speed_desc)
    return "".join(b)


def offset(lat: float, lon: float, az_deg: float, dist_nm: float) -> tuple[float, float]:
    """Point ``dist_nm`` NM from (lat, lon) on azimuth ``az_deg``, deg."""
    la, lo, _ = direct(lat, lon, az_deg, dist_nm * NM_M)
    return la, lo


def write_file(path: str | Path, records: list[str]) -> Path:
    """Write records (one per line) to an ARINC-424 file."""
    path = Path(path)
    path.write_text("".join(r + "\n" for r in records), encoding="latin-1")
    return path
