"""A SID that starts on the runway: the takeoff roll, rotation and initial climb, then the
handover to the procedure guidance (``procedure.start: takeoff``, ``fms-testbed fly --takeoff``).

The aircraft starts at rest on the threshold of the SID's runway (the runway record: threshold
position and elevation, magnetic bearing + airport variation = true bearing, as the airborne
start's departure end is found), on the centreline and heading, gear down, flaps at the
aircraft file's takeoff setting (``takeoff:`` block), JSBSim's terrain at the threshold
elevation (a flat runway: its slope is not modelled). The takeoff is flown on the true state,
as a pilot flies it looking out; the navigation source runs (and is logged) from brake
release, guidance flies on it from the handover. The scenario's wind comes in once the
aircraft rolls faster than twice the wind speed (at rest a tailwind puts alpha at 180°),
ramped in as after a trim; scenario events fall due from the handover on. Then:

1. **roll** — the throttle goes to ``takeoff.thrust_norm`` over :data:`SPOOL_S`; nose-wheel
   steering (``fcs/steer-cmd-norm``) and rudder hold the centreline: heading error plus the
   angle to a point :data:`LOOKAHEAD_S` ahead on it, with yaw-rate damping.
2. **rotate** at VR (CAS) at :data:`ROTATE_RATE_DPS` to ``takeoff.pitch_deg`` (elevator on the
   pitch-rate error, proportional + integral, scaled with q̄ like the inner loops).
3. **climb** after liftoff (no weight on the wheels): wings level on the extended centreline
   through the bank and yaw inner loops, pitch for V2 + ``climb_add_cas_mps`` (never above
   ``pitch_max_deg``), gear up at a positive rate of climb (> 1 m/s) above 35 ft; from the
   acceleration height (the approach settings' ``acceleration_height_m``, else 1,000 ft) the
   pitch target eases (≤ 1 deg/s) to accelerate to the planned climb speed (the guidance's
   speed target once LNAV is on, else ``limits.climb_tas_mps`` as a CAS) and the flaps come up
   on the go-around retraction schedule (:class:`~fms_testbed.loop.steps.ConfigStep`).
4. **LNAV** from :data:`LNAV_HEIGHT_M` (400 ft) above the runway and no earlier than where
   the airborne start would start (one roll-in anticipation before the DER): the procedure guidance
   steers (its bank command through the flight's roll-rate limit), the pitch stays the
   takeoff's — as an FMS engages LNAV in the takeoff climb and VNAV later. 400 ft is the
   lowest height a departure turn is designed for (120 m, ICAO PANS-OPS Doc 8168, turning
   departures).
5. **handover** (VNAV) once at least :data:`HANDOVER_HEIGHT_M` (400 ft) above the runway,
   past its departure end (DER) and within :data:`HANDOVER_SPEED_MARGIN_MPS` (10 kt) of the
   planned climb speed, or :data:`HANDOVER_MAX_HEIGHT_M` (3,000 ft) above the runway whatever
   the speed: the inner-loop trims take the surfaces and throttle of the moment, every loop
   is engaged and the normal loop (procedure guidance, vertical law, flap retraction on the
   go-around schedule of the approach settings) flies on. The DER, because the built path
   and its vertical profile begin there (the airborne start's reference, 35 ft above it):
   before it the guidance's altitude command is that start height, so a vertical handover
   short of it dives (measured, KJFK DEEZZ5 RW31L, 737: handed over at 400 ft 2.3 km before
   the DER, the command was 14.6 m and the aircraft sank from 202 m to 105 m); on a long
   runway the takeoff climb therefore goes on to the DER (737, KSEA 16L: ~1,600 ft there).
   The speed, because the vertical law handed an aircraft 30 kt below its planned climb
   speed pushes to its n_y floor to accelerate (measured: 0.53 g at the 737's handover at
   KSEA 16L). LNAV before the vertical handover, because a SID's first turn can begin at or
   soon after the DER (KJFK DEEZZ5: 110° left 971 m past it; handed over whole at the turn's
   start the 737 overshot it by 172 m).

A run-away during the takeoff ends the flight ``diverged``: non-finite state, stall,
leaving the runway (more than :data:`EXCURSION_M` off the centreline or past its end on the
wheels), ground contact after liftoff, or no handover within :data:`TIMEOUT_S`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.core.errors import ConfigError
from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import FT_M, KT_MPS
from fms_testbed.guidance.lateral import LateralGains, anticipation_m
from fms_testbed.loop.steps import (POSITIVE_RATE_MPS, ConfigStep, FrameSampling, LateralStep,
                                    NavHold, WindRamp, merge_guidance)
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
GEAR_UP_HEIGHT_M = 35 * FT_M
"""The gear comes up at a positive rate of climb above this height, m."""
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
    """The runway of SID sequence ``seq`` (its runway transition's threshold record, the one the
    airborne start's departure end is computed from), None when it has none or no elevation."""
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
    """Refuse a takeoff start that cannot be flown: :class:`ConfigError` (file, field, reason)."""
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
class TakeoffStart:
    """The takeoff phase of one flight (module docstring): :meth:`start` puts the aircraft on
    the runway, :meth:`fly` flies it to the handover, :meth:`summary` says what happened."""

    runway: DepartureRunway
    cfg: AircraftConfig
    t_s: dict = field(default_factory=dict)          # event -> time, s
    at: dict = field(default_factory=dict)           # event -> values at that time
    max_dev_ground_m: float = 0.0
    max_dev_air_m: float = 0.0
    vr_cas_mps: float = 0.0
    v2_cas_mps: float = 0.0

    def start(self, ac) -> None:
        """Put ``ac`` at rest on the threshold (:func:`~fms_testbed.sim.takeoff.ground_start`)."""
        rw = self.runway
        ground_start(ac, rw.lat_deg, rw.lon_deg, rw.elev_m, rw.bearing_deg,
                     self.cfg.takeoff.flaps_norm)

    def fly(self, flight):
        """Fly the takeoff phase of ``flight`` (a :class:`~fms_testbed.loop.flight.Flight`), one
        ``yield`` per outer step, logging its rows; return True at the handover, False (with
        ``flight.status``/``reason`` set) when the takeoff failed."""
        ac, cfg, rw, to = flight.aircraft, self.cfg, self.runway, self.cfg.takeoff
        fdm = ac.fdm
        ac.engage(bank=False, yaw=False, ny=False, nx=False)
        mass_kg = float(ac.state().mass_kg)
        self.vr_cas_mps, self.v2_cas_mps = to.speeds_cas_mps(mass_kg)
        v_climb = self.v2_cas_mps + to.climb_add_cas_mps
        idle = cfg.inner_loops.throttle_min
        brg = math.radians(rw.bearing_deg)
        wind = WindRamp(fdm, flight.scn, flight.dt_outer_s)
        check = Divergence(cfg)
        n_sub = max(1, flight.n_frames // CONTROL_FRAMES)
        frames = flight.n_frames // n_sub
        dt_c = frames * ac.dt_s
        log_every = max(1, int(round(1.0 / (flight.scn.log_rate_hz * flight.dt_outer_s))))
        i_wow = RAW["wow"]
        phase = "roll"
        pilot = TakeoffControl(math.radians(to.pitch_deg), math.radians(to.pitch_max_deg),
                               to.pitch_rate_kp, to.pitch_rate_ki)
        # the wind comes in once the aircraft rolls faster than twice its speed (the relative
        # wind then blows from ahead: at rest a tailwind puts alpha at 180 deg), ramped over
        # loop.steps.WIND_RAMP_S from there
        w_max = flight.scn.wind_profile.max_speed_mps if wind.active else 0.0
        t_wind = None
        nav_spec = flight.scn.navigation_spec
        nav_dt = float(nav_spec.get("dt_s", 0.1)) if nav_spec.get("source") == "sins" else 0.0
        sampling = FrameSampling(flight.navigation, ac)
        navigate = (NavHold(flight.navigation, nav_dt) if nav_dt > flight.dt_outer_s + 1e-9
                    else sampling)   # as the flight loop does
        gear_up = cfg.approach is not None and cfg.approach.fixed_gear
        ap = cfg.approach
        h_accel = ap.acceleration_height_m if ap is not None else ACCEL_HEIGHT_M
        config = self._config_step(flight, ac, gear_up) if ap is not None else None
        guide, tg = flight.guidance, flight.targets
        lateral = LateralStep(cfg, flight.dt_outer_s)
        n_guided = 0                                    # guidance calls (LNAV engaged)
        # LNAV from where the airborne start starts: one roll-in anticipation before the DER
        # (the guidance projects an aircraft far before the path start onto its first
        # segment: a fly-by arc at the DER then reads 1.8 km off, measured)
        lnav_lead_m = anticipation_m(cfg.limits.climb_tas_mps, math.radians(20.0),
                                     LateralGains.for_aircraft(cfg))
        v_plan = cfg.limits.climb_tas_mps     # planned climb speed, CAS (the guidance's, once on)
        t0 = fdm.get_sim_time()
        bank_cmd, thr = 0.0, idle
        k = 0
        while True:
            raw = ac.read_raw()
            s = ac.state(raw)
            t = s.t_s - t0
            along, cross = rw.along_cross_m(math.degrees(s.lat_rad), math.degrees(s.lon_rad))
            wow = raw[i_wow] > 0.5
            h_m = s.alt_m - rw.elev_m
            why = self._failure(s, raw[i_wow], check, along, cross, phase, t)
            if why:
                flight.status, flight.reason = "diverged", f"takeoff: {why}"
                return False
            nav = navigate(s)                 # the navigation source runs from brake release
            # LNAV: the procedure guidance steers from LNAV_HEIGHT_M (engaged on a logging
            # step, so that its log records stay in step with the flight's rows)
            if guide is not None and phase == "climb" and (n_guided or (
                    h_m >= LNAV_HEIGHT_M and along >= rw.length_m - lnav_lead_m
                    and k % log_every == 0)):
                if not n_guided:
                    self._mark("lnav", s, along, cross, t)
                    lateral.last_bank_rad = bank_cmd
                    # steady and wings level on the centreline: the aileron and rudder of the
                    # moment are the lateral trims (propeller torque: the c172p needs 0.07
                    # aileron; its bank loop has no integral, measured 0.6 deg off otherwise)
                    fdm["fms/trim/aileron"] = fdm["fcs/aileron-cmd-norm"]
                    fdm["fms/trim/rudder"] = fdm["fcs/rudder-cmd-norm"]
                gout = guide.update(flight.dt_outer_s, nav, s)
                n_guided += 1
                merge_guidance(gout, tg)
                bank_cmd = lateral(tg, nav, True)
                if gout.tas_mps is not None and s.tas_mps > 1.0:   # the planned speed, CAS
                    v_plan = gout.tas_mps * s.cas_mps / s.tas_mps
            else:
                gout = None
            if k % log_every == 0:
                _log_row(flight, raw, nav, gout, bank_cmd, brg, thr)
            if phase == "climb" and "der" not in self.t_s and along >= rw.length_m:
                self._mark("der", s, along, cross, t)
            done = gout is not None and gout.done
            if done or (phase == "climb" and h_m >= HANDOVER_HEIGHT_M
                        and along >= rw.length_m and n_guided % log_every == 0 and (
                            s.cas_mps >= v_plan - HANDOVER_SPEED_MARGIN_MPS
                            or h_m >= HANDOVER_MAX_HEIGHT_M)):
                self._mark("handover", s, along, cross, t)
                if wind.active:
                    wind(wind.end_s, s.alt_m)         # all of it from here (the ramp's end)
                handover(ac)
                if config is not None:
                    config.gear_down = not gear_up
                    flight.config_step = config
                return True
            if wind.active:
                if t_wind is None and s.gs_mps > 2.0 * w_max:
                    t_wind = s.t_s
                if t_wind is not None and (s.t_s - t_wind <= wind.end_s or wind.varies):
                    wind(s.t_s - t_wind, s.alt_m)
            for j in range(n_sub):
                if j:
                    raw = ac.read_raw()
                    s = ac.state(raw)
                    along, cross = rw.along_cross_m(math.degrees(s.lat_rad),
                                                    math.degrees(s.lon_rad))
                    wow = raw[i_wow] > 0.5
                    h_m = s.alt_m - rw.elev_m
                t = s.t_s - t0
                # -- phase changes
                if phase == "roll" and s.cas_mps >= self.vr_cas_mps:
                    phase = "rotate"
                    self._mark("rotate", s, along, cross, t)
                if phase == "rotate" and not wow and h_m > 0.0:
                    phase = "climb"
                    self._mark("liftoff", s, along, cross, t)
                    fdm["fcs/steer-cmd-norm"] = 0.0
                    fdm["fms/trim/rudder"] = 0.0       # the yaw loop takes the rudder
                    fdm["fms/trim/aileron"] = 0.0
                    ac.engage(bank=True, yaw=True, ny=False, nx=False)
                if "v2" not in self.t_s and s.cas_mps >= self.v2_cas_mps:
                    self._mark("v2", s, along, cross, t)
                if phase == "climb" and not gear_up and s.vs_mps > POSITIVE_RATE_MPS \
                        and h_m > GEAR_UP_HEIGHT_M:
                    gear_up = True
                    ac.configure(gear_down=False)
                    self._mark("gear_up", s, along, cross, t)
                # -- controls
                thr = idle + (to.thrust_norm - idle) * min(1.0, t / SPOOL_S)
                if phase != "climb":
                    self.max_dev_ground_m = max(self.max_dev_ground_m, abs(cross))
                    steer, rudder = pilot.ground(dt_c, _wrap(s.heading_rad - brg), cross,
                                                 s.gs_mps, s.r_rps)
                    set_controls(ac, steer=steer, rudder=rudder, throttle=thr)
                else:
                    if not n_guided:   # on the extended centreline until LNAV
                        self.max_dev_air_m = max(self.max_dev_air_m, abs(cross))
                        bank_cmd = pilot.bank(_wrap(s.track_rad - brg), cross)
                    ac.command(bank_rad=bank_cmd, throttle=thr)
                    if h_m >= h_accel and "accelerate" not in self.t_s:
                        self._mark("accelerate", s, along, cross, t)
                    if "accelerate" in self.t_s:
                        v_climb = max(self.v2_cas_mps + to.climb_add_cas_mps, v_plan)
                    if config is not None and "accelerate" in self.t_s:
                        config.gear_down = not gear_up
                        config(s, flight.targets, False)     # flaps up on schedule
                if phase != "roll":
                    set_controls(ac, elevator=pilot.pitch(
                        dt_c, s.pitch_rad, s.q_rps, fdm["fms/sched/qbar-ratio"],
                        s.cas_mps - v_climb if phase == "climb" else None, s.alpha_rad))
                if not sampling.run(frames):
                    flight.status, flight.reason = "diverged", "takeoff: JSBSim stopped"
                    return False
            k += 1
            yield k

    def _failure(self, s, wow, check, along, cross, phase, t) -> str | None:
        if phase == "climb":
            return check(s, wow)
        if not math.isfinite(s.alt_m + s.tas_mps + s.pitch_rad + s.alpha_rad):
            return "non-finite state (JSBSim diverged)"
        if s.alpha_rad > check.stall_rad:
            return f"stall: alpha {math.degrees(s.alpha_rad):.1f} deg at t={t:.1f} s"
        if abs(cross) > EXCURSION_M:
            return f"runway excursion: {cross:+.0f} m off the centreline at t={t:.1f} s"
        if self.runway.length_m > 0 and along > self.runway.length_m:
            return (f"still on the wheels at the runway end ({self.runway.length_m:.0f} m) "
                    f"at t={t:.1f} s")
        if t > TIMEOUT_S:
            return f"no handover within {TIMEOUT_S:.0f} s"
        return None

    def _mark(self, name, s, along, cross, t) -> None:
        self.t_s[name] = round(t, 2)
        self.at[name] = {"along_m": round(along, 1), "cross_m": round(cross, 2),
                         "cas_mps": round(s.cas_mps, 2), "height_m": round(s.alt_m -
                                                                           self.runway.elev_m, 1),
                         "pitch_deg": round(math.degrees(s.pitch_rad), 2)}

    def _config_step(self, flight, ac, gear_up: bool) -> ConfigStep:
        """Flaps retracted on the go-around schedule of the approach settings, from the
        takeoff detent (the approach detent nearest ``takeoff.flaps_norm``)."""
        ap = self.cfg.approach
        k = min(range(len(ap.flaps)),
                key=lambda j: abs(ap.flaps[j].cmd_norm - self.cfg.takeoff.flaps_norm))
        cs = ConfigStep(ap, ac, k, not gear_up, getattr(flight.guidance, "events", None))
        cs.go_around = True      # retract mode: each detent up above its speed + margin
        return cs

    def summary(self) -> dict:
        """The takeoff as flown: times after brake release (s), ground roll (threshold to
        liftoff, m), speeds (CAS, m/s), largest centreline deviations (m), the handover."""
        out = {"start": "takeoff", "runway": self.runway.ident,
               "vr_cas_mps": round(self.vr_cas_mps, 2), "v2_cas_mps": round(self.v2_cas_mps, 2),
               "times_s": dict(self.t_s), "events": dict(self.at),
               "max_centreline_dev_ground_m": round(self.max_dev_ground_m, 2),
               "max_centreline_dev_air_m": round(self.max_dev_air_m, 2)}
        if "liftoff" in self.at:
            out["ground_roll_m"] = self.at["liftoff"]["along_m"]
        if "v2" in self.t_s:
            out["time_to_v2_s"] = self.t_s["v2"]
        if "der" in self.at:
            out["der_height_m"] = self.at["der"]["height_m"]
        if "handover" in self.t_s:
            out["handover_s"] = self.t_s["handover"]
            out["handover_along_m"] = self.at["handover"]["along_m"]
        return out


def _log_row(flight, raw, nav, gout, bank_cmd: float, brg_rad: float, thr: float) -> None:
    """One timeseries row of the takeoff, in the flight loop's layout: no vertical commands;
    the heading target is the runway's until LNAV; the guidance's log record once it steers."""
    flight.raw_log.extend(raw)
    hdg = brg_rad if gout is None else math.nan
    flight.rows.append((bank_cmd, hdg, math.nan, math.nan, thr, math.nan, math.nan,
                        nav.lat_rad, nav.lon_rad, nav.alt_m, nav.heading_rad, nav.roll_rad,
                        nav.pitch_rad))
    flight.extra_rows.append({**nav.errors, **gout.log} if gout is not None
                             else dict(nav.errors))


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


__all__ = ["DepartureRunway", "HANDOVER_HEIGHT_M", "TakeoffControl", "TakeoffStart",
           "check_takeoff", "departure_runway"]
