"""Aircraft configuration: one readable YAML file per aircraft under ``aircraft/``.

A file names the JSBSim model and holds the aircraft's limits (speed range, bank, load factors,
climb capability), its trim bounds, the envelope points it is tested at, and the tuning of the
inner loops and the coupled law. Tuning is frozen data; controller state lives elsewhere.

All quantities are SI with the unit in the key (``_mps``, ``_m``, ``_deg``, ``_s``) except load
factors (g, dimensionless) and normalised controls. Adding an aircraft means adding one file.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Annotated

from pydantic import AliasChoices, BaseModel, ConfigDict, Field, ValidationError, model_validator

from fms_testbed.core.errors import ConfigError
from fms_testbed.core.planning import DEPARTURE_ACCEL_MPS2
from fms_testbed.core.units import KT_MPS
from fms_testbed.data import aircraft_dir
from fms_testbed.config.yamlfile import read_mapping, validation_message

Pos = Annotated[float, Field(gt=0)]
NonNeg = Annotated[float, Field(ge=0)]


class _Frozen(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Limits(_Frozen):
    """Operating limits used by trim checks, divergence detection, guidance and the monitor."""

    cas_min_mps: Pos = Field(description="minimum clean operating CAS (stall margin included), m/s")
    cas_max_mps: Pos = Field(description="maximum operating CAS (VMO), m/s")
    mach_max: Annotated[float, Field(gt=0, lt=3)] = Field(description="maximum operating Mach (MMO)")
    alt_max_m: Pos = Field(description="service ceiling, m")
    bank_max_deg: Annotated[float, Field(gt=0, le=45)] = Field(description="max bank in guidance, deg")
    roll_rate_max_dps: Annotated[float, Field(gt=0, le=60)] = Field(
        5.0, description="rate limit on the bank command from heading hold/guidance, deg/s")
    ny_min: Annotated[float, Field(ge=-1, le=1)] = Field(description="min normal load factor, g")
    ny_max: Annotated[float, Field(ge=1, le=4)] = Field(description="max normal load factor, g")
    ny_limit_min: Annotated[float, Field(ge=-4, le=0)] = Field(
        -1.0, description="limit manoeuvring load factor, negative, g (CS 25.337: -1.0 for "
                          "transport aeroplanes; the envelope check of a flight's outcome)")
    ny_limit_max: Annotated[float, Field(ge=1.5, le=10)] = Field(
        2.5, description="limit manoeuvring load factor, positive, g (CS 25.337: 2.5 for "
                         "transport aeroplanes; CS 23: 3.8 normal category)")
    stall_alpha_deg: Pos = Field(description="alpha at which the run is declared stalled, deg")
    climb_rate_max_mps: Pos = Field(description="max sustained climb rate near sea level, m/s")
    climb_gradient_max: Annotated[float, Field(gt=0, lt=0.5)] = Field(
        description="max climb gradient (rise over run) at the planned speed, dimensionless")
    descent_rate_max_mps: Pos = Field(description="max planned descent rate, m/s")
    climb_cas_mps: Pos = Field(
        validation_alias=AliasChoices("climb_cas_mps", "climb_tas_mps"),
        description="planned terminal-area speed for path building and guidance, a CAS, m/s "
                    "(its TAS at each leg's planned altitude); the older key climb_tas_mps is read "
                    "as the same CAS")

    @model_validator(mode="after")
    def _order(self):
        if self.cas_min_mps >= self.cas_max_mps:
            raise ValueError("cas_min_mps must be below cas_max_mps")
        if self.ny_min >= self.ny_max:
            raise ValueError("ny_min must be below ny_max")
        return self


class TrimSettings(_Frozen):
    """Trim bounds: JSBSim's alpha search is bounded to avoid trimming past the lift peak."""

    alpha_max_deg: Annotated[float, Field(gt=0, le=30)] = Field(description="upper alpha bound, deg")
    alpha_min_deg: Annotated[float, Field(ge=-10, le=0)] = -4.0


class EnvelopePoint(_Frozen):
    """A condition the aircraft is trimmed and tested at."""

    alt_m: Annotated[float, Field(ge=0, le=20000)]
    tas_mps: Pos


class PIDGains(_Frozen):
    """Proportional/integral/derivative gains of one inner loop (units depend on the loop)."""

    kp: float
    ki: NonNeg = 0.0
    kd: float = 0.0
    kff: float = Field(0.0, description="feed-forward of the command's deviation from trim "
                                        "(n_y - 1, n_x), control units per g")


