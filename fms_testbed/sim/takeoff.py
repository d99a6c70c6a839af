"""JSBSim mechanics of a takeoff roll: the aircraft at rest on the runway, and its controls.

:func:`ground_start` places the aircraft on the ground at a runway point:
``ic/terrain-elevation-ft`` at the runway elevation, ``ic/h-agl-ft`` 0, at rest on the runway
heading, gear down, flaps at the takeoff setting, engines running at idle, then JSBSim's
ground trim
(``simulation/do_simple_trim`` = 2) settles height, pitch and roll on the gear reactions
(measured: the CG ends 1.1 m above the runway for the 737, 1.3 m for the c172p, 2.7 m for the
global5000, pitch 0.5° / 3.0° / 0.3°). The inner-loop system is switched on
(``fms/ap/master`` 1) with every loop disengaged: its trim properties then pass straight to the
surfaces (the elevator through its rate limit) and ``fms/cmd/throttle`` to the throttles, so
:func:`set_controls` drives the aircraft directly and :func:`handover` leaves the loops
engaged about the surfaces of the moment. Nose-wheel steering is JSBSim's own
``fcs/steer-cmd-norm`` (each gear's ``max_steer`` scales it); brakes stay off.
"""

from __future__ import annotations

import math

import jsbsim

from fms_testbed.core.errors import TrimError
from fms_testbed.core.units import FT_M
from fms_testbed.sim.jsbsim_core import JSBSimAircraft, TrimResult


def ground_start(ac: JSBSimAircraft, lat_deg: float, lon_deg: float, elev_m: float,
                 heading_deg: float, flap_cmd_norm: float) -> TrimResult:
    """Put ``ac`` at rest on the ground at (``lat_deg``, ``lon_deg``) deg, terrain at
    ``elev_m`` m above mean sea level, heading ``heading_deg`` (deg true), gear down, flaps at
    ``flap_cmd_norm``, engines at idle (module docstring).

    Returns
    -------
    The ground condition as a :class:`TrimResult` (TAS 0; the flight summary's ``trim``).

    Raises
    ------
    TrimError : JSBSim rejects the initial condition or the ground trim fails
    """
    fdm, c = ac.fdm, ac.cfg
    fdm["atmosphere/delta-T"] = ac.isa_dev_c * 1.8
    fdm["ic/lat-geod-deg"] = lat_deg
    fdm["ic/long-gc-deg"] = lon_deg
    fdm["ic/terrain-elevation-ft"] = elev_m / FT_M
    fdm["ic/h-agl-ft"] = 0.0
    fdm["ic/vt-kts"] = 0.0
    fdm["ic/psi-true-deg"] = heading_deg
    fdm["ic/theta-deg"] = 0.0
    fdm["ic/phi-deg"] = 0.0
    for comp in ("north", "east", "down"):
        fdm[f"atmosphere/wind-{comp}-fps"] = 0.0
    fdm["fms/ap/master"] = 0.0
    for loop in ("bank", "yaw", "ny", "nx"):
        fdm[f"fms/ap/{loop}-engage"] = 0.0
    for loop in ("bank", "yaw", "ny"):
        fdm[f"fms/ap/{loop}-trigger"] = -1.0
    for prop in ("fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm",
                 "fcs/pitch-trim-cmd-norm", "fcs/steer-cmd-norm", "fcs/left-brake-cmd-norm",
                 "fcs/right-brake-cmd-norm", "fcs/center-brake-cmd-norm"):
        fdm[prop] = 0.0
    idle = c.inner_loops.throttle_min
    fdm["gear/gear-cmd-norm"] = 1.0
    fdm["gear/gear-pos-norm"] = 1.0
    fdm["fcs/flap-cmd-norm"] = flap_cmd_norm
    fdm["fcs/flap-pos-norm"] = flap_cmd_norm
    for i in range(ac.n_engines):
        fdm[f"fcs/throttle-cmd-norm[{i}]"] = idle
        fdm[f"fcs/mixture-cmd-norm[{i}]"] = 1.0
        fdm[f"fcs/advance-cmd-norm[{i}]"] = 1.0
    cond = f"{c.name} ({c.jsbsim_model}) on the ground at {elev_m:.0f} m"
    if not fdm.run_ic():
        raise TrimError(f"JSBSim rejected the initial condition: {cond}")
    fdm["propulsion/set-running"] = -1
    try:
        fdm["simulation/do_simple_trim"] = 2          # ground trim: on the gear reactions
    except (jsbsim.TrimFailureError, RuntimeError) as exc:
        raise TrimError(f"ground trim failed for {cond}: {str(exc).strip() or 'no convergence'}"
                        ) from None
    if fdm["gear/wow"] < 0.5:
        raise TrimError(f"ground trim failed for {cond}: no weight on the wheels")
    res = TrimResult(alt_m=fdm["position/h-sl-ft"] * FT_M, tas_mps=0.0,
                     alpha_deg=math.degrees(fdm["aero/alpha-rad"]),
                     pitch_deg=math.degrees(fdm["attitude/theta-rad"]), throttle=idle,
                     elevator=0.0, aileron=0.0, rudder=0.0)
    return ac.hold_trim(res)   # also what the flight summary reports as its start condition


def set_controls(ac: JSBSimAircraft, elevator: float | None = None,
                 aileron: float | None = None, rudder: float | None = None,
                 steer: float | None = None, throttle: float | None = None) -> None:
    """Direct controls while the inner loops are disengaged (normalised -1..1, throttle 0..1;
    None leaves a control as it is): through the inner-loop system's trim properties (module
    docstring), the nose wheel through ``fcs/steer-cmd-norm`` (positive: nose right)."""
    fdm = ac.fdm
    for prop, v in (("fms/trim/elevator", elevator), ("fms/trim/aileron", aileron),
                    ("fms/trim/rudder", rudder), ("fcs/steer-cmd-norm", steer)):
        if v is not None:
            fdm[prop] = max(-1.0, min(1.0, float(v)))
    if throttle is not None:
        ac.command(throttle=throttle)


def handover(ac: JSBSimAircraft) -> None:
    """End the takeoff: nose wheel centred, the elevator and throttle trims at the elevator and
    throttle of the moment (the aileron and rudder trims stay: the bank and yaw loops have
    flown since lift-off, and a trim taken mid-roll would stay as a bank bias), every loop
    engaged and the n_y and n_x loops flying from there."""
    fdm = ac.fdm
    fdm["fcs/steer-cmd-norm"] = 0.0
    fdm["fms/trim/elevator"] = fdm["fcs/elevator-cmd-norm"]
    fdm["fms/trim/throttle"] = fdm["fms/throttle-out"]
    ac.engage()


__all__ = ["ground_start", "handover", "set_controls"]
