"""The named steps of one outer-loop period of a flight, in the order the loop calls them:

read (JSBSim → :class:`AircraftState`, in :mod:`fms_testbed.sim.jsbsim_core`) → check
(:class:`~fms_testbed.sim.divergence.Divergence`) → wind ramp (:class:`WindRamp`) → navigate
(the navigation source, or :class:`NavHold` between slower updates) → events (:class:`EventQueue`
into :class:`Targets`) → guide (the guidance, merged by :func:`merge_guidance`) → lateral
(:class:`LateralStep`: heading hold or bank hold, roll-rate limit) → vertical + command
(:class:`VerticalStep`: the vertical law or the direct inner-loop targets, sent to JSBSim) →
configuration (:class:`ConfigStep`: flaps and gear on the approach schedule, go-around) → log.

Each step is small and testable alone; tuning (gains, limits from the aircraft file) is given at
construction, run-time state lives in the step object.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.config.scenario import Event, Scenario
from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.core.contracts import GuidanceOutput
from fms_testbed.core.state import AirData, AircraftState, NavSolution
from fms_testbed.core.units import FT_M
from fms_testbed.guidance.lateral import heading_hold_bank_rad, wrap_pi

WIND_RAMP_S = 20.0
"""The scenario's steady wind grows linearly from zero to its value over this time after trim, s
(JSBSim 1.3.3 cannot trim in wind)."""


@dataclass(slots=True)
class Targets:
    """What the flight is currently asked to do (events and guidance write here).

    bank_rad: bank target, rad;  heading_rad: heading-hold target, rad (None: bank hold)
    ny: normal load-factor target, g;  nx: tangential load-factor target, g (None: throttle)
    throttle: direct throttle 0..1 (None: the n_x loop);  alt_m: altitude target, m
    speed_kind: "tas" or "cas";  speed_mps: speed target, m/s
    vertical: True while the vertical law flies alt_m/speed_mps
    """

    bank_rad: float = 0.0
    heading_rad: float | None = None
    ny: float = 1.0
    nx: float | None = None
    throttle: float | None = None
    alt_m: float | None = None
    speed_kind: str = "tas"
    speed_mps: float | None = None
    vertical: bool = False


class EventQueue:
    """Timed and conditional scenario events, each fired once, in file order."""

    def __init__(self, events: list[Event]):
        self.pending = list(events)

    def due(self, t_s: float, alt_m: float) -> list[Event]:
        """Remove and return the events due at time ``t_s`` (s) and altitude ``alt_m`` (m)."""
        fired, keep = [], []
        for ev in self.pending:
            if ev.t_s is not None:
                ok = t_s + 1e-9 >= ev.t_s
            else:
                w = ev.when
                ok = ((w.alt_m_above is None or alt_m >= w.alt_m_above)
                      and (w.alt_m_below is None or alt_m <= w.alt_m_below)
                      and (w.t_s_after is None or t_s >= w.t_s_after))
            (fired if ok else keep).append(ev)
        self.pending = keep
        return fired


def apply_event(ev: Event, tg: Targets) -> None:
    """Write an event's targets into ``tg`` (unset targets keep their value)."""
    if ev.bank_deg is not None:
        tg.bank_rad, tg.heading_rad = math.radians(ev.bank_deg), None
    if ev.heading_deg is not None:
        tg.heading_rad = math.radians(ev.heading_deg)
    if ev.ny is not None:
        tg.ny, tg.vertical = ev.ny, False
    if ev.nx is not None:
        tg.nx, tg.throttle, tg.vertical = ev.nx, None, False
    if ev.throttle is not None:
        tg.throttle, tg.nx, tg.vertical = ev.throttle, None, False
    if ev.altitude_m is not None:
        tg.alt_m, tg.vertical = ev.altitude_m, True
    kind, spd = ev.speed
    if spd is not None:
        tg.speed_kind, tg.speed_mps, tg.vertical = kind, spd, True