class InnerLoopGains(_Frozen):
    """Inner-loop tuning (run inside JSBSim as ``<system>`` components every
    ``frames_per_update`` JSBSim frames: 60 Hz by default at JSBSim's 120 Hz).

    * bank: aileron (norm) per rad of bank error; kd per rad/s of roll rate
    * yaw: rudder (norm) per rad of sideslip (kp) and per rad/s of yaw rate (kd)
    * ny: elevator (norm) per g of normal-load-factor error; kd per rad/s of pitch rate
    * nx: throttle (norm) per g of tangential-load-factor error
    * heading: bank command (rad) per rad of heading error (outer loop, Python)
    """

    bank: PIDGains
    yaw: PIDGains
    ny: PIDGains
    nx: PIDGains
    heading_kp: Pos = Field(description="bank command per heading error, rad/rad")
    heading_ki: NonNeg = 0.0
    elevator_rate_max_ps: Pos = Field(1.5, description="elevator command rate limit, norm/s")
    throttle_min: Annotated[float, Field(ge=0, le=1)] = 0.0
    throttle_max: Annotated[float, Field(ge=0, le=1.0)] = 1.0
    frames_per_update: Annotated[int, Field(ge=1, le=4)] = Field(
        2, description="inner loops run every N JSBSim frames (JSBSim channel execrate): "
                       "1 = 120 Hz, 2 = 60 Hz (a flight-control computer's rate; half the cost)")


class InnerLoopSpec(_Frozen):
    """Step-response specification the inner loops must meet on this aircraft (tests check it).

    Settling: last time outside ±5 % of the step around the target; overshoot in % of the step.
    """

    bank_step_deg: Pos = 25.0
    bank_settle_max_s: Pos = 6.0
    ny_step: Pos = Field(0.1, description="n_y step size, g (flown up and down)")
    ny_settle_max_s: Pos = 2.0
    nx_step: Pos = Field(0.05, description="n_x step size, g (flown up and down)")
    nx_settle_max_s: Pos = 1.5
    overshoot_max_pct: Pos = 10.0
    nx_overshoot_max_pct: Pos = 10.0


class CoupledLawGains(_Frozen):
    """Multi-coupled thrust/elevator law tuning (Kulikov et al., eq. 2 and 5)."""

    T_V_s: Pos = Field(description="speed-channel time constant, s")
    xi_V: Pos = Field(description="speed-channel damping ratio")
    T_H_s: Pos = Field(description="altitude-channel time constant, s")
    xi_H: Pos = Field(description="altitude-channel damping ratio")
    dH_limit_m: Pos = Field(100.0, description="altitude-error limit (level-change mode), m")


class SchedulePoint(_Frozen):
    """One row of the coupled law's gain schedule: the scheduling variables and the tuning."""

    qbar_pa: Pos = Field(description="dynamic pressure, Pa")
    mass_kg: Pos = Field(description="mass, kg")
    T_V_s: Pos = Field(description="speed-channel time constant, s")
    xi_V: Pos = Field(description="speed-channel damping ratio")
    T_H_s: Pos = Field(description="altitude-channel time constant, s")
    xi_H: Pos = Field(description="altitude-channel damping ratio")
    ny_trim_tau_s: Pos = Field(description="n_y tracking-error integrator time constant, s")


class CoupledLawSchedule(_Frozen):
    """Gain schedule of the coupled law in dynamic pressure and mass (``fms-testbed tune
    --envelope``): a table, piecewise linear in ln q̄ per mass level and linear in mass
    (:mod:`fms_testbed.control.schedule`)."""

    points: list[SchedulePoint] = Field(min_length=1)


class FlapDetent(_Frozen):
    """One flap detent the approach schedule uses: its name (as the crew calls it), the
    normalised JSBSim command ``fcs/flap-cmd-norm`` that selects it (the model's own traverse
    settings), the CAS at or below which it is selected on approach (and above which it is
    retracted in a go-around), m/s, and its placard (limit) CAS, m/s."""

    name: str
    cmd_norm: Annotated[float, Field(ge=0, le=1)] = Field(
        description="JSBSim fcs/flap-cmd-norm selecting this detent")
    select_cas_mps: Pos = Field(description="selected on approach at or below this CAS, m/s")
    max_cas_mps: Pos = Field(description="placard (limit) speed of the detent, m/s")

    @model_validator(mode="after")
    def _select_below_max(self):
        if self.select_cas_mps > self.max_cas_mps:
            raise ValueError(f"flap {self.name}: select_cas_mps above max_cas_mps")
        return self


