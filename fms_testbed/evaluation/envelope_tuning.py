"""Tuning of the coupled law across the envelope: design points → tuned gains → schedule →
checks (margins on every loop, robustness, nonlinear JSBSim steps).

1. every design point is trimmed, linearised and tuned (:func:`.envelope_points.tune_point`);
2. the tuned (T_V, ξ_V, T_H, ξ_H, τ_ny-trim) become the schedule: a table continuous in dynamic
   pressure and mass through every tuned point (:mod:`fms_testbed.control.schedule`);
3. one bank-loop gain set is tuned to the margin goals at every point
   (:func:`.envelope_points.tune_bank_loop`) and its nonlinear bank steps are flown;
4. every point is checked with the *scheduled* gains — the ones the law flies: margins of the six
   broken loops (python-control ``stability_margins`` and ``disk_margins``), the same margins
   under the robustness set (mass ±:data:`ROBUST_MASS_FRAC`, CG ±:data:`ROBUST_CG_M`, an
   actuator delay of :data:`ROBUST_DELAY_S`), the nonlinear altitude and speed steps
   (max|ΔV|, max|ΔH|), and whether the engines can give the altitude step at constant speed
   (:func:`.envelope_points.thrust_margin`: a point where the full-thrust excess power is below
   the step's peak climb rate is ``thrust_limited``: there the speed must pay for the climb).

Points run on a local process pool (``workers``) or through a caller's ``map_jobs`` (the CLI's
Dask cluster); each job is one design point.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

import multiprocessing
import control as ct
import numpy as np
import pandas as pd
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from fms_testbed.config.aircraft import AircraftConfig, load_aircraft
from fms_testbed.config.yamlfile import read_mapping, validation_message
from fms_testbed.control.coupled_law import CoupledLaw, params_from_config
from fms_testbed.control.loops import BREAKS, margins
from fms_testbed.control.schedule import SCHEDULED, GainSchedule, schedule_from_points
from fms_testbed.core.atmosphere import cas_to_tas
from fms_testbed.core.errors import ConfigError, TrimError
from fms_testbed.core.units import SLUG_KG
from fms_testbed.evaluation.envelope_points import (point_loops, thrust_margin, tune_bank_loop,
                                                    tune_point, verify)
from fms_testbed.sim.inner_steps import check_aircraft, replace_gains
from fms_testbed.sim.linearise import DesignPoint, linearise

MASS_FACTORS = (0.9, 1.1)
"""Default grid: masses as fractions of the model's loaded mass."""
APPROACH_ALT_M = 600.0
"""Default grid: altitude of the approach-configuration points, m."""
APPROACH_ADD_CAS_MPS = (0.0, 5.0)
"""Default grid: approach points at Vapp(m) plus these, m/s CAS (the Global 5000 model's
landing flap trims below α −4° from Vapp + 7 m/s)."""
ROBUST_MASS_FRAC = 0.10
"""Robustness set: mass ± this fraction."""
ROBUST_CG_M = 0.20
"""Robustness set: CG ± this, m (about 5 % of a narrow-body's mean aerodynamic chord)."""
ROBUST_DELAY_S = 0.10
"""Robustness set: pure delay added at every actuator, s (inner-loop lag)."""
FIG_OMEGA_RPS = np.logspace(-2.5, 1.7, 300)
"""Frequencies of the Bode and Nichols figures, rad/s."""


def loaded_mass_kg(cfg: AircraftConfig) -> float:
    """The loaded mass of the aircraft ``cfg``'s JSBSim model, kg (its file's fuel and payload)."""
    from fms_testbed.sim.jsbsim_core import JSBSimAircraft

    ac = JSBSimAircraft(cfg)
    ac.fdm.run_ic()
    return float(ac.fdm["inertia/mass-slugs"]) * SLUG_KG


def default_grid(cfg: AircraftConfig) -> list[DesignPoint]:
    """The default grid of aircraft ``cfg``: its envelope points × :data:`MASS_FACTORS` clean,
    plus approach points (landing flap, gear down) at :data:`APPROACH_ALT_M` and Vapp(m) +
    :data:`APPROACH_ADD_CAS_MPS` per mass."""
    m0 = loaded_mass_kg(cfg)
    pts = [DesignPoint(e.alt_m, e.tas_mps, round(f * m0), "clean")
           for e in cfg.envelope for f in MASS_FACTORS]
    if cfg.approach is not None:
        for f in MASS_FACTORS:
            m = round(f * m0)
            for add in APPROACH_ADD_CAS_MPS:
                cas = cfg.approach.vapp_cas_mps_at(m) + add
                pts.append(DesignPoint(APPROACH_ALT_M, round(float(cas_to_tas(cas, APPROACH_ALT_M)), 1),
                                       m, "approach"))
    return pts


