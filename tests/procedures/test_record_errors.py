"""Record errors are data: each field reader's format and range checks on real CIFP records,
line numbers that survive \\x85, and the structural defects (duplicates, concatenated files,
records out of place, all legs rejected) that make a transition degraded."""

import pytest

from fms_testbed.core.errors import UserError
from fms_testbed.data import procedures_dir
from fms_testbed.procedures import database as dbmod
from fms_testbed.procedures.database import load_database, load_text
from fms_testbed.procedures.fields import (FieldError, RecordError, check_record, parse_alt_ft,
                                           parse_lat, parse_lon, parse_magvar, read_int)
from fms_testbed.procedures.legrecord import parse_leg
from fms_testbed.procedures.records import parse_waypoint

EXCERPT = procedures_dir() / "cifp_excerpt.dat"
TEXT = EXCERPT.read_text(encoding="latin-1")
LINES = TEXT.split("\n")[:-1]

# Real records from the FAA CIFP 2301 (public domain), all in the embedded excerpt.
VA = ("SUSAP KJFKK6DDEEZZ54RW04B 010         0        VA                     0438        + 00520"
      "     18000                        241211808")
RF = ("SCANP PAFAPAFH02LZ AGLDHL 040OKXACPAPC0E   L010RF       0025001938    12030032    + 03200"
      "                 CFNRF PAPCA FS   073392108")
HM = ("SCANP PABEPAFI19RZ I      060ROLLRPAEA0EE  R   HM                     0972T010    + 02000"
      "                           0 DS   054981208")
PC = ("SUSAP KJFKK6CAROKE K60    R     N40282056W073540760                       W0127     NAR"
      "           AROKE                    240532008")


def put(rec: str, col: int, text: str) -> str:
    """``rec`` with ``text`` written from 1-based column ``col``."""
    return rec[:col - 1] + text + rec[col - 1 + len(text):]


def test_the_real_records_are_132_columns_and_parse():
    for rec in (VA, RF, HM, PC):
        assert len(rec) == 132
        check_record(rec)
    assert {LINES.index(r) for r in (VA, RF, HM, PC)}  # they are in the excerpt


@pytest.mark.parametrize("rec, col, text, field", [
    (VA, 71, "3601", "course"),                  # above 360.0 deg
    (VA, 71, "361T", "course"),                  # true course above 360 deg
    (VA, 71, "04 8", "course"),                  # internal blank
    (VA, 85, "0052X", "altitude 1"),             # letters in the altitude field
    (VA, 85, "+0520", "altitude 1"),             # int() accepts '+'; ARINC does not
    (VA, 85, "61000", "altitude 1"),             # above 60,000 ft
    (VA, 85, "FL601", "altitude 1"),
    (VA, 85, "FL000", "altitude 1"),
    (VA, 85, "FL6 1", "altitude 1"),
    (VA, 95, "00500", "transition altitude"),    # below 1,000 ft
    (VA, 100, "000", "speed limit"),             # speed limit 0 (ZeroDivisionError before)
    (VA, 100, "029", "speed limit"),
    (VA, 100, "451", "speed limit"),
    (VA, 103, "0300", "vertical angle"),         # a positive (climbing) path angle
    (VA, 103, "-1X0", "vertical angle"),
    (VA, 45, "000", "RNP"),                      # RNP 0 NM
    (VA, 45, "01X", "RNP"),
    (VA, 27, "000", "sequence number"),
    (VA, 27, "0A0", "sequence number"),
    (VA, 27, "   ", "sequence number"),
    (VA, 48, "ZZ", "path terminator"),
    (VA, 44, "X", "turn direction"),
    (VA, 50, "N", "turn direction valid"),
    (VA, 83, "Q", "altitude descriptor"),
    (VA, 118, "X", "speed limit descriptor"),
    (VA, 40, "Z", "waypoint description 1"),
    (VA, 39, "2", "continuation number"),        # a continuation is not a leg
    (VA, 20, "#", "route type"),
    (VA, 7, "KJ.K", "airport ident"),
    (VA, 21, "RW 4B", "transition ident"),       # not left-justified
    (RF, 57, "000000", "arc radius"),            # RF of radius 0
    (RF, 37, "ZZ", "fix section"),
    (RF, 30, "     ", "fix ident"),              # region and section without a fix
    (RF, 115, "XX", "centre fix section"),
    (HM, 75, "T000", "time"),                    # a hold of 0 minutes
    (HM, 75, "0000", "distance"),                # a hold of 0 NM
    (HM, 75, "T01-", "time"),
])
def test_a_malformed_field_of_a_real_leg_record_is_named(rec, col, text, field):
    bad = put(rec, col, text)
    assert len(bad) == 132
    with pytest.raises(FieldError) as e:
        parse_leg(bad, 1)
    assert e.value.field == field
    assert e.value.column <= col + len(text) - 1 and e.value.last_column >= col