class ApproachSettings(_Frozen):
    """How the aircraft is slowed and configured for an approach and a go-around.

    Vapp (final approach CAS) is given at a reference mass and scaled with the square root of
    the mass ratio (stall speed at a given lift coefficient, V ∝ sqrt(m)):
    ``Vapp(m) = vapp_cas_mps · sqrt(m / mass_ref_kg)``. ``source`` says where the numbers come
    from.
    """

    vapp_cas_mps: Pos = Field(description="final approach CAS at mass_ref_kg (Vref + additive), m/s")
    mass_ref_kg: Pos = Field(description="mass Vapp is given at, kg")
    flaps: list[FlapDetent] = Field(min_length=1, description="detents used, retracted to "
                                                               "landing (first: flaps up)")
    landing_flap: str = Field(description="name of the landing detent")
    go_around_flap: str = Field(description="name of the go-around detent")
    gear_with_flap: str | None = Field(None, description="the gear goes down with this detent "
                                                          "(None: fixed gear)")
    gear_down_height_m: Pos | None = Field(
        None, description="the gear goes down at the latest at this height above the runway, m "
                          "(None: fixed gear)")
    decel_mps2: Pos = Field(0.25, description="deceleration planned on approach (TAS), m/s²")
    go_around_add_cas_mps: NonNeg = Field(
        5.0, description="the go-around climbs at Vapp plus this until the acceleration "
                         "height, m/s")
    acceleration_height_m: Pos = Field(
        300.0, description="height above the runway where a go-around accelerates and "
                           "cleans up, m")
    source: str = Field(description="where the speeds come from")

    @model_validator(mode="after")
    def _names(self):
        names = [f.name for f in self.flaps]
        for key in ("landing_flap", "go_around_flap", "gear_with_flap"):
            v = getattr(self, key)
            if v is not None and v not in names:
                raise ValueError(f"{key} {v!r} is not one of the flaps {names}")
        cmds = [f.cmd_norm for f in self.flaps]
        sel = [f.select_cas_mps for f in self.flaps]
        if cmds != sorted(cmds) or sel != sorted(sel, reverse=True):
            raise ValueError("flaps must be listed from up to landing: cmd_norm increasing, "
                             "select_cas_mps decreasing")
        if (self.gear_with_flap is None) != (self.gear_down_height_m is None):
            raise ValueError("gear_with_flap and gear_down_height_m go together (both null: "
                             "fixed gear)")
        return self

    @property
    def fixed_gear(self) -> bool:
        """True when the gear is not retractable."""
        return self.gear_with_flap is None

    def index(self, name: str) -> int:
        """Position of detent ``name`` in :attr:`flaps`."""
        return [f.name for f in self.flaps].index(name)

    def vapp_cas_mps_at(self, mass_kg: float | None) -> float:
        """Final approach CAS at mass ``mass_kg`` (kg; None: the reference mass), m/s:
        ``vapp_cas_mps · sqrt(mass_kg / mass_ref_kg)``."""
        if mass_kg is None or not mass_kg > 0:
            return self.vapp_cas_mps
        return self.vapp_cas_mps * (mass_kg / self.mass_ref_kg) ** 0.5


