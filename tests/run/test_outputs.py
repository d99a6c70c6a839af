"""Output folders (issue 11): checked before any work, written atomically with run.json last, a
previous run replaced as a whole, other content refused, symlinks never followed, a kill
mid-write leaves the previous run intact."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fms_testbed.core.errors import UserError
from fms_testbed.run.outputs import RUN_MARKER, OutputFolder, check_out_dir


def _write_run(out, files):
    with OutputFolder(out) as tmp:
        for name, text in files.items():
            (tmp / name).write_text(text)
    return out


def test_new_folder_gets_run_json_last(tmp_path):
    out = _write_run(tmp_path / "r", {"summary.json": "{}"})
    info = json.loads((out / RUN_MARKER).read_text())
    assert info["tool"] == "fms-testbed" and "version" in info and "finished_utc" in info
    assert sorted(p.name for p in out.iterdir()) == ["run.json", "summary.json"]
    assert not list(tmp_path.glob(".r.*"))        # no temporary folder left


def test_second_run_leaves_nothing_of_the_first(tmp_path):
    out = _write_run(tmp_path / "r", {"timeseries.csv": "a", "plot.png": "b", "summary.json": "1"})
    _write_run(out, {"summary.json": "2"})
    assert sorted(p.name for p in out.iterdir()) == ["run.json", "summary.json"]
    assert (out / "summary.json").read_text() == "2"


def test_folder_with_other_content_is_refused_unless_overwrite(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(UserError, match="holds other files"):
        check_out_dir(out)
    _write_run_overwrite = OutputFolder(out, overwrite=True)
    with _write_run_overwrite as tmp:
        (tmp / "summary.json").write_text("{}")
    assert not (out / "thesis.tex").exists()


def test_file_symlink_and_readonly_targets(tmp_path):
    f = tmp_path / "afile"
    f.write_text("x")
    with pytest.raises(UserError, match="is a file"):
        check_out_dir(f)
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    with pytest.raises(UserError, match="symbolic link"):
        check_out_dir(link)
    if os.geteuid() != 0:   # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o500)
        with pytest.raises(UserError, match="permission denied"):
            check_out_dir(ro / "out")


def test_symlink_inside_a_previous_run_is_not_followed(tmp_path):
    out = _write_run(tmp_path / "r", {"summary.json": "1"})
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    (out / "summary.json").unlink()
    (out / "summary.json").symlink_to(victim)
    _write_run(out, {"summary.json": "new"})
    assert victim.read_text() == "keep me"
    assert not (out / "summary.json").is_symlink()


def test_failure_inside_leaves_the_previous_run(tmp_path):
    out = _write_run(tmp_path / "r", {"summary.json": "old"})
    with pytest.raises(RuntimeError):
        with OutputFolder(out) as tmp:
            (tmp / "summary.json").write_text("half")
            raise RuntimeError("disk on fire")
    assert (out / "summary.json").read_text() == "old"
    assert not list(tmp_path.glob(".r.partial-*"))


def test_kill_mid_write_leaves_the_previous_run_complete(tmp_path):
    out = _write_run(tmp_path / "r", {"summary.json": "old"})
    code = ("import sys, time\n"
            "from fms_testbed.run.outputs import OutputFolder\n"
            f"with OutputFolder({str(out)!r}) as tmp:\n"
            "    (tmp / 'timeseries.csv').write_text('')\n"
            "    print('writing', flush=True)\n"
            "    time.sleep(30)\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "writing"
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=10)
    assert (out / "summary.json").read_text() == "old"
    assert json.loads((out / RUN_MARKER).read_text())["tool"] == "fms-testbed"
    assert not (out / "timeseries.csv").exists()
    _write_run(out, {"summary.json": "new"})          # the next run removes the partial folder
    assert not list(tmp_path.glob(".r.partial-*"))


def test_cli_refuses_a_bad_out_before_flying(tmp_path):
    f = tmp_path / "afile"
    f.write_text("x")
    cpu0 = os.times()
    r = subprocess.run([sys.executable, "-m", "fms_testbed", "demo", "--out", str(f)],
                       capture_output=True, text=True, timeout=120)
    cpu1 = os.times()
    assert r.returncode == 2 and "is a file" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    # checked before loading JSBSim or flying: the child's CPU time (load-independent) is the
    # import and the argument check, a fraction of the demo flight's
    child_cpu_s = (cpu1.children_user + cpu1.children_system
                   - cpu0.children_user - cpu0.children_system)
    assert child_cpu_s < 5, child_cpu_s


def test_a_run_of_another_kind_is_replaced_only_with_overwrite(tmp_path):
    out = tmp_path / "r"
    with OutputFolder(out, kind="regress-run") as tmp:
        (tmp / "flights").mkdir()
    assert json.loads((out / RUN_MARKER).read_text())["kind"] == "regress-run"
    with pytest.raises(UserError, match="holds a regress-run run, not a fly run"):
        check_out_dir(out, kind="fly")
    with OutputFolder(out, overwrite=True, kind="fly") as tmp:
        (tmp / "summary.json").write_text("{}")
    assert not (out / "flights").exists()
    check_out_dir(out, kind="fly")                   # its own kind: replaced without a word


def test_an_input_is_never_an_output(tmp_path):
    run = tmp_path / "run"
    with OutputFolder(run, kind="fly") as tmp:
        (tmp / "timeseries.parquet").write_text("x")
    for target in (run, run / "sub", tmp_path):
        with pytest.raises(UserError, match="input"):
            check_out_dir(target, overwrite=True, kind="fly", inputs=[run])
    db = tmp_path / "db.dat"
    db.write_text("records")
    with pytest.raises(UserError, match="input"):
        check_out_dir(tmp_path, overwrite=True, kind="fly", inputs=[db])
    check_out_dir(tmp_path / "elsewhere", kind="fly", inputs=[db])      # beside it: fine


@pytest.mark.parametrize("argv", [
    ["fly", "--airport", "KENV", "--procedure", "X", "--no-plots"],
    ["imu-test", "--duration-h", "0.02"],
    ["montecarlo", "--runs", "1", "--duration-min", "1"],
])
def test_commands_never_replace_a_regress_run(argv, tmp_path, capsys):
    from fms_testbed.cli import main

    out = tmp_path / "campaign"
    with OutputFolder(out, kind="regress-run") as tmp:
        (tmp / "flights").mkdir()
        (tmp / "flights" / "part-1.parquet").write_text("rows")
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds a regress-run run" in err and len(err.splitlines()) == 1
    assert (out / "flights" / "part-1.parquet").read_text() == "rows"


def test_montecarlo_never_writes_into_its_trajectory(tmp_path, capsys):
    from fms_testbed.cli import main

    run = tmp_path / "flight"
    with OutputFolder(run, kind="montecarlo") as tmp:
        (tmp / "timeseries.parquet").write_text("x")
    for out in (run, run / "mc"):
        assert main(["montecarlo", "--runs", "1", "--duration-min", "1", "--trajectory",
                     str(run), "--out", str(out), "--overwrite"]) == 2
        assert "input" in capsys.readouterr().err
    assert (run / "timeseries.parquet").read_text() == "x"


def test_empty_out_is_refused(capsys):
    from fms_testbed.cli import main

    assert main(["imu-test", "--duration-h", "0.02", "--out", ""]) == 2
    assert "give a folder name" in capsys.readouterr().err


def test_a_run_json_that_is_not_json_is_named(tmp_path):
    out = tmp_path / "r"
    out.mkdir()
    (out / RUN_MARKER).write_text("{oops")
    with pytest.raises(UserError, match="its run.json is not valid JSON: line 1 col 2"):
        check_out_dir(out, kind="fly")


def test_unwritable_targets_are_refused_whoever_runs_the_test(tmp_path, monkeypatch):
    """The refusal of a read-only folder, also where the test runs as root (who writes
    anywhere): ``os.access`` answers as it would for an ordinary user."""
    import fms_testbed.run.outputs as outputs
    ro = tmp_path / "ro"
    ro.mkdir()
    real_access = os.access
    monkeypatch.setattr(outputs.os, "access",
                        lambda p, mode: False if Path(p) == ro else real_access(p, mode))
    with pytest.raises(UserError, match=r"cannot write in .*ro \(permission denied\)"):
        check_out_dir(ro / "out")
    with pytest.raises(UserError, match="the folder is read-only"):
        check_out_dir(ro)
