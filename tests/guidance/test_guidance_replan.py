"""guidance/replan.roll_out_state: where a rebuild starts when the aircraft is still banked."""

from __future__ import annotations

import math

import pytest

from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import G0_MPS2
from fms_testbed.guidance.lateral import LateralGains
from fms_testbed.guidance.replan import roll_out_state


def test_wings_level_changes_nothing():
    assert roll_out_state(47.0, -112.0, 1.0, 140.0, 0.0, LateralGains()) == (47.0, -112.0, 1.0)


@pytest.mark.parametrize("roll_deg", [-20.0, -10.0, 10.0, 25.0])
def test_roll_out_keeps_turning_the_way_it_banks(roll_deg):
    """The track turns with the bank (right bank → right), by g tanφ / V · t / 2 with
    t = |φ| / p_max; the start moves V t along the mean track."""
    g = LateralGains(roll_rate_dps=5.0)
    v = 140.0
    la, lo, trk = roll_out_state(47.0, -112.0, math.radians(285.0), v, math.radians(roll_deg), g)
    t = abs(roll_deg) / 5.0
    dpsi = G0_MPS2 * math.tan(math.radians(roll_deg)) / v * t / 2.0
    assert trk - math.radians(285.0) == pytest.approx(dpsi)
    assert math.copysign(1.0, dpsi) == math.copysign(1.0, roll_deg)
    dist_m, az_deg = inverse(47.0, -112.0, la, lo)[:2]
    assert dist_m == pytest.approx(v * t, rel=1e-6)
    assert math.radians(az_deg) % (2 * math.pi) == pytest.approx(
        (math.radians(285.0) + dpsi / 2.0) % (2 * math.pi), abs=1e-6)
