"""The same cases on a dask.distributed cluster (a LocalCluster on 127.0.0.1, two one-thread
worker processes) give the local pool's rows, column for column apart from wall times; a
cluster whose workers run several threads is refused before any case is submitted."""

from __future__ import annotations

import pandas as pd
import pytest

from fms_testbed.campaign.store import read_flights

from campaign_helpers import SMALL, regress
from test_campaign_run import comparable

distributed = pytest.importorskip("distributed", reason="dask[distributed] is not installed "
                                                        "(pip install 'fms-testbed[dist]')")


@pytest.fixture
def cluster():
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=40) as c:
        yield c


def test_dask_cluster_gives_the_local_pools_rows(cluster, small_run, tmp_path):
    out = tmp_path / "dask"
    assert regress("run", *SMALL, "--scheduler", cluster.scheduler_address, "--no-progress",
                   "--out", str(out)) == 0
    pd.testing.assert_frame_equal(comparable(read_flights(out)),
                                  comparable(read_flights(small_run)))


def test_multithreaded_workers_are_refused(tmp_path, capsys):
    from distributed import LocalCluster

    # an in-process cluster on loopback TCP: enough to be refused, quick to start
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp://",
                      host="127.0.0.1", dashboard_address=None, silence_logs=40) as c:
        assert regress("run", *SMALL, "--scheduler", c.scheduler_address, "--no-progress",
                       "--out", str(tmp_path / "o")) == 2
    err = capsys.readouterr().err
    assert "run 2 threads; start them with --nthreads 1" in err
    assert not list((tmp_path / "o").glob("flights/*.parquet"))