class _GridPoint(BaseModel):
    model_config = ConfigDict(extra="forbid")
    alt_m: float = Field(ge=0, le=20000)
    tas_mps: float = Field(gt=30, le=400)
    mass_kg: float | None = Field(None, gt=0)
    config: str = Field("clean", pattern="^(clean|approach)$")


class _Grid(BaseModel):
    model_config = ConfigDict(extra="forbid")
    points: list[_GridPoint] = Field(min_length=1)


def read_grid(path: str | Path) -> list[DesignPoint]:
    """Design points from the YAML file ``path``: ``points: [{alt_m, tas_mps, mass_kg, config}]``.

    Raises
    ------
    ConfigError
        Naming the file and the field of a bad entry.
    """
    raw = read_mapping(Path(path), "grid file")
    try:
        g = _Grid.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(validation_message(str(path), err)) from None
    return [DesignPoint(p.alt_m, p.tas_mps, p.mass_kg, p.config) for p in g.points]


def _aircraft(ref: str) -> AircraftConfig:
    return load_aircraft(ref)


def _tune_job(ref: str, point: DesignPoint) -> dict:
    """Linearise and tune one point (runs in a worker); a failed trim is a row, not a crash."""
    cfg = _aircraft(ref)
    t0 = time.perf_counter()
    try:
        model = linearise(cfg, point)
    except TrimError as exc:
        return {"point": point, "status": f"trim failed: {exc}"}
    res = tune_point(cfg, model, params_from_config(cfg))
    out = {"point": point, "status": "ok" if res.feasible else "hard goals not met",
           "qbar_pa": model.qbar_pa, "mass_kg": model.mass_kg, "engine_lag_s": model.engine_lag_s,
           "n_evals": res.n_evals, "cost_start": res.start.cost, "cost": res.goals.cost,
           "tune_s": time.perf_counter() - t0, "model": model}
    out.update({f"tuned_{n}": getattr(res.params, n) for n in SCHEDULED})
    return out


def _loop_columns(pl, prefix: str = "") -> dict:
    """Margins of every broken loop of ``pl`` as flat columns."""
    row = {}
    for b in BREAKS:
        m = margins(pl.loop(b))
        row.update({f"{prefix}gm_{b}_db": m.gm_db, f"{prefix}pm_{b}_deg": m.pm_deg,
                    f"{prefix}dm_{b}": m.disk_margin, f"{prefix}delay_{b}_s": m.delay_margin_s,
                    f"{prefix}wc_{b}_rps": m.wc_rps})
    return row


def loop_responses(pl, omega_rps: np.ndarray = FIG_OMEGA_RPS) -> dict[str, np.ndarray]:
    """L(jω) of every broken loop of ``pl`` on ``omega_rps`` (rad/s), for the figures."""
    out = {}
    for b in BREAKS:
        fr = ct.frequency_response(pl.loop(b), omega_rps)
        out[b] = np.asarray(fr.complex).ravel()
    return out


def _mins(row: dict, prefix: str = "") -> tuple[float, float, float]:
    gm = min(row[f"{prefix}gm_{b}_db"] for b in BREAKS)
    pm = min(row[f"{prefix}pm_{b}_deg"] for b in BREAKS)
    dm = min(row[f"{prefix}dm_{b}"] for b in BREAKS)
    return gm, pm, dm


def robustness_set(point: DesignPoint, mass_kg: float) -> list[tuple[DesignPoint, float]]:
    """(design point, actuator delay s) of the robustness check around ``point`` at mass
    ``mass_kg`` (kg): :data:`ROBUST_NAMES` in order."""
    f = ROBUST_MASS_FRAC
    return ([(replace(point, mass_kg=mass_kg * (1 + s * f)), 0.0) for s in (-1, 1)]
            + [(replace(point, mass_kg=mass_kg, cg_shift_m=s * ROBUST_CG_M), 0.0) for s in (-1, 1)]
            + [(replace(point, mass_kg=mass_kg), ROBUST_DELAY_S)])