class TakeoffSettings(_Frozen):
    """How the aircraft takes off when a SID starts on the runway (``procedure.start:
    takeoff``): flap setting, rotation and takeoff-safety speeds (CAS at ``mass_ref_kg``,
    scaled with the square root of the mass ratio like Vapp), the pitch it rotates to and the
    most it pitches up to hold the climb-out speed ``v2_cas_mps + climb_add_cas_mps``.
    ``source`` says where the numbers come from."""

    flaps_norm: Annotated[float, Field(ge=0, le=1)] = Field(
        description="takeoff flap setting, JSBSim fcs/flap-cmd-norm")
    vr_cas_mps: Pos = Field(description="rotation speed VR at mass_ref_kg, m/s CAS")
    v2_cas_mps: Pos = Field(description="takeoff safety speed V2 at mass_ref_kg, m/s CAS")
    pitch_deg: Annotated[float, Field(gt=0, le=25)] = Field(
        description="pitch attitude rotated to at VR, deg")
    pitch_max_deg: Annotated[float, Field(gt=0, le=30)] = Field(
        20.0, description="highest pitch flown to hold the climb-out speed, deg")
    climb_add_cas_mps: NonNeg = Field(
        10.0 * KT_MPS, description="climb out at V2 plus this (default 10 kt), m/s")
    thrust_norm: Annotated[float, Field(gt=0, le=1)] = Field(
        1.0, description="takeoff throttle (normalised)")
    departure_accel_mps2: Pos = Field(
        DEPARTURE_ACCEL_MPS2, description="acceleration (CAS along the path) a departure is "
        "planned to make good from the acceleration height while it goes on climbing, m/s² "
        "(the planner's departure speeds: fms_testbed.legs.model.Performance)")
    mass_ref_kg: Pos = Field(description="mass the speeds are given at, kg")
    pitch_rate_kp: Pos = Field(
        8.0, description="elevator (normalised) per rad/s of pitch-rate error, at the design "
                         "point's dynamic pressure (scaled with q_ref/q like the inner loops)")
    pitch_rate_ki: NonNeg = Field(
        8.0, description="elevator per rad of integrated pitch-rate error (per rad/s per s)")
    source: str = Field(description="where the numbers come from")

    @model_validator(mode="after")
    def _order(self):
        if self.vr_cas_mps > self.v2_cas_mps:
            raise ValueError("vr_cas_mps must not be above v2_cas_mps")
        if self.pitch_deg > self.pitch_max_deg:
            raise ValueError("pitch_deg must not be above pitch_max_deg")
        return self

    def speeds_cas_mps(self, mass_kg: float | None) -> tuple[float, float]:
        """(VR, V2) at mass ``mass_kg`` (kg; None: the reference mass), m/s CAS:
        ``V · sqrt(mass_kg / mass_ref_kg)``."""
        k = 1.0 if mass_kg is None or not mass_kg > 0 else (mass_kg / self.mass_ref_kg) ** 0.5
        return self.vr_cas_mps * k, self.v2_cas_mps * k


class AircraftConfig(_Frozen):
    """One aircraft: the JSBSim model plus everything the testbed needs to fly it."""

    name: str
    description: str = ""
    jsbsim_model: Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_-]*$", max_length=64)] = Field(
        description="model folder name in the jsbsim wheel's aircraft/ (a plain name: no path)")
    category: str = Field(description="narrow-body | business-jet | light")
    imu_lever_arm_m: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="position of the IMU relative to the centre of gravity in "
        "body axes (x forward, y right, z down), m: the lever arm of the strapdown navigation's "
        "IMU (its outputs are moved back to the CG); 0: the IMU at the CG")
    limits: Limits
    trim: TrimSettings
    envelope: list[EnvelopePoint] = Field(min_length=1)
    default_condition: EnvelopePoint
    inner_loops: InnerLoopGains
    inner_spec: InnerLoopSpec = Field(default_factory=InnerLoopSpec)
    coupled_law: CoupledLawGains | None = None
    coupled_law_schedule: CoupledLawSchedule | None = Field(
        None, description="gains of the coupled law scheduled in dynamic pressure and mass "
                          "(replace T_V_s, xi_V, T_H_s, xi_H of coupled_law in flight)")
    approach: ApproachSettings | None = Field(
        None, description="approach speeds and configuration (None: flown clean at the "
                          "planned approach speed)")
    takeoff: TakeoffSettings | None = Field(
        None, description="takeoff settings (None: a SID cannot start with a takeoff roll)")
    source_file: str = ""


def list_aircraft() -> list[str]:
    """Names of the shipped aircraft configurations."""
    return sorted(p.stem for p in aircraft_dir().glob("*.yaml"))


def load_aircraft_file(path: str | Path) -> AircraftConfig:
    """Load and validate an aircraft YAML file; raise :class:`ConfigError` naming file and field."""
    path = Path(path)
    raw = read_mapping(path, "aircraft file")
    raw.setdefault("name", path.stem)
    raw["source_file"] = str(path)
    try:
        return AircraftConfig.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(validation_message(str(path), err)) from None


@lru_cache(maxsize=32)
def load_aircraft(name: str) -> AircraftConfig:
    """Load a shipped aircraft by name (``aircraft/NAME.yaml``) or from a path to a YAML file."""
    p = Path(name)
    if p.suffix in (".yaml", ".yml") and p.exists():
        return load_aircraft_file(p)
    path = aircraft_dir() / f"{name}.yaml"
    if not path.exists():
        raise ConfigError(
            f"unknown aircraft '{name}': shipped aircraft are {', '.join(list_aircraft())}")
    return load_aircraft_file(path)
