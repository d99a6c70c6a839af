"""Fly a real ARINC-424 procedure in JSBSim: build it, start the aircraft on it, fly the closed
loop with :class:`~fms_testbed.guidance.fms.ProcedureGuidance`, then measure the flight errors.

Start condition (stated plainly, it is a simplification): by default a SID starts
**airborne at the departure end of the runway (DER)** at the
builder's planned start altitude (35 ft above the runway), trimmed straight and level at the
planned start speed on the runway heading; the profile then climbs it. STARs and
approaches start at their first fix at the first coded altitude, on the first segment's
course. In both cases the aircraft is placed one roll-in anticipation distance (≈ 400 m for the
737) *before* the path start on that course, so a turn that begins at the path start is entered
like any other planned turn. The start speed is the planned TAS (a SID from its runway: the
plan's climb-out speed, V2 + the takeoff's increment) moved into the first leg's coded speed
limit. An approach ends at the runway/MAP unless the missed approach is flown
(``procedure.missed``: go-around at the MAP, the missed-approach legs to the end of the first
holding circuit). JSBSim's terrain is set to the procedure's airport
(:func:`fms_testbed.path.runway.terrain_elevation_m`: an approach's runway threshold, else the
airport reference elevation, never above a SID's start), so height above ground is height
above the runway and ground contact ends a flight that gets there. With ``procedure.start:
takeoff`` a SID starts instead at rest on its runway's threshold and takes off
(:mod:`fms_testbed.loop.takeoff`; terrain at the threshold elevation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any


from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.errors import ConfigError
from fms_testbed.guidance.fms import ProcedureGuidance
from fms_testbed.control import procedure_law
from fms_testbed.config.procedure import ProcedureSpec, parse_procedure
from fms_testbed.path.plan import FlyablePath, build_procedure, load_db
from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.config.scenario import Scenario, parse_scenario
from fms_testbed.core.atmosphere import cas_to_tas_scalar
from fms_testbed.guidance.vertical import cas_band, planned_limits, tas_target_mps
from fms_testbed.guidance.lateral import LateralGains, anticipation_m
from fms_testbed.core.geodesy import direct
from fms_testbed.core.planning import PLANNED_BANK_DEG, SCREEN_HEIGHT_M
from fms_testbed.core.units import G0_MPS2
from fms_testbed.loop.takeoff import DepartureRunway, check_takeoff, departure_runway

OUTER_RATE_HZ = 10.0
"""Rate of navigation, guidance and the vertical law in procedure flights, Hz (an FMS runs
LNAV/VNAV at 5-20 Hz; the same as the scenario default). A scenario's ``outer_rate_hz`` wins."""


def initial_from_path(fp: FlyablePath, cfg) -> dict[str, float]:
    """The scenario ``initial`` block for the start of a built path (module docstring)."""
    seg0 = fp.path.segments[0].geom
    # the course of the first segment long enough to fly (a bridge of a few metres has none)
    crs = next((sg.geom.start_course_deg for sg in fp.path.segments
                if sg.geom.length_m() >= 50.0), seg0.start_course_deg)
    # start one roll-in anticipation before the path start on its initial course, so that a
    # turn beginning at the path start (a fly-by at the DER) is flown like any planned turn
    lead = anticipation_m(cfg.limits.climb_cas_mps, math.radians(PLANNED_BANK_DEG),
                          LateralGains.for_aircraft(cfg))
    lat, lon, _ = direct(seg0.start[0], seg0.start[1], crs + 180.0, lead)
    alt = fp.path.legs[0].start.alt_m
    # the planned speed is a CAS (guidance flies it so): its TAS at the start altitude, in the
    # first leg's band (coded limit, an approach's planned speed)
    lo, hi = cas_band(planned_limits(fp.seq.legs, fp.path.proc_type,
                                     cfg.limits.cas_min_mps)[0], None)
    dev = fp.params.isa_dev_c if fp.params is not None else 0.0
    cas = cfg.limits.climb_cas_mps
    if fp.path.legs[0].departure_cas_mps is not None:   # a departure: its climb-out speed
        cas = min(cas, fp.path.legs[0].departure_cas_mps)
    tas = tas_target_mps(cas_to_tas_scalar(cas, alt, dev), alt, lo, hi,
                         cfg.limits.cas_min_mps, dev)
    hdg = fp.path.segments[0].heading_deg   # a heading leg: its heading (drift in the plan)
    return {"lat_deg": lat, "lon_deg": lon, "alt_m": alt,
            "tas_mps": round(tas, 3), "heading_deg": (crs if hdg is None else hdg) % 360.0}


