"""Goals of the envelope tuning: the closed-form step response, the altitude-loop goal against
the file law, the lateral path-error goal of the bank-loop tuning."""

from __future__ import annotations

from dataclasses import replace

import control as ct
import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.evaluation import envelope_points as ep
from fms_testbed.sim.inner_steps import replace_gains
from fms_testbed.sim.linearise import DesignPoint, linearise


@pytest.fixture(scope="module")
def point():
    cfg = load_aircraft("737")
    return cfg, linearise(cfg, DesignPoint(3000.0, 111.1, None, "clean"))


def test_step_outputs_match_python_control(point):
    cfg, model = point
    pl = ep.point_loops(cfg, model, ep.start_law(cfg))
    sys = pl.closed("lon", ["V_cmd", "H_cmd"], ["V", "h", "throttle", "elevator"])
    u = np.array([11.0, 100.0])
    y = ep.step_outputs(sys, u)
    t = np.arange(0.0, ep.T_STEP_S + 0.05, 0.1)
    ref = ct.forced_response(sys, t, np.tile(u[:, None], (1, len(t)))).outputs.T[1:len(y) + 1]
    assert np.abs(y - ref).max() < 1e-6 * np.abs(ref).max()


def test_altitude_goal_refuses_a_slower_or_less_damped_altitude_loop(point):
    cfg, model = point
    law = ep.start_law(cfg)
    ref = ep.linear_goals(ep.point_loops(cfg, model, law))
    assert 5.0 < ref.h_rise_s < 60.0
    assert ep._constraints(ref, ref)[-2:].min() >= 0.0
    slow = ep.linear_goals(ep.point_loops(cfg, model, replace(law, T_H_s=1.4 * law.T_H_s)))
    assert slow.h_rise_s > ref.h_rise_s and ep._constraints(slow, ref)[-2] < 0.0
    light = ep.linear_goals(ep.point_loops(cfg, model, replace(law, xi_H=0.6 * law.xi_H)))
    assert light.h_overshoot > ref.h_overshoot and ep._constraints(light, ref)[-1] < 0.0


def test_a_softer_bank_loop_has_the_larger_path_error(point):
    cfg, model = point
    g = cfg.inner_loops.bank
    soft = replace_gains(cfg, "bank", g.model_copy(update={"kp": 0.5 * g.kp}))
    e_file = ep.path_error_ms(ep.point_loops(cfg, model, ep.start_law(cfg)))
    e_soft = ep.path_error_ms(ep.point_loops(soft, model, ep.start_law(cfg)))
    assert e_soft > e_file > 0.0
    sl = ep._bank_slack(cfg, [model], g.model_copy(update={"kp": 0.5 * g.kp}), [e_file])
    assert sl[-1] < 0.0
