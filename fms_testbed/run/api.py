"""One run path for every scenario: :func:`run_scenario` flies a scenario file, a mapping or a
validated :class:`~fms_testbed.config.scenario.Scenario`, with or without a ``procedure:`` block,
and returns :class:`~fms_testbed.run.results.Results`. The CLI's ``run``, ``fly`` and ``demo`` use
it, so a scenario flies the same from Python and from the command line.
"""

from __future__ import annotations

from pathlib import Path

from fms_testbed.config.aircraft import AircraftConfig
from fms_testbed.config.scenario import Scenario, parse_scenario
from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.core.contracts import Guidance, record_dict
from fms_testbed.core.errors import UserError
from fms_testbed.core.planning import PROC_TYPE_NAMES
from fms_testbed.core.units import NM_M
from fms_testbed.evaluation.flight_errors import error_columns, flight_errors
from fms_testbed.evaluation.outcome import DEFAULT_ENROUTE_RNP_NM, decide
from fms_testbed.loop.flight import Flight
from fms_testbed.loop.procedure import PreparedProcedure, prepare_procedure
from fms_testbed.navigation.attitude_reference import attitude_reference_summary
from fms_testbed.navigation.monitor import monitor_flight
from fms_testbed.run.results import Results
from fms_testbed.run.summary import ProcedureInfo, assemble


def with_truth_model(nav: dict | None, truth_model: str, where: str) -> dict:
    """The navigation block ``nav`` with ``truth_model`` set (``strapdown`` or ``linear``).

    Parameters
    ----------
    nav : a scenario's ``navigation:`` mapping (None: truth navigation)
    truth_model : the INS units' truth side
    where : the scenario's name for the error line

    Raises
    ------
    UserError : the block names no source with INS units
    """
    if not nav or nav.get("source", "truth") == "truth":
        raise UserError(f"{where}: --truth-model needs a navigation source with INS units "
                        "(--nav sins|ins_gnss|attitude_reference, or the scenario's)")
    return {**nav, "truth_model": truth_model}


def load(scenario, overrides: dict | None = None) -> tuple[Scenario, PreparedProcedure | None]:
    """Validate a scenario (path, mapping or :class:`Scenario`) and build its procedure.

    Parameters
    ----------
    scenario : path to a YAML file, a mapping, or a validated :class:`Scenario`
    overrides : keys merged into the scenario before validation; each top-level key replaces
        the scenario's (``wind``, ``navigation``, ``aircraft``, ...), except ``procedure``, whose
        keys are merged into the scenario's ``procedure:`` block (e.g. ``{"rnp_nm": 0.3}``)

    Returns
    -------
    (scenario, prepared procedure or None)
    """
    overrides = dict(overrides or {})
    if isinstance(scenario, Scenario):
        source = scenario.source_file or "<scenario>"
        raw = scenario.model_dump(exclude_none=True)
    elif isinstance(scenario, dict):
        source, raw = "<scenario>", dict(scenario)
    else:
        path = Path(scenario)
        source = str(path)
        raw = read_mapping(path, "scenario file")
        raw.setdefault("name", path.stem)
    proc_over = overrides.pop("procedure", None)
    truth_model = overrides.pop("navigation_truth_model", None)
    if proc_over is not None:
        if isinstance(raw.get("procedure"), dict):
            raw["procedure"] = {**raw["procedure"], **proc_over}
        elif set(proc_over) <= {"rnp_nm", "allow_degraded"}:   # on a flight without a procedure
            if "rnp_nm" in proc_over:
                raw["rnp_nm"] = proc_over["rnp_nm"]
        else:
            raise UserError(f"{source}: procedure options need a scenario with a 'procedure:' "
                            "block")
    raw.update(overrides)
    if truth_model is not None:
        raw["navigation"] = with_truth_model(raw.get("navigation"), truth_model, source)
    raw.pop("source_file", None)
    _relative_to(raw, source)
    if raw.get("procedure") is not None:
        return prepare_procedure(raw, source)
    raw.pop("procedure", None)
    return parse_scenario(raw, source), None


def _relative_to(raw: dict, source: str) -> None:
    """Relative file paths in a scenario file (aircraft YAML, IMU YAML) are relative to the
    scenario's folder, not to the current one (``procedure.db`` is resolved the same way by
    :func:`fms_testbed.path.plan.load_db`)."""
    if source.startswith("<"):
        return
    base = Path(source).parent

    def fix(v):
        if isinstance(v, str) and Path(v).suffix in (".yaml", ".yml") and not Path(v).is_absolute():
            return str(base / v)
        return v

    if "aircraft" in raw:
        raw["aircraft"] = fix(raw["aircraft"])
    nav = raw.get("navigation")
    if isinstance(nav, dict) and "imu" in nav:
        raw["navigation"] = {**nav, "imu": fix(nav["imu"])}


def _procedure_info(scn: Scenario, proc: PreparedProcedure) -> ProcedureInfo:
    p = proc.path.path
    return ProcedureInfo(
        p.name, p.airport, PROC_TYPE_NAMES.get(p.proc_type), p.proc_id, p.transition,
        p.start_kind, p.leg_types(), round(p.length_m() / NM_M, 2), p.status,
        scn.navigation_spec["source"],
        [f"leg {f.leg_index + 1}: {f.category}: {f.message}" for f in p.findings],
        list(proc.path.degraded))


