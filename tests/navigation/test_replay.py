"""nav-replay: bad files get one line and exit 2; on another simulator's data (pyins) the
replayed filter's covariance is honest and its accuracy that of pyins' own filter; a recorded
flight replays to the flight's own solution."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fms_testbed.cli.nav_replay import replay_files
from fms_testbed.navigation.replay_io import ReplayInputError, read_gnss, read_imu, read_init

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))


def _imu_file(tmp_path: Path, **change) -> Path:
    t = np.arange(5) * 0.01
    df = pd.DataFrame({"t_s": t, **{c: np.zeros(5) for c in (
        "gyro_x_rps", "gyro_y_rps", "gyro_z_rps", "accel_x_mps2", "accel_y_mps2")},
        "accel_z_mps2": np.full(5, -9.8)})
    for k, v in change.items():
        df[k] = v
    p = tmp_path / "imu.csv"
    df.to_csv(p, index=False)
    return p


def test_bad_imu_files_name_file_column_and_row(tmp_path):
    with pytest.raises(ReplayInputError, match=r"imu.csv: column 'gyro_y_rps', row 3: not a "
                                               r"finite number"):
        read_imu(_imu_file(tmp_path, gyro_y_rps=[0, 0, np.nan, 0, 0]))
    with pytest.raises(ReplayInputError, match=r"column 't_s', row 4: time does not increase"):
        read_imu(_imu_file(tmp_path, t_s=[0, 0.01, 0.02, 0.02, 0.03]))
    p = _imu_file(tmp_path)
    pd.read_csv(p).drop(columns=["accel_z_mps2"]).to_csv(p, index=False)
    with pytest.raises(ReplayInputError, match=r"column 'accel_z_mps2' missing"):
        read_imu(p)


def test_rate_and_increment_forms_give_the_same_increments(tmp_path):
    t, inc = read_imu(_imu_file(tmp_path, gyro_z_rps=[0.0, 0.1, 0.2, 0.3, 0.4]))
    assert inc.shape == (4, 6)
    assert np.allclose(inc[:, 2], [0.0005, 0.0015, 0.0025, 0.0035])    # trapezoid ω Δt
    df = pd.DataFrame({"t_s": t, "dtheta_x_rad": 0.0, "dtheta_y_rad": 0.0,
                       "dtheta_z_rad": np.r_[0.0, inc[:, 2]], "dv_x_mps": 0.0, "dv_y_mps": 0.0,
                       "dv_z_mps": np.r_[0.0, inc[:, 5]]})
    df.to_parquet(tmp_path / "inc.parquet")
    t2, inc2 = read_imu(tmp_path / "inc.parquet")
    assert np.array_equal(t, t2) and np.allclose(inc, inc2)


def test_bad_gnss_and_init_fields(tmp_path):
    g = tmp_path / "gnss.csv"
    pd.DataFrame({"t_s": [0, 1], "lat_deg": [47, 95], "lon_deg": [8, 8], "alt_m": [0, 0]}
                 ).to_csv(g, index=False)
    with pytest.raises(ReplayInputError, match=r"gnss.csv: column 'lat_deg', row 2: outside"):
        read_gnss(g)
    i = tmp_path / "init.json"
    i.write_text(json.dumps({"t_s": 0, "lat_deg": 47}))
    with pytest.raises(ReplayInputError, match=r"init.json: field 'lon_deg'"):
        read_init(i)


def test_the_cli_prints_one_line_and_exits_2_on_a_bad_file(tmp_path):
    imu = _imu_file(tmp_path, gyro_x_rps=[0, 0, 0, "x", 0])
    r = subprocess.run([sys.executable, "-m", "fms_testbed", "nav-replay", "--imu", str(imu),
                        "--gnss", str(imu), "--init", str(imu), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, timeout=300,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "column 'gyro_x_rps', row 4" in lines[0], r.stderr
    assert not (tmp_path / "o").exists()


@pytest.fixture(scope="module")
def pyins_case(tmp_path_factory):
    import bench_nav_replay as B
    d = tmp_path_factory.mktemp("pyins")
    data = B.make_files(7, d, 240.0)
    ours = replay_files(d / "imu.csv", d / "gnss.csv", d / "init.json", d / "truth.csv")
    return ours, B.pyins_filter(*data)


def test_replay_on_pyins_data_has_an_honest_covariance(pyins_case):
    ours, _ = pyins_case
    z = ours["stats"]["rms_error_over_sigma"]
    assert all(v < 1.5 for v in z.values()), z


def test_replay_on_pyins_data_is_as_accurate_as_pyins_own_filter(pyins_case):
    ours, theirs = pyins_case
    assert ours["stats"]["horizontal_m"]["p95"] <= 1.2 * theirs["h95"]
    err = ours["errors"]
    late = err.err_heading_deg[err.t_s >= 60].to_numpy()
    assert np.sqrt(np.mean(late ** 2)) <= 1.2 * theirs["hdg_rms_late"]
