"""The strapdown bank: an error-free IMU reproduces a JSBSim flight; the interface the filter
drives (correct, take_fed_back, freeze, errors, measured) and its conventions; seeds; faults."""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from fms_testbed.core.units import DPH_RPS
from fms_testbed.navigation.bank import InsBankLike
from fms_testbed.navigation.inertial.bank import StrapdownBank
from fms_testbed.navigation.ins_bank import InsBank, derive_seeds
from fms_testbed.sensors.sins.presets import load_imu
from tests.navigation.strapdown_helpers import error_free_flight, recorded_flight

LEVER = (12.0, 0.5, 1.5)


def _worst(probe):
    E = np.array([e[0] for _, e in probe.log])
    return (np.max(np.abs(E[:, 0:3])), np.max(np.abs(E[:, 3:6])), np.max(np.abs(E[:, 6:9])))


def test_an_error_free_imu_reproduces_the_jsbsim_flight():
    """180 s with a 110° turn and a 800 m climb: the mechanised error-free increments stay on
    JSBSim's trajectory (position: JSBSim's own position vs the trapezoidal integral of its
    velocity, 1e-5 m)."""
    pos, vel, att = _worst(error_free_flight(180.0))
    assert pos < 1e-4 and vel < 1e-8 and att < 1e-10


def test_with_a_lever_arm_the_outputs_are_the_cg_trajectory():
    """IMU 12 m ahead of the CG: the bank's outputs (moved back to the CG) follow JSBSim's CG;
    position within JSBSim's own rate/attitude consistency (a few mm), velocity within the
    lever-arm term of the last frame's mean rate (half a frame behind JSBSim's rate)."""
    pos, vel, att = _worst(error_free_flight(180.0, LEVER))
    assert pos < 0.01 and vel < 5e-3 and att < 1e-10


@pytest.mark.slow
def test_an_error_free_imu_reproduces_a_ten_minute_flight():
    pos, vel, att = _worst(error_free_flight(600.0))
    assert pos < 1e-3 and vel < 1e-7 and att < 1e-10


def _bank(imu="STIM300", n=3, seed=7, **kw):
    return StrapdownBank([imu] * n, derive_seeds(seed, n), **kw)


def _run(bank, calls, n):
    npp = len(bank.frame_properties)
    out = None
    for truth, frames in calls[:n]:
        out = bank.update(truth, None if frames is None else frames[:, :npp])
    return out


def test_both_banks_satisfy_the_interface():
    """Same members, same parameter names as the protocol."""
    for b in (_bank(), InsBank([load_imu("STIM300")] * 2, [1, 2])):
        assert isinstance(b, InsBankLike)
        for name in ("update", "output", "correct", "take_fed_back", "freeze", "errors",
                     "measured"):
            want = list(inspect.signature(getattr(InsBankLike, name)).parameters)[1:]
            assert list(inspect.signature(getattr(b, name)).parameters) == want, name
    ins = InsBank([load_imu("STIM300")], [1])
    calls = recorded_flight(60.0)
    for truth, _ in calls[:3]:
        ins.update(truth)
    f, w = ins.measured(0)
    t = calls[2][0]
    assert np.allclose(f, t.f_body_mps2, atol=0.1)        # truth + declared-size errors
    assert abs(w[0] - t.p_rps) < 1e-4


def test_correcting_by_the_true_errors_puts_a_unit_on_the_truth():
    """correct(i, errors(i)[:15]) zeroes the navigation errors: the sign and frame conventions
    of correct and errors agree (ENU metres, indicated minus true, C_ind = (I - ε×) C_true)."""
    calls = recorded_flight(60.0)
    bank = _bank(lever_arm_m=LEVER)
    _run(bank, calls, 400)
    e = bank.errors(0)
    assert np.max(np.abs(e[:3])) > 10.0                   # a STIM300 after 40 s of turning
    bank.correct(0, e[:15])
    after = bank.errors(0)
    assert np.max(np.abs(after[0:3])) < 0.01 * np.max(np.abs(e[:3]))
    assert np.max(np.abs(after[3:6])) < 1e-3
    assert np.max(np.abs(after[6:9])) < 1e-9
    assert np.allclose(after[9:15], 0.0, atol=1e-15)      # the compensation took the bias
    assert np.allclose(bank.take_fed_back()[0], e[:15]) and not bank.take_fed_back().any()
    assert np.max(np.abs(bank.errors(1)[:3])) > 10.0      # the other units are untouched