@pytest.mark.parametrize("rec, col, text, attr, value", [
    (VA, 71, "3600", "course_deg", 360.0),
    (VA, 71, "360T", "course_deg", 360.0),
    (VA, 85, "-0145", "alt1_m", -145 * 0.3048),  # below sea level (KCLR, FAA CIFP)
    (VA, 85, "FL390", "alt1_m", 39000 * 0.3048),
    (VA, 100, "030", "speed_limit_mps", 30 * 1852.0 / 3600.0),
    (VA, 103, "-999", "vpa_deg", -9.99),
    (HM, 75, "T001", "time_s", 6.0),
])
def test_the_edges_of_each_range_are_accepted(rec, col, text, attr, value):
    assert getattr(parse_leg(put(rec, col, text), 1), attr) == pytest.approx(value)


@pytest.mark.parametrize("col, text, field", [
    (33, "N40289999", "latitude seconds"),   # seconds 99.99
    (33, "N40602056", "latitude minutes"),   # minutes 60
    (33, "N91000000", "latitude"),           # 91 deg
    (33, "N90000001", "latitude"),           # beyond the pole
    (33, "X40282056", "latitude"),
    (42, "W181000000", "longitude"),
    (42, "E180000001", "longitude"),
    (42, "W07354076A", "longitude"),
    (75, "E9999", "magnetic variation"),     # E999.9
    (75, "W1801", "magnetic variation"),
    (75, "E01 7", "magnetic variation"),
    (14, "AR KE", "waypoint ident"),
])
def test_latitude_longitude_and_variation_ranges(col, text, field):
    with pytest.raises(FieldError) as e:
        parse_waypoint(put(PC, col, text), 1)
    assert e.value.field == field and e.value.column == col


def test_the_pole_the_antimeridian_and_180_deg_variation_are_accepted():
    assert parse_lat(put(PC, 33, "S90000000"), 33) == -90.0
    assert parse_lon(put(PC, 42, "E180000000"), 42) == 180.0
    assert parse_magvar(put(PC, 75, "W1800"), 75) == -180.0
    assert parse_magvar(put(PC, 75, "T    "), 75) == 0.0


@pytest.mark.parametrize("text", ["1²3", "+12", "1_0", "1 2", "١٢", "12-"])
def test_numbers_are_ascii_digits_only(text):
    # str.isdigit() accepts '²' and Arabic-Indic digits, int() accepts '+', '_' and them too
    rec = put(" " * 132, 10, f"{text:<5}")
    with pytest.raises(FieldError) as e:
        read_int(rec, 10, 14, "rho")
    assert "ASCII" in e.value.reason


def test_altitude_reader_rejects_non_ascii_digits():
    with pytest.raises(FieldError, match="ASCII"):
        parse_alt_ft(put(VA, 85, "005²0"), 85)
    with pytest.raises(FieldError, match="FL"):
        parse_alt_ft(put(VA, 85, "FL2²0"), 85)


@pytest.mark.parametrize("rec, field", [
    (VA[:131], "record length"),
    (VA + " ", "record length"),
    (put(VA, 71, "043²"), "course"),              # a Latin-1 superscript two
    (put(VA, 60, "\x85"), "arc radius"),          # NEL: str.splitlines() would split here
    (put(VA, 60, "\x0c"), "arc radius"),
    (put(VA, 31, "a"), "fix ident"),              # ARINC-424 is upper case
    (put(VA, 121, "_"), "character set"),         # a reserved column
])
def test_record_length_and_character_set(rec, field):
    with pytest.raises(FieldError) as e:
        parse_leg(rec, 1)
    assert e.value.field == field