@dataclass
class PreparedProcedure:
    """A scenario's procedure, built and checked: what :class:`~fms_testbed.loop.flight.Flight`
    needs to fly it.

    Attributes
    ----------
    spec : the validated ``procedure:`` block
    path : the built path (with its sequence, RNP per leg and monitor findings)
    db : the database it was built from (guidance rebuilds conditional legs from it)
    """

    spec: ProcedureSpec
    path: FlyablePath
    db: Any

    @cached_property
    def terrain_elev_m(self) -> float:
        """Terrain elevation of the flight, m (module docstring)."""
        from fms_testbed.path.runway import terrain_elevation_m

        if self.spec.start == "takeoff":
            return departure_runway(self.db, self.path.seq).elev_m
        h = terrain_elevation_m(self.db, self.path.seq)
        p = self.path.path
        if p.proc_type == "D" and p.legs:   # a SID starts at the screen height over its DER
            h = min(h, p.legs[0].start.alt_m - SCREEN_HEIGHT_M)
        return h

    @cached_property
    def runway(self):
        """The approach's runway (:class:`~fms_testbed.path.runway.ApproachRunway`; None for
        other procedures)."""
        from fms_testbed.path.runway import approach_runway

        return approach_runway(self.db, self.path.seq) if self.db is not None else None

    def takeoff_runway(self) -> DepartureRunway | None:
        """The runway of a SID flown from a takeoff (``procedure.start: takeoff``), None for an
        airborne start."""
        if self.spec.start != "takeoff":
            return None
        return departure_runway(self.db, self.path.seq)

    def guidance(self, scn: Scenario, cfg) -> tuple[ProcedureGuidance, Any]:
        """The procedure guidance and the vertical law (None: the scenario's) for a flight."""
        g = ProcedureGuidance(self.path, cfg, db=self.db, spec=self.spec)
        law = procedure_law(cfg) if scn.vertical_law == "coupled" and cfg.coupled_law else None
        return g, law


def _wind_or_none(raw_wind):
    from fms_testbed.config.scenario import WindSpec, wind_profile
    from pydantic import TypeAdapter, ValidationError

    if raw_wind is None or raw_wind == {}:
        return None
    try:
        return wind_profile(TypeAdapter(WindSpec).validate_python(raw_wind))
    except (ValidationError, ValueError):
        return None   # parse_scenario reports it with the file and field


def planned_conditions(raw: dict):
    """(wind profile or None, ISA deviation K) the path of a scenario mapping is planned for:
    its ``forecast:`` block where it gives them, else the actual ``wind:`` and
    ``atmosphere:`` (invalid blocks count as absent: :func:`parse_scenario` reports them)."""
    fc = raw.get("forecast") if isinstance(raw.get("forecast"), dict) else {}
    atm = raw.get("atmosphere") if isinstance(raw.get("atmosphere"), dict) else {}
    dev = fc.get("isa_dev_c", atm.get("isa_dev_c", 0.0))
    dev = float(dev) if isinstance(dev, (int, float)) and not isinstance(dev, bool) else 0.0
    if fc.get("calm") is True:
        return None, dev
    return _wind_or_none(fc["wind"] if fc.get("wind") is not None else raw.get("wind")), dev


def prepare(raw: dict, source: str = "<scenario>", db=None
            ) -> tuple[Scenario, ProcedureSpec, FlyablePath, Any]:
    """Validate a scenario mapping that has a ``procedure:`` block and build the procedure.

    ``initial`` defaults to the start of the built path (:func:`initial_from_path`) and
    ``duration_s`` to 1.6 × the path length at the planned speed + 120 s (guidance ends the
    flight at the end of the procedure anyway), ``outer_rate_hz`` to :data:`OUTER_RATE_HZ`.

    Returns
    -------
    (scenario, procedure spec, built procedure, database)
    """
    raw = dict(raw)
    if "procedure" not in raw:
        raise ConfigError(f"{source}: a procedure flight needs a 'procedure:' block")
    spec = parse_procedure(raw["procedure"], source)
    if "aircraft" not in raw:
        raise ConfigError(f"{source}: field 'aircraft': missing")
    cfg = load_aircraft(raw["aircraft"])
    if db is None:
        base = Path(source).parent if source and not source.startswith("<") else None
        db = load_db(spec.db, base)
    wind, isa_dev_c = planned_conditions(raw)
    fp = build_procedure(db, spec, cfg, wind=wind, isa_dev_c=isa_dev_c)
    if spec.start == "takeoff":
        check_takeoff(source, fp.seq.proc_type, departure_runway(db, fp.seq), cfg)
    raw.setdefault("initial", initial_from_path(fp, cfg))
    actual = _wind_or_none(raw.get("wind"))
    w_max = max(wind.max_speed_mps if wind else 0.0, actual.max_speed_mps if actual else 0.0)
    v_min = max(cfg.limits.climb_cas_mps - w_max,
                0.5 * cfg.limits.climb_cas_mps)   # into the wind
    # + two full turns: a path rebuilt in flight after a conditional leg may loop back
    r_turn = cfg.limits.climb_cas_mps ** 2 / (G0_MPS2 * math.tan(math.radians(PLANNED_BANK_DEG)))
    raw.setdefault("duration_s", min(6 * 3600.0, (1.6 * fp.path.length_m()
                                                  + 4.0 * math.pi * r_turn) / v_min + 120.0))
    raw.setdefault("name", f"{spec.airport}-{spec.procedure}".lower())
    raw.setdefault("outer_rate_hz", OUTER_RATE_HZ)
    raw["procedure"] = spec.model_dump(exclude_none=True)
    return parse_scenario(raw, source), spec, fp, db


def load_procedure_scenario(path: str | Path):
    """Read a procedure scenario YAML file and :func:`prepare` it."""
    path = Path(path)
    raw = read_mapping(path, "scenario file")
    raw.setdefault("name", path.stem)
    return prepare(raw, str(path))


def prepare_procedure(raw: dict, source: str = "<scenario>", db=None
                      ) -> tuple[Scenario, PreparedProcedure]:
    """:func:`prepare`, returning the scenario and a :class:`PreparedProcedure`."""
    scn, spec, fp, db = prepare(raw, source, db)
    return scn, PreparedProcedure(spec, fp, db)