def results_of(flight: Flight) -> Results:
    """The :class:`Results` of a (finished or stopped) :class:`Flight`: its timeseries and summary,
    and for a procedure flight the errors, RNP containment, constraints and sequencing."""
    df, record = flight.result()
    proc, g = flight.procedure, flight.guidance
    blocks: dict = {}
    rebuilt: list = []
    rnp_nm = None
    if proc is not None:
        blocks["procedure"] = _procedure_info(flight.scn, proc)
        pe = flight_errors(df, proc.path, g.seq.legs_sequenced, g.done and not g.abort_reason,
                           g.vnav.floor_m)
        blocks.update(errors=pe.errors, rnp=pe.rnp, constraints=pe.constraints,
                      constraints_met=pe.constraints_met, sequencing=pe.sequencing)
        if proc.path.path.proc_type == "F":            # approaches: the threshold crossing
            from fms_testbed.evaluation.threshold import threshold_crossing
            blocks["threshold"] = threshold_crossing(df, proc.path.path, proc.runway,
                                                     g.vnav.speed.vapp_cas_mps,
                                                     flight.cfg.approach)
        blocks["guidance_events"] = g.events
        if "xtk_m" in df:
            df = error_columns(df)
        rebuilt = list(g.replan.rebuilt)
    else:
        scn = flight.scn
        rnp_nm = scn.rnp_nm if scn.rnp_nm is not None else (
            DEFAULT_ENROUTE_RNP_NM if scn.navigation_spec["source"] != "truth" else None)
    df, blocks["navigation"] = monitor_flight(df, flight.navigation,
                                              None if rnp_nm is None else rnp_nm * NM_M)
    blocks["attitude_reference"] = attitude_reference_summary(df)   # flight-test mode
    so_far = {**record_dict(record), **record_dict({k: v for k, v in blocks.items()
                                                     if v is not None})}
    decision = decide(so_far, df, flight.cfg, rnp_nm)
    rec = getattr(flight.navigation, "recorder", None)     # navigation.record_sensors
    return Results(df=df, summary=assemble(record, decision, **blocks), scenario=flight.scn,
                   procedure=proc, flown_paths=rebuilt,
                   sensors=rec.tables() if rec is not None else None)


def run_scenario(scenario, out_dir: str | Path | None = None, seed: int | None = None,
                 overrides: dict | None = None, csv: bool = False, plots: bool = True,
                 progress: bool | None = None, guidance: Guidance | None = None,
                 aircraft_config: AircraftConfig | None = None, vertical_law=None) -> Results:
    """Fly a scenario and optionally write its outputs.

    Parameters
    ----------
    scenario : path to a YAML file, a mapping, or a validated :class:`Scenario`; a scenario with
        a ``procedure:`` block is a procedure flight (built from the database it names)
    out_dir : folder for ``timeseries.parquet``, ``summary.json`` and plots (None: write nothing)
    seed : seed for turbulence and navigation errors (default 0); ``navigation.seed`` in the
        scenario, when given, seeds the navigation errors instead
    overrides : top-level scenario keys merged in before validation
    csv, plots : also write ``timeseries.csv`` / the PNG plots (with ``out_dir``)
    progress : progress bar (default: on a terminal, for runs longer than 2 s)
    guidance : a path guidance to fly instead of the scenario's procedure
    aircraft_config : an :class:`AircraftConfig` replacing the scenario's aircraft (tuning)
    vertical_law : a ready vertical-law instance replacing the scenario's ``vertical_law``

    Returns
    -------
    :class:`Results` (``.df``, ``.summary``, ``.plot()``, ``.save(dir)``)
    """
    if aircraft_config is not None and not isinstance(aircraft_config, AircraftConfig):
        raise UserError("aircraft_config must be an AircraftConfig")
    scn, proc = load(scenario, overrides)
    flight = Flight(scn, cfg=aircraft_config, seed=seed, guidance=guidance, progress=progress,
                    vertical_law=vertical_law, procedure=None if guidance is not None else proc)
    flight.run()
    res = results_of(flight)
    if out_dir is not None:
        res.save(out_dir, csv=csv, plots=plots)
    return res


def fly_procedure(scn: Scenario, spec, fp, db, out_dir: str | Path | None = None,
                  seed: int | None = None, plots: bool = True, csv: bool = False,
                  progress: bool | None = None) -> Results:
    """Fly an already built procedure; the same as :func:`run_scenario` on its scenario,
    without building it again.

    Parameters
    ----------
    scn, spec, fp, db : :func:`fms_testbed.loop.procedure.prepare`'s results
    out_dir, seed, plots, csv, progress : :func:`run_scenario`'s
    """
    flight = Flight(scn, seed=seed, progress=progress, procedure=PreparedProcedure(spec, fp, db))
    flight.run()
    res = results_of(flight)
    if out_dir is not None:
        res.save(out_dir, csv=csv, plots=plots)
    return res
__all__ = ["fly_procedure", "load", "results_of", "run_scenario"]