ROBUST_NAMES = ("mass_lo", "mass_hi", "cg_fwd", "cg_aft", "delay")
"""Members of :func:`robustness_set`, in its order (column suffixes)."""


def _robust_columns(cfg, point: DesignPoint, mass_kg: float, law_at, nominal) -> dict:
    """Smallest margins of each member of :func:`robustness_set` (each re-trimmed and
    linearised; the delay member on the nominal model) and over the set."""
    row = {}
    for name, (pt, delay) in zip(ROBUST_NAMES, robustness_set(point, mass_kg)):
        try:
            model = nominal if delay else linearise(cfg, pt)
        except TrimError:
            row[f"robust_pm_{name}_deg"] = math.nan
            continue
        gm, pm, dm = _mins(_loop_columns(point_loops(cfg, model, law_at(model), delay_s=delay)))
        row.update({f"robust_gm_{name}_db": gm, f"robust_pm_{name}_deg": pm,
                    f"robust_dm_{name}": dm})
    for key, col in (("gm", "robust_gm_min_db"), ("pm", "robust_pm_min_deg"),
                     ("dm", "robust_disk_margin")):
        vals = [v for k, v in row.items() if k.startswith(f"robust_{key}_") and
                math.isfinite(v)]
        row[col] = min(vals, default=math.nan)
    return row


def _check_job(ref: str, point: DesignPoint, schedule: GainSchedule, robust: bool,
               duration_s: float, bank=None) -> tuple[dict, dict]:
    """Margins, robustness and the nonlinear steps with the scheduled gains (and the bank-loop
    gains ``bank`` when given) at one point; returns (row, figure data: loop responses and the
    step runs)."""
    cfg = _aircraft(ref)
    if bank is not None:
        cfg = replace_gains(cfg, "bank", bank)
    t0 = time.perf_counter()
    base = params_from_config(cfg)

    def law_at(model):
        return replace(base, **schedule.values(model.qbar_pa, model.mass_kg))

    try:
        model = linearise(cfg, point)
    except TrimError as exc:
        return {"status": f"trim failed: {exc}"}, {}
    row = {f"sched_{k}": v for k, v in schedule.values(model.qbar_pa, model.mass_kg).items()}
    pl = point_loops(cfg, model, law_at(model))
    row.update(_loop_columns(pl))
    row.update(thrust_margin(cfg, point, pl))
    row["gm_min_db"], row["pm_min_deg"], row["disk_margin"] = _mins(row)
    if robust:
        row.update(_robust_columns(cfg, point, model.mass_kg, law_at, model))
    chk = verify(cfg, point, lambda: CoupledLaw(params=base, schedule=schedule), duration_s)
    old = verify(cfg, point, lambda: CoupledLaw(params=base), duration_s)
    row.update(max_dv_kmh=chk.max_dv_kmh, max_dh_m=chk.max_dh_m, old_max_dv_kmh=old.max_dv_kmh,
               old_max_dh_m=old.max_dh_m, check_s=time.perf_counter() - t0)
    return row, {"freq": loop_responses(pl), "runs": {"new": chk.runs, "old": old.runs}}


@dataclass
class EnvelopeResult:
    """Outcome of :func:`tune_envelope`: one row per design point, the schedule, timings (s),
    and per point label the figure data (:func:`loop_responses`, the step runs)."""

    points: pd.DataFrame
    schedule: GainSchedule
    tune_wall_s: float
    check_wall_s: float
    workers: int
    figures: dict
    bank: object = None
    bank_slack: tuple = ()
    bank_steps: list = ()


def _pool_map(fn, jobs: list[tuple], workers: int) -> list:
    if workers <= 1:
        return [fn(*j) for j in jobs]
    ctx = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as ex:
        futs = [ex.submit(fn, *j) for j in jobs]
        return [f.result() for f in futs]


