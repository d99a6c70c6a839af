"""The navigation step's fast paths against the reference paths, on a seeded three-INS run.

- One discretisation of the truth model shared by the INS units (``InsBank(share=True)``) and
  the compiled raw-sensor errors give the numbers of the per-unit paths (1e-12 relative;
  measured bitwise equal).
- The multi-rate prediction (``prediction.PredictionInterval``: one F for the three filters at
  the mean of their units' states, intervals ending at every GNSS epoch and baro reading, after
  ``predict_interval_s`` or ``predict_rotation_deg`` of body rotation) follows the per-step,
  per-filter prediction: the same fixes used (each at the filters' time, its time of validity,
  the estimate carried to the INS of the delivery), σ of the nine navigation states within a few
  per cent (the held P between boundaries is the main difference), the output within
  centimetres.
"""

import numpy as np

from fms_testbed.navigation import make_source
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile

SPEC = {"source": "ins_gnss", "imu": "STIM300", "n_ins": 3, "truth_model": "linear"}


def _states():
    return aircraft_states(fly_profile([Segment(60), Segment(40, 3), Segment(60),
                                        Segment(30, -3), Segment(30)], dt_s=0.1))


def _run(fused: bool, share: bool, states=None):
    states = _states() if states is None else states
    nav = make_source(SPEC, seed=5)
    nav.fused, nav.bank.share = fused, share
    rows, sig = [], []
    for s in states:
        sol = nav.update(s)
        if abs(s.t_s - 80.0) < 1e-6:
            nav.inject({"unit": "ins2", "kind": "gyro_bias_step", "axis": "z", "size_dph": 80.0},
                       s.t_s)
        rows.append([sol.lat_rad, sol.lon_rad, sol.alt_m, *sol.v_enu_mps, sol.heading_rad,
                     sol.errors["anp_m"], sol.errors["ins_used"], sol.errors["nse_east_m"],
                     sol.errors["nse_north_m"], sol.errors["att_err_heading_deg"]]
                    + [f.P[i, i] for f in nav.filters for i in (0, 4, 8, 14)]
                    + [f.x[17] for f in nav.filters]
                    + [x for u in nav.bank.units for x in u.x[[0, 4, 8, 14, 20]]])
        sig.append(np.sqrt(np.diag(nav.filters[0].P)[:9]))
    events = [(e["t_s"], e["kind"], e["unit"]) for e in nav.events]
    return np.array(rows), np.array(sig), events, len(nav.nis_log)


def test_shared_truth_discretisation_gives_the_per_unit_numbers():
    a, _, ea, _ = _run(False, True)
    b, _, eb, _ = _run(False, False)
    assert ea == eb
    assert any(k == "fault_injected" for _, k, _ in ea)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)


def test_multi_rate_prediction_follows_the_per_step_filter():
    a, sa, ea, na = _run(True, True)
    b, sb, eb, nb = _run(False, True)
    assert na == nb                             # every fix found its step boundary
    # the same events; their times within 0.5 s (the fused prediction builds one F from the
    # units' mean measured f, ω, the per-step one each unit's own)
    ka = [e for e in ea if e[1] != "detected"]
    kb = [e for e in eb if e[1] != "detected"]
    assert [e[1:] for e in ka] == [e[1:] for e in kb]
    assert all(abs(x[0] - y[0]) <= 0.5 for x, y in zip(ka, kb))
    # σ and output compared from 10 s to the fault at 80 s: after it the exclusion, whose time
    # differs by 0.2 s between the paths (F and Q from each unit's measured f, ω against one F
    # from the units' mean), switches the output's mean of units (measured: 8.8 % of tilt σ,
    # 1.8 heading σ at the switch)
    k, e = 100, 800
    rel = np.abs(sa[k:e] - sb[k:e]) / sb[k:e]
    assert np.median(rel, axis=0).max() < 0.03
    # tilt: 7.4 % measured in the turns (the interval's F at its start takes the measured f, ω
    # of the step before it; the per-step filter those of its own step)
    assert rel[:, 6:8].max() < 0.1
    assert rel[:, 8].max() < 0.15               # heading, while the turn makes it observable
    assert rel[:, :6].max() < 0.3               # position/velocity: held P before a fix
    assert np.abs(a[k:e, 9:11] - b[k:e, 9:11]).max() < 0.05        # NSE E, N, m
    hdg_sigma_deg = np.degrees(sb[k:e, 8])
    assert (np.abs(a[k:e, 11] - b[k:e, 11]) / hdg_sigma_deg).max() < 0.5


