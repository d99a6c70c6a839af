"""The testbed opens no socket and writes nothing outside the run's output folder, although
the wheel's 737 declares telnet/UDP inputs and global5000 a CSV output."""

from __future__ import annotations

import os
from pathlib import Path

import jsbsim

from fms_testbed.sim import jsbsim_core
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.run import run_scenario


def _sockets() -> set[str]:
    out = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:"):
            out.add(target)
    return out


def _tree(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def test_wheel_models_do_declare_io_that_we_strip():
    root = Path(jsbsim.get_default_root_dir()) / "aircraft"
    assert "<input" in (root / "737" / "737.xml").read_text()
    assert "<output" in (root / "global5000" / "global5000.xml").read_text()


def test_no_socket_and_no_stray_file(tmp_path):
    wheel = Path(jsbsim.get_default_root_dir())
    wheel_before = _tree(wheel)
    cwd_before = _tree(tmp_path)
    sockets_before = _sockets()
    out = tmp_path / "out"
    for name in ("737", "global5000"):
        res = run_scenario({"name": name, "aircraft": name, "duration_s": 5, "hold": True,
                            "initial": {"alt_m": 3000, "tas_mps": 111.1}},
                           out_dir=out / name, plots=False, progress=False)
        assert res.summary["status"] == "ok"
    assert _sockets() == sockets_before, "a socket was opened"
    assert _tree(wheel) == wheel_before, "files appeared in the jsbsim package"
    new = _tree(tmp_path) - cwd_before
    assert all(p == "out" or p.startswith("out/") for p in new), sorted(new)
    assert {p.name for p in (out / "global5000").iterdir()} == {
        "timeseries.parquet", "summary.json", "run.json", "track.geojson", "track.kml"}


def test_sanitised_copies_are_removed_on_cleanup():
    jsbsim_core.JSBSimAircraft(load_aircraft("c172p"))
    sandbox = jsbsim_core._sandbox_dir()
    assert sandbox.exists()
    jsbsim_core.cleanup()
    assert not sandbox.exists()
