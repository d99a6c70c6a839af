"""Trim of every shipped aircraft at every envelope point (>= 3 each), and trim failures."""

from __future__ import annotations

import pytest

from fms_testbed.config.aircraft import list_aircraft, load_aircraft
from fms_testbed.core.errors import TrimError
from fms_testbed.sim.jsbsim_core import JSBSimAircraft

CASES = [(n, i) for n in list_aircraft() for i in range(len(load_aircraft(n).envelope))]


@pytest.mark.parametrize("name, idx", CASES)
def test_trim_holds_straight_and_level(name, idx):
    cfg = load_aircraft(name)
    pt = cfg.envelope[idx]
    ac = JSBSimAircraft(cfg)
    tr = ac.trim(pt.alt_m, pt.tas_mps, heading_deg=45.0, lat_deg=40.0, lon_deg=-100.0)
    assert 0.0 <= tr.throttle <= 1.0
    assert cfg.trim.alpha_min_deg <= tr.alpha_deg <= cfg.trim.alpha_max_deg
    ac.engage()
    ac.run(120 * 20)  # 20 s with the inner loops holding wings level, 1 g, n_x 0
    s = ac.state()
    assert abs(s.alt_m - pt.alt_m) < 15.0, f"altitude drift {s.alt_m - pt.alt_m:.1f} m"
    assert abs(s.tas_mps - pt.tas_mps) < 2.0
    assert abs(s.roll_rad) < 0.01


def test_retrim_after_a_run_is_repeatable():
    cfg = load_aircraft("737")
    ac = JSBSimAircraft(cfg)
    a = ac.trim(3000, 111.1)
    ac.engage()
    ac.command(nx=0.05, bank_rad=0.3)
    ac.run(600)
    b = ac.trim(3000, 111.1)
    # fuel burnt during the run makes the aircraft slightly lighter
    assert b.alpha_deg == pytest.approx(a.alpha_deg, abs=0.05)
    assert b.throttle == pytest.approx(a.throttle, abs=0.01)


def test_trim_failure_names_aircraft_and_condition():
    cfg = load_aircraft("737")
    ac = JSBSimAircraft(cfg)
    with pytest.raises(TrimError) as exc:
        ac.trim(3000, 45.0)  # far below the 737's minimum speed
    msg = str(exc.value)
    assert "737" in msg and "3000 m" in msg and "162 km/h" in msg
