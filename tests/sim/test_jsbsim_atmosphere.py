"""JSBSim's non-standard day and wind: ``atmosphere/delta-T`` against the planner's ISA model,
the trim at a CAS on a warm/cold day, and the wind profile set at the aircraft's altitude."""

import pytest

from fms_testbed.config.scenario import parse_scenario
from fms_testbed.core.atmosphere import cas_to_tas, isa
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.loop.flight import Flight
from fms_testbed.sim.jsbsim_core import bare_fdm


@pytest.mark.parametrize("dev", [-20.0, 0.0, 20.0])
def test_delta_t_matches_the_planners_atmosphere(dev):
    """JSBSim at geometric altitude h is the planner's model at the geopotential altitude
    h R / (R + h) (R = 6,356,766 m) within 1e-4: the same hydrostatic warm/cold day."""
    f = bare_fdm("737")
    f["atmosphere/delta-T"] = dev * 1.8
    for h in (0.0, 3000.0, 9000.0, 12000.0):
        f["ic/h-sl-ft"] = h / FT_M
        f["ic/vt-kts"] = 250.0
        f.run_ic()
        t, p, rho = isa(h * 6356766.0 / (6356766.0 + h), dev)
        assert f["atmosphere/T-R"] / 1.8 == pytest.approx(float(t), rel=1e-4)
        assert f["atmosphere/P-psf"] * 47.880259 == pytest.approx(float(p), rel=1e-4)
        assert f["atmosphere/rho-slugs_ft3"] * 515.378818 == pytest.approx(float(rho), rel=1e-4)


def _flight(extra, duration_s=5.0):
    scn = parse_scenario({"name": "atm", "aircraft": "737", "duration_s": duration_s,
                          "hold": True, "initial": {"alt_m": 3000, "cas_kt": 250,
                                                    "heading_deg": 90}} | extra)
    return Flight(scn, progress=False)


@pytest.mark.parametrize("dev", [-20.0, 20.0])
def test_trim_at_a_cas_flies_the_tas_of_the_day(dev):
    """250 kt CAS at 3000 m: trimmed at the TAS of the day (≈ 281 / 295 kt), JSBSim's CAS is
    250 kt again, and the engines give more thrust on the warm day (thinner air)."""
    fl = _flight({"atmosphere": {"isa_dev_c": dev}})
    df, summ = fl.run()
    want = float(cas_to_tas(250 * KT_MPS, 3000.0, dev))
    assert summ["trim"]["tas_mps"] == pytest.approx(want, rel=1e-4)
    assert df["cas_mps"].iloc[-1] / KT_MPS == pytest.approx(250.0, abs=0.3)
    assert fl.aircraft["atmosphere/delta-T"] == pytest.approx(dev * 1.8)
    isa_thr = _flight({}).run()[1]["trim"]["throttle"]
    assert (summ["trim"]["throttle"] - isa_thr) * dev > 0


def test_wind_profile_is_set_at_the_aircraft_altitude():
    """A profile 10 kt at sea level → 50 kt at 20,000 ft from 270: after the ramp JSBSim's wind
    is the profile's at the altitude flown (an event climbs the aircraft through the layers)."""
    fl = _flight({"wind": [{"alt_ft": 0, "from_deg": 270, "speed_kt": 10},
                           {"alt_ft": 20000, "from_deg": 270, "speed_kt": 50}],
                  "events": [{"t_s": 25, "alt_m": 3600}]}, duration_s=60.0)
    df, _ = fl.run()
    alt = fl.aircraft["position/h-sl-ft"]
    want_kt = 10.0 + 40.0 * alt / 20000.0
    east_kt = fl.aircraft["atmosphere/wind-east-fps"] * FT_M / KT_MPS
    assert east_kt == pytest.approx(want_kt, abs=0.05)
    assert abs(fl.aircraft["atmosphere/wind-north-fps"]) < 1e-6
    assert df["alt_m"].iloc[-1] - df["alt_m"].iloc[0] > 150.0   # it did climb through layers
