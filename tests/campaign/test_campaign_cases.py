"""Cases of a campaign: 'each' flies every transition at least once with the fewest sequences,
'all' every combination; case ids are stable, change exactly with the records a case uses, and
seed the case by themselves; the airport sample is a seeded rule; conditions the flight stack
cannot honour are refused."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.campaign.cases import (aircraft_files, case_seed, enumerate_cases,
                                        flyable_sequences, sample_airports)
from fms_testbed.campaign.conditions import command_line_sets, make_conditions, read_conditions
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.procedures.index import load_index

from campaign_helpers import regress

CALM = command_line_sets([None], [{"source": "truth"}])


@dataclass(frozen=True)
class _Seq:
    proc_type: str
    transition: str
    route_type: str = "5"


idents = st.lists(st.sampled_from(["RW01", "RW19B", "RW27L", "RW09"]), unique=True, max_size=4)
enroute = st.lists(st.sampled_from(["ALPHA", "BRAVO", "CHRLY", "DELTA", "ECHO"]), unique=True,
                   max_size=5)


@settings(max_examples=80, deadline=None)
@given(idents, enroute, st.booleans(), st.sampled_from("DE"))
def test_each_covers_every_transition_with_the_fewest_sequences(rw, en, common, kind):
    seqs = [_Seq(kind, t) for t in rw + en] + ([_Seq(kind, "ALL")] if common else [])
    if not seqs:
        return
    each = flyable_sequences(seqs, "each")
    assert {r for r, _ in each if r} == set(rw) and {t for _, t in each if t} == set(en)
    assert len(each) == max(len(rw), len(en), 1)
    every = flyable_sequences(seqs, "all")
    assert len(every) == max(len(rw), 1) * max(len(en), 1) and len(set(every)) == len(every)
    assert set(each) <= set(every)


def test_approach_transitions_and_the_final_alone():
    seqs = [_Seq("F", "", "R"), _Seq("F", "ALPHA", "A"), _Seq("F", "BRAVO", "A")]
    assert flyable_sequences(seqs, "each") == [("", "ALPHA"), ("", "BRAVO")]
    assert flyable_sequences(seqs, "all") == [("", "ALPHA"), ("", "BRAVO"), ("", "")]
    assert flyable_sequences(seqs[:1], "each") == [("", "")]


def _cases(db_path=None, seed=0):
    ix = load_index(db_path)
    return enumerate_cases(ix, ["KBFI", "KDLS"], ["D", "E", "F"], aircraft_files(["737"]),
                           CALM, "each", seed)


def test_case_ids_are_stable_unique_and_seed_the_case():
    a, b = _cases(), _cases()
    assert [c.case_id for c in a] == [c.case_id for c in b]
    assert len({c.case_id for c in a}) == len(a)
    assert len({c.key for c in a}) == len(a)
    assert all(c.seed == case_seed(c.case_id) and 0 <= c.seed < 2**31 for c in a)
    other = _cases(seed=1)
    assert not {c.case_id for c in a} & {c.case_id for c in other}


def test_case_id_changes_exactly_with_the_records_a_case_uses(tmp_path):
    base = _cases()
    src = load_index(None).path
    lines = Path(src).read_text(encoding="latin-1").split("\n")
    # recode the altitude of one leg of KBFI's CBAIN1 SID (cols 85-89)
    k = next(i for i, ln in enumerate(lines) if ln.startswith("SUSAP KBFIK1DCBAIN1")
             and ln[84:89].strip())
    lines[k] = lines[k][:84] + "09000" + lines[k][89:]
    copy = tmp_path / "db.dat"
    copy.write_text("\n".join(lines), encoding="latin-1")
    after = _cases(copy)
    changed = {a.key for a, b in zip(base, after) if a.case_id != b.case_id}
    assert [a.key for a in base] == [b.key for b in after]
    assert changed and all(key[2] == "CBAIN1" for key in changed)


def _renumbered(lines: list[str], start: int) -> list[str]:
    """Records from ``start`` on with their file record number (cols 124-128) one higher."""
    out = list(lines)
    for i in range(start, len(out)):
        ln = out[i]
        if len(ln) >= 128 and ln[123:128].isdigit():
            out[i] = ln[:123] + f"{int(ln[123:128]) + 1:05d}" + ln[128:]
    return out


def test_case_ids_do_not_change_with_the_file_record_number(tmp_path):
    """A new cycle that inserts a record near the top renumbers every later record (cols
    124-128) and nothing else: no case id changes."""
    base = _cases()
    lines = Path(load_index(None).path).read_text(encoding="latin-1").split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.startswith("S") and len(ln) >= 132)
    extra = lines[k][:13] + "ZZZZZ" + lines[k][18:]     # an unrelated record, inserted at k
    moved = _renumbered(lines, k)
    moved.insert(k, extra)
    assert sum(a != b for a, b in zip(lines[k:], moved[k + 1:])) > 100   # every id's lines moved
    copy = tmp_path / "cycle-b.dat"
    copy.write_text("\n".join(moved), encoding="latin-1")
    after = _cases(copy)
    assert [(c.key, c.case_id, c.records_sha256) for c in base] == \
        [(c.key, c.case_id, c.records_sha256) for c in after]


def test_airport_sample_is_a_seeded_rule():
    db = load_index(None).db
    known = db.airport_idents()
    s1 = sample_airports(db, known, 4, 7, ["D", "E", "F"])
    assert s1 == sample_airports(db, known, 4, 7, ["D", "E", "F"]) and len(s1) == 4
    assert s1 == sorted(s1) and set(s1) <= set(known)
    assert any(sample_airports(db, known, 4, s, ["D", "E", "F"]) != s1 for s in range(8))
    big = sample_airports(db, known, 2, 7, ["D", "E", "F"], min_transitions=40)
    assert all(len(db.procedure_index(a)) >= 40 for a in big)
    with pytest.raises(UserError, match="only"):
        sample_airports(db, known, 50, 7, ["D"])


def test_conditions_refuse_what_the_stack_cannot_fly(tmp_path):
    with pytest.raises(ConfigError, match="isa_dev_c.*less than or equal to 60"):
        make_conditions({"isa_dev_c": 95}, "x")
    with pytest.raises(ConfigError, match="field 'wind'.*not above layer"):
        make_conditions({"wind": [{"alt_ft": 5000, "from_deg": 1, "speed_kt": 5},
                                  {"alt_ft": 0, "from_deg": 1, "speed_kt": 5}]}, "x")
    with pytest.raises(ConfigError, match="field 'missed': expected true or false"):
        make_conditions({"missed": "yes"}, "x")
    with pytest.raises(ConfigError, match="wind.from_deg"):
        make_conditions({"wind": {"from_deg": 400, "speed_kt": 10}}, "x")
    f = tmp_path / "c.yaml"
    f.write_text("conditions:\n  - {name: a}\n  - {name: a, wind: {from_deg: 90, speed_kt: 5}}\n")
    with pytest.raises(ConfigError, match="unique"):
        read_conditions(f)
    f.write_text("conditions:\n  - {name: calm}\n  - name: west\n    wind: {from_deg: 270, "
                 "speed_kt: 30}\n")
    sets = read_conditions(f)
    assert [c.name for c in sets] == ["calm", "west"]
    assert sets[0].nominal and not sets[1].nominal


@pytest.mark.parametrize("argv, msg", [
    (["--isa-dev-c", "99"], "--isa-dev-c '99': must be within -60..60"),
    (["--isa-dev-c", "warm"], "expected a number of °C"),
    (["--nav", "sins"], "give the IMU preset"),
    (["--nav", "sins:NOPE"], "unknown IMU preset"),
    (["--keep", "movies"], "'movies' is not one of"),
    (["--airports", "KXXX"], "no airport 'KXXX'"),
    (["--types", "SIDS"], "is not one of SID, STAR, APPROACH"),
])
def test_run_refuses_in_one_line(argv, msg, tmp_path, capsys):
    assert regress("run", *argv, "--out", str(tmp_path / "o"), "--no-progress") == 2
    err = capsys.readouterr().err.strip()
    assert msg in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_isa_deviation_and_wind_profile_enter_the_condition_set_and_case_id():
    """An ISA deviation and a wind profile are condition-set keys: they go into the scenario
    overrides, the canonical JSON the case id hashes, and the default name; an ISA set keeps the
    case id it had before the key existed (no 'atmosphere' key at 0)."""
    from fms_testbed.campaign.conditions import command_line_sets

    isa = make_conditions({}, "x")
    hot = make_conditions({"isa_dev_c": 20}, "x")
    prof = make_conditions({"wind": [{"alt_ft": 0, "from_deg": 250, "speed_kt": 10},
                                     {"alt_ft": 10000, "from_deg": 280, "speed_kt": 50}]}, "x")
    assert isa.overrides() == {"navigation": {"source": "truth"}}
    assert "atmosphere" not in isa.canonical()
    assert hot.overrides()["atmosphere"] == {"isa_dev_c": 20.0}
    assert hot.name == "calm ISA+20" and not hot.nominal and isa.nominal
    assert '"isa_dev_c":20.0' in hot.canonical()
    assert prof.name == "wind profile 2 layers"
    assert prof.wind_speed_mps == pytest.approx(50 * 0.514444, rel=1e-4)
    assert prof.overrides()["wind"][1]["alt_ft"] == 10000
    sets = command_line_sets([None], [{"source": "truth"}], [0.0, 15.0, -15.0])
    assert [c.name for c in sets] == ["calm", "calm ISA+15", "calm ISA-15"]
    assert len({c.canonical() for c in sets}) == 3


def test_regress_run_takes_isa_deviations_as_condition_sets(tmp_path):
    """``regress run --wind calm 270/30 --isa-dev-c 0 20``: four condition sets, the ISA ones
    named and hashed as before, the warm ones with 'ISA+20' and an atmosphere override."""
    from fms_testbed.cli import build_parser
    from fms_testbed.cli.regress import config_from_args

    args = build_parser().parse_args(["regress", "run", "--wind", "calm", "270/30",
                                      "--isa-dev-c", "0", "20", "--out", str(tmp_path / "o")])
    sets = config_from_args(args).conditions
    assert [c.name for c in sets] == ["calm", "calm ISA+20", "wind 270/30kt",
                                      "wind 270/30kt ISA+20"]
    assert sets[1].overrides()["atmosphere"] == {"isa_dev_c": 20.0}
    assert sets[0].canonical() == make_conditions({}, "x").canonical()
    f = tmp_path / "c.yaml"
    f.write_text("conditions:\n  - name: hot-shear\n    isa_dev_c: 20\n    wind:\n"
                 "      - {alt_ft: 0, from_deg: 250, speed_kt: 10}\n"
                 "      - {alt_ft: 10000, from_deg: 280, speed_kt: 50}\n")
    (c,) = read_conditions(f)
    assert c.isa_dev_c == 20.0 and len(c.overrides()["wind"]) == 2
