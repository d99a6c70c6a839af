"""The lateral law: feed-forward, feedback signs, limits, roll anticipation."""

from __future__ import annotations

import math

import pytest

from fms_testbed.core.units import G0_MPS2
from fms_testbed.guidance.lateral import LateralGains, anticipation_m, bank_command_rad, feedforward_bank_rad

GAINS = LateralGains(bank_max_deg=25.0, roll_rate_dps=5.0)


def test_on_an_arc_without_error_the_bank_is_the_coordinated_turn_bank():
    v, r = 118.0, 3900.0
    bank = bank_command_rad(0.0, 0.0, v, 1.0 / r, GAINS)
    assert bank == pytest.approx(math.atan(v * v / (G0_MPS2 * r)), rel=1e-12)
    assert bank_command_rad(0.0, 0.0, v, -1.0 / r, GAINS) == pytest.approx(-bank)


def test_right_of_the_path_banks_left_and_left_banks_right():
    assert bank_command_rad(50.0, 0.0, 120.0, 0.0, GAINS) < 0
    assert bank_command_rad(-50.0, 0.0, 120.0, 0.0, GAINS) > 0
    # heading right of the desired track: bank left
    assert bank_command_rad(0.0, math.radians(5), 120.0, 0.0, GAINS) < 0


def test_converging_at_the_intercept_angle_commands_no_bank():
    """Far right of the path, already flying back at the 45° intercept: wings level."""
    bank = bank_command_rad(5000.0, math.radians(-45.0), 120.0, 0.0, GAINS)
    assert abs(math.degrees(bank)) < 0.5


def test_bank_is_limited_to_the_aircraft_limit():
    # far left of the path, heading 90° left of it, on a right-hand arc: bank right, limited
    assert math.degrees(bank_command_rad(-1e5, -math.pi / 2, 150.0, 1 / 1000.0, GAINS)) \
        == pytest.approx(25.0)
    assert math.degrees(bank_command_rad(1e5, math.pi / 2, 150.0, -1 / 1000.0, GAINS)) \
        == pytest.approx(-25.0)


def test_anticipation_centres_the_roll_ramp_on_the_transition():
    phi = feedforward_bank_rad(118.0, 1 / 3900.0)
    d = anticipation_m(118.0, phi, GAINS)
    ramp_s = math.degrees(phi) / 5.0
    assert d == pytest.approx(118.0 * (ramp_s / 2 + GAINS.roll_lag_s))
