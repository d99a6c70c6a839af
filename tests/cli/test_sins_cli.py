"""``fms-testbed ins``: run directories, synthetic trajectories, error reporting, analysis results."""

import math

import numpy as np
import pandas as pd
import pytest

from fms_testbed.cli import main
from fms_testbed.core.errors import UserError
from fms_testbed.sensors.sins.analysis import SinsOptions, covariance_run, horizontal_radius, montecarlo_run
from fms_testbed.sensors.sins.presets import load_imu
from fms_testbed.sensors.sins.trajectory import REQUIRED_COLUMNS, from_dataframe, straight_level


def _write_run_dir(tmp_path, drop=()):
    tr = straight_level(120.0, 0.5, lat_deg=10.0, speed_mps=150.0, heading_deg=300.0)
    d = math.degrees
    df = pd.DataFrame({
        "t_s": tr.t_s, "lat_deg": d(1) * tr.lat_rad, "lon_deg": d(1) * tr.lon_rad,
        "alt_m": tr.alt_m, "ve_mps": tr.v_enu_mps[:, 0], "vn_mps": tr.v_enu_mps[:, 1],
        "vu_mps": tr.v_enu_mps[:, 2], "roll_deg": d(1) * tr.rpy_rad[:, 0],
        "pitch_deg": d(1) * tr.rpy_rad[:, 1], "heading_deg": d(1) * tr.rpy_rad[:, 2],
        "p_dps": d(1) * tr.w_eb_b_rps[:, 0], "q_dps": d(1) * tr.w_eb_b_rps[:, 1],
        "r_dps": d(1) * tr.w_eb_b_rps[:, 2], "fx_mps2": tr.f_b_mps2[:, 0],
        "fy_mps2": tr.f_b_mps2[:, 1], "fz_mps2": tr.f_b_mps2[:, 2]})
    df = df.drop(columns=list(drop))
    run = tmp_path / "run"
    run.mkdir()
    df.to_parquet(run / "timeseries.parquet")
    return run


def test_ins_covariance_on_a_run_directory(tmp_path, capsys):
    run = _write_run_dir(tmp_path)
    out = tmp_path / "out"
    assert main(["ins", str(run), "--imu", "HG1700", "--out", str(out),
                 "--table-every-s", "60"]) == 0
    table = pd.read_csv(out / "ins_p95_table.csv")
    assert list(table.columns) == ["t_min", "h95_m", "v95_m"]
    assert table["t_min"].tolist() == [0.0, 1.0, 2.0]
    assert table["h95_m"].iloc[0] == 0.0 and (np.diff(table["h95_m"]) > 0).all()
    for name in ("ins_position.png", "ins_attitude.png", "ins_p95.png"):
        assert (out / name).stat().st_size > 10_000
    assert "h95_m" in capsys.readouterr().out


def test_ins_montecarlo_on_a_synthetic_trajectory(tmp_path):
    out = tmp_path / "mc"
    assert main(["ins", "synthetic:stationary", "--mode", "montecarlo", "-n", "50",
                 "--duration-s", "60", "--out", str(out), "--seed", "3"]) == 0
    table = pd.read_csv(out / "ins_p95_table.csv")
    assert {"h95_m", "v95_m", "h95_cov_m", "v95_cov_m"} <= set(table.columns)
    real = pd.read_parquet(out / "ins_realisations.parquet")
    assert real["realisation"].nunique() == 20 and {"dp_e_m", "eps_u_rad"} <= set(real.columns)


@pytest.mark.parametrize("args, match", [
    (["ins", "nowhere/"], "not a run directory"),
    (["ins", "synthetic:loop"], "unknown synthetic"),
    (["ins", "synthetic:stationary", "--imu", "LN-200X"], "unknown IMU preset"),
    (["ins", "synthetic:stationary", "-n", "1", "--mode", "montecarlo"], "-n"),
])
def test_ins_user_errors_exit_2_with_one_line(tmp_path, capsys, args, match):
    assert main(args + ["--out", str(tmp_path / "o"), "--duration-s", "10"]) == 2
    err = capsys.readouterr().err.strip()
    assert match in err and "\n" not in err


def test_missing_columns_are_named(tmp_path):
    run = _write_run_dir(tmp_path, drop=("fx_mps2", "p_dps"))
    with pytest.raises(UserError, match="p_dps, fx_mps2"):
        from fms_testbed.sensors.sins.trajectory import from_run_dir
        from_run_dir(run)


def test_time_must_increase():
    df = pd.DataFrame({c: [0.0, 0.0, 1.0] for c in REQUIRED_COLUMNS})
    with pytest.raises(UserError, match="row 1: t_s not increasing"):
        from_dataframe(df)


def test_horizontal_radius_matches_circular_and_1d_limits():
    assert horizontal_radius(4.0, 4.0, 0.0) == pytest.approx(2 * math.sqrt(-2 * math.log(0.05)),
                                                               rel=1e-9)
    assert horizontal_radius(9.0, 0.0, 0.0) == pytest.approx(3 * 1.959963985, rel=1e-6)
    # elongated ellipse: against sampling
    rng = np.random.default_rng(0)
    xy = rng.multivariate_normal([0, 0], [[9.0, 2.0], [2.0, 1.0]], 400_000)
    assert horizontal_radius(9.0, 1.0, 2.0) == pytest.approx(
        np.percentile(np.hypot(*xy.T), 95), rel=0.01)


def test_covariance_and_monte_carlo_agree_along_a_flight():
    tr = straight_level(300.0, 0.1, speed_mps=200.0, heading_deg=45.0)
    imu = load_imu("STIM300")
    cov = covariance_run(tr, imu, SinsOptions())
    mc = montecarlo_run(tr, imu, 2000, seed=1, opts=SinsOptions())
    # sample σ within 4 standard errors (σ√(1/2N)) of the covariance σ for every live state
    live = cov.sigma[-1] > 0
    z = (mc.sigma[-1][live] / cov.sigma[-1][live] - 1) / math.sqrt(1 / (2 * 2000))
    assert np.all(np.abs(z) < 4), z
    assert mc.h95_m[-1] == pytest.approx(cov.h95_m[-1], rel=0.06)


def test_non_finite_values_are_reported_with_row_and_column():
    df = pd.DataFrame({c: [0.0, 1.0, 2.0] for c in REQUIRED_COLUMNS})
    df.loc[2, "fz_mps2"] = float("nan")
    with pytest.raises(UserError, match="row 2: column fz_mps2"):
        from_dataframe(df)
