"""The navigation step's fast paths (one discretisation of the truth model shared by the INS
units, one compiled prediction for the three filters, the compiled raw-sensor errors) give the
numbers of the per-unit paths: a seeded three-INS run with a gyro fault, compared sample by
sample. Tolerance: 1e-12 relative (measured: bitwise equal)."""

import numpy as np

from fms_testbed.navigation import make_source
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile


def _run(fast: bool):
    states = aircraft_states(fly_profile([Segment(60), Segment(40, 3), Segment(60)], dt_s=0.1))
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=5)
    nav.fused = nav.bank.share = fast
    rows = []
    for s in states:
        sol = nav.update(s)
        if abs(s.t_s - 80.0) < 1e-6:
            nav.inject({"unit": "ins2", "kind": "gyro_bias_step", "axis": "z", "size_dph": 80.0},
                       s.t_s)
        rows.append([sol.lat_rad, sol.lon_rad, sol.alt_m, *sol.v_enu_mps, sol.heading_rad,
                     sol.errors["anp_m"], sol.errors["ins_used"]]
                    + [f.P[i, i] for f in nav.filters for i in (0, 4, 8, 14)]
                    + [f.x[17] for f in nav.filters]
                    + [x for u in nav.bank.units for x in u.x[[0, 4, 8, 14, 20]]])
    return np.array(rows), [(e["t_s"], e["kind"], e["unit"]) for e in nav.events]


def test_fast_paths_give_the_per_unit_numbers():
    a, ea = _run(True)
    b, eb = _run(False)
    assert ea == eb
    assert any(k == "fault_injected" for _, k, _ in ea)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)


def _gamma(v):
    return np.array([[v[1], v[2], 0, 0, 0, 0], [0, 0, v[0], v[2], 0, 0], [0, 0, 0, 0, v[0], v[1]]])


def test_compiled_sensor_errors_are_eq_5_1():
    """bias + compensation + scale factor + misalignment Γ(v) m (paper eq. 5.1), the white
    noise made negligible by a huge averaging interval."""
    states = aircraft_states(fly_profile([Segment(20, 3)], dt_s=0.1))
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=6)
    for s in states:
        nav.update(s)
    s = states[-1]
    nav.bank.compensation[:] = np.random.default_rng(1).standard_normal((3, 6)) * 1e-4
    got = nav.bank.sensor_errors(s, 1e300)
    f, w = s.f_body_mps2, np.array([s.p_rps, s.q_rps, s.r_rps])
    for i, u in enumerate(nav.bank.units):
        x, b = u.x, u.x[9:15] + nav.bank.compensation[i]
        np.testing.assert_allclose(got[i, :3], b[:3] + x[15:18] * f + _gamma(f) @ x[21:27],
                                   rtol=1e-12, atol=1e-18)
        np.testing.assert_allclose(got[i, 3:], b[3:] + x[18:21] * w + _gamma(w) @ x[27:33],
                                   rtol=1e-12, atol=1e-18)
