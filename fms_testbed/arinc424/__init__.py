"""ARINC-424 procedure database: parser, the 23 path terminators, segmentation, monitor.

Typical use::

    from fms_testbed.arinc424 import load_database, build_sequence, check_path, Performance
    from fms_testbed.aircraft import load_aircraft

    db = load_database()                       # embedded excerpt; or a path to a CIFP file
    perf = Performance.from_aircraft(load_aircraft("737"))
    for seq in db.select("KJFK", "DEEZZ5"):
        path = check_path(build_sequence(db, seq, perf), perf)
        print(path.name, path.status, [f.message for f in path.findings])

``path.segments`` are :class:`fms_testbed.path.Line`/:class:`~fms_testbed.path.Arc` tagged with
their leg; ``path.legs[i].termination`` says how each leg ends; ``path.profile`` is the planned
vertical profile. See the README section "ARINC-424 procedures".
"""

from .database import Database, Sequence, load_database
from .legs import LEG_TYPES
from .model import (BuildParams, BuiltLeg, Finding, FlightState, PathSegment, Performance,
                    ProcedurePath, Termination)
from .monitor import check_path
from .segmentation import build_sequence

__all__ = ["LEG_TYPES", "BuildParams", "BuiltLeg", "Database", "Finding", "FlightState",
           "PathSegment", "Performance", "ProcedurePath", "Sequence", "Termination",
           "build_sequence", "check_path", "load_database"]