# ------------------------------------------------------------------- whole files

def _db(lines: list[str], name: str = "mut.dat"):
    return load_text("".join(ln + "\n" for ln in lines), name)


def _seq(db, key):
    return next(s for s in db.sequences(key[0]) if s.key == key)


KEY_04B = ("KJFK", "D", "DEEZZ5", "4", "RW04B")
K = LINES.index(VA)  # 0-based index of the first leg of KJFK DEEZZ5 RW04B


def test_clean_excerpt_has_no_rejected_record_and_no_degraded_transition():
    db = load_database()
    seqs = [s for a in db.airport_idents() for s in db.sequences(a)]
    assert len(seqs) == 306 and db.issues == []
    assert not any(s.degraded for s in seqs)


def test_nel_inside_a_record_does_not_shift_later_line_numbers():
    lines = list(LINES)
    j = K + 40
    lines[K] = put(lines[K], 124, "\x85")          # a byte str.splitlines() splits at
    lines[j] = put(lines[j], 71, "12X4")            # a course error 40 lines later
    db = _db(lines)
    db.sequences("KJFK")
    assert [e.line for e in db.issues] == [K + 1, j + 1]
    assert db.issues[1].field == "course" and db.issues[1].text == lines[j]
    assert db.n_lines == len(LINES)


def test_a_rejected_leg_degrades_its_transition_and_names_the_line():
    lines = list(LINES)
    lines[K + 1] = put(lines[K + 1], 85, "0X520")  # letters in an altitude
    db = _db(lines, "bad.dat")
    seq = _seq(db, KEY_04B)
    assert seq.degraded and [d.kind for d in seq.defects] == ["rejected"]
    assert seq.defects[0].lines == (K + 2,) and len(seq.legs) == 2
    assert str(seq.defects[0]).startswith(f"bad.dat:{K + 2}: altitude 1:")
    err = db.issues[0]
    assert isinstance(err, RecordError) and err.row()["columns"] == "85-89"
    others = [s for s in db.sequences("KJFK") if s.key != KEY_04B]
    assert not any(s.degraded for s in others)


def test_a_file_concatenated_with_itself_degrades_every_transition():
    db = _db(LINES + LINES)
    seqs = [s for a in db.airport_idents() for s in db.sequences(a)]
    assert len(seqs) == 306
    for s in seqs:
        assert {"duplicate", "interleaved"} & {d.kind for d in s.defects}, s.name
    assert all(any(d.kind == "duplicate" for d in s.defects) for s in seqs)


def test_a_repeated_sequence_number_and_sequence_order():
    lines = list(LINES)
    lines.insert(K + 1, lines[K])                 # record 010 twice
    s = _seq(_db(lines), KEY_04B)
    assert [d.kind for d in s.defects] == ["duplicate"]
    assert s.defects[0].lines == (K + 1, K + 2)
    lines = list(LINES)
    lines[K], lines[K + 1] = lines[K + 1], lines[K]  # 020 before 010
    s = _seq(_db(lines), KEY_04B)
    assert [d.kind for d in s.defects] == ["order"]


def test_a_record_moved_away_or_a_key_changed_inside_a_transition_is_interleaved():
    lines = list(LINES)
    moved = lines.pop(K + 1)
    lines.insert(K + 30, moved)
    db = _db(lines)
    s = _seq(db, KEY_04B)
    assert {d.kind for d in s.defects} == {"interleaved", "order"}  # and 020 now after 030
    # the transition the record landed in is interrupted too
    host = next(x for x in db.sequences("KJFK") if K + 30 in x.lines and x.key != KEY_04B)
    assert host.degraded
    lines = list(LINES)
    lines[K + 1] = put(lines[K + 1], 21, "RW04C")  # a valid key, another transition
    db = _db(lines)
    kinds = {s.transition: [d.kind for d in s.defects] for s in db.sequences("KJFK")
             if s.proc_id == "DEEZZ5"}
    assert kinds["RW04B"] == ["interleaved"] and kinds["RW04C"] == ["interleaved"]


