"""Scenario keys for the day's conditions: wind profile, ISA deviation, forecast."""

import pytest

from fms_testbed.config.scenario import parse_scenario
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.units import FT_M, KT_MPS

BASE = {"aircraft": "737", "initial": {"alt_m": 3000, "tas_kmh": 400}, "duration_s": 10}
PROFILE = [{"alt_ft": 0, "from_deg": 270, "speed_kt": 10},
           {"alt_ft": 10000, "from_deg": 270, "speed_kt": 50}]


def test_constant_wind_still_works_and_profile_is_interpolated():
    s = parse_scenario(BASE | {"wind": {"from_deg": 270, "speed_kt": 20}})
    assert s.wind_profile.at(5000.0) == pytest.approx((20 * KT_MPS, 270.0))
    p = parse_scenario(BASE | {"wind": PROFILE}).wind_profile
    assert p.at(5000 * FT_M) == pytest.approx((30 * KT_MPS, 270.0))
    assert p.at(20000 * FT_M)[0] == pytest.approx(50 * KT_MPS)
    assert parse_scenario(BASE).wind_profile is None


def test_isa_deviation_and_forecast():
    s = parse_scenario(BASE | {"atmosphere": {"isa_dev_c": 15}})
    assert s.isa_dev_c == 15.0 and s.planned_isa_dev_c == 15.0
    f = parse_scenario(BASE | {"atmosphere": {"isa_dev_c": 15}, "wind": PROFILE,
                               "forecast": {"isa_dev_c": 0, "wind": {"from_deg": 300,
                                                                     "speed_kt": 5}}})
    assert f.isa_dev_c == 15.0 and f.planned_isa_dev_c == 0.0
    assert f.planned_wind_profile.at(0.0) == pytest.approx((5 * KT_MPS, 300.0))
    assert f.wind_profile.layered
    calm = parse_scenario(BASE | {"wind": PROFILE, "forecast": {"calm": True}})
    assert calm.planned_wind_profile is None and calm.wind_profile is not None
    assert parse_scenario(BASE).isa_dev_c == 0.0


@pytest.mark.parametrize("extra, field, why", [
    ({"wind": list(reversed(PROFILE))}, "wind", "not above layer"),
    ({"wind": []}, "wind", "at least one layer"),
    ({"wind": [{"from_deg": 270, "speed_kt": 10}]}, "wind.0", "needs an altitude"),
    ({"wind": [{"alt_m": 0, "alt_ft": 0, "from_deg": 270, "speed_kt": 10}]}, "wind.0",
     "one altitude"),
    ({"wind": {"from_deg": 270}}, "wind", "exactly one of speed_mps or speed_kt"),
    ({"atmosphere": {"isa_dev_c": 80}}, "atmosphere.isa_dev_c", "less than or equal to 60"),
    ({"atmosphere": {"isa_dev": 10}}, "atmosphere.isa_dev", "unknown field"),
    ({"forecast": {"calm": True, "wind": {"from_deg": 1, "speed_kt": 2}}}, "forecast",
     "not both"),
])
def test_bad_condition_keys_name_the_field(extra, field, why):
    with pytest.raises(ConfigError) as exc:
        parse_scenario(BASE | extra, "s.yaml")
    msg = str(exc.value)
    assert msg.startswith("s.yaml: field ") and f"'{field}'" in msg and why in msg, msg
