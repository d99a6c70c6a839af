"""Guidance speed caps ahead of arcs in wind (guidance/speed_plan.arc_speed_cap_mps)."""

import pytest


def test_arc_speed_cap_is_a_ground_speed_limit_less_the_wind():
    """v_TAS ≤ sqrt(R g tan(γ − 3°)) − |wind| ahead of an arc (never below half of it)."""
    import math

    from fms_testbed.core.units import G0_MPS2
    from fms_testbed.guidance.speed_plan import ARC_BANK_MARGIN_DEG, arc_speed_cap_mps

    r = 2245.0
    g_tan = G0_MPS2 * math.tan(math.radians(25.0 - ARC_BANK_MARGIN_DEG))
    vg = math.sqrt(r * g_tan)

    class P:                      # the two attributes the cap reads of a local piece
        is_arc, radius_m, length_m = True, r, 1000.0

    assert arc_speed_cap_mps([P()], 0, 0.0, 100.0, 25.0) == pytest.approx(vg)
    assert arc_speed_cap_mps([P()], 0, 0.0, 100.0, 25.0, 15.4) == pytest.approx(vg - 15.4)
    assert arc_speed_cap_mps([P()], 0, 0.0, 100.0, 25.0, 500.0) == pytest.approx(0.5 * vg)
