"""``fms-testbed montecarlo``: outputs of a small campaign (fault-free phase with an outage and an
accelerometer fault phase), same numbers for another ``--chunk``, one-line user errors."""

import json

import pandas as pd
import pytest

from fms_testbed.cli import main


def _run(out, *extra):
    return main(["montecarlo", "--runs", "3", "--duration-min", "1.5", "--profile", "turns",
                 "--outage", "40:70", "--fault", "accel_bias_step:x:10000", "--fault-runs", "2",
                 "--fault-duration-min", "1.5", "--fault-at-s", "30", "--seed", "4",
                 "--out", str(out), *extra])


def test_small_campaign_writes_tables_plot_and_summary(tmp_path, capsys):
    out = tmp_path / "mc"
    assert _run(out, "--chunk", "3") == 0
    text = capsys.readouterr().out
    assert "fault-free: 3 runs" in text and "accel_bias_step x 10000 ug" in text
    for name in ("montecarlo.csv", "montecarlo.md", "realisations.csv", "summary.json",
                 "montecarlo.png", "run.json"):
        assert (out / name).is_file(), name
    df = pd.read_csv(out / "montecarlo.csv")
    ff = df[df.phase == "fault-free"].iloc[0]
    assert ff.runs == 3 and ff.false_exclusions == 0
    assert ff.false_exclusion_rate_upper95_per_h == pytest.approx(3.0 / (3 * 1.5 / 60), rel=0.01)
    assert 0.1 < ff.nse95_gnss_m < 10.0 and ff.nse95_coast_m > ff.nse95_gnss_m
    assert 0.0 < ff.outage_nse_within_rnp <= 1.0
    fa = df[df.phase != "fault-free"].iloc[0]
    assert fa.excluded_frac == 1.0 and fa.wrong_exclusions == 0 and fa.tte_median_s < 10.0
    per = pd.read_csv(out / "realisations.csv")
    assert list(per.realisation) == [0, 1, 2, 3, 4]
    s = json.loads((out / "summary.json").read_text())
    assert s["seed"] == 4 and s["outages_s"] == [[40.0, 70.0]]
    # realisations carry their own seeds: another chunking, on two processes, gives the same
    # per-run numbers
    out2 = tmp_path / "mc2"
    assert _run(out2, "--chunk", "1", "--workers", "2") == 0
    per2 = pd.read_csv(out2 / "realisations.csv")
    pd.testing.assert_series_equal(per.nse_max_m, per2.nse_max_m, rtol=1e-9)


@pytest.mark.parametrize("argv, words", [
    (["--fault", "gyro_bias_step:q:20"], "axis"),
    (["--fault", "wobble:x:20"], "kind"),
    (["--fault", "gyro_bias_step:x"], "KIND:AXIS:SIZE"),
    (["--outage", "90:30"], "START_S < END_S"),
    (["--trajectory", "/nonexistent/run"], "timeseries.parquet"),
    (["--imu", "NOPE"], "NOPE"),
])
def test_user_errors_are_one_line(tmp_path, capsys, argv, words):
    rc = main(["montecarlo", "--runs", "1", "--duration-min", "1", *argv,
               "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert len(err.splitlines()) == 1 and words in err, err
