"""Piston engines are leaned with altitude inside JSBSim (sim/inner_loops.mixture_channel):
left full rich, JSBSim's O-320 floods above ~2,800 m and no level trim exists there."""

from __future__ import annotations

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.sim.inner_loops import P_SL_PSF
from fms_testbed.sim.jsbsim_core import JSBSimAircraft, bare_fdm, has_piston_engines


def test_piston_engines_are_recognised_from_the_engine_files():
    assert has_piston_engines("c172p")
    assert not has_piston_engines("737")
    assert not has_piston_engines("global5000")


def test_full_rich_floods_the_bare_model_at_altitude():
    """The cause, measured on the bare model: full throttle at 3,048 m, 150 km/h TAS."""
    hp = {}
    for mix in (1.0, 0.688):
        fdm = bare_fdm("c172p")
        fdm["ic/h-sl-ft"] = 10000.0
        fdm["ic/vt-kts"] = 81.0
        fdm.run_ic()
        fdm["propulsion/set-running"] = -1
        fdm["fcs/throttle-cmd-norm[0]"] = 1.0
        fdm["fcs/mixture-cmd-norm[0]"] = mix
        for _ in range(240):
            fdm.run()
        hp[mix] = fdm["propulsion/engine[0]/power-hp"]
    assert hp[1.0] < 20.0 < 100.0 < hp[0.688]


@pytest.mark.parametrize("alt_m, tas_mps", [(500.0, 45.0), (3048.0, 47.8), (3962.0, 50.0)])
def test_c172p_trims_level_up_to_its_ceiling(alt_m, tas_mps):
    ac = JSBSimAircraft(load_aircraft("c172p"))
    r = ac.trim(alt_m, tas_mps)
    assert r.throttle < 0.95
    p_psf = ac["atmosphere/P-psf"]
    assert ac["fcs/mixture-cmd-norm[0]"] == pytest.approx(min(1.0, p_psf / P_SL_PSF), rel=1e-3)
