"""ARINC-424 parsing: field decoding on real records, clear errors, fuzzed files still load."""

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.procedures.database import load_database
from fms_testbed.procedures.legrecord import parse_leg
from fms_testbed.procedures.fields import FieldError, parse_lat
from fms_testbed.core.errors import UserError
from fms_testbed.core.units import FT_M, NM_M
from fms_testbed.data import procedures_dir

EXCERPT = procedures_dir() / "cifp_excerpt.dat"
# Real records from the FAA CIFP 2301 (public domain).
VA = ("SUSAP KJFKK6DDEEZZ54RW04B 010         0        VA                     0438        + 00520"
      "     18000                        241211808")
RF = ("SCANP PAFAPAFH02LZ AGLDHL 040OKXACPAPC0E   L010RF       0025001938    12030032    + 03200"
      "                 CFNRF PAPCA FS   073392108")
HM = ("SCANP PABEPAFI19RZ I      060ROLLRPAEA0EE  R   HM                     0972T010    + 02000"
      "                           0 DS   054981208")


def test_va_record_fields():
    leg = parse_leg(VA, 7)
    assert (leg.airport, leg.proc_type, leg.proc_id, leg.transition) == ("KJFK", "D", "DEEZZ5", "RW04B")
    assert leg.path_term == "VA" and leg.seq == 10
    assert leg.course_deg == pytest.approx(43.8) and not leg.course_true
    assert leg.alt_desc == "+" and leg.alt1_m == pytest.approx(520 * FT_M)
    assert leg.trans_alt_m == pytest.approx(18000 * FT_M)
    assert leg.fix is None and leg.line == 7


def test_rf_record_fields():
    leg = parse_leg(RF, 1)
    assert leg.path_term == "RF" and leg.turn_dir == "L"
    assert leg.arc_radius_m == pytest.approx(2.5 * NM_M)
    assert leg.centre.ident == "CFNRF" and leg.centre.section == "PC"
    assert leg.fix.ident == "OKXAC" and leg.rnp_nm == pytest.approx(1.0)  # "010" = 01 x 10^-0
    assert leg.course_deg == pytest.approx(120.3)


def test_hold_time_is_in_seconds_and_turn_direction_kept():
    leg = parse_leg(HM, 1)
    assert leg.time_s == pytest.approx(60.0) and leg.distance_m is None
    assert leg.turn_dir == "R" and leg.course_deg == pytest.approx(97.2)


def test_flight_level_altitude():
    rec = VA[:84] + "FL180" + VA[89:]
    assert parse_leg(rec, 1).alt1_m == pytest.approx(18000 * FT_M)


def test_bad_path_terminator_names_column_48():
    with pytest.raises(FieldError) as e:
        parse_leg(VA[:47] + "ZZ" + VA[49:], 1)
    assert e.value.column == 48 and "ZZ" in e.value.reason


def test_bad_latitude_names_the_column():
    with pytest.raises(FieldError) as e:
        parse_lat("x" * 32 + "N4X382374", 33)
    assert e.value.column == 33


def test_missing_file_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="cannot read"):
        load_database(tmp_path / "none.dat")


def test_malformed_record_is_reported_and_the_rest_loads(tmp_path):
    lines = EXCERPT.read_text(encoding="latin-1").splitlines()
    k = next(i for i, r in enumerate(lines) if r[4:6] == "P " and r[12] == "D")
    lines[k] = lines[k][:70] + "12X4" + lines[k][74:]
    f = tmp_path / "bad.dat"
    f.write_text("\n".join(lines) + "\n", encoding="latin-1")
    db = load_database(f)
    apt = lines[k][6:10].strip()
    db.sequences(apt)
    assert len(db.issues) == 1
    issue = db.issues[0]
    assert issue.line == k + 1 and issue.column == 71 and issue.field == "course"
    assert str(f) in str(issue)
    good = load_database(EXCERPT)
    n_good = sum(len(s.legs) for s in good.sequences(apt))
    assert sum(len(s.legs) for s in db.sequences(apt)) == n_good - 1


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 40))
def test_fuzzed_file_still_loads_and_every_issue_points_at_a_corrupted_line(tmp_path_factory,
                                                                          seed, n):
    rng = random.Random(seed)
    lines = EXCERPT.read_text(encoding="latin-1").splitlines()
    bad = set()
    for _ in range(n):
        k = rng.randrange(5, len(lines))
        rec = list(lines[k])
        if rng.random() < 0.2:
            rec = rec[:rng.randrange(10, 120)]            # truncated record
        else:
            for _ in range(rng.randint(1, 4)):
                rec[rng.randrange(len(rec))] = rng.choice("X9- /T.N")
        lines[k] = "".join(rec)
        bad.add(k + 1)
    f = tmp_path_factory.mktemp("fuzz") / "fuzz.dat"
    f.write_text("\n".join(lines) + "\n", encoding="latin-1")
    db = load_database(f)
    n_legs = 0
    for apt in db.airport_idents():
        n_legs += sum(len(s.legs) for s in db.sequences(apt))
    assert n_legs > 0
    for issue in db.issues:
        # a continuation record is reported when the primary before it was changed into a
        # different leg (its own line is intact)
        assert issue.line in bad or (issue.field == "continuation number"
                                     and issue.line - 1 in bad), issue
        assert 1 <= issue.column <= 133 and issue.reason
