"""The phase-1 test database (Danilin, seed 000): about 50 synthesised procedures with the
outcome each is designed to have, written beside it as a manifest.

Danilin's method flies a test database of ~50 synthesised procedures first; only when its
residual error rate is acceptable does the software go on to the integration phase (~100
airports, > 5,000 procedure flights). This module states that database: two synthetic
airports (``XTDA``, magnetic variation 0°; ``XTDB``, variation 10° E so its magnetic courses
must be turned true), their runways, VOR/DMEs and fixes, and SIDs, STARs and approaches that
together fly every one of the 23 path terminators and the leg combinations that matter
(CA→DF, VI/CI→CF intercepts, VA→VM, FM→HM, IF→AF, TF→RF→TF, PI then the final, hold entries
from each ICAO sector, CF after DF, every altitude descriptor, speed limits, fly-over and
fly-by), approaches with missed-approach legs (parsed, not flown: an approach ends at the
MAP), and deliberately miscoded procedures — Danilin's class 3, database coding errors — each
with what the monitor should say.

Every expectation is design intent, stated here before any flight (module
:data:`PROCEDURES`, field ``expect``); the campaign check (:mod:`fms_testbed.campaign.manifest`)
compares a run's outcomes with it. Expectation kinds:

* ``fly`` — a valid procedure: flown to its end with a status in ``status`` (``ok``) and the
  monitor's verdict in ``monitor`` (``ok``; ``corrected`` where a correction is designed in),
  the finding text matching ``says`` when given;
* ``refuse`` — a coding error the software must not fly: status ``impossible`` (the builder or
  the monitor refuses) or ``degraded`` (a record rejected, a sequence number repeated), the
  reason matching ``says``;
* ``flag`` — a coding error that can be flown but must be reported: whatever the flight's
  status, the monitor's findings (or the refusal's reason) match ``says``.

Geometry: every fix is placed by bearing (deg true) and distance (NM) from an airport or
another fix (:func:`world`), so the database is self-contained and parses with
:func:`~fms_testbed.procedures.database.load_database`.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from pathlib import Path

from fms_testbed.procedures.synth import (airport_record, leg_record, runway_record,
                                          vor_record, waypoint_record)
from fms_testbed.procedures.testdb_cases import PROCEDURES  # noqa: F401 (re-export)
from fms_testbed.procedures.testdb_world import (  # noqa: F401 (re-export)
    AIRPORTS, RUNWAY_LENGTH_FT, RUNWAYS, VORS, TestProcedure, world)

MANIFEST_KIND = "fms-testbed-testdb-manifest"
"""``kind`` of a test-database manifest."""
MANIFEST_VERSION = 1


def _fix_records(pts: dict) -> list[str]:
    out = []
    for ident, apt in VORS.items():
        out.append(vor_record(ident, *pts[ident], var_deg=AIRPORTS[apt][2]))
    skip = {"APT_A", "APT_B", "RW09", "RW27", "RWB09"} | set(VORS)
    for name in sorted(pts):
        if name not in skip:
            out.append(waypoint_record(name, *pts[name]))
    return out


def _airport_records(pts: dict) -> list[str]:
    out = []
    for icao, (lat, lon, var) in AIRPORTS.items():
        out.append(airport_record(icao, lat, lon, var_deg=var))
        for (apt, rwy), (pt, brg) in RUNWAYS.items():
            if apt == icao:
                out.append(runway_record(icao, rwy, *pts[pt], brg, length_ft=RUNWAY_LENGTH_FT))
    return out


def procedure_records(proc: TestProcedure) -> list[str]:
    """The leg records of one procedure, in file order (sequence numbers 010, 020, ...).

    Parameters
    ----------
    proc : the procedure
    """
    out = []
    for part in proc.parts:
        for k, lg in enumerate(part.legs):
            rec = leg_record(proc.airport, proc.ident, lg.pt, lg.seq or 10 * (k + 1),
                             proc_type=proc.subsection, transition=part.transition,
                             route_type=part.route_type, **lg.kw)
            if lg.corrupt:
                col, text = lg.corrupt
                rec = rec[:col - 1] + text + rec[col - 1 + len(text):]
            out.append(rec)
    return out


def records() -> list[str]:
    """Every record of the test database: navaids and fixes, airports and runways, then the
    procedures (each transition's records consecutive)."""
    pts = world()
    out = _fix_records(pts) + _airport_records(pts)
    for icao in AIRPORTS:
        for sub in "DEF":
            for p in PROCEDURES:
                if p.airport == icao and p.subsection == sub:
                    out += procedure_records(p)
    return out


def manifest(db_sha256: str) -> dict:
    """The manifest of the test database (design intent; module docstring).

    Parameters
    ----------
    db_sha256 : SHA-256 of the written database file (the check refuses another file)
    """
    entries = []
    for p in PROCEDURES:
        runway, trans = p.case_key()
        e = asdict(p.expect)
        e["status"], e["monitor"] = list(e["status"]), list(e["monitor"])
        entries.append({"airport": p.airport, "type": p.type, "procedure": p.ident,
                        "runway": runway, "transition": trans, "purpose": p.purpose,
                        "combinations": list(p.combos),
                        "coding": "valid" if p.expect.kind == "fly" else "miscoded",
                        "flown_legs": " ".join(p.flown_legs()),
                        "coded_legs": " ".join(p.coded_legs()), "expect": e})
    return {"kind": MANIFEST_KIND, "version": MANIFEST_VERSION, "database_sha256": db_sha256,
            "airports": list(AIRPORTS), "procedures": entries}


def manifest_path(db_path: str | Path) -> Path:
    """Where the manifest of a database file is: beside it, ``FILE.manifest.json``.

    Parameters
    ----------
    db_path : the database file
    """
    db_path = Path(db_path)
    return db_path.with_name(db_path.name + ".manifest.json")


def write_testdb(path: str | Path) -> tuple[Path, Path]:
    """Write the test database (132-column records) and its manifest beside it.

    Parameters
    ----------
    path : the database file to write (its folder must exist)

    Returns
    -------
    (database path, manifest path)
    """
    path = Path(path)
    data = "".join(r + "\n" for r in records()).encode("latin-1")
    path.write_bytes(data)
    mpath = manifest_path(path)
    mpath.write_text(json.dumps(manifest(hashlib.sha256(data).hexdigest()), indent=1,
                                ensure_ascii=False) + "\n", encoding="utf-8")
    return path, mpath


__all__ = ["AIRPORTS", "MANIFEST_KIND", "MANIFEST_VERSION", "PROCEDURES", "Expect", "Leg",
           "Part", "TestProcedure", "manifest", "manifest_path", "procedure_records", "records",
           "world", "write_testdb"]