def test_intervals_end_at_gnss_epochs_and_after_the_rotation_limit():
    nav = make_source(SPEC, seed=5)
    flushes = []
    iv_flush = None
    for s in aircraft_states(fly_profile([Segment(30), Segment(30, 3)], dt_s=0.1)):
        nav.update(s)
        if iv_flush is None and nav._interval is not None:
            iv_flush = nav._interval.flush

            def counted(ins, t_s, f_b, w_ib, _f=iv_flush):
                flushes.append(t_s)
                _f(ins, t_s, f_b, w_ib)
            nav._interval.flush = counted
    t = np.array(flushes)
    straight, turn = t[(t > 5) & (t < 29)], t[t > 35]
    assert 0.9 <= len(straight) / 24 <= 1.1     # at each fix's epoch (and baro reading)
    assert len(turn) / (t.max() - 35) >= 3.0    # 3 °/s and at most 1° per interval


def test_corrected_outputs_and_comparison_vectors_are_eq_6_10_and_enu_differences():
    """The compiled corrected outputs of three units (paper eq. 6.10 for the Euler errors) and
    seed 001's comparison vectors against a plain statement with euler.eps_to_euler_errors and
    ins_filter.enu_difference_m."""
    from fms_testbed.navigation.ins_filter import enu_difference_m
    from fms_testbed.navigation.ins_gnss import _corrected_many
    from fms_testbed.sensors.sins.euler import eps_to_euler_errors
    rng = np.random.default_rng(3)
    O = np.column_stack([0.8 + 1e-5 * rng.standard_normal(3), 0.14 + 1e-5 * rng.standard_normal(3),
                         3000 + rng.standard_normal(3), 150 + rng.standard_normal((3, 3)),
                         0.3 * rng.standard_normal((3, 2)), [6.27, 0.01, 3.0]])
    DX = np.column_stack([5 * rng.standard_normal((3, 3)), 0.1 * rng.standard_normal((3, 3)),
                          1e-3 * rng.standard_normal((3, 3))])
    C, Y = _corrected_many(O, DX)
    from fms_testbed.core.earth import radii_m
    for i in range(3):
        rm, rn = radii_m(O[i, 0])
        dr, dp, dh = eps_to_euler_errors(*DX[i, 6:9], O[i, 7], O[i, 8])
        want = [O[i, 0] - DX[i, 1] / (rm + O[i, 2]),
                O[i, 1] - DX[i, 0] / ((rn + O[i, 2]) * np.cos(O[i, 0])), O[i, 2] - DX[i, 2],
                *(O[i, 3:6] - DX[i, 3:6]), O[i, 6] - dr, O[i, 7] - dp, (O[i, 8] - dh) % (2 * np.pi)]
        np.testing.assert_allclose(C[i], want, rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(Y[i, :3], enu_difference_m(*C[i, :3], *C[0, :3]), rtol=1e-12,
                                   atol=1e-9)
        np.testing.assert_array_equal(Y[i, 3:], C[i, 3:])


def test_a_drift_fault_drops_the_held_truth_matrices_of_its_unit():
    """drift_scale replaces a unit's IMU model: from the next step that unit propagates with
    matrices of its new model (its own S), not the others' held ones."""
    states = aircraft_states(fly_profile([Segment(20)], dt_s=0.1))
    nav = make_source(SPEC, seed=2)
    for s in states[:100]:
        nav.update(s)
    nav.inject({"unit": "ins2", "kind": "drift_scale", "factor": 3.0}, states[99].t_s)
    nav.update(states[100])
    u0, u1 = nav.bank.units[0], nav.bank.units[1]
    assert u1.imu is not u0.imu
    assert u1._held is not u0._held
    S0, S1 = u0._held[3], u1._held[3]
    # the gyro-bias random-walk columns carry the factor (σ × 3), the others are unchanged
    assert np.abs(S1).sum() > np.abs(S0).sum()
