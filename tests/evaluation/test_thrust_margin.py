"""The thrust rule of the envelope check: the full-thrust excess power, measured as the energy
rate, against JSBSim's thrust and drag, and the points where the altitude step needs more than
the engines give."""

from __future__ import annotations

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.control.coupled_law import params_from_config
from fms_testbed.core.units import FT_M, G0_MPS2, LBF_N
from fms_testbed.evaluation.envelope_points import excess_power_mps, point_loops, thrust_margin
from fms_testbed.sim.linearise import DesignPoint, linearise, trim_point


def _thrust_n(ac) -> float:
    return sum(ac.fdm[f"propulsion/engine[{i}]/thrust-lbs"] for i in range(ac.n_engines)) * LBF_N


@pytest.mark.parametrize("name, point", [
    ("737", DesignPoint(3000.0, 111.1, None, "clean")),
    ("global5000", DesignPoint(12000.0, 230.0, 40000.0, "clean")),
])
def test_excess_power_is_thrust_minus_drag_times_speed_over_weight(name, point):
    """The energy-rate measurement against the forces JSBSim reports at the end of the same
    full-thrust run: P_s = (T cos α - D) V / W (thrust along the body axis)."""
    cfg = load_aircraft(name)
    got = excess_power_mps(cfg, point)
    ac, _ = trim_point(cfg, point)
    ac.engage(nx=False)
    ac.command(bank_rad=0.0, ny=1.0, throttle=cfg.inner_loops.throttle_max)
    ac.run(int(15.0 / ac.dt_s))
    f = ac.fdm
    drag_n = f["forces/fwx-aero-lbs"] * LBF_N
    ref = ((_thrust_n(ac) * math.cos(f["aero/alpha-rad"]) - drag_n) * f["velocities/vt-fps"]
           * FT_M / (f["inertia/weight-lbs"] * LBF_N))
    assert got == pytest.approx(ref, rel=0.1)


def test_the_high_point_of_the_global5000_is_thrust_limited_and_the_737s_is_not():
    out = {}
    for name, point in (("737", DesignPoint(3000.0, 111.1, None, "clean")),
                        ("global5000", DesignPoint(12000.0, 230.0, 40000.0, "clean"))):
        cfg = load_aircraft(name)
        pl = point_loops(cfg, linearise(cfg, point), params_from_config(cfg))
        out[name] = thrust_margin(cfg, point, pl)
    assert not out["737"]["thrust_limited"] and out["737"]["dv_energy_kmh"] == 0.0
    g = out["global5000"]
    assert g["thrust_limited"] and g["ps_max_mps"] < g["ps_step_mps"]
    # ΔV of the energy balance is positive and below the whole step's energy: g ΔH / V
    assert 0.0 < g["dv_energy_kmh"] < G0_MPS2 * 100.0 / 230.0 * 3.6
