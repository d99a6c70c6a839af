"""`fms-testbed --version` and `fms-testbed procedures list`: airports, procedures, transitions
as aligned tables or JSON, counted from the parsed database; unknown idents name near matches."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import fms_testbed
from fms_testbed.cli import main
from fms_testbed.procedures import catalogue
from fms_testbed.procedures.database import load_database

CIFP = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "cifp" / "FAACIFP18_230126"


def test_version_prints_the_package_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"fms-testbed {fms_testbed.__version__}"


def _columns_start_where_the_header_says(text: str) -> None:
    """Every row of an aligned table has a column separator ('  ') before each header column
    start: the header's columns line up with the data."""
    lines = text.splitlines()
    dash = next(i for i, ln in enumerate(lines) if ln.startswith("---"))
    starts = [i for i, ch in enumerate(lines[dash]) if ch == "-" and (i == 0
              or lines[dash][i - 1] == " ")]
    assert len(starts) >= 3
    for ln in lines[dash + 1:]:
        for s in starts[1:]:
            assert ln[s - 2:s] == "  ", (ln, s)


def _parsed_counts(db, airport):
    """(SIDs, STARs, approaches, transitions) of an airport from its parsed sequences."""
    seqs = db.sequences(airport)
    kinds = {(s.proc_type, s.proc_id) for s in seqs}
    return tuple(sum(t == k for t, _ in kinds) for k in "DEF") + (len(seqs),)


def test_airports_are_counted_as_the_parsed_database_holds_them(capsys):
    db = load_database()
    assert main(["procedures", "list"]) == 0
    text = capsys.readouterr().out
    _columns_start_where_the_header_says(text)
    df = catalogue.airports(db)
    assert list(df["airport"]) == db.airport_idents()
    for r in df.itertuples():
        assert (r.sids, r.stars, r.approaches, r.transitions) == _parsed_counts(db, r.airport)
        assert r.airport in text
    assert df.set_index("airport").loc["KJFK", "name"] == "JOHN F KENNEDY INTL"


def test_procedures_of_kjfk_list_type_runways_transitions_and_leg_codes(capsys):
    assert main(["procedures", "list", "--airport", "kjfk"]) == 0
    text = capsys.readouterr().out
    _columns_start_where_the_header_says(text)
    row = next(ln for ln in text.splitlines() if " DEEZZ5 " in ln)
    assert row.startswith("SID") and "RW04B" in row and "CANDR TOWIN" in row
    assert main(["procedures", "list", "--airport", "KJFK", "--json"]) == 0
    recs = {r["procedure"]: r for r in json.loads(capsys.readouterr().out)}
    db = load_database()
    seqs = db.sequences("KJFK")
    assert set(recs) == {s.proc_id for s in seqs}
    for pid, r in recs.items():
        mine = [s for s in seqs if s.proc_id == pid]
        assert set(r["leg_codes"]) == {lg.path_term for s in mine for lg in s.legs}
        assert r["n_legs"] == sum(len(s.legs) for s in mine)
    assert recs["I22L"]["type"] == "APPROACH" and recs["I22L"]["runways"] == ["RW22L"]
    assert recs["PARCH3"]["type"] == "STAR" and "RW31B" in recs["PARCH3"]["runways"]


def test_transitions_of_a_procedure_give_their_leg_sequences(capsys):
    assert main(["procedures", "list", "--airport", "KJFK", "--procedure", "DEEZZ5",
                 "--json"]) == 0
    recs = json.loads(capsys.readouterr().out)
    seqs = load_database().select("KJFK", "DEEZZ5")
    assert [r["transition"] for r in recs] == [s.transition for s in seqs]
    for r, s in zip(recs, seqs):
        assert r["legs"] == [lg.path_term for lg in s.legs] and r["n_legs"] == len(s.legs)
    parts = {r["transition"]: r["part"] for r in recs}
    assert parts["RW04B"] == "runway" and parts[""] == "common" and parts["CANDR"] == "en-route"
    assert main(["procedures", "list", "--airport", "KJFK", "--procedure", "DEEZZ5"]) == 0
    _columns_start_where_the_header_says(capsys.readouterr().out)


@pytest.mark.parametrize("args, wanted", [
    (["--airport", "KJKF"], "KJFK"),
    (["--airport", "KJFK", "--procedure", "DEEZ5"], "DEEZZ5"),
    (["--procedure", "DEEZZ5"], "--airport"),
])
def test_unknown_idents_are_one_line_naming_the_near_matches(capsys, args, wanted):
    assert main(["procedures", "list"] + args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and wanted in err


def test_the_whole_cifp_is_summarised_from_its_raw_records():
    if not CIFP.exists():
        pytest.skip(f"FAA CIFP not found at {CIFP}")
    db = load_database(CIFP)
    df = catalogue.airports(db)
    assert len(df) == len(db.airport_idents())
    for apt in ("KSEA", "PAFA", "00R"):          # raw-record counts = parsed counts
        r = df.set_index("airport").loc[apt]
        assert (r.sids, r.stars, r.approaches, r.transitions) == _parsed_counts(db, apt)
    procs = catalogue.procedures(db, "KSEA").set_index("procedure")
    assert procs.loc["ISBRG1", "type"] == "SID" and "RW34R" in procs.loc["ISBRG1", "runways"]
