"""Loops broken for margins: the interconnection, the margins, the schedule."""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pytest

from fms_testbed.control import linear
from fms_testbed.control.coupled_law import CoupledLaw, CoupledLawParams
from fms_testbed.control.loops import connect, margins
from fms_testbed.control.schedule import qbar_from_state, schedule_from_points

P = CoupledLawParams(T_V_s=6.0, xi_V=0.9, T_H_s=9.0, xi_H=0.8)


def test_connect_agrees_with_python_control_interconnect():
    """The point-mass plant and the law joined by name give the same W(jω) as the
    python-control interconnection of control.linear.closed_loop."""
    V0 = 120.0
    ref = linear.closed_loop(P, V0, 0.8, 0.5)
    plant = linear.plant_ss(V0, 0.8, 0.5)
    law = linear.law_ss(P, V0)
    mine = connect([plant, law], ["V_cmd", "H_cmd"], ["V", "H", "theta", "nx_cmd"])
    w = np.logspace(-3, 1, 50)
    assert np.allclose(linear.frequency_response(mine, w), linear.frequency_response(ref, w),
                       atol=1e-9)


def test_connect_solves_a_direct_feedthrough_loop():
    """y = 2 u, u = r - 0.5 y → y = r (an algebraic loop python-control's interconnect rejects)."""
    a = ct.ss([], [], [], [[2.0]], inputs=["u"], outputs=["y"])
    b = ct.ss([], [], [], [[1.0, -0.5]], inputs=["r", "y"], outputs=["u"])
    s = connect([a, b], ["r"], ["y"])
    assert float(np.asarray(s.D)[0, 0]) == pytest.approx(1.0)


def test_margins_of_a_known_loop():
    """L = k / (s (s+1)(s+2)): phase crossover at √2 rad/s where |L| = k/6 → GM = 6/k;
    PM from the gain crossover solved numerically; delay margin = PM / ω_c."""
    k = 2.0
    L = ct.ss(ct.tf([k], [1, 3, 2, 0]))
    m = margins(L)
    assert m.gm_db == pytest.approx(20 * math.log10(6 / k), abs=0.05)
    from scipy.optimize import brentq

    # |L(jω)| = 1  ⇔  x (x + 1)(x + 4) = k² with x = ω²
    wc = math.sqrt(brentq(lambda x: x * (x + 1) * (x + 4) - k * k, 1e-6, 10.0))
    pm = 180.0 - 90.0 - math.degrees(math.atan(wc) + math.atan(wc / 2))
    assert m.pm_deg == pytest.approx(pm, abs=0.2)
    assert m.delay_margin_s == pytest.approx(math.radians(pm) / wc, rel=0.01)
    assert 0 < m.disk_margin < 2


def test_schedule_passes_through_its_points_and_is_linear_between():
    rows = [{"qbar_pa": q, "mass_kg": m, "T_V_s": tv}
            for q, m, tv in ((3000.0, 40000.0, 5.0), (9000.0, 40000.0, 8.0),
                             (3000.0, 60000.0, 6.0), (9000.0, 60000.0, 10.0))]
    s = schedule_from_points(rows)
    for r in rows:
        assert s.values(r["qbar_pa"], r["mass_kg"])["T_V_s"] == pytest.approx(r["T_V_s"])
    mid_q = math.exp(0.5 * (math.log(3000.0) + math.log(9000.0)))
    assert s.values(mid_q, 40000.0)["T_V_s"] == pytest.approx(6.5)
    assert s.values(mid_q, 50000.0)["T_V_s"] == pytest.approx(0.5 * (6.5 + 8.0))
    assert s.values(1e6, 1e6)["T_V_s"] == pytest.approx(10.0)     # held beyond the table


def test_law_follows_the_schedule_in_flight():
    """A law with a schedule takes the scheduled T_V at the state's q̄ and mass."""
    from fms_testbed.core.state import AircraftState
    from fms_testbed.core.atmosphere import isa

    sch = schedule_from_points([{"qbar_pa": 4000.0, "mass_kg": 50000.0, "T_V_s": 5.0},
                                {"qbar_pa": 16000.0, "mass_kg": 50000.0, "T_V_s": 9.0}])
    law = CoupledLaw(params=P, schedule=sch)
    T, p, _ = isa(3000.0)
    st = AircraftState(0.0, 0.8, 0.0, 3000.0, 150.0, 120.0, 150.0, 0.0, np.zeros(3), 0.0, 0.05,
                       0.0, 0.0, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, np.zeros(3), 0.45,
                       3000.0, 0.5, 50000.0, float(p), float(T))
    law.update(0.1, st, 3000.0, 150.0)
    q = qbar_from_state(150.0, float(p), float(T))
    want = 5.0 + 4.0 * math.log(q / 4000.0) / math.log(4.0)
    assert 5.0 < want < 9.0
    assert law.params.T_V_s == pytest.approx(want, rel=1e-6)


def _airframe(V0=120.0):
    """A stable hand-made longitudinal airframe (V, α, θ, q, h; the aero terms in the
    air-relative V and α only, ḣ = V₀ (θ - α))."""
    from fms_testbed.sim.linearise import longitudinal_ss

    g = 9.80665
    A = np.array([[-0.02, 5.0, -g, 0.0, 0.0],
                  [-0.002, -0.8, 0.0, 1.0, 0.0],
                  [0.0, 0.0, 0.0, 1.0, 0.0],
                  [0.0, -2.0, 0.0, -1.2, 0.0],
                  [0.0, -V0, V0, 0.0, 0.0]])
    B = np.array([[2.0, 0.0], [0.0, -0.1], [0.0, 0.0], [0.0, -3.0], [0.0, 0.0]])
    return longitudinal_ss(A, B, V0, 0.2), V0


def test_gusts_leave_the_air_relative_trim_and_carry_the_aircraft_with_the_air():
    """Controls fixed, a steady updraft w or headwind u: the aircraft settles back to its
    air-relative trim (V, α as before) while climbing with the air (ḣ = w, inertial γ =
    w / V₀); the headwind changes nothing inertial in the climb."""
    from fms_testbed.control.loops import GUST_INPUTS, with_gusts

    lon, V0 = _airframe()
    sys = with_gusts(lon, V0)
    assert list(sys.input_labels) == ["throttle", "elevator", *GUST_INPUTS]
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    ih = list(sys.state_labels).index("h_m")
    keep = [i for i in range(A.shape[0]) if i != ih]          # h is an integrator
    out = list(sys.output_labels)
    for k, w in ((2, 1.5), (3, 2.0)):
        # the first instant: α (updraft) or V (headwind) jumps by the gust
        y0 = D[:, k] * w
        assert y0[out.index("alpha" if k == 2 else "V")] == pytest.approx(
            w / V0 if k == 2 else w, rel=1e-9)
        # the steady state with the controls fixed
        x = np.zeros(A.shape[0])
        x[keep] = -np.linalg.solve(A[np.ix_(keep, keep)], B[keep, k] * w)
        y = C @ x + D[:, k] * w
        assert abs(y[out.index("alpha")]) < 1e-12 and abs(y[out.index("V")]) < 1e-9
        assert A[ih] @ x + B[ih, k] * w == pytest.approx(w if k == 2 else 0.0, abs=1e-9)
        assert y[out.index("gamma")] == pytest.approx(w / V0 if k == 2 else 0.0, abs=1e-12)
