"""Shared fixtures for the SINS tests: a 33-state F at a manoeuvring flight state."""

import numpy as np

from fms_testbed.sensors.sins.analysis import SinsOptions, system_matrix
from fms_testbed.sensors.sins.presets import load_imu


def flight_F(imu_name: str = "STIM300", vertical: str = "free"):
    """F (33×33) and Q diagonal for a climbing, banked, turning aircraft at 47° N, 3000 m."""
    imu = load_imu(imu_name)
    F = system_matrix(0.82, 3000.0, np.array([150.0, 100.0, 5.0]), np.array([0.3, 0.05, 1.0]),
                      np.array([0.01, -0.02, 0.05]), np.array([0.5, 0.3, -10.2]), imu,
                      SinsOptions(vertical=vertical))
    return F, imu.q_psd.copy(), imu
