"""Running scenarios: outputs, columns, reproducibility, divergence handling."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from fms_testbed.run import run_scenario
from fms_testbed.core.timeseries import COLUMNS
from fms_testbed.core.units import KT_MPS

BASE = {"aircraft": "737", "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000,
                                        "tas_kmh": 400, "heading_deg": 90}}

REQUIRED = ("t_s lat_deg lon_deg alt_m tas_mps gs_mps vs_mps heading_deg track_deg pitch_deg "
            "roll_deg alpha_deg gamma_deg nx ny throttle elevator aileron rudder nav_lat_deg "
            "nav_lon_deg nav_alt_m nav_heading_deg").split()


def test_run_writes_outputs_and_documented_columns(tmp_path):
    scn = {**BASE, "name": "turn", "duration_s": 60, "hold": True,
           "events": [{"t_s": 2, "heading_deg": 150}]}
    res = run_scenario(scn, out_dir=tmp_path / "o", csv=True)
    files = {p.name for p in (tmp_path / "o").iterdir()}
    assert {"timeseries.parquet", "timeseries.csv", "summary.json", "ground_track.png",
            "time_histories.png"} <= files
    df = pd.read_parquet(tmp_path / "o" / "timeseries.parquet")
    assert list(df.columns[:len(COLUMNS)]) == [c for c, _ in COLUMNS]
    assert set(REQUIRED) <= set(df.columns)
    assert any(c.startswith("cmd_") for c in df.columns)
    summ = json.loads((tmp_path / "o" / "summary.json").read_text())
    for key in ("status", "reason", "duration_s", "wall_time_s", "real_time_factor", "metrics"):
        assert key in summ
    assert summ["status"] == "ok"
    # heading hold reached the target on the navigation (= true) heading
    assert df["heading_deg"].iloc[-1] == pytest.approx(150, abs=1.0)
    assert np.allclose(df["nav_lat_deg"], df["lat_deg"]) and np.allclose(df["nav_alt_m"], df["alt_m"])
    assert df["roll_deg"].abs().max() <= 25.0 + 1.5
    # logged at 10 Hz
    assert np.diff(df["t_s"]).mean() == pytest.approx(0.1, abs=1e-6)


def test_direct_inner_loop_targets_are_tracked():
    scn = {**BASE, "duration_s": 20, "events": [{"t_s": 1, "bank_deg": -20}, {"t_s": 1, "ny": 1.08},
                                                 {"t_s": 1, "nx": 0.03}]}
    df = run_scenario(scn).df
    late = df[df.t_s > 12]
    assert late["roll_deg"].mean() == pytest.approx(-20, abs=0.5)
    assert late["ny"].mean() == pytest.approx(1.08, abs=0.01)
    assert late["nx"].mean() == pytest.approx(0.03, abs=0.005)


def test_throttle_event_disengages_the_nx_loop():
    df = run_scenario({**BASE, "duration_s": 6, "events": [{"t_s": 1, "throttle": 0.3}]}).df
    assert df["throttle"].iloc[-1] == pytest.approx(0.3, abs=1e-6)
    assert math.isnan(df["cmd_nx"].iloc[-1])


def test_same_seed_same_numbers_with_turbulence():
    scn = {**BASE, "duration_s": 15, "hold": True, "turbulence": {"severity": "moderate"}}
    a = run_scenario(scn, seed=3).df
    b = run_scenario(scn, seed=3).df
    c = run_scenario(scn, seed=4).df
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["alt_m"], c["alt_m"])


@pytest.mark.parametrize("events, aircraft, reason", [
    ([{"t_s": 1, "throttle": 0.0}, {"t_s": 1, "ny": 1.15}], "c172p", "stall"),
    ([{"t_s": 1, "throttle": 1.0}, {"t_s": 1, "ny": 0.6}], "737", "overspeed"),
])
def test_divergence_ends_with_status_and_reason(tmp_path, events, aircraft, reason):
    ini = {"alt_m": 3000, "tas_mps": 111.1} if aircraft == "737" else {"alt_m": 1500, "tas_mps": 50}
    res = run_scenario({"aircraft": aircraft, "initial": ini, "duration_s": 300, "events": events},
                       out_dir=tmp_path / "d")
    assert res.summary["status"] == "diverged"
    assert reason in res.summary["reason"]
    assert res.summary["duration_s"] < 300
    assert (tmp_path / "d" / "time_histories.png").exists()


def test_ground_contact_is_a_divergence():
    res = run_scenario({"aircraft": "c172p", "initial": {"alt_m": 60, "tas_mps": 50},
                        "duration_s": 120, "events": [{"t_s": 1, "ny": 0.9}]})
    assert res.summary["status"] == "diverged" and "ground" in res.summary["reason"]


def test_cas_target_converted_with_altitude():
    scn = {**BASE, "duration_s": 5, "hold": True, "events": [{"t_s": 1, "cas_kt": 200}]}
    df = run_scenario(scn).df
    from fms_testbed.core.atmosphere import cas_to_tas
    last = df.iloc[-1]
    assert last["cmd_tas_mps"] == pytest.approx(float(cas_to_tas(200 * KT_MPS, last["alt_m"])), rel=1e-4)


def test_steady_wind_is_ramped_in_and_then_held():
    """JSBSim trims in calm air; the scenario's wind then ramps in over 20 s and stays."""
    from fms_testbed.loop.flight import WIND_RAMP_S

    scn = {**BASE, "duration_s": 90, "hold": True, "wind": {"from_deg": 0, "speed_kt": 30},
           "events": [{"t_s": 1, "heading_deg": 90}]}
    df = run_scenario(scn).df
    late = df[df.t_s > WIND_RAMP_S + 40]
    # wind from the north at 30 kt: ground velocity has a southward component, heading crabs left
    assert late["vn_mps"].mean() == pytest.approx(-30 * KT_MPS, abs=0.5)
    crab_deg = ((late["heading_deg"] - late["track_deg"] + 180) % 360 - 180).mean()
    assert crab_deg == pytest.approx(-math.degrees(math.asin(30 * KT_MPS / 111.1)), abs=0.5)
    assert late["tas_mps"].mean() == pytest.approx(111.1, abs=0.3)


