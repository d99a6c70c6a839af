"""Plain data passed between the simulation, the controllers and the navigation model.

Data flows one way: JSBSim -> :class:`AircraftState` (truth) -> navigation model ->
:class:`NavSolution` -> guidance / laws -> :class:`Commands` -> inner loops (in JSBSim).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(slots=True)
class AircraftState:
    """True aircraft state read from JSBSim at one instant (SI, radians unless named _deg).

    Treat as immutable (not frozen only because a frozen dataclass costs 5 µs more to build,
    and one is built at every outer step).

    Attributes
    ----------
    t_s: simulation time, s
    lat_rad, lon_rad: geodetic WGS-84 latitude/longitude, rad
    alt_m: altitude above mean sea level, m
    tas_mps, cas_mps, gs_mps: true air speed, calibrated air speed, ground speed, m/s
    vs_mps: vertical speed (up positive), m/s
    v_enu_mps: ground velocity in ENU, m/s, shape (3,)
    roll_rad, pitch_rad, heading_rad: Euler angles (body to local NED), rad; heading true
    track_rad: ground track (true), rad
    alpha_rad, beta_rad: angle of attack and sideslip, rad
    gamma_rad: ground-relative (inertial) flight-path angle, rad: JSBSim's
        ``flight-path/gamma-rad`` = atan2(-v_down, v_ground)
    p_rps, q_rps, r_rps: body rates, rad/s
    nx: tangential (wind-axis) load factor, g;  ny: normal (lift-axis) load factor, g
    f_body_mps2: specific force in body axes (forward, right, down), m/s^2, shape (3,)
    mach: Mach number;  agl_m: height above ground, m
    throttle: mean throttle command, 0..1;  mass_kg: current mass, kg
    p_static_pa, t_static_k: static pressure (Pa) and temperature (K) of the air at the
    aircraft (NaN where the producer has no atmosphere, e.g. a synthetic profile)
    """

    t_s: float
    lat_rad: float
    lon_rad: float
    alt_m: float
    tas_mps: float
    cas_mps: float
    gs_mps: float
    vs_mps: float
    v_enu_mps: np.ndarray
    roll_rad: float
    pitch_rad: float
    heading_rad: float
    track_rad: float
    alpha_rad: float
    beta_rad: float
    gamma_rad: float
    p_rps: float
    q_rps: float
    r_rps: float
    nx: float
    ny: float
    f_body_mps2: np.ndarray
    mach: float
    agl_m: float
    throttle: float
    mass_kg: float
    p_static_pa: float = float("nan")
    t_static_k: float = float("nan")


@dataclass(slots=True)
class AirData:
    """What the air-data computer gives guidance and the laws (SI): its sensors' view of the air,
    never the truth itself; the producer is :class:`fms_testbed.sensors.air_data.AirDataComputer`.

    Attributes
    ----------
    t_s : time of the measurement, s
    tas_mps, cas_mps : true and calibrated airspeed, m/s
    mach : Mach number
    pressure_alt_m : pressure altitude (the ISA altitude of the measured static pressure), m
    baro_alt_m : barometric altitude the altimeter shows (pressure altitude corrected with the
        altimeter setting the computer knows), m
    vs_mps : barometric vertical speed (up positive), m/s
    p_static_pa : measured static pressure, Pa
    t_static_k : measured static (outside) air temperature, K
    alpha_rad, beta_rad : angle of attack and sideslip from the vanes, rad
    valid : False when the computer has failed (its numbers are then not to be used)
    """

    t_s: float
    tas_mps: float
    cas_mps: float
    mach: float
    pressure_alt_m: float
    baro_alt_m: float
    vs_mps: float
    p_static_pa: float
    t_static_k: float
    alpha_rad: float
    beta_rad: float
    valid: bool = True


@dataclass(slots=True)
class NavSolution:
    """What the navigation system believes (same units as :class:`AircraftState`); treat as
    immutable."""

    t_s: float
    lat_rad: float
    lon_rad: float
    alt_m: float
    v_enu_mps: np.ndarray
    roll_rad: float
    pitch_rad: float
    heading_rad: float
    errors: dict[str, float] = field(default_factory=dict)
    """Key error-state components for logging (e.g. ``{"nse_h_m": ..., "bias_gx_dph": ...}``)."""
    pos_cov_enu_m2: np.ndarray | None = None
    """Covariance of the position error in local ENU, m², shape (3, 3); ``None`` when the source
    does not estimate it (truth, a free-running SINS without a filter)."""
    valid: bool = True
    """False when the source cannot give a usable solution (e.g. every INS excluded)."""
    heading_sigma_rad: float | None = None
    """1σ of the heading error the source estimates, rad (``None``: not estimated — truth, a
    free-running SINS)."""


@dataclass(slots=True)
class Commands:
    """Targets for the inner loops; ``None`` leaves a channel as it is.

    bank_rad: bank-angle command (bank-hold loop), rad
    heading_rad: heading command (heading-hold outer loop, which sets bank), rad, true
    ny: normal (lift-axis) load-factor command, g;  nx: tangential load-factor command, g
    throttle: direct throttle command, 0..1 (disengages the nx loop)
    alt_m, tas_mps: altitude and speed targets for the coupled law
    """

    bank_rad: float | None = None
    heading_rad: float | None = None
    ny: float | None = None
    nx: float | None = None
    throttle: float | None = None
    alt_m: float | None = None
    tas_mps: float | None = None