def merge_guidance(gout: GuidanceOutput, tg: Targets) -> None:
    """Write the guidance output ``gout`` into the targets ``tg``: its bank replaces heading/bank
    hold, its altitude and TAS engage the vertical law."""
    if gout.bank_rad is not None:
        tg.bank_rad, tg.heading_rad = gout.bank_rad, None
    if gout.alt_m is not None:
        tg.alt_m, tg.vertical = gout.alt_m, True
    if gout.tas_mps is not None:
        tg.speed_kind, tg.speed_mps, tg.vertical = "tas", gout.tas_mps, True


def wind_ned_mps(scn: Scenario, alt_m: float = 0.0) -> tuple[float, float, float]:
    """The wind of scenario ``scn`` at ``alt_m`` (m; a profile is interpolated) as the velocity
    of the air, NED, m/s."""
    prof = scn.wind_profile
    if prof is None:
        return (0.0, 0.0, 0.0)
    n, e = prof.ned_at(alt_m)
    return (n, e, 0.0)


class WindRamp:
    """The scenario's wind in JSBSim: ramped in linearly over :data:`WIND_RAMP_S` from its
    start (:meth:`start`: after a trim at once, on a takeoff roll once rolling), and, for a
    profile over altitude, the wind at the aircraft's present altitude set every outer step
    (``varies``; a steady wind is set only during the ramp).

    Parameters
    ----------
    fdm : the JSBSim instance; scn : the scenario (its wind)
    dt_outer_s : outer-loop period, s (the ramp's last setting is one step past its end)
    start_s : time the ramp starts, s (None: not yet, :meth:`start` later)
    """

    def __init__(self, fdm, scn: Scenario, dt_outer_s: float, start_s: float | None = 0.0):
        self.profile = scn.wind_profile
        self.active = self.profile is not None and self.profile.max_speed_mps > 0.0
        self.max_speed_mps = self.profile.max_speed_mps if self.active else 0.0
        self.varies = self.active and self.profile.layered
        self.end_s = WIND_RAMP_S + dt_outer_s
        self.t0_s = start_s
        self.wind_ned = wind_ned_mps(scn)
        pm = fdm.get_property_manager()
        self.nodes = [pm.get_node(f"atmosphere/wind-{c}-fps", False)
                      for c in ("north", "east", "down")]

    def start(self, t_s: float) -> None:
        """Start the ramp at ``t_s`` (s) unless it has started."""
        if self.t0_s is None:
            self.t0_s = t_s

    def finish(self, alt_m: float) -> None:
        """All of the wind from now on (the ramp's end), at altitude ``alt_m`` (m)."""
        if self.active:
            self(self.end_s, alt_m)
        self.t0_s = -math.inf

    def step(self, t_s: float, alt_m: float) -> None:
        """The wind for this outer step at time ``t_s`` (s) and altitude ``alt_m`` (m)."""
        if self.active and self.t0_s is not None:
            tau = t_s - self.t0_s
            if tau <= self.end_s or self.varies:
                self(tau, alt_m)

    def __call__(self, t_s: float, alt_m: float = 0.0) -> None:
        """Set the wind ``t_s`` (s) after the ramp's start at altitude ``alt_m`` (m)."""
        frac = min(1.0, t_s / WIND_RAMP_S)
        if self.varies:
            n, e = self.profile.ned_at(alt_m)
            w = (n, e, 0.0)
        else:
            w = self.wind_ned
        for node, c in zip(self.nodes, w):
            node.set_double_value(frac * c / FT_M)