def test_flight_stepped_in_pieces_equals_one_run():
    """Flight.step(n) in uneven pieces flies exactly what run() flies (same seed, same rows), and
    result() mid-flight reports what has been flown so far."""
    from fms_testbed.loop.flight import Flight
    from fms_testbed.config.scenario import parse_scenario

    scn = parse_scenario({**BASE, "name": "steps", "duration_s": 40, "hold": True,
                          "events": [{"t_s": 5, "heading_deg": 120}, {"t_s": 10, "alt_m": 3100}]})
    whole_df, whole = Flight(scn, seed=3, progress=False).run()
    f = Flight(scn, seed=3, progress=False)
    assert f.step(7) and f.step(150)
    mid_df, mid = f.result()
    assert mid["reason"] == "in flight" and len(mid_df) == 157
    assert mid_df["t_s"].iloc[-1] == pytest.approx(15.6)
    while f.step(33):
        pass
    assert not f.step(1)
    df, summ = f.result()
    assert summ["status"] == whole["status"] == "ok" and summ["reason"] == "duration flown"
    pd.testing.assert_frame_equal(df, whole_df)


def test_logged_columns_match_the_state_the_laws_see():
    """The vectorised conversion of the logged raw reads (timeseries.build_frame) gives the same
    values as the per-step AircraftState (jsbsim_core.state): one contract, two code paths."""
    from fms_testbed.sim.jsbsim_core import _READ, _STATE_ORDER, raw_to_si
    from fms_testbed.loop.flight import Flight
    from fms_testbed.config.scenario import parse_scenario

    assert tuple(_READ)[:len(_STATE_ORDER)] == _STATE_ORDER  # state() unpacks in this order
    f = Flight(parse_scenario({**BASE, "name": "c", "duration_s": 20,
                               "events": [{"t_s": 1, "bank_deg": 20}]}), progress=False)
    f.step(150)
    ac = f.aircraft
    raw = ac.read_raw()
    s = ac.state(raw)
    si = {k: float(v[0]) for k, v in raw_to_si(np.array([raw])).items()}
    assert si["alt_m"] == pytest.approx(s.alt_m) and si["tas_mps"] == pytest.approx(s.tas_mps)
    assert si["nx"] == pytest.approx(s.nx) and si["ny"] == pytest.approx(s.ny)
    assert si["cas_mps"] == pytest.approx(s.cas_mps) and si["mass_kg"] == pytest.approx(s.mass_kg)
    assert math.radians(si["lat_deg"]) == pytest.approx(s.lat_rad)
    assert np.allclose([si["ve"], si["vn"], -si["vd"]], s.v_enu_mps)
    assert np.allclose(np.array([si["fx"], si["fy"], si["fz"]]) / si["mass_kg"], s.f_body_mps2)
    # no vertical target: the n_y loop holds its 1 g command through the 20 deg bank; the loops'
    # own 60 Hz measurement agrees with this frame's value to a frame's change
    assert s.roll_rad == pytest.approx(math.radians(20), abs=math.radians(1))
    assert s.ny == pytest.approx(1.0, abs=0.02)
    assert ac["fms/meas/ny"] == pytest.approx(s.ny, abs=0.01)
    assert ac["fms/meas/nx"] == pytest.approx(s.nx, abs=0.01)
