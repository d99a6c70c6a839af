"""Wind over altitude: linear in the components between layers, constant beyond the ends."""

import math

import pytest

from fms_testbed.core.wind import WindProfile


def test_profile_interpolates_the_vector_and_holds_the_ends():
    p = WindProfile.from_layers([(0.0, 270.0, 10.0), (3000.0, 270.0, 40.0)])
    assert p.at(-100.0) == pytest.approx((10.0, 270.0))
    assert p.at(1500.0) == pytest.approx((25.0, 270.0))
    assert p.at(9000.0) == pytest.approx((40.0, 270.0))
    n, e = p.ned_at(1500.0)
    assert n == pytest.approx(0.0, abs=1e-9) and e == pytest.approx(25.0)   # blows to the east
    # opposite layers: calm half-way (the vector, not speed and direction apart)
    q = WindProfile.from_layers([(0.0, 90.0, 20.0), (2000.0, 270.0, 20.0)])
    assert q.at(1000.0)[0] == pytest.approx(0.0, abs=1e-9)
    assert q.strongest_between(500.0, 1500.0)[0] == pytest.approx(10.0)
    assert WindProfile.constant(12.0, 45.0).at(5000.0) == pytest.approx((12.0, 45.0))
    assert not WindProfile.constant(12.0, 45.0).layered and p.layered
    assert p.max_speed_mps == pytest.approx(40.0)


def test_profile_rejects_unordered_layers():
    with pytest.raises(ValueError, match="increase strictly"):
        WindProfile.from_layers([(1000.0, 0.0, 5.0), (1000.0, 0.0, 6.0)])
    with pytest.raises(ValueError, match="one or more"):
        WindProfile((), (), ())


def test_direction_convention():
    """from 360 blows to the south: the air moves south (north component negative)."""
    n, e = WindProfile.constant(10.0, 360.0).ned_at(0.0)
    assert n == pytest.approx(-10.0) and e == pytest.approx(0.0, abs=1e-9)
    assert math.isclose(WindProfile.constant(10.0, 90.0).at(0.0)[1], 90.0)