class FrameSampling:
    """Run JSBSim frames for a navigation source whose sensors sample every frame.

    :meth:`run` advances the aircraft, reading the source's ``frame_properties`` after each frame
    (:meth:`~fms_testbed.sim.jsbsim_core.JSBSimAircraft.run_sampled`); calling the object with
    the true state at a navigation step hands the source the frames since its previous call
    (``None`` on the first). A source with no frame properties costs one attribute test.

    Parameters
    ----------
    source : the navigation source (:class:`~fms_testbed.core.contracts.NavigationSource`)
    aircraft : the :class:`~fms_testbed.sim.jsbsim_core.JSBSimAircraft` it flies on
    """

    def __init__(self, source, aircraft):
        self.source, self.aircraft = source, aircraft
        props = source.frame_properties
        self.getters = aircraft.frame_getters(props) if props else ()
        self.buf = np.empty((64, len(props)))
        self.n = 0
        self.first = True

    def run(self, n_frames: int) -> bool:
        """Advance ``n_frames`` JSBSim frames (sampled when the source asks); False if JSBSim
        stops."""
        if not self.getters:
            return self.aircraft.run(n_frames)
        if self.n + n_frames > len(self.buf):
            grown = np.empty((2 * (self.n + n_frames), self.buf.shape[1]))
            grown[:self.n] = self.buf[:self.n]
            self.buf = grown
        ok = self.aircraft.run_sampled(n_frames, self.getters, self.buf[self.n:])
        self.n += n_frames
        return ok

    def __call__(self, s: AircraftState) -> NavSolution:
        """The navigation solution at ``s.t_s`` (the frames are valid only during the call)."""
        if not self.getters:
            return self.source.update(s)
        frames = None if self.first else self.buf[:self.n]
        self.first, self.n = False, 0
        return self.source.update(s, frames)


class NavHold:
    """Apply the last navigation errors to truth between navigation updates (navigation slower
    than the outer loop)."""

    def __init__(self, source, dt_s: float):
        self.source, self.dt_s = source, dt_s
        self.next_t = 0.0
        self.err = None
        self.errors: dict[str, float] = {}

    def __call__(self, s: AircraftState) -> NavSolution:
        """The navigation solution at ``s.t_s``."""
        if self.err is None or s.t_s + 1e-9 >= self.next_t:
            nav = self.source.update(s)
            self.err = (nav.lat_rad - s.lat_rad, nav.lon_rad - s.lon_rad, nav.alt_m - s.alt_m,
                        nav.v_enu_mps - s.v_enu_mps, nav.roll_rad - s.roll_rad,
                        nav.pitch_rad - s.pitch_rad, wrap_pi(nav.heading_rad - s.heading_rad))
            self.errors = dict(nav.errors)
            self.next_t = s.t_s + self.dt_s
            return nav
        e = self.err
        return NavSolution(t_s=s.t_s, lat_rad=s.lat_rad + e[0], lon_rad=s.lon_rad + e[1],
                           alt_m=s.alt_m + e[2], v_enu_mps=s.v_enu_mps + e[3],
                           roll_rad=s.roll_rad + e[4], pitch_rad=s.pitch_rad + e[5],
                           heading_rad=wrap_pi(s.heading_rad + e[6]) % (2 * math.pi),
                           errors=self.errors)


class LateralStep:
    """Bank command: heading hold on the navigation heading, else the bank target; commands from
    guidance or heading hold are limited to the aircraft's passenger-comfort roll rate."""

    __slots__ = ("bank_max_rad", "roll_step_rad", "heading_kp", "last_bank_rad")

    def __init__(self, cfg: AircraftConfig, dt_outer_s: float):
        lim = cfg.limits
        self.bank_max_rad = math.radians(lim.bank_max_deg)
        self.roll_step_rad = math.radians(lim.roll_rate_max_dps) * dt_outer_s
        self.heading_kp = cfg.inner_loops.heading_kp
        self.last_bank_rad = 0.0

    def __call__(self, tg: Targets, nav: NavSolution, guided: bool) -> float:
        """The bank command, rad, for this outer step."""
        hdg_cmd = tg.heading_rad
        if hdg_cmd is not None:
            bank = heading_hold_bank_rad(hdg_cmd, nav.heading_rad, self.heading_kp,
                                         self.bank_max_rad)
        else:
            bank = tg.bank_rad
        if hdg_cmd is not None or guided:
            last, step = self.last_bank_rad, self.roll_step_rad
            bank = min(max(bank, last - step), last + step)
        self.last_bank_rad = bank
        return bank


