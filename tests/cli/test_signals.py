"""A flight interrupted by SIGINT ends with exit 130 and one 'interrupted' line; SIGTERM ends it
with the JSBSim sandbox folder removed from the temporary folder."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "sins-stim300.yaml"


def _long_scenario(tmp_path) -> Path:
    """The shipped SINS flight lengthened to 6 h, so it is surely still flying when signalled."""
    p = tmp_path / "long.yaml"
    p.write_text(SCENARIO.read_text().replace("duration_s: 600", "duration_s: 21600"))
    assert "duration_s: 21600" in p.read_text()
    return p


def _start(tmp_path, settle_s: float = 1.0):
    env = {**os.environ, "TMPDIR": str(tmp_path / "tmp")}
    (tmp_path / "tmp").mkdir()
    p = subprocess.Popen([sys.executable, "-m", "fms_testbed", "run", str(_long_scenario(tmp_path)),
                          "--out", str(tmp_path / "out"), "--no-plots"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.time() + 60
    while time.time() < deadline and not list((tmp_path / "tmp").glob("fms-testbed-jsbsim-*")):
        time.sleep(0.05)
    assert list((tmp_path / "tmp").glob("fms-testbed-jsbsim-*")), "the flight never started"
    time.sleep(settle_s)            # 1 s: inside the closed loop (SINS kernels in numba)
    return p


def test_sigint_exits_130_with_one_line(tmp_path):
    p = _start(tmp_path)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130, err[-2000:]
    assert "interrupted" in err and "Traceback" not in err
    assert not list((tmp_path / "tmp").glob("fms-testbed-jsbsim-*"))
    assert not (tmp_path / "out").exists()          # nothing that looks like a finished run


@pytest.mark.parametrize("settle_s", [0.0, 0.3, 1.0])
def test_sigterm_removes_the_jsbsim_sandbox(tmp_path, settle_s):
    """SIGTERM at the JSBSim load, while the numba kernels load, and in the closed loop: exit
    128 + 15, one line, no traceback (a SIGTERM inside a numba dispatcher call used to surface
    as a SystemError traceback and exit 1)."""
    p = _start(tmp_path, settle_s)
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 128 + signal.SIGTERM, err[-2000:]
    assert "Traceback" not in err
    assert not list((tmp_path / "tmp").glob("fms-testbed-jsbsim-*"))


def test_an_exit_raised_by_our_handler_inside_a_callback_is_not_reported(monkeypatch):
    """The SIGTERM/SIGINT handlers' exception raised inside a callback that cannot propagate it
    (llvmlite's object-cache notification while numba compiles) is not handed to Python's
    report ('Exception ignored in ...' with a traceback); any other unraisable exception, or
    the same one with no signal recorded, is."""
    import types
    from fms_testbed import cli

    reported = []
    monkeypatch.setattr(sys, "__unraisablehook__", lambda u: reported.append(u.exc_type))

    def unraisable(exc):
        return types.SimpleNamespace(exc_type=type(exc), exc_value=exc, exc_traceback=None,
                                     err_msg="Exception ignored in", object=None)

    monkeypatch.setattr(cli, "_terminated", [])
    cli._quiet_signal_unraisable(unraisable(SystemExit(143)))
    assert reported == [SystemExit]                            # no signal recorded: reported
    monkeypatch.setattr(cli, "_terminated", [signal.SIGTERM])
    cli._quiet_signal_unraisable(unraisable(SystemExit(143)))
    assert reported == [SystemExit]                            # our own exit: quiet
    cli._quiet_signal_unraisable(unraisable(ValueError("a bug")))
    assert reported == [SystemExit, ValueError]                # anything else: reported