def test_feedback_keeps_a_unit_on_the_truth():
    """Correcting every second by the true errors (a perfect filter) holds the unit within the
    error one second of free inertial builds."""
    calls = recorded_flight(60.0)
    bank = _bank(n=1, lever_arm_m=LEVER)
    worst = 0.0
    for k, (truth, frames) in enumerate(calls[:600]):
        bank.update(truth, None if frames is None else frames)
        if k % 10 == 0:
            e = bank.errors(0)
            worst = max(worst, np.max(np.abs(e[:3])))
            bank.correct(0, e[:15])
    assert worst < 1.0


def test_measured_is_the_compensated_imu_output_over_the_step():
    calls = recorded_flight(60.0)
    bank = _bank(imu={}, n=1)
    _run(bank, calls, 300)
    truth = calls[299][0]
    f, w = bank.measured(0)
    assert np.allclose(f, truth.f_body_mps2, atol=0.05)   # JSBSim's specific force, step mean
    assert np.allclose(bank.sensor_errors(truth, 0.1), 0.0, atol=1e-12)
    bank.correct(0, np.r_[np.zeros(9), [0.01, 0, 0], [0, 0, 1e-5]])
    _run(bank, calls[300:], 1)
    f2, w2 = bank.measured(0)
    assert f2[0] == pytest.approx(bank.true_mean[0] - 0.01, abs=1e-12)
    assert w2[2] == pytest.approx(bank.true_mean[5] - 1e-5, abs=1e-15)


def test_same_seed_same_run_and_units_do_not_share_numbers():
    calls = recorded_flight(60.0)
    a, b = _bank(seed=3), _bank(seed=3)
    oa, ob = _run(a, calls, 200), _run(b, calls, 200)
    assert [o.lat_rad for o in oa] == [o.lat_rad for o in ob]
    assert len({o.lat_rad for o in oa}) == 3
    two = StrapdownBank(["STIM300"] * 2, derive_seeds(3, 3)[:2])
    assert [o.lat_rad for o in _run(two, calls, 200)] == [o.lat_rad for o in oa[:2]]


def test_stuck_output_and_the_truth_side_faults():
    calls = recorded_flight(60.0)
    bank = _bank(imu="HG9900")
    _run(bank, calls, 100)
    assert bank.inject(0, {"kind": "stuck"}) == "output stuck"
    held = bank.output(0, calls[99][0])
    bank.inject(1, {"kind": "gyro_bias_step", "axis": "z", "size_dph": 50.0})
    bank.inject(2, {"kind": "accel_bias_step", "axis": "x", "size_ug": 2000.0})
    ref = _bank(imu="HG9900")
    _run(ref, calls, 100)
    out = _run(bank, calls[100:], 200)
    _run(ref, calls[100:], 200)
    assert out[0].lat_rad == held.lat_rad and out[0].t_s == calls[299][0].t_s
    assert bank.errors(1)[14] - ref.errors(1)[14] == pytest.approx(50.0 * DPH_RPS)
    dh = math.degrees(bank.errors(1)[8] - ref.errors(1)[8])
    assert dh == pytest.approx(50.0 * 20.0 / 3600.0, rel=0.1)   # ε_U' = -δω_U, z down
    dv = np.hypot(*(bank.errors(2)[3:5] - ref.errors(2)[3:5]))
    assert dv == pytest.approx(2e-3 * 9.81 * 20.0, rel=0.1)        # 2 mg for 20 s: 0.39 m/s
    with pytest.raises(ValueError, match="not an INS fault"):
        bank.inject(0, {"kind": "gnss_outage"})