class VerticalStep:
    """The vertical channel and the command to JSBSim: the vertical law while an altitude/speed
    target is active (the law works in the vertical plane and returns the vertical component of
    n_y, divided here by cos φ), else the direct n_y/n_x/throttle targets.

    The speeds and the altitude the step reads are the air data's: a CAS target is flown as its
    TAS at the barometric altitude on the day, an unset speed target holds the measured TAS,
    and the law is handed the true state with the air-data TAS, CAS, Mach and barometric
    altitude in place of the true ones (the same object when they agree, as with an error-free
    air-data computer)."""

    __slots__ = ("law", "command", "dt_s", "engaged", "isa_dev_c")

    def __init__(self, law, aircraft, dt_outer_s: float):
        self.law, self.command, self.dt_s = law, aircraft.command, dt_outer_s
        self.engaged = False
        # a CAS target flown as its TAS on the day (the air-data computer's temperature)
        self.isa_dev_c = aircraft.isa_dev_c

    def __call__(self, s: AircraftState, air: AirData, tg: Targets, bank_rad: float
                 ) -> tuple[float, float, float, float]:
        """Compute and send this step's commands; return them: (cmd_nx g, cmd_ny g, altitude
        command m, TAS command m/s), NaN where inactive."""
        if tg.vertical:
            if tg.alt_m is None:
                tg.alt_m = air.baro_alt_m
            alt_cmd = tg.alt_m
            if tg.speed_mps is None:
                tg.speed_kind, tg.speed_mps = "tas", air.tas_mps
            tas_cmd = (cas_to_tas_scalar(tg.speed_mps, air.baro_alt_m, self.isa_dev_c)
                       if tg.speed_kind == "cas"
                       else tg.speed_mps)
            law = self.law
            if not (air.tas_mps == s.tas_mps and air.baro_alt_m == s.alt_m
                    and air.cas_mps == s.cas_mps and air.mach == s.mach):
                s = replace(s, tas_mps=air.tas_mps, cas_mps=air.cas_mps, mach=air.mach,
                            alt_m=air.baro_alt_m)
            if not self.engaged:
                law.engage(s, alt_cmd, tas_cmd)
                self.engaged = True
            cmd_nx, ny_vert = law.update(self.dt_s, s, alt_cmd, tas_cmd)
            cmd_ny = ny_vert / max(math.cos(s.roll_rad), 0.5)
            self.command(bank_rad=bank_rad, ny=cmd_ny, nx=cmd_nx)
            return cmd_nx, cmd_ny, alt_cmd, tas_cmd
        self.engaged = False
        nan = math.nan
        cmd_ny = tg.ny
        if tg.throttle is not None:
            self.command(bank_rad=bank_rad, ny=cmd_ny, throttle=tg.throttle)
            return nan, cmd_ny, nan, nan
        cmd_nx = tg.nx if tg.nx is not None else 0.0
        self.command(bank_rad=bank_rad, ny=cmd_ny, nx=cmd_nx)
        return cmd_nx, cmd_ny, nan, nan


FLAP_RETRACT_MARGIN_MPS = 2.5
"""In a go-around a detent is retracted once the CAS is this much above its selection speed,
m/s (5 kt: no retraction at the edge of the schedule)."""
POSITIVE_RATE_MPS = 1.0
"""A go-around raises the gear once climbing faster than this, m/s (positive rate)."""


