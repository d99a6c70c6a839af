"""JSBSim linearisation at a design point, checked against the nonlinear JSBSim model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.evaluation.linear_check import fit_mode, linear_pulse, nonlinear_pulse
from fms_testbed.sim.jsbsim_core import JSBSimAircraft, wind_axis_load_factors
from fms_testbed.sim.linearise import (DesignPoint, linearise, longitudinal_modes,
                                       set_mass_and_cg, trim_point)

PT = DesignPoint(3000.0, 111.1)


@pytest.fixture(scope="module")
def model737():
    return linearise(load_aircraft("737"), PT)


def test_short_period_matches_the_nonlinear_pulse_response(model737):
    """The short period of FGLinearization's model and the one fitted to JSBSim's own free
    response agree within 2 % in frequency and 0.02 in damping; the linear pitch-rate response
    to the same pulse stays within 3 % of its peak (RMS) over 10 s."""
    sp, _ = longitudinal_modes(model737)
    nl = nonlinear_pulse(load_aircraft("737"), PT)
    t = nl[:, 0]
    sel = (t >= 2.0) & (t <= 10.0)
    fit = fit_mode(t[sel], nl[sel, 1], sp.wn_rps)
    assert fit.wn_rps == pytest.approx(sp.wn_rps, rel=0.02)
    assert fit.zeta == pytest.approx(sp.zeta, abs=0.02)
    lin = linear_pulse(model737, t)
    early = t < 10.0
    rms = np.sqrt(np.mean((lin[early, 0] - nl[early, 1]) ** 2))
    assert rms <= 0.03 * np.abs(nl[early, 1]).max()


def test_phugoid_matches_the_nonlinear_response(model737):
    """Phugoid period within 3 % and damping within 0.01 of the ones fitted to JSBSim's free
    response (with the central-difference speed column; FGLinearization's own gives ζ 0.12
    against the fitted 0.045)."""
    _, ph = longitudinal_modes(model737)
    nl = nonlinear_pulse(load_aircraft("737"), PT)
    sel = nl[:, 0] >= 10.0
    fit = fit_mode(nl[sel, 0], nl[sel, 2], ph.wn_rps)
    assert fit.period_s == pytest.approx(ph.period_s, rel=0.03)
    assert fit.zeta == pytest.approx(ph.zeta, abs=0.01)


def test_load_factor_outputs_follow_the_accelerometer_of_the_nonlinear_model(model737):
    """The linear n_y output (V0/g)(q - α̇) against the wind-axis load factor JSBSim's forces
    give, during an elevator pulse: within 5 % of the peak."""
    import control as ct

    cfg = load_aircraft("737")
    ac, tr = trim_point(cfg, PT)
    fdm = ac.fdm
    fdm["fms/ap/master"] = 0.0
    ny0 = ac.state().ny
    n = int(4.0 / ac.dt_s)
    t, ny = np.empty(n), np.empty(n)
    for k in range(n):
        t[k] = (k + 1) * ac.dt_s
        fdm["fcs/elevator-cmd-norm"] = tr.elevator + (0.02 if 1.0 <= t[k] < 2.0 else 0.0)
        fdm.run()
        st = ac.state()
        ny[k] = st.ny - ny0
    u = np.zeros((2, n))
    u[1] = np.where((t >= 1.0) & (t < 2.0), 0.02, 0.0)
    y = ct.forced_response(model737.lon, t, u).outputs
    lin_ny = y[list(model737.lon.output_labels).index("ny")]
    assert np.abs(lin_ny - ny).max() <= 0.05 * np.abs(ny).max()
    assert wind_axis_load_factors(0.0, -1.0, 0.0, 1.0)[1] == 1.0


def test_linearisation_leaves_the_aircraft_flying(model737):
    """FGLinearization suspends the integration with a zero frame time; the model restores it."""
    cfg = load_aircraft("737")
    ac, tr = trim_point(cfg, PT)
    linearise(cfg, PT, ac, tr)
    t0 = ac.fdm.get_sim_time()
    ac.run(12)
    assert ac.fdm.get_sim_time() == pytest.approx(t0 + 12 * ac.dt_s)


@pytest.mark.parametrize("mass_frac, cg_m", [(0.9, 0.0), (1.1, 0.0), (1.0, 0.2), (1.0, -0.2)])
def test_mass_and_cg_are_set_through_fuel_and_ballast(mass_frac, cg_m):
    """The mass JSBSim reports is the one asked for (0.1 %); with a ballast (mass added or a CG
    shift) the CG ends at the shift (1 cm); fuel removed moves the CG as the tanks say."""
    ac = JSBSimAircraft(load_aircraft("737"))
    ac.fdm.run_ic()
    m0 = ac.fdm["inertia/mass-slugs"] * 14.593902937
    shift = set_mass_and_cg(ac, mass_frac * m0, cg_m)
    assert ac.fdm["inertia/mass-slugs"] * 14.593902937 == pytest.approx(mass_frac * m0, rel=1e-3)
    if mass_frac >= 1.0:
        assert shift == pytest.approx(cg_m, abs=0.01)
    else:
        assert abs(shift) < 0.5


def test_aft_cg_lowers_the_short_period_frequency():
    """Physics check: moving the CG aft reduces static stability, so ω_sp falls."""
    cfg = load_aircraft("737")
    fwd = longitudinal_modes(linearise(cfg, DesignPoint(3000.0, 111.1, cg_shift_m=-0.2)))[0]
    aft = longitudinal_modes(linearise(cfg, DesignPoint(3000.0, 111.1, cg_shift_m=0.2)))[0]
    assert aft.wn_rps < fwd.wn_rps
    assert math.isfinite(aft.zeta)
