"""``--isa-dev-c`` on fly/run: the same override mechanism as ``--wind``."""

from __future__ import annotations

import json

import pytest

from fms_testbed.cli import main
from fms_testbed.cli.common import parse_isa_dev
from fms_testbed.core.errors import UserError


def test_parse_isa_dev():
    assert parse_isa_dev("15") == 15.0 and parse_isa_dev("-20.5") == -20.5
    for bad in ("hot", "61", "nan"):
        with pytest.raises(UserError, match="--isa-dev-c"):
            parse_isa_dev(bad)


def test_fly_on_a_warm_day_trims_at_the_warm_tas(tmp_path, capsys):
    """KJFK RNAV 04R final on an ISA+20 day: the start TAS is the planned CAS's TAS at ISA+20,
    written in the summary; a bad value exits 2 with one line."""
    out = tmp_path / "o"
    rc = main(["fly", "--airport", "KJFK", "--procedure", "R04RY", "--aircraft", "737",
               "--isa-dev-c", "20", "--out", str(out)])
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    out0 = tmp_path / "isa"
    assert main(["fly", "--airport", "KJFK", "--procedure", "R04RY", "--aircraft", "737",
                 "--out", str(out0)]) == 0
    s0 = json.loads((out0 / "summary.json").read_text())
    ratio = s["trim"]["tas_mps"] / s0["trim"]["tas_mps"]
    assert 1.03 < ratio < 1.045       # ≈ √(T+20)/T at the start altitude
    capsys.readouterr()
    assert main(["fly", "--airport", "KJFK", "--procedure", "R04RY", "--isa-dev-c", "99",
                 "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--isa-dev-c '99'" in err and len(err.splitlines()) == 1
