"""Inner loops meet their step specs on every shipped aircraft at its design point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.config.aircraft import list_aircraft, load_aircraft
from fms_testbed.sim.inner_steps import check_aircraft, specs_for, step_metrics


@pytest.mark.parametrize("name", list_aircraft())
def test_inner_loop_specs(name):
    cfg = load_aircraft(name)
    results = check_aircraft(cfg)
    assert len(results) == len(specs_for(cfg)) == 5
    failed = [f"{r.spec.loop} {r.spec.amplitude:+.3f}: settle {r.settle_s:.2f} s "
              f"(max {r.spec.settle_max_s}), overshoot {r.overshoot_pct:.1f} % "
              f"(max {r.spec.overshoot_max_pct})" for r in results if not r.ok]
    assert not failed, failed
    # the bank and n_y specs hold on every aircraft unchanged
    assert cfg.inner_spec.bank_settle_max_s <= 6.0 and cfg.inner_spec.ny_settle_max_s <= 2.0


def test_step_metrics_on_a_known_second_order_response():
    t = np.linspace(0, 20, 20001)
    zeta, wn = 0.5, 2.0
    wd = wn * math.sqrt(1 - zeta**2)
    y = 1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))
    settle, over = step_metrics(t, y, 0.0, 1.0)
    assert over == pytest.approx(100 * math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2)), rel=1e-3)
    assert 2.5 < settle < 3.5  # ≈ 3/(ζ ω_n) for the 5 % band


def test_unsettled_response_reports_infinite_settling():
    t = np.linspace(0, 1, 11)
    settle, _ = step_metrics(t, t * 0.5, 0.0, 1.0)
    assert settle == math.inf


@pytest.mark.parametrize("loop", ["ny", "nx", "bank"])
def test_inner_loops_at_60_hz_track_like_120_hz(loop):
    """The default 60 Hz update (JSBSim channel execrate 2) gives the 120 Hz step response: a
    PID or rate limit stepping with the frame time instead of the channel's would not (the n_y and
    n_x loops integrate with ki > 0 on the 737)."""
    from fms_testbed.sim.inner_steps import step_response
    from fms_testbed.sim.jsbsim_core import JSBSimAircraft

    cfg = load_aircraft("737")
    assert cfg.inner_loops.frames_per_update == 2
    spec = next(s for s in specs_for(cfg) if s.loop == loop)
    resp = {}
    for n in (1, 2):
        c = cfg.model_copy(update={"inner_loops": cfg.inner_loops.model_copy(
            update={"frames_per_update": n})})
        resp[n] = step_response(JSBSimAircraft(c), spec, cfg.default_condition)
    diff = np.max(np.abs(resp[1].y - resp[2].y)) / abs(spec.amplitude)
    assert diff < 0.05, f"{loop}: 60 Hz vs 120 Hz response differs by {diff:.1%} of the step"
    assert abs(resp[1].settle_s - resp[2].settle_s) < 0.2


def test_doubling_the_pid_step_would_be_caught():
    """Counter-check of the test above: halving ki (what a wrong integrator step does) moves the
    n_x response by more than the 5 % tolerance."""
    from fms_testbed.sim.inner_steps import replace_gains, step_response
    from fms_testbed.sim.jsbsim_core import JSBSimAircraft

    cfg = load_aircraft("737")
    spec = next(s for s in specs_for(cfg) if s.loop == "nx")
    g = cfg.inner_loops.nx
    a = step_response(JSBSimAircraft(cfg), spec, cfg.default_condition)
    b = step_response(JSBSimAircraft(replace_gains(cfg, "nx", g.model_copy(update={"ki": g.ki / 2}))),
                      spec, cfg.default_condition)
    assert np.max(np.abs(a.y - b.y)) / abs(spec.amplitude) > 0.05