def tune_envelope(cfg: AircraftConfig, points: list[DesignPoint], workers: int = 2,
                  robust: bool = True, duration_s: float = 90.0,
                  map_jobs: Callable | None = None) -> EnvelopeResult:
    """Tune every point, fit the schedule, check every point with it (module docstring).

    Parameters
    ----------
    cfg : aircraft (loaded by name or file in the workers);  points : the design points
    workers : local processes;  robust : run the robustness set
    duration_s : length of each nonlinear step run, s
    map_jobs : ``map_jobs(fn, jobs) -> [fn(*job) for job in jobs]`` in the jobs' order, run
        elsewhere (e.g. on a Dask cluster); None: a local pool of ``workers`` processes. ``fn``
        is a module-level function and every job's arguments are picklable

    Raises
    ------
    ConfigError
        When fewer than three points trim (no schedule can be fitted).
    """
    ref = cfg.source_file or cfg.name
    run = map_jobs or (lambda fn, jobs: _pool_map(fn, jobs, workers))
    t0 = time.perf_counter()
    tuned = run(_tune_job, [(ref, p) for p in points])
    t1 = time.perf_counter()
    ok = [r for r in tuned if "qbar_pa" in r]
    models = [r.pop("model") for r in ok]
    if len(ok) < 3:
        raise ConfigError(f"{cfg.name}: only {len(ok)} design points trimmed; a schedule "
                          "needs at least 3")
    sched = schedule_from_points([{"qbar_pa": r["qbar_pa"], "mass_kg": r["mass_kg"],
                                   **{n: r[f"tuned_{n}"] for n in SCHEDULED}} for r in ok])
    bank, before, after = tune_bank_loop(cfg, models)
    checks = run(_check_job, [(ref, r["point"], sched, robust, duration_s, bank)
                              for r in tuned if "qbar_pa" in r])
    steps = [r for r in check_aircraft(replace_gains(cfg, "bank", bank)) if r.spec.loop == "bank"]
    t2 = time.perf_counter()
    rows, figs, it = [], {}, iter(checks)
    for r in tuned:
        p = r.pop("point")
        base = {"alt_m": p.alt_m, "tas_mps": p.tas_mps, "mass_kg": p.mass_kg,
                "config": p.config}
        base.update(r)
        if "qbar_pa" in r:
            c, fig = next(it)
            if c.get("status", "ok") != "ok":
                base["status"] = c["status"]
            base.update({k: v for k, v in c.items() if k != "status"})
            if fig:
                figs[p.label()] = fig
        rows.append(base)
    return EnvelopeResult(pd.DataFrame(rows), sched, t1 - t0, t2 - t1, workers, figs, bank,
                          (before, after), steps)


POINT_COLUMNS = ("alt_m", "tas_mps", "mass_kg", "config", "gm_min_db", "pm_min_deg",
                 "disk_margin", "max_dv_kmh", "max_dh_m")
"""The leading columns of ``points.csv`` (the per-loop margins and the rest follow)."""


def points_table(res: EnvelopeResult) -> pd.DataFrame:
    """``points.csv``: :data:`POINT_COLUMNS` first, then every other column."""
    df = res.points
    for c in POINT_COLUMNS:
        if c not in df:
            df[c] = math.nan
    return df[list(POINT_COLUMNS) + [c for c in df.columns if c not in POINT_COLUMNS]]


def schedule_block(s: GainSchedule) -> dict:
    """The ``coupled_law_schedule`` block of an aircraft file (plain YAML types)."""
    return {"points": s.table()}


def aircraft_with_schedule(cfg: AircraftConfig, s: GainSchedule, bank=None) -> str:
    """The text of aircraft ``cfg``'s file with its ``coupled_law_schedule`` block replaced by
    the schedule ``s`` (appended when it has none) and, when ``bank`` (PID gains) is given, its
    ``inner_loops.bank`` line replaced."""
    import re

    src = Path(cfg.source_file).read_text()
    if bank is not None:
        line = f"  bank: {{kp: {bank.kp:g}, ki: {bank.ki:g}, kd: {bank.kd:g}}}"
        src, n = re.subn(r"(?m)^  bank: \{[^}]*\}", line, src, count=1)
        if n != 1:
            raise ConfigError(f"{cfg.source_file}: no one-line 'bank: {{...}}' under inner_loops")
    lines, out, skip = src.splitlines(), [], False
    for ln in lines:
        if ln.startswith("coupled_law_schedule:"):
            skip = True
            continue
        if skip and (ln.startswith((" ", "\t")) or not ln.strip()):
            continue
        skip = False
        out.append(ln)
    block = yaml.safe_dump({"coupled_law_schedule": schedule_block(s)}, sort_keys=False,
                           default_flow_style=None, width=100)
    return "\n".join(out).rstrip("\n") + "\n" + block