def test_a_line_whose_transition_cannot_be_read_degrades_its_neighbours():
    lines = list(LINES)
    lines[K + 1] = lines[K + 1][:20]               # truncated before the transition ident
    db = _db(lines)
    s = _seq(db, KEY_04B)
    assert [d.kind for d in s.defects] == ["rejected"] and s.defects[0].lines == (K + 2,)
    assert db.issues[0].field == "record length"


def test_a_continuation_record_must_follow_its_primary():
    i = next(k for k, r in enumerate(LINES) if r[4:6] == "P " and r[12] in "DEF"
             and r[38] == "2")
    lines = list(LINES)
    lines[i - 1], lines[i] = lines[i], lines[i - 1]  # continuation before its primary
    db = _db(lines)
    db.sequences(LINES[i][6:10].strip())
    assert any(e.field == "continuation number" and e.line == i for e in db.issues)


def test_a_transition_whose_legs_are_all_rejected_is_kept_with_no_legs():
    lines = [put(r, 71, "XXXX") if r[4:6] == "P " and r[12] in "DEF" and r[38] in "01" else r
             for r in LINES]
    db = _db(lines)
    seqs = [s for a in db.airport_idents() for s in db.sequences(a)]
    assert len(seqs) == 306
    assert all(s.degraded and not s.legs for s in seqs)
    n_legs = sum(1 for r in LINES if r[4:6] == "P " and r[12] in "DEF" and r[38] in "01")
    assert len(db.issues) == n_legs and {e.field for e in db.issues} == {"course"}


def test_a_rejected_fix_record_degrades_the_transitions_that_name_it():
    lines = list(LINES)
    i = next(k for k, r in enumerate(LINES) if r[4:6] == "EA" and r[13:18].strip() == "DEEZZ")
    lines[i] = put(lines[i], 33, "N40289999")     # latitude seconds 99.99
    db = _db(lines)
    s = _seq(db, KEY_04B)
    assert [d.kind for d in s.defects] == ["fix-rejected"] and "DEEZZ" in s.defects[0].reason
    assert db.issues[0].field == "latitude seconds" and db.issues[0].line == i + 1


def test_a_record_of_an_unknown_section_is_rejected():
    lines = list(LINES)
    lines[K] = put(lines[K], 5, "Q")
    db = _db(lines)
    assert db.issues[0].field == "section" and db.issues[0].line == K + 1
    assert _seq(db, KEY_04B).degraded        # its neighbour line is RW04B's


def test_crlf_line_ends_are_accepted():
    db = load_text("".join(r + "\r\n" for r in LINES), "crlf.dat")
    assert sum(len(db.sequences(a)) for a in db.airport_idents()) == 306 and not db.issues


@pytest.mark.parametrize("make, what", [
    (lambda p: p.mkdir(), "a directory"),
    (lambda p: __import__("os").mkfifo(p), "a FIFO"),
])
def test_db_must_be_a_regular_file(tmp_path, make, what):
    p = tmp_path / "db"
    make(p)
    with pytest.raises(UserError, match=what):
        load_database(p)


def test_dev_zero_is_refused_at_once():
    with pytest.raises(UserError, match="character device"):
        load_database("/dev/zero")


def test_the_size_is_checked_before_reading(monkeypatch):
    monkeypatch.setattr(dbmod, "MAX_DB_BYTES", 100_000)
    with pytest.raises(UserError, match="larger than"):
        load_database(EXCERPT)


def test_the_documented_ranges_are_the_ones_checked():
    from pathlib import Path

    from fms_testbed.procedures.fields import RANGES
    doc = (Path(__file__).resolve().parents[2] / "docs" / "procedures-integrity.md").read_text()
    for name, (lo, hi, unit) in RANGES.items():
        assert f"| {name} | {lo} – {hi} | {unit} |" in doc, name
