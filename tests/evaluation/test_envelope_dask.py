"""Design points of ``tune --envelope`` on a dask.distributed cluster (a LocalCluster on
127.0.0.1, one-thread worker processes) give the local pool's numbers; a cluster whose workers
run several threads is refused before any point is submitted."""

from __future__ import annotations

import pandas as pd
import pytest

from fms_testbed.cli import main
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.sim.linearise import DesignPoint

distributed = pytest.importorskip("distributed", reason="dask[distributed] is not installed "
                                                        "(pip install 'fms-testbed[dist]')")

GRID = [DesignPoint(1000.0, 105.0, None, "clean"), DesignPoint(3000.0, 111.1, None, "clean"),
        DesignPoint(6000.0, 150.0, None, "clean")]
WALL = ("tune_s", "check_s")


@pytest.mark.slow
def test_dask_cluster_gives_the_local_pools_points():
    from distributed import LocalCluster

    from fms_testbed.cli.tune_envelope import DaskJobs
    from fms_testbed.evaluation.envelope_tuning import tune_envelope

    cfg = load_aircraft("737")
    local = tune_envelope(cfg, GRID, workers=1, robust=False, duration_s=40.0)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=40) as c:
        jobs = DaskJobs(c.scheduler_address)
        try:
            assert jobs.workers == 2
            dask = tune_envelope(cfg, GRID, workers=2, robust=False, duration_s=40.0,
                                 map_jobs=jobs)
        finally:
            jobs.close()
    a, b = (r.points.drop(columns=list(WALL)) for r in (local, dask))
    pd.testing.assert_frame_equal(a, b)
    assert local.schedule.table() == dask.schedule.table()
    assert (local.bank.kp, local.bank.kd) == (dask.bank.kp, dask.bank.kd)


def test_multithreaded_workers_are_refused(tmp_path, capsys):
    from distributed import LocalCluster

    grid = tmp_path / "grid.yaml"
    grid.write_text("points:\n  - {alt_m: 3000, tas_mps: 111}\n")
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp://",
                      host="127.0.0.1", dashboard_address=None, silence_logs=40) as c:
        assert main(["tune", "--aircraft", "737", "--envelope", "--grid", str(grid),
                     "--scheduler", c.scheduler_address, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "run 2 threads; start them with --nthreads 1" in err
    assert not (tmp_path / "o").exists()


def test_bad_scheduler_address_is_one_line(tmp_path, capsys):
    assert main(["tune", "--aircraft", "737", "--envelope", "--scheduler", "foo:1",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "expected tcp://HOST:PORT" in err and "\n" not in err
