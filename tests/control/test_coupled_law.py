"""The coupled law on the point-mass plant: decoupling, second-order dynamics, limits, windup."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.control import VERTICAL_LAWS, CoupledLaw, CoupledLawParams
from fms_testbed.control.coupled_law import gravity_ratio, params_from_config
from fms_testbed.core.earth import OMEGA_IE_RPS
from fms_testbed.core.units import G0_MPS2
from fms_testbed.control.pointmass import (CommandEvent, PointMassParams, make_state,
                                           second_order_step, simulate)

V0 = 400 / 3.6
#: lag-free inner-loop model: on the ideal plant the n_y tracking-error integrator stays at zero
P = CoupledLawParams(T_V_s=6.0, xi_V=1.0, T_H_s=8.0, xi_H=1.0, ny_min=0.5, ny_max=1.6,
                     ny_model_tau_s=0.0)
WIDE = PointMassParams(nx_idle=-0.3, nx_max=0.5)


@pytest.fixture
def aircraft_737():
    return load_aircraft("737")


def test_engagement_is_bumpless_in_trimmed_flight():
    gr = gravity_ratio(0.0, 3000.0)
    s = make_state(0.0, V0, 0.0, 3000.0, 0.012, gr, 0.5)
    law = CoupledLaw(params=P)
    law.engage(s, 3000.0, V0)
    nx, ny = law.update(0.025, s, 3000.0, V0)
    # the integrator starts at the measured n_x and the elevator channel asks for level flight
    assert nx == pytest.approx(0.012 - 0.025 * 2 / 6 * 0.012, abs=1e-9)
    assert ny == pytest.approx(gr, abs=1e-12)


def test_altitude_step_follows_the_second_order_error_dynamics_exactly():
    df = simulate(CoupledLaw(params=P), WIDE, 3000.0, V0, 80.0, [CommandEvent(t_s=0.0, alt_m=3080.0)])
    want = 3000.0 + 80.0 * second_order_step(df["t_s"].to_numpy(), P.T_H_s, P.xi_H)
    assert np.max(np.abs(df["alt_m"] - want)) < 0.005 * 80.0
    # and the speed does not move (exact form of eq. 7/8 on the plant of eq. 1)
    assert np.max(np.abs(df["tas_mps"] - V0)) * 3.6 < 0.05


def test_speed_step_follows_second_order_and_leaves_altitude_alone():
    df = simulate(CoupledLaw(params=P), WIDE, 3000.0, V0, 80.0,
                  [CommandEvent(t_s=0.0, tas_mps=V0 + 50 / 3.6)])
    want = V0 + 50 / 3.6 * second_order_step(df["t_s"].to_numpy(), P.T_V_s, P.xi_V)
    assert np.max(np.abs(df["tas_mps"] - want)) < 0.005 * 50 / 3.6
    assert np.max(np.abs(df["alt_m"] - 3000.0)) < 0.01


def test_altitude_error_limit_turns_a_large_step_into_a_constant_climb_rate():
    df = simulate(CoupledLaw(params=P), WIDE, 3000.0, V0, 60.0, [CommandEvent(t_s=0.0, alt_m=3500.0)])
    mid = df[(df["t_s"] > 40) & (df["alt_m"] < 3350)]
    assert len(mid) > 10
    assert mid["vs_mps"].to_numpy() == pytest.approx(P.vy_limit_mps, rel=1e-3)


def test_dropping_the_cross_terms_costs_speed_in_a_level_change():
    """Baseline (a) — no cross couplings — loses several km/h where the coupled law loses none."""
    ev = [CommandEvent(t_s=0.0, alt_m=3500.0)]
    coupled = simulate(CoupledLaw(params=P), WIDE, 3000.0, V0, 120.0, ev)
    pi = simulate(VERTICAL_LAWS["pi"](params=P), WIDE, 3000.0, V0, 120.0, ev)
    dv_c = np.max(np.abs(coupled["tas_mps"] - V0)) * 3.6
    dv_pi = np.max(np.abs(pi["tas_mps"] - V0)) * 3.6
    assert dv_c < 0.05
    assert dv_pi > 2.0


def test_paper_form_is_nearly_decoupled():
    p = replace(P, form="paper")
    df = simulate(CoupledLaw(params=p), WIDE, 3000.0, V0, 120.0, [CommandEvent(t_s=0, alt_m=3500)])
    assert np.max(np.abs(df["tas_mps"] - V0)) * 3.6 < 0.5
    assert df["alt_m"].iloc[-1] == pytest.approx(3500.0, abs=1.0)


def test_normal_load_factor_command_respects_the_aircraft_limits():
    p = replace(P, ny_min=0.9, ny_max=1.05, dH_limit_m=500.0)
    df = simulate(CoupledLaw(params=p), WIDE, 3000.0, V0, 60.0, [CommandEvent(t_s=0, alt_m=3500)])
    assert df["cmd_ny"].max() <= 1.05 + 1e-12
    assert df["cmd_ny"].min() >= 0.9 - 1e-12


# --- limits: anti-windup and speed protection -------------------------------------------------

CLIMB_LIMITED = PointMassParams(nx_idle=-0.1, nx_max=0.03, tau_nx_s=0.5, tau_ny_s=0.5)
IDLE_LIMITED = PointMassParams(nx_idle=-0.03, nx_max=0.3, tau_nx_s=0.5, tau_ny_s=0.5)


def _fly(p, pm, alt_cmd):
    p = replace(p, ny_model_tau_s=pm.tau_ny_s)
    return simulate(CoupledLaw(params=p), pm, 3000.0, V0, 250.0, [CommandEvent(t_s=5, alt_m=alt_cmd)])


def test_no_integrator_windup_at_max_throttle():
    """Climb needing more thrust than there is (speed protection off to force saturation)."""
    p = replace(P, speed_protection=False)
    ok = _fly(p, CLIMB_LIMITED, 3500.0)
    wound = _fly(replace(p, anti_windup=False), CLIMB_LIMITED, 3500.0)
    assert ok["cmd_nx"].max() <= CLIMB_LIMITED.nx_max + 0.011
    assert wound["cmd_nx"].max() > 1.0                       # what the back-calculation prevents
    # after the climb: no speed overshoot from a wound-up integrator
    assert (ok["tas_mps"].max() - V0) * 3.6 < 0.5
    assert (wound["tas_mps"].max() - V0) * 3.6 > 20.0


def test_speed_protection_gives_up_climb_rate_not_speed_when_thrust_limited():
    prot = _fly(P, CLIMB_LIMITED, 3500.0)
    raw = _fly(replace(P, speed_protection=False), CLIMB_LIMITED, 3500.0)
    assert np.max(np.abs(prot["tas_mps"] - V0)) * 3.6 < 1.0
    assert (V0 - raw["tas_mps"].min()) * 3.6 > 20.0
    assert prot["alt_m"].iloc[-1] == pytest.approx(3500.0, abs=2.0)
    assert prot["vs_mps"].max() < P.vy_limit_mps             # the climb was slowed instead


def test_no_overspeed_in_an_idle_descent():
    prot = _fly(P, IDLE_LIMITED, 2500.0)
    raw = _fly(replace(P, speed_protection=False), IDLE_LIMITED, 2500.0)
    assert (prot["tas_mps"].max() - V0) * 3.6 < 1.0
    assert (raw["tas_mps"].max() - V0) * 3.6 > 20.0
    assert prot["cmd_nx"].min() >= IDLE_LIMITED.nx_idle - 0.021     # pegged just below idle
    assert prot["alt_m"].iloc[-1] == pytest.approx(2500.0, abs=2.0)


# --- tuning from the config; gravity ---------------------------------------------------------

def test_params_come_from_the_aircraft_config(aircraft_737):
    p = params_from_config(aircraft_737)
    g = aircraft_737.coupled_law
    assert (p.T_V_s, p.xi_V, p.T_H_s, p.xi_H) == (g.T_V_s, g.xi_V, g.T_H_s, g.xi_H)
    assert (p.ny_min, p.ny_max) == (aircraft_737.limits.ny_min, aircraft_737.limits.ny_max)
    for cls in VERTICAL_LAWS.values():
        assert cls(aircraft_737).params == p


def test_invalid_tuning_is_rejected_with_the_field_name():
    with pytest.raises(ValueError, match="T_V_s"):
        CoupledLawParams(T_V_s=0.0, xi_V=1.0, T_H_s=8.0, xi_H=1.0)
    with pytest.raises(ValueError, match="form"):
        CoupledLawParams(T_V_s=6.0, xi_V=1.0, T_H_s=8.0, xi_H=1.0, form="tecs")


def test_gravity_ratio_includes_height_latitude_and_eotvos():
    assert gravity_ratio(math.radians(45), 0.0) == pytest.approx(9.80620 / G0_MPS2, abs=2e-5)
    assert gravity_ratio(0.0, 10000.0) < gravity_ratio(0.0, 0.0)
    east = gravity_ratio(math.radians(47), 3000.0, 111.0, 0.0)
    west = gravity_ratio(math.radians(47), 3000.0, -111.0, 0.0)
    assert (west - east) * G0_MPS2 == pytest.approx(4 * OMEGA_IE_RPS * 111 * math.cos(
        math.radians(47)), rel=1e-6)


@settings(max_examples=25, deadline=None)
@given(T_V=st.floats(4.0, 15.0), xi_V=st.floats(0.6, 1.5), T_H=st.floats(5.0, 20.0),
       xi_H=st.floats(0.6, 1.5), dH=st.floats(-90.0, 90.0))
def test_any_tuning_keeps_speed_during_an_unclipped_altitude_step(T_V, xi_V, T_H, xi_H, dH):
    p = CoupledLawParams(T_V_s=T_V, xi_V=xi_V, T_H_s=T_H, xi_H=xi_H, ny_model_tau_s=0.0)
    df = simulate(CoupledLaw(params=p), WIDE, 3000.0, V0, 40.0, [CommandEvent(t_s=0, alt_m=3000 + dH)],
                  dt_s=0.05, substeps=2)
    # zero in continuous time; what is left is the 20 Hz discretisation (PI baseline: ~3 km/h)
    assert np.max(np.abs(df["tas_mps"] - V0)) * 3.6 < 0.1
