"""path/monitor._long_way_turns: a TF/CF whose coded turn direction makes it turn the long way
round (more than 270° for a track change under 90°) is reported (Danilin class 3); a course
reversal is not."""

from __future__ import annotations

import pytest

from fms_testbed.legs.model import Performance
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.testdb import write_testdb


@pytest.fixture(scope="module")
def testdb(tmp_path_factory):
    path, _ = write_testdb(tmp_path_factory.mktemp("tdb") / "testdb.dat")
    return load_database(path)


def _checked(db, airport, name):
    perf = Performance.from_aircraft(load_aircraft("737"))
    seq = next(s for s in db.sequences(airport) if s.name == name)
    return check_path(build_sequence(db, seq, perf), perf)


def _long_way(p):
    return [f for f in p.findings if "short way" in f.message]


def test_tf_coded_to_turn_the_long_way_is_reported(testdb):
    """XTURN: a TF coded to turn right where the track turns 45° left."""
    p = _checked(testdb, "XTDA", "XTDA SID XTURN RW09")
    found = _long_way(p)
    assert len(found) == 1 and found[0].danilin_class == 3, p.findings
    assert "right turn" in found[0].message


def test_legs_turning_the_short_way_are_not_reported(testdb):
    """Every valid procedure of the test database (designed to turn the way it is coded)."""
    from fms_testbed.procedures.testdb import PROCEDURES

    for tp in PROCEDURES:
        if tp.expect.kind != "fly":
            continue
        db_airport = tp.airport
        names = [s.name for s in testdb.sequences(db_airport)
                 if s.name.split()[2] == tp.ident]
        for name in names:
            assert not _long_way(_checked(testdb, db_airport, name)), name
