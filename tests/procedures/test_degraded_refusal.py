"""A degraded procedure is refused in one line naming the record (file, line, field, reason)
by the planner and by ``procedures build``, unless allowed; then what is in doubt is kept."""

import pytest

from fms_testbed.cli import main
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.config.procedure import parse_procedure
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.data import procedures_dir
from fms_testbed.path.plan import build_procedure
from fms_testbed.procedures.database import load_database, load_text

LINES = (procedures_dir() / "cifp_excerpt.dat").read_text(encoding="latin-1").split("\n")[:-1]
# the demo SID DEEZZ5 RW31L + CANDR
K = next(i for i, r in enumerate(LINES) if r.startswith("SUSAP KJFKK6DDEEZZ54RW31L 030"))
CFG = load_aircraft("737")
SPEC = {"airport": "KJFK", "procedure": "DEEZZ5", "runway": "31L", "transition": "CANDR"}


def _concatenated(tmp_path):
    p = tmp_path / "twice.dat"
    p.write_text("".join(r + "\n" for r in LINES + LINES), encoding="latin-1")
    return p


def test_a_sound_procedure_is_built_with_nothing_in_doubt():
    fp = build_procedure(load_database(), parse_procedure(SPEC), CFG)
    assert fp.degraded == () and fp.path.segments


def test_a_procedure_with_a_rejected_leg_is_refused_naming_the_record():
    lines = list(LINES)
    lines[K] = lines[K][:70] + "12X4" + lines[K][74:]
    db = load_text("".join(r + "\n" for r in lines), "bad.dat")
    with pytest.raises(UserError) as e:
        build_procedure(db, parse_procedure(SPEC), CFG)
    msg = str(e.value)
    assert "\n" not in msg and f"bad.dat:{K + 1}: course:" in msg and "degraded" in msg
    fp = build_procedure(db, parse_procedure({**SPEC, "allow_degraded": True}), CFG)
    assert len(fp.degraded) == 1 and fp.degraded[0].startswith(f"bad.dat:{K + 1}: course")
    clean = build_procedure(load_database(), parse_procedure(SPEC), CFG)
    assert len(fp.seq.legs) == len(clean.seq.legs) - 1       # flown with that leg missing


def test_a_concatenated_file_is_refused(tmp_path):
    db = load_database(_concatenated(tmp_path))
    with pytest.raises(UserError, match="sequence number .* is coded twice"):
        build_procedure(db, parse_procedure(SPEC), CFG)


def test_allow_degraded_is_a_strict_boolean():
    with pytest.raises(ConfigError, match="allow_degraded"):
        parse_procedure({**SPEC, "allow_degraded": 1})


def test_cli_build_refuses_a_degraded_procedure_with_exit_2(tmp_path, capsys):
    db = _concatenated(tmp_path)
    out = tmp_path / "out"
    rc = main(["procedures", "build", "--db", str(db), "--airport", "KJFK", "--procedure",
               "DEEZZ5", "--transition", "RW04B", "--out", str(out)])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{db}:" in err[0] and "sequence number" in err[0]
    assert not out.exists()
    rc = main(["procedures", "build", "--db", str(db), "--airport", "KJFK", "--procedure",
               "DEEZZ5", "--transition", "RW04B", "--allow-degraded", "--out", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "KJFK SID DEEZZ5 RW04B: degraded (monitor:" in text and "degraded (duplicate)" in text
    assert (out / "KJFK_SID_DEEZZ5_RW04B.geojson").exists()
