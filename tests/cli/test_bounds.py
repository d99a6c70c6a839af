"""Arguments checked before any work: durations, sizes, seeds and fault sizes bounded by what
the machine can do (a one-line refusal naming the limit or the estimate), and the short tests a
user asks for run."""

from __future__ import annotations

import json

import pytest

from fms_testbed.cli import main
from fms_testbed.cli.imu_test import BYTES_PER_PROFILE_S, FIXED_B, MEMORY_SHARE, check_duration
from fms_testbed.cli.montecarlo import estimate_wall_s
from fms_testbed.core.errors import UserError


def _refused(argv, capsys) -> str:
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("argv, says", [
    (["montecarlo", "--duration-min", "inf"], "must be > 0 and <= 1440 min"),
    (["montecarlo", "--duration-min", "1e9"], "must be > 0 and <= 1440 min"),
    (["montecarlo", "--runs", "1000000000"], "must be within 0..1000000"),
    (["montecarlo", "--runs", "1e9"], "expected a whole number"),
    (["montecarlo", "--runs", "1000000"], "estimated 1000 h of wall time"),
    (["montecarlo", "--fault", "gyro_bias_step:z:nan"], "sizes must be finite numbers"),
    (["montecarlo", "--seed", str(2 ** 70)], "must be within 0..9223372036854775807"),
    (["imu-test", "--duration-h", "inf"], "finite number of hours >= 0.0167 (60 s)"),
    (["imu-test", "--duration-h", "1e-9"], "finite number of hours >= 0.0167 (60 s)"),
    (["imu-test", "--duration-h", "1e9"], "longer than this machine can hold in memory"),
    (["fly", "--airport", "KENV", "--procedure", "X", "--seed", str(2 ** 31)],
     "must be within 0..2147483647"),
    (["regress", "run", "--seed", "1180591620717411303424"], "must be within 0..92233"),
    (["regress", "run", "--workers", "0"], "must be within 1..1024"),
    (["regress", "run", "--case-timeout", "nan"], "must be > 0 and <= 604800 s"),
])
def test_out_of_bounds_is_one_line(argv, says, tmp_path, capsys):
    err = _refused([*argv, "--out", str(tmp_path / "o")], capsys)
    assert says in err, err
    assert not (tmp_path / "o").exists()


def test_imu_test_limit_follows_the_memory():
    gib = 2 ** 30
    # streamed: one hour is 3,600 s of the temperature grid at BYTES_PER_PROFILE_S, any rate
    limit_h = (MEMORY_SHARE * 16 * gib - FIXED_B) / BYTES_PER_PROFILE_S / 3600.0
    assert check_duration(limit_h * 0.99, 100.0, 16 * gib) == pytest.approx(limit_h * 0.99 * 3600)
    with pytest.raises(UserError, match=f"at most {limit_h:.0f} h at 100 Hz"):
        check_duration(limit_h * 1.01, 100.0, 16 * gib)
    assert check_duration(1000.0, 100.0, None) == 3.6e6      # no memory figure: no upper bound


@pytest.mark.parametrize("duration_h", ["0.0167", "0.02", "0.0275"])
def test_imu_test_of_a_minute_runs(duration_h, tmp_path, capsys):
    out = tmp_path / "imu"
    assert main(["imu-test", "--duration-h", duration_h, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["outputs"] and (out / "run.json").exists()
    assert json.loads((out / "run.json").read_text())["kind"] == "imu-test"


def test_montecarlo_estimate_scales_with_the_work():
    one = estimate_wall_s(100, 600.0, 0, 50, 600.0, 1)
    assert estimate_wall_s(200, 600.0, 0, 50, 600.0, 1) == pytest.approx(2 * one)
    assert estimate_wall_s(200, 600.0, 0, 50, 600.0, 2) == pytest.approx(one)
    assert estimate_wall_s(0, 600.0, 2, 50, 600.0, 1) == pytest.approx(one)
