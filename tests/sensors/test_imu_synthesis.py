"""The truth-side IMU against things it did not make: JSBSim's own height datum, rates and
forces, and pyins' ``sim.generate_imu`` and strapdown ``Integrator`` on the same trajectory."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.earth import (earth_rate_ned, ellipsoidal_height_m, normal_gravity_mps2,
                                    radii_m, sea_level_height_m)
from fms_testbed.sensors.imu.kinematics import euler_to_quat, qconj, qrot, quat_to_euler
from fms_testbed.sensors.imu.synthesis import FRAME_PROPERTIES, ImuSynthesizer, synthesize
from fms_testbed.sim.jsbsim_core import JSBSimAircraft
from tests.navigation.strapdown_helpers import recorded_flight

FT = 0.3048


@pytest.fixture(scope="module")
def aircraft():
    return JSBSimAircraft(load_aircraft("737"))


@pytest.mark.parametrize("lat_deg", [0.0, 30.0, 47.0, 70.0])
@pytest.mark.parametrize("alt_m", [300.0, 3000.0, 11000.0])
def test_sea_level_height_is_jsbsims_h_sl(aircraft, lat_deg, alt_m):
    """``position/h-sl-ft`` (the package's alt_m) from ``position/geod-alt-ft`` to 1e-7 m."""
    fdm = aircraft.fdm
    fdm["ic/lat-geod-deg"] = lat_deg
    fdm["ic/h-sl-ft"] = alt_m / FT
    fdm.run_ic()
    lat, h = fdm["position/lat-geod-rad"], fdm["position/geod-alt-ft"] * FT
    assert sea_level_height_m(lat, h) == pytest.approx(fdm["position/h-sl-ft"] * FT, abs=1e-7)
    assert ellipsoidal_height_m(lat, fdm["position/h-sl-ft"] * FT) == pytest.approx(h, abs=1e-7)


def test_jsbsim_rates_are_earth_relative_and_positions_integrate_velocity(aircraft):
    """What the synthesis assumes of JSBSim 1.3.3: p, q, r = ω_eb (p_i - p = C_n^b ω_ie^n), and
    the geodetic position is the trapezoidal integral of the NED velocity."""
    aircraft.trim(3000.0, 120.0, 30.0, lat_deg=47.0, lon_deg=8.0)
    aircraft.engage()
    aircraft.command(bank_rad=0.4, ny=1.0 / math.cos(0.4))
    props = FRAME_PROPERTIES + (("position/lat-geod-rad", 1.0), ("position/long-gc-rad", 1.0),
                                ("position/geod-alt-ft", FT), ("velocities/p-rad_sec", 1.0),
                                ("velocities/q-rad_sec", 1.0), ("velocities/r-rad_sec", 1.0),
                                ("velocities/pi-rad_sec", 1.0), ("velocities/qi-rad_sec", 1.0),
                                ("velocities/ri-rad_sec", 1.0))
    g = aircraft.frame_getters(props)
    buf = np.empty((120 * 60, len(props)))
    aircraft.run_sampled(len(buf), g, buf)
    lat, lon, h = buf[0, 6:9]
    for k in range(1, len(buf)):
        v0, v1 = buf[k - 1, :3], buf[k, :3]
        rm, rn = radii_m(lat)
        lat1 = lat + 0.5 * (v0[0] + v1[0]) / (rm + h) / 120.0
        lon += 0.5 * (v0[1] + v1[1]) / ((rn + h) * math.cos(0.5 * (lat + lat1))) / 120.0
        lat, h = lat1, h - 0.5 * (v0[2] + v1[2]) / 120.0
    rm, rn = radii_m(lat)
    assert abs(lat - buf[-1, 6]) * rm < 1e-4 and abs(h - buf[-1, 8]) < 1e-4
    assert abs(lon - buf[-1, 7]) * rn * math.cos(lat) < 1e-4
    f = buf[-1]
    w_ie = qrot(qconj(euler_to_quat(f[3], f[4], f[5])), earth_rate_ned(f[6]))
    assert np.allclose(f[12:15] - f[9:12], w_ie, atol=1e-12)


def test_synthesised_specific_force_is_jsbsims():
    """Δv/Δt of the last frame of each step against JSBSim's total force over mass (gravity
    model and the half-frame lag apart: JSBSim's gravitation vs WGS-84 normal gravity)."""
    calls = recorded_flight(180.0)
    syn = ImuSynthesizer()
    syn.start(calls[0][0])
    df = []
    for truth, frames in calls[1:]:
        inc, dt = syn.increments(truth, frames[:, :6])
        df.append(inc[-1, 3:] / dt - truth.f_body_mps2)
    df = np.abs(np.array(df))
    assert np.median(df) < 1e-4                      # m/s², 10 µg
    assert np.max(df) < 0.05                         # the fastest transients


def _frame_by_frame(n_steps: int):
    """The IMU's own states and error-free increments over the first ``n_steps`` steps of the
    recorded flight, frame by frame."""
    calls = recorded_flight(180.0)
    syn = ImuSynthesizer()
    syn.start(calls[0][0])
    rows, incs = [syn.row.copy()], []
    out = np.empty((1, 6))
    for truth, frames in calls[1:n_steps + 1]:
        for f in frames:
            synthesize(syn.row, np.ascontiguousarray(f[None, :6]), 1.0 / 120.0, syn.lever,
                       False, out)
            rows.append(syn.row.copy())
            incs.append(out[0].copy())
    return np.array(rows), np.array(incs)


def _pyins_gravity(lat, h):
    """pyins' normal gravity: Somigliana with the linear height term only."""
    from pyins import earth
    return earth.gravity(np.degrees(lat), h)


def test_pyins_generate_imu_gives_the_same_increments():
    """pyins' exact increments of the spline through the same samples: Δθ agrees to 1e-10 rad
    (of 1e-4 per frame); Δv to 1e-8 m/s once the two gravity models' difference (pyins keeps
    only the linear height term of normal gravity) is taken out."""
    pytest.importorskip("pyins")
    from pyins import sim
    R, inc = _frame_by_frame(300)
    t = np.arange(len(R)) / 120.0
    lla = np.c_[np.degrees(R[:, 0]), np.degrees(R[:, 1]), R[:, 2]]
    rph = np.degrees([quat_to_euler(tuple(q)) for q in R[:, 6:10]])
    _, imu = sim.generate_imu(t, lla, rph, R[:, 3:6], sensor_type="increment")
    ref = imu.values[1:]
    assert np.max(np.abs(inc[:, :3] - ref[:, :3])) < 1e-10
    dg = np.array([_pyins_gravity(r[0], r[2]) - normal_gravity_mps2(r[0], r[2]) for r in R[:-1]])
    grav = np.array([qrot(qconj(tuple(q)), (0.0, 0.0, d / 120.0)) for q, d in zip(R[:-1, 6:10], dg)])
    assert np.max(np.abs(inc[:, 3:] - ref[:, 3:])) > 5e-8          # the gravity difference...
    assert np.max(np.abs(inc[:, 3:] - ref[:, 3:] - grav)) < 1e-8   # ...is all there is


def test_pyins_integrator_on_our_increments_follows_the_trajectory():
    """pyins' strapdown ``Integrator`` on the synthesised increments stays on the trajectory
    for 30 s (its gravity model's drift removed: Δv_D = ∫Δg dt, Δh = -∫∫Δg dt²)."""
    pytest.importorskip("pyins")
    import pandas as pd
    from pyins import strapdown
    from pyins.util import TRAJECTORY_COLS
    R, inc = _frame_by_frame(300)
    t = np.arange(len(R)) / 120.0
    cols = ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    imu = pd.DataFrame(np.vstack([inc[:1], inc]), index=t, columns=cols)
    rph = np.degrees(quat_to_euler(tuple(R[0, 6:10])))
    pva = pd.Series(np.r_[np.degrees(R[0, :2]), R[0, 2], R[0, 3:6], rph], index=TRAJECTORY_COLS)
    out = strapdown.Integrator(pva).integrate(
        strapdown.compute_increments_from_imu(imu, "increment")).iloc[-1]
    dg = np.array([_pyins_gravity(r[0], r[2]) - normal_gravity_mps2(r[0], r[2]) for r in R[:-1]])
    dv = np.sum(dg) / 120.0
    dh = -np.sum(np.cumsum(dg) / 120.0) / 120.0
    rm, rn = radii_m(R[-1, 0])
    assert abs(math.radians(out.lat) - R[-1, 0]) * rm < 0.01
    assert abs(math.radians(out.lon) - R[-1, 1]) * rn < 0.01
    assert abs(out.alt - R[-1, 2] - dh) < 0.01 and abs(dh) > 0.005
    assert np.allclose(out[["VN", "VE", "VD"]].values - R[-1, 3:6] - [0, 0, dv], 0, atol=2e-4)
    att = np.array(out[["roll", "pitch", "heading"]].values, float) - np.degrees(
        quat_to_euler(tuple(R[-1, 6:10])))
    assert np.max(np.abs((att + 180) % 360 - 180)) < 1e-6
