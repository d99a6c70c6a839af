"""The takeoff phase of a SID that starts on the runway: the takeoff roll, rotation and initial
climb, then the handover to the airborne phase (``procedure.start: takeoff``, ``fms-testbed fly
--takeoff``).

The aircraft starts at rest on the threshold of the SID's runway (the runway record: threshold
position and elevation, magnetic bearing + airport variation = true bearing), on the centreline
and heading, gear down, flaps at the aircraft file's takeoff setting (``takeoff:`` block),
JSBSim's terrain at the threshold elevation (a flat runway: its slope is not modelled). The
takeoff is flown on the true state, as a pilot flies it looking out; the navigation source runs
(and is logged) from brake release, guidance flies on it from LNAV. The scenario's wind comes
in once the aircraft rolls faster than twice the wind speed (at rest a tailwind puts α at
180°), ramped in as after a trim; scenario events fall due from the handover on. The control
(:class:`TakeoffControl`) runs every :data:`CONTROL_FRAMES` JSBSim frames:

1. **roll** — the throttle goes to ``takeoff.thrust_norm`` over :data:`SPOOL_S`; nose-wheel
   steering (``fcs/steer-cmd-norm``) and rudder hold the centreline: heading error plus the
   angle to a point :data:`LOOKAHEAD_S` ahead on it, with yaw-rate damping.
2. **rotate** at VR (CAS) at :data:`ROTATE_RATE_DPS` to ``takeoff.pitch_deg`` (elevator on the
   pitch-rate error, proportional + integral, scaled with q̄ like the inner loops).
3. **climb** after lift-off (no weight on the wheels): wings level on the extended centreline
   through the bank and yaw inner loops, pitch for V2 + ``climb_add_cas_mps`` (never above
   ``pitch_max_deg``), gear up at a positive rate of climb above :data:`GEAR_UP_HEIGHT_M`; from
   the acceleration height (the approach settings' ``acceleration_height_m``, else
   :data:`ACCEL_HEIGHT_M`) the pitch target eases (≤ 1 deg/s) to accelerate to the planned
   climb speed (the guidance's speed target once LNAV is on, else
   ``limits.climb_cas_mps``, which holds a CAS)
   and the flaps come up on the go-around retraction schedule
   (:class:`~fms_testbed.loop.steps.ConfigStep`).
4. **LNAV** from :data:`LNAV_HEIGHT_M` above the runway and no earlier than where the airborne
   start would start (one roll-in anticipation before the departure end, DER): the procedure
   guidance steers (its bank command through the flight's roll-rate limit), the pitch stays
   the takeoff's. :data:`LNAV_HEIGHT_M` is the lowest height a departure turn is designed for
   (120 m, ICAO PANS-OPS Doc 8168, turning departures).
5. **handover** (VNAV) once at least :data:`HANDOVER_HEIGHT_M` above the runway, past the DER
   (the built path and its vertical profile begin there) and within
   :data:`HANDOVER_SPEED_MARGIN_MPS` of the planned climb speed, or
   :data:`HANDOVER_MAX_HEIGHT_M` above the runway whatever the speed: the inner-loop trims take
   the surfaces and throttle of the moment, every loop is engaged and the airborne phase
   (procedure guidance, vertical law, flap retraction) flies on from the same step.

A run-away during the takeoff ends the flight ``diverged``: non-finite state, stall, leaving
the runway (more than :data:`EXCURSION_M` off the centreline or past its end on the wheels),
ground contact after lift-off, or no handover within :data:`TIMEOUT_S`. Why the handover waits
for the DER and the speed, and LNAV comes first, is measured in ``docs/flying.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from pydantic import ConfigDict

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.contracts import OMIT_NONE
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.core.planning import PLANNED_BANK_DEG, SCREEN_HEIGHT_M
from fms_testbed.core.state import AirData, AircraftState, NavSolution
from fms_testbed.guidance.lateral import LateralGains, anticipation_m, wrap_pi
from fms_testbed.loop.phases import AirbornePhase, LoopParts
from fms_testbed.loop.steps import POSITIVE_RATE_MPS, ConfigStep
from fms_testbed.sim.divergence import Divergence
from fms_testbed.sim.jsbsim_core import RAW
from fms_testbed.sim.takeoff import ground_start, handover, set_controls

LNAV_HEIGHT_M = 400 * FT_M
"""Height above the runway where the procedure guidance takes over the lateral steering, m."""
HANDOVER_HEIGHT_M = 400 * FT_M
"""Lowest height above the runway of the full handover (vertical too), m (module docstring)."""
ACCEL_HEIGHT_M = 1000 * FT_M
"""Acceleration height of an aircraft without approach settings, m."""
GAMMA_MIN_DEG = 3.0
"""The climb-out never flies a flight-path angle below this (pitch ≥ alpha + it), deg."""
HANDOVER_SPEED_MARGIN_MPS = 10 * KT_MPS
"""The full handover waits for the CAS to be within this of the planned climb speed, m/s."""
HANDOVER_MAX_HEIGHT_M = 3000 * FT_M
"""... or for this height above the runway, whatever the speed, m."""
GEAR_UP_HEIGHT_M = SCREEN_HEIGHT_M
"""The gear comes up at a positive rate of climb above this height (the screen height), m."""
SPOOL_S = 3.0
"""Throttle ramp from idle to takeoff thrust, s."""
ROTATE_RATE_DPS = 3.0
"""Rotation pitch rate, deg/s (transport practice: 2-3 deg/s)."""
LOOKAHEAD_S = 3.0
"""Centreline tracking aims at a point this many seconds of ground speed ahead (≥ 30 m), s."""
EXCURSION_M = 30.0
"""More than this off the centreline on the wheels is a runway excursion, m."""
TIMEOUT_S = 240.0
"""No handover this long after brake release ends the flight, s."""
CONTROL_FRAMES = 4
"""JSBSim frames between two takeoff-control updates (30 Hz at 120 Hz)."""
# gains (normalised control per rad, per rad/s): tuned on the 737, c172p and global5000
_STEER_K, _STEER_KR = 2.0, 1.0            # nose wheel: per rad of aim error, per rad/s of yaw rate
_RUDDER_K, _RUDDER_KR = 2.0, 2.0
_AIM_KI, _AIM_I_MAX = 0.5, 0.5            # integral of the aim error (crosswind): 1/s, rad s
_THETA_K = 1.0                            # pitch-rate command per rad of pitch error, 1/s
_SPEED_K = math.radians(0.4)              # pitch-target rate per m/s of CAS error, rad/s
_THETA_C_RATE = math.radians(1.0)         # pitch-target rate limit down (up: rotation rate), rad/s
_BANK_K, _BANK_KY = 1.5, 0.004            # bank per rad of track error, per m off centreline
_BANK_MAX = math.radians(10.0)


@dataclass(frozen=True)
class DepartureRunway:
    """The runway a SID takes off from: ``ident`` ('RW34R'), threshold ``lat_deg``/``lon_deg``
    (deg) and ``elev_m`` (m), ``bearing_deg`` (true, deg), ``length_m`` (m)."""

    ident: str
    lat_deg: float
    lon_deg: float
    elev_m: float
    bearing_deg: float
    length_m: float

    def along_cross_m(self, lat_deg: float, lon_deg: float) -> tuple[float, float]:
        """(along the centreline from the threshold, right of it), m, of a point (deg)."""
        d, az, _ = inverse(self.lat_deg, self.lon_deg, lat_deg, lon_deg)
        a = math.radians(az - self.bearing_deg)
        return d * math.cos(a), d * math.sin(a)


def departure_runway(db, seq) -> DepartureRunway | None:
    """The runway of SID sequence ``seq`` in database ``db`` (its runway transition's threshold
    record, the one the airborne start's departure end is computed from), None when it has none
    or no elevation."""
    from fms_testbed.path.segmentation import runway_record   # the airborne start's look-up

    if db is None or seq.proc_type != "D":
        return None
    rwy = runway_record(db, seq.airport, seq.transition)
    if rwy is None:
        return None
    apt = db.airports.get(seq.airport)
    elev = rwy.elev_m if rwy.elev_m is not None else (apt.elev_m if apt is not None else None)
    if elev is None or rwy.bearing_deg is None:
        return None
    var = apt.magvar_deg if apt is not None and apt.magvar_deg else 0.0
    brg = (rwy.bearing_deg + var) % 360.0
    return DepartureRunway(rwy.ident, rwy.lat_deg, rwy.lon_deg, float(elev), brg,
                           float(rwy.length_m or 0.0))


def check_takeoff(source: str, proc_type: str, rwy: DepartureRunway | None,
                  cfg: AircraftConfig) -> None:
    """Refuse a takeoff start that cannot be flown: :class:`ConfigError` (file, field, reason).

    Parameters
    ----------
    source : the scenario's file (for the message); proc_type : the procedure's type letter
    rwy : its departure runway (None: none found); cfg : the aircraft (its ``takeoff:`` block)
    """
    where = f"{source}: field 'procedure.start'"
    if proc_type != "D":
        kind = {"E": "a STAR", "F": "an approach"}.get(proc_type, "this procedure")
        raise ConfigError(f"{where}: 'takeoff' is for SIDs, {kind} starts airborne")
    if rwy is None:
        raise ConfigError(f"{where}: 'takeoff' needs the SID's runway (give procedure.runway; "
                          "no runway record with a bearing and elevation was found)")
    if cfg.takeoff is None:
        raise ConfigError(f"{where}: aircraft {cfg.name} has no takeoff settings "
                          f"(a 'takeoff:' block in {cfg.source_file or 'its aircraft file'})")


@dataclass
class TakeoffControl:
    """The pilot of the takeoff (module docstring, steps 1-3) as a controller: tuning from the
    aircraft file (``takeoff:``) and the module's gains, state (integrators, pitch target)
    here; :meth:`ground`, :meth:`pitch` and :meth:`bank` take the step ``dt_s`` and the state
    and return the controls.

    Ground: aim error ``e = (ψ - runway) + atan(y / L)`` (y m right of the centreline,
    ``L = max(30 m, LOOKAHEAD_S · GS)``), PI, nose wheel ``-(K e + K_r r)`` and rudder
    ``K e + K_r r`` (positive rudder yaws left). Pitch:
    ``q_cmd = clip(K_θ (θ_c - θ), -2, 3) deg/s``, elevator
    ``-(q̄_ref/q̄) (K_p e_q + K_i ∫e_q)`` (``takeoff.pitch_rate_kp/ki``); climbing, the pitch
    target moves ``dθ_c/dt = clip(K_V (CAS - V_target), -1, +3 deg/s)`` within
    [α + 3 deg, ``pitch_max_deg``].
    Air: bank ``clip(-K_χ (χ - runway) - K_y y, ±10 deg)``.
    """

    theta_c_rad: float
    theta_max_rad: float
    pitch_kp: float = 8.0
    pitch_ki: float = 8.0
    aim_int: float = 0.0
    q_int: float = 0.0

    def ground(self, dt_s: float, heading_err_rad: float, cross_m: float, gs_mps: float,
               r_rps: float) -> tuple[float, float]:
        """(nose-wheel steering, rudder), normalised, for heading error ``heading_err_rad`` (rad,
        heading minus runway bearing), ``cross_m`` m right of the centreline, ground speed
        ``gs_mps`` (m/s) and yaw rate ``r_rps`` (rad/s)."""
        aim = heading_err_rad + math.atan2(cross_m, max(30.0, LOOKAHEAD_S * gs_mps))
        self.aim_int = max(-_AIM_I_MAX, min(_AIM_I_MAX, self.aim_int + aim * dt_s))
        e = aim + _AIM_KI * self.aim_int
        return -(_STEER_K * e + _STEER_KR * r_rps), _RUDDER_K * e + _RUDDER_KR * r_rps

    def pitch(self, dt_s: float, pitch_rad: float, q_rps: float, qbar_ratio: float,
              cas_err_mps: float | None = None, alpha_rad: float = 0.0) -> float:
        """Elevator (normalised) toward the pitch target; with ``cas_err_mps`` (CAS minus the
        climb-out speed, m/s) the target first moves to hold the speed, never below
        ``alpha_rad`` + :data:`GAMMA_MIN_DEG` (the aircraft keeps climbing while it
        accelerates)."""
        if cas_err_mps is not None:
            self.theta_c_rad += max(-_THETA_C_RATE, min(math.radians(ROTATE_RATE_DPS),
                                                        _SPEED_K * cas_err_mps)) * dt_s
            floor = max(math.radians(2.0), alpha_rad + math.radians(GAMMA_MIN_DEG))
            self.theta_c_rad = min(self.theta_max_rad, max(floor, self.theta_c_rad))
        q_cmd = max(-math.radians(2.0), min(math.radians(ROTATE_RATE_DPS),
                                            _THETA_K * (self.theta_c_rad - pitch_rad)))
        e_q = q_cmd - q_rps
        self.q_int += e_q * dt_s
        return -qbar_ratio * (self.pitch_kp * e_q + self.pitch_ki * self.q_int)

    @staticmethod
    def bank(track_err_rad: float, cross_m: float) -> float:
        """Bank command, rad, for track error ``track_err_rad`` (rad, track minus runway
        bearing) and ``cross_m`` m right of the centreline."""
        return max(-_BANK_MAX, min(_BANK_MAX, -_BANK_K * track_err_rad - _BANK_KY * cross_m))



@dataclass
class TakeoffMark:
    """The aircraft at one event of the takeoff: along the centreline from the threshold and
    right of it (m), CAS (m/s), height above the runway (m), pitch (deg)."""

    __pydantic_config__ = ConfigDict(extra="forbid")

    along_m: float
    cross_m: float
    cas_mps: float
    height_m: float
    pitch_deg: float


@dataclass
class TakeoffRecord:
    """The takeoff as flown (the summary's ``takeoff`` block).

    Attributes
    ----------
    start : 'takeoff'
    runway : the runway ident ('RW16L'); vr_cas_mps, v2_cas_mps : VR and V2 of the mass, CAS m/s
    times_s : time after brake release of each event (rotate, liftoff, v2, gear_up,
        accelerate, lnav, der, handover), s
    events : the aircraft at each event (:class:`TakeoffMark`)
    max_centreline_dev_ground_m, max_centreline_dev_air_m : largest centreline deviation on the
        wheels and in the air before LNAV, m
    ground_roll_m : threshold to lift-off, m; time_to_v2_s : s; der_height_m : height at the
        runway's end, m; handover_s, handover_along_m : when and where the handover came, s, m
        (None: not reached)
    """

    __pydantic_config__ = ConfigDict(extra="forbid")

    start: str
    runway: str
    vr_cas_mps: float
    v2_cas_mps: float
    times_s: dict[str, float]
    events: dict[str, TakeoffMark]
    max_centreline_dev_ground_m: float
    max_centreline_dev_air_m: float
    ground_roll_m: float | None = field(default=None, metadata=OMIT_NONE)
    time_to_v2_s: float | None = field(default=None, metadata=OMIT_NONE)
    der_height_m: float | None = field(default=None, metadata=OMIT_NONE)
    handover_s: float | None = field(default=None, metadata=OMIT_NONE)
    handover_along_m: float | None = field(default=None, metadata=OMIT_NONE)


class TakeoffPhase:
    """The takeoff phase of the flight loop (module docstring; the phase steps of
    :mod:`.phases`).

    Parameters
    ----------
    parts : the flight's shared parts (:class:`~.phases.LoopParts`)
    runway : the departure runway
    guided : the flight has a guidance (LNAV engages)
    airborne : builds the airborne phase of the handover from its configuration step (None: an
        aircraft without approach settings)
    """

    name = "takeoff"
    fires_events = False
    always_guided = False
    hands_over = True

    def __init__(self, parts: LoopParts, runway: DepartureRunway, guided: bool,
                 airborne: Callable[[ConfigStep | None], AirbornePhase]):
        cfg, ac = parts.cfg, parts.aircraft
        to = cfg.takeoff
        self.parts, self.runway, self.cfg, self.to, self.ac = parts, runway, cfg, to, ac
        self.guided_flight, self.airborne = guided, airborne
        self.times_s: dict[str, float] = {}
        self.marks: dict[str, TakeoffMark] = {}
        self.max_dev_ground_m = self.max_dev_air_m = 0.0
        ac.engage(bank=False, yaw=False, ny=False, nx=False)
        self.vr_cas_mps, self.v2_cas_mps = to.speeds_cas_mps(float(ac.state().mass_kg))
        self.v_climb_cas_mps = self.v2_cas_mps + to.climb_add_cas_mps
        self.throttle_idle = cfg.inner_loops.throttle_min
        self.bearing_rad = math.radians(runway.bearing_deg)
        self.check_air = Divergence(cfg)
        self.n_sub = max(1, parts.n_frames // CONTROL_FRAMES)
        self.frames = parts.n_frames // self.n_sub
        self.dt_c = self.frames * ac.dt_s
        self.stage = "roll"
        self.pilot = TakeoffControl(math.radians(to.pitch_deg), math.radians(to.pitch_max_deg),
                                    to.pitch_rate_kp, to.pitch_rate_ki)
        ap = cfg.approach
        self.gear_up = ap is not None and ap.fixed_gear
        self.h_accel = ap.acceleration_height_m if ap is not None else ACCEL_HEIGHT_M
        self.config = self._config_step() if ap is not None else None
        self.n_guided = 0
        # LNAV from where the airborne start starts: one roll-in anticipation before the DER
        self.lnav_lead_m = anticipation_m(cfg.limits.climb_cas_mps, math.radians(PLANNED_BANK_DEG),
                                          LateralGains.for_aircraft(cfg))
        # planned climb speed, a CAS (limits.climb_cas_mps holds a CAS; the guidance's once on)
        self.v_plan_cas_mps = cfg.limits.climb_cas_mps
        self.t0 = ac.fdm.get_sim_time()
        self.bank_cmd_rad, self.throttle = 0.0, self.throttle_idle
        self._s, self._wow = None, True           # this step's state, on the wheels
        self.t_run_s = self.along_m = self.cross_m = self.h_m = 0.0   # s, m, m, m

    # ------------------------------------------------------------------ the phase steps
    def check(self, s: AircraftState, raw: list[float]) -> str | None:
        """Why the takeoff must end now (module docstring), with 'takeoff: ' first."""
        self._locate(s, raw[RAW["wow"]])
        why = self._failure(s, raw[RAW["wow"]])
        return f"takeoff: {why}" if why else None

    def wind(self, s: AircraftState) -> None:
        """The wind comes in once the aircraft rolls faster than twice its speed."""
        w = self.parts.wind
        if w.active and s.gs_mps > 2.0 * w.max_speed_mps:
            w.start(s.t_s)
        w.step(s.t_s, s.alt_m)

    def guided(self, s: AircraftState) -> bool:
        """LNAV: the guidance steers from :data:`LNAV_HEIGHT_M` above the runway and one roll-in
        anticipation before its end (engaged here, with the lateral trims of the moment)."""
        if not self.guided_flight or self.stage != "climb":
            return False
        if self.n_guided:
            return True
        if self.h_m < LNAV_HEIGHT_M or self.along_m < self.runway.length_m - self.lnav_lead_m:
            return False
        self._mark("lnav", s)
        self.parts.lateral.last_bank_rad = self.bank_cmd_rad
        # steady and wings level on the centreline: the aileron and rudder of the moment are
        # the lateral trims (the bank loop has no integral for a propeller's torque)
        fdm = self.ac.fdm
        fdm["fms/trim/aileron"] = fdm["fcs/aileron-cmd-norm"]
        fdm["fms/trim/rudder"] = fdm["fcs/rudder-cmd-norm"]
        return True

    def after_guidance(self, s: AircraftState, gout):
        """The DER mark, then the handover (module docstring) — the airborne phase flies the
        rest of this step — or the takeoff goes on."""
        if gout is not None:
            self.n_guided += 1
            if gout.tas_mps is not None and s.tas_mps > 1.0:    # the planned speed, as a CAS
                self.v_plan_cas_mps = gout.tas_mps * s.cas_mps / s.tas_mps
        length, h_m = self.runway.length_m, self.h_m
        if self.stage == "climb" and "der" not in self.times_s and self.along_m >= length:
            self._mark("der", s)
        done = gout is not None and gout.done
        if not (done or (self.stage == "climb" and h_m >= HANDOVER_HEIGHT_M
                         and self.along_m >= length
                         and (s.cas_mps >= self.v_plan_cas_mps - HANDOVER_SPEED_MARGIN_MPS
                              or h_m >= HANDOVER_MAX_HEIGHT_M))):
            return self
        self._mark("handover", s)
        self.parts.wind.finish(s.alt_m)          # all of the wind from here (the ramp's end)
        handover(self.ac)
        if self.config is not None:
            self.config.gear_down = not self.gear_up
        return self.airborne(self.config)

    def command(self, s: AircraftState, nav: NavSolution, air: AirData, gout) -> tuple:
        """LNAV's bank command (through the flight's roll-rate limit) when the guidance steers;
        the log values (:data:`~fms_testbed.core.timeseries.LOG_FIELDS`: bank rad, the runway
        heading until LNAV rad, -, -, throttle, -, -, the navigation solution)."""
        if gout is not None:
            self.bank_cmd_rad = self.parts.lateral(self.parts.targets, nav, True)
        nan = math.nan
        return (self.bank_cmd_rad, self.bearing_rad if gout is None else nan, nan, nan,
                self.throttle, nan, nan, nav.lat_rad, nav.lon_rad, nav.alt_m, nav.heading_rad,
                nav.roll_rad, nav.pitch_rad)

    def advance(self) -> str:
        """The takeoff control over the JSBSim frames to the next outer step, every
        :data:`CONTROL_FRAMES` frames; '' or why the flight must end."""
        ac, s, wow = self.ac, self._s, self._wow
        for j in range(self.n_sub):
            if j:
                raw = ac.read_raw()
                s = ac.state(raw)
                wow = self._locate(s, raw[RAW["wow"]])
            self._control(s, wow)
            if not self.parts.sampling.run(self.frames):
                return "takeoff: JSBSim stopped"
        return ""

    # ------------------------------------------------------------------ the takeoff control
    def _locate(self, s: AircraftState, wow: float) -> bool:
        """The aircraft on the runway now (``t_s`` after brake release, ``along_m`` /
        ``cross_m`` on the centreline, ``h_m`` above the runway); True on the wheels."""
        self._s, self._wow = s, wow > 0.5
        rw = self.runway
        self.t_run_s = s.t_s - self.t0
        self.along_m, self.cross_m = rw.along_cross_m(math.degrees(s.lat_rad),
                                                     math.degrees(s.lon_rad))
        self.h_m = s.alt_m - rw.elev_m
        return self._wow

    def _control(self, s: AircraftState, wow: bool) -> None:
        """One takeoff-control update (module docstring, steps 1-3)."""
        ac, to, h_m, cross = self.ac, self.to, self.h_m, self.cross_m
        if self.stage == "roll" and s.cas_mps >= self.vr_cas_mps:
            self.stage = "rotate"
            self._mark("rotate", s)
        if self.stage == "rotate" and not wow and h_m > 0.0:
            self.stage = "climb"
            self._mark("liftoff", s)
            fdm = ac.fdm
            fdm["fcs/steer-cmd-norm"] = 0.0
            fdm["fms/trim/rudder"] = 0.0       # the yaw loop takes the rudder
            fdm["fms/trim/aileron"] = 0.0
            ac.engage(bank=True, yaw=True, ny=False, nx=False)
        if "v2" not in self.times_s and s.cas_mps >= self.v2_cas_mps:
            self._mark("v2", s)
        if self.stage == "climb" and not self.gear_up and s.vs_mps > POSITIVE_RATE_MPS \
                and h_m > GEAR_UP_HEIGHT_M:
            self.gear_up = True
            ac.configure(gear_down=False)
            self._mark("gear_up", s)
        self.throttle = self.throttle_idle + (to.thrust_norm - self.throttle_idle) * min(1.0, self.t_run_s / SPOOL_S)
        if self.stage != "climb":
            self.max_dev_ground_m = max(self.max_dev_ground_m, abs(cross))
            steer, rudder = self.pilot.ground(self.dt_c, wrap_pi(s.heading_rad - self.bearing_rad),
                                              cross, s.gs_mps, s.r_rps)
            set_controls(ac, steer=steer, rudder=rudder, throttle=self.throttle)
        else:
            self._climb_out(s, cross, h_m)
        if self.stage != "roll":
            set_controls(ac, elevator=self.pilot.pitch(
                self.dt_c, s.pitch_rad, s.q_rps, ac.fdm["fms/sched/qbar-ratio"],
                s.cas_mps - self.v_climb_cas_mps if self.stage == "climb" else None, s.alpha_rad))

    def _climb_out(self, s: AircraftState, cross: float, h_m: float) -> None:
        """After lift-off: wings level on the extended centreline until LNAV, the acceleration
        from the acceleration height, flaps up on schedule."""
        if not self.n_guided:   # on the extended centreline until LNAV
            self.max_dev_air_m = max(self.max_dev_air_m, abs(cross))
            self.bank_cmd_rad = self.pilot.bank(wrap_pi(s.track_rad - self.bearing_rad), cross)
        self.ac.command(bank_rad=self.bank_cmd_rad, throttle=self.throttle)
        if h_m >= self.h_accel and "accelerate" not in self.times_s:
            self._mark("accelerate", s)
        if "accelerate" in self.times_s:
            self.v_climb_cas_mps = max(self.v2_cas_mps + self.to.climb_add_cas_mps, self.v_plan_cas_mps)
            if self.config is not None:
                self.config.gear_down = not self.gear_up
                self.config(s, self.parts.targets, False)     # flaps up on schedule

    def _failure(self, s: AircraftState, wow: float) -> str | None:
        t, along, cross = self.t_run_s, self.along_m, self.cross_m
        if self.stage == "climb":
            return self.check_air(s, wow)
        if not math.isfinite(s.alt_m + s.tas_mps + s.pitch_rad + s.alpha_rad):
            return "non-finite state (JSBSim diverged)"
        if s.alpha_rad > self.check_air.stall_rad:
            return f"stall: alpha {math.degrees(s.alpha_rad):.1f} deg at t={t:.1f} s"
        if abs(cross) > EXCURSION_M:
            return f"runway excursion: {cross:+.0f} m off the centreline at t={t:.1f} s"
        if self.runway.length_m > 0 and along > self.runway.length_m:
            return (f"still on the wheels at the runway end ({self.runway.length_m:.0f} m) "
                    f"at t={t:.1f} s")
        if t > TIMEOUT_S:
            return f"no handover within {TIMEOUT_S:.0f} s"
        return None

    def _mark(self, name: str, s: AircraftState) -> None:
        self.times_s[name] = round(self.t_run_s, 2)
        self.marks[name] = TakeoffMark(round(self.along_m, 1), round(self.cross_m, 2),
                                    round(s.cas_mps, 2), round(s.alt_m - self.runway.elev_m, 1),
                                    round(math.degrees(s.pitch_rad), 2))

    def _config_step(self) -> ConfigStep:
        """Flaps retracted on the go-around schedule of the approach settings, from the
        takeoff detent (the approach detent nearest ``takeoff.flaps_norm``)."""
        ap = self.cfg.approach
        k = min(range(len(ap.flaps)),
                key=lambda j: abs(ap.flaps[j].cmd_norm - self.to.flaps_norm))
        cs = ConfigStep(ap, self.ac, k, not self.gear_up, self.parts.events)
        cs.go_around = True      # retract mode: each detent up above its speed + margin
        return cs

    def record(self) -> TakeoffRecord:
        """The takeoff as flown (:class:`TakeoffRecord`)."""
        at, ts = self.marks, self.times_s
        return TakeoffRecord(
            "takeoff", self.runway.ident, round(self.vr_cas_mps, 2), round(self.v2_cas_mps, 2), dict(ts),
            dict(at), round(self.max_dev_ground_m, 2), round(self.max_dev_air_m, 2),
            ground_roll_m=at["liftoff"].along_m if "liftoff" in at else None,
            time_to_v2_s=ts.get("v2"),
            der_height_m=at["der"].height_m if "der" in at else None,
            handover_s=ts.get("handover"),
            handover_along_m=at["handover"].along_m if "handover" in at else None)


def start_on_runway(ac, runway: DepartureRunway, cfg: AircraftConfig) -> None:
    """Put ``ac`` at rest on the threshold of ``runway`` with the takeoff flaps of aircraft
    ``cfg`` (:func:`~fms_testbed.sim.takeoff.ground_start`)."""
    ground_start(ac, runway.lat_deg, runway.lon_deg, runway.elev_m, runway.bearing_deg,
                 cfg.takeoff.flaps_norm)


__all__ = ["DepartureRunway", "HANDOVER_HEIGHT_M", "TakeoffControl", "TakeoffMark",
           "TakeoffPhase", "TakeoffRecord", "check_takeoff", "departure_runway",
           "start_on_runway"]
