"""VNAV's altitude read-ahead follows the coupled law's gain schedule in flight: with a
schedule in the aircraft file, the lead 2 ξ_H T_H and T_H² of the vertical guidance are those
the law takes at the same air data and mass; without one, the file's."""

from __future__ import annotations


import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft, load_aircraft_file
from fms_testbed.control import CoupledLaw
from fms_testbed.control.schedule import schedule_from_points
from fms_testbed.core.atmosphere import R_JPKGK, isa
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.evaluation.envelope_tuning import aircraft_with_schedule
from fms_testbed.guidance.fms import ProcedureGuidance
from fms_testbed.loop.procedure import prepare

ROWS = [{"qbar_pa": q, "mass_kg": m, "T_V_s": 6.0, "xi_V": 0.9, "T_H_s": th, "xi_H": xh,
         "ny_trim_tau_s": 3.0}
        for q, m, th, xh in ((3000.0, 50000.0, 12.0, 0.8), (12000.0, 50000.0, 7.0, 1.0),
                             (3000.0, 70000.0, 14.0, 0.9), (12000.0, 70000.0, 8.0, 1.1))]


@pytest.fixture(scope="module")
def flight():
    scn, spec, fp, db = prepare({"aircraft": "737", "procedure": {
        "airport": "KJFK", "procedure": "DEEZZ5", "runway": "04B"}})
    return fp, db, spec


def _guidance(flight, cfg):
    fp, db, spec = flight
    return ProcedureGuidance(fp, cfg, db=db, spec=spec)


def _step(g, fp, tas, alt):
    seg = fp.path.segments[0]
    lat, lon = seg.geom.start
    nav = NavSolution(1.0, np.radians(lat), np.radians(lon), alt, np.array([0.0, tas, 0.0]),
                      0.0, 0.05, 0.0)
    t, p, _ = isa(alt)
    g.update(0.1, nav, AirData(1.0, tas, tas, 0.4, alt, alt, 0.0, p, t, 0.05, 0.0))
    return p, t


def test_read_ahead_follows_the_schedule_the_law_flies(flight, tmp_path):
    base = load_aircraft("737")
    path = tmp_path / "tuned.yaml"
    path.write_text(aircraft_with_schedule(base, schedule_from_points(ROWS)))
    cfg = load_aircraft_file(path)
    g = _guidance(flight, cfg)
    file_lead = 2 * base.coupled_law.xi_H * base.coupled_law.T_H_s
    assert g.vnav.lead_s == pytest.approx(file_lead)           # no mass yet: the file's
    law = CoupledLaw(cfg)
    for tas, alt, mass in ((110.0, 3000.0, 55000.0), (200.0, 1000.0, 65000.0),
                           (80.0, 6000.0, 60000.0)):
        g.set_mass(mass)
        p, t = _step(g, flight[0], tas, alt)
        # the law at the same air data and mass (q̄ = ½ ρ V², ρ = p / (R T))
        rho = p / (R_JPKGK * t)
        want = law.schedule.values(0.5 * rho * tas * tas, mass)
        assert g.vnav.lead_s == pytest.approx(2 * want["xi_H"] * want["T_H_s"], rel=1e-9)
        assert g.vnav.t2_s2 == pytest.approx(want["T_H_s"] ** 2, rel=1e-9)
        assert g.vnav.lead_s != pytest.approx(file_lead, rel=0.01)


def test_without_a_schedule_the_read_ahead_is_the_files(flight):
    cfg = load_aircraft("737")
    assert cfg.coupled_law_schedule is None
    g = _guidance(flight, cfg)
    g.set_mass(60000.0)
    _step(g, flight[0], 150.0, 2000.0)
    assert g.vnav.lead_s == pytest.approx(2 * cfg.coupled_law.xi_H * cfg.coupled_law.T_H_s)
    assert g.vnav.t2_s2 == pytest.approx(cfg.coupled_law.T_H_s ** 2)