def flap_index_for_cas(ap, cas_mps: float) -> int:
    """The detent (index into ``ap.flaps``) the approach schedule has out at CAS ``cas_mps``
    (m/s): the last one whose selection speed is at or above it."""
    k = 0
    for j, f in enumerate(ap.flaps):
        if cas_mps <= f.select_cas_mps:
            k = j
    return min(k, ap.index(ap.landing_flap))


class ConfigStep:
    """Flaps and gear of an aircraft with approach settings (``AircraftConfig.approach``).

    On approach a detent is selected once both the CAS and the CAS target are at or below its
    selection speed (one detent at a time, never past the landing detent); the gear goes down
    with ``gear_with_flap`` or at ``gear_down_height_m`` above the terrain (the runway),
    whichever comes first. In a go-around (``go_around`` true) the flaps go to the go-around
    detent at once, the gear comes up at a positive rate of climb, and each detent is retracted
    when the CAS is :data:`FLAP_RETRACT_MARGIN_MPS` above its selection speed. Each change is
    appended to ``events`` (t_s, kind 'config', detail).
    """

    __slots__ = ("ap", "configure", "k", "gear_down", "go_around", "events", "k_land",
                 "k_ga", "k_gear")

    def __init__(self, ap, aircraft, flap_index: int = 0, gear_down: bool = False,
                 events: list | None = None):
        self.ap, self.configure = ap, aircraft.configure
        self.k, self.gear_down, self.go_around = flap_index, gear_down, False
        self.events = events if events is not None else []
        self.k_land, self.k_ga = ap.index(ap.landing_flap), ap.index(ap.go_around_flap)
        self.k_gear = None if ap.fixed_gear else ap.index(ap.gear_with_flap)

    def departure(self) -> None:
        """Fly a departure: the retract-only schedule of the go-around from here on (no
        extension, no event: the aircraft is already clean or in its takeoff setting)."""
        self.go_around = True

    def _event(self, t_s: float, detail: str) -> None:
        self.events.append({"t_s": round(t_s, 2), "kind": "config", "detail": detail})

    def __call__(self, s: AircraftState, tg: Targets, go_around: bool) -> None:
        """Move flaps and gear for this step (state ``s``, targets ``tg``)."""
        flaps, k0, g0 = self.ap.flaps, self.k, self.gear_down
        cas = s.cas_mps
        if go_around and not self.go_around:
            self.go_around = True
            self.k = min(self.k, self.k_ga)
            self._event(s.t_s, "go-around")
        if not self.go_around:
            tgt = cas
            if tg.speed_mps is not None:
                tgt = tg.speed_mps * (cas / s.tas_mps if tg.speed_kind == "tas" and s.tas_mps > 1
                                      else 1.0)
            while self.k < self.k_land and cas <= flaps[self.k + 1].select_cas_mps                     and tgt <= flaps[self.k + 1].select_cas_mps:
                self.k += 1
            if self.k_gear is not None and not self.gear_down and (
                    self.k >= self.k_gear or s.agl_m <= self.ap.gear_down_height_m):
                self.gear_down = True
        else:
            if self.gear_down and self.k_gear is not None and s.vs_mps > POSITIVE_RATE_MPS:
                self.gear_down = False
            while self.k > 0 and cas >= flaps[self.k].select_cas_mps + FLAP_RETRACT_MARGIN_MPS:
                self.k -= 1
        if self.k != k0:
            self._event(s.t_s, f"flaps {flaps[self.k].name}")
        if self.gear_down != g0:
            self._event(s.t_s, "gear down" if self.gear_down else "gear up")
        if self.k != k0 or self.gear_down != g0:
            self.configure(flap_cmd_norm=flaps[self.k].cmd_norm,
                           gear_down=None if self.k_gear is None else self.gear_down)


__all__ = ["WIND_RAMP_S", "ConfigStep", "flap_index_for_cas", "Targets", "EventQueue", "apply_event", "merge_guidance",
           "wind_ned_mps", "WindRamp", "NavHold", "LateralStep", "VerticalStep"]
