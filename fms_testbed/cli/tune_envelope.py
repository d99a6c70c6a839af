"""``fms-testbed tune --envelope``: the coupled law tuned over a grid of design points into a gain
schedule, checked on every loop and in the nonlinear JSBSim loop; and ``analyse --plant jsbsim``.

Outputs of ``tune --envelope`` in the run folder: ``points.csv`` (one row per design point:
alt_m, tas_mps, mass_kg, config, gm_min_db, pm_min_deg, disk_margin, max_dv_kmh, max_dh_m, then
the per-loop margins, the tuned and scheduled gains, the robustness minima and the old gains'
nonlinear deviations), ``schedule.yaml``, ``aircraft.yaml`` (the aircraft file with the schedule:
``--aircraft FILE`` for every command), ``report.md`` and the figures ``nichols.png``,
``bode-worst.png``, ``steps.png``, ``schedule.png``, and ``bode/<point>.png`` (one Bode figure
per design point, margins marked).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from fms_testbed.cli.common import markdown_table
from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.errors import UserError
from fms_testbed.run.outputs import OutputFolder

GOAL_DV_KMH = 1.0
"""Goal: nonlinear max|ΔV| in the altitude step, km/h."""
GOAL_DH_M = 1.5
"""Goal: nonlinear max|ΔH| in the speed step, m."""
FIGURES = ("nichols.png", "bode-worst.png", "steps.png", "schedule.png")
CAMPAIGN_TYPES = "STAR,APPROACH"
"""Procedure types of the campaign check (descending profiles carry the vertical path error)."""


def _fly(aircraft: str, cond: Path, out: Path, airports, limit, types: str, workers: int,
         scheduler: str | None) -> pd.DataFrame:
    """One ``regress run`` of the campaign check (truth navigation); its flights table."""
    from fms_testbed.campaign.cases import parse_types
    from fms_testbed.campaign.conditions import read_conditions
    from fms_testbed.campaign.runner import RunConfig, run_campaign

    run_campaign(RunConfig(out=out, conditions=read_conditions(cond), airports=airports,
                           types=parse_types(types), aircraft=[aircraft], limit=limit,
                           workers=workers, scheduler=scheduler, progress=False,
                           command=["tune", "--verify-campaign", aircraft], overwrite=True))
    return pd.read_parquet(out / "flights")


def campaign_check(old_ref: str, new_ref: str, out: Path, airports=None, limit=None,
                   types: str = CAMPAIGN_TYPES, workers: int = 2, wind: str = "270/30",
                   turbulence: str = "moderate", scheduler: str | None = None):
    """Fly the same procedure sample with aircraft ``old_ref`` (file gains) and ``new_ref``
    (tuned file) in a steady wind ``wind`` (FROM_DEG/SPEED_KT) and ``turbulence``, into
    ``out/old`` and ``out/new``; write ``out/campaign-shift.md`` and ``campaign-shift.png``
    (:mod:`fms_testbed.evaluation.campaign_shift`). Returns (the shift, its Markdown).

    Parameters
    ----------
    airports : ICAO idents (None: every airport of the embedded excerpt);  limit : first N cases
    types : procedure types;  workers : local processes;  scheduler : Dask address instead
    """
    from fms_testbed.cli.common import parse_wind
    from fms_testbed.evaluation.campaign_shift import (METRICS, campaign_shift, conditions_yaml,
                                                       shift_markdown)
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.tuning import plot_campaign_shift

    w = parse_wind(wind)
    out.mkdir(parents=True, exist_ok=True)
    cond = out / "conditions.yaml"
    cond.write_text(conditions_yaml(w, turbulence))
    s = campaign_shift(_fly(old_ref, cond, out / "old", airports, limit, types, workers, scheduler),
                       _fly(new_ref, cond, out / "new", airports, limit, types, workers, scheduler))
    md = shift_markdown(s, old_ref, new_ref, wind, turbulence,
                        markdown_table(s.table.reset_index()))
    (out / "campaign-shift.md").write_text(md)
    save(plot_campaign_shift(s.runs, METRICS, f"{old_ref}: file gains vs tuned schedule, wind "
                             f"{wind} kt, {turbulence} turbulence ({s.n_pairs} paired flights)"),
         out / "campaign-shift.png")
    return s, md


class DaskJobs:
    """``map_jobs`` of :func:`~fms_testbed.evaluation.envelope_tuning.tune_envelope` on the
    dask.distributed cluster at ``address`` (``tcp://HOST:PORT``), connected through the
    regression's code (:mod:`fms_testbed.campaign.executors`): its workers must run one thread
    each (JSBSim is one instance per process). ``workers`` is the cluster's worker count;
    :meth:`close` closes the client."""

    def __init__(self, address: str):
        from fms_testbed.campaign.executors import _connect, parse_scheduler

        parse_scheduler(address)
        self.address = address
        self.client = _connect(address)
        threads = self.client.nthreads()
        multi = sorted(w for w, n in threads.items() if n != 1)
        if not threads or multi:
            self.client.close()
            raise UserError(f"--scheduler {address}: " + (
                "the cluster has no workers" if not threads else
                f"workers {', '.join(multi[:3])} run {threads[multi[0]]} threads; start them "
                "with --nthreads 1 (JSBSim is one instance per process)"))
        self.workers = len(threads)

    def __call__(self, fn, jobs: list[tuple]) -> list:
        """``[fn(*job) for job in jobs]`` on the cluster, in the jobs' order."""
        futs = [self.client.submit(fn, *j, pure=False) for j in jobs]
        return self.client.gather(futs)

    def close(self) -> None:
        """Close the client."""
        self.client.close()


def goal_lines(df: pd.DataFrame) -> list[tuple[bool, str]]:
    """(met, text) of the envelope goals over every trimmed point of ``df`` (``points.csv``)."""
    from fms_testbed.evaluation.envelope_points import GM_MIN_DB, PM_MIN_DEG

    ok = df[df["gm_min_db"].notna()]
    lim = ok[ok.thrust_limited.astype(bool)] if "thrust_limited" in ok else ok.iloc[:0]
    fly = ok.drop(index=lim.index)
    out = [(bool((ok.gm_min_db >= GM_MIN_DB).all()),
            f"GM ≥ {GM_MIN_DB:g} dB on every loop at every point: min {ok.gm_min_db.min():.1f} dB"),
           (bool((ok.pm_min_deg >= PM_MIN_DEG).all()),
            f"PM ≥ {PM_MIN_DEG:g}° on every loop at every point: min {ok.pm_min_deg.min():.1f}°"),
           (bool((fly.max_dv_kmh <= GOAL_DV_KMH).all()),
            f"nonlinear max|ΔV| in the altitude step ≤ {GOAL_DV_KMH:g} km/h at the {len(fly)} "
            f"points with the thrust for it: max {fly.max_dv_kmh.max():.2f} km/h (file gains "
            f"{fly.old_max_dv_kmh.max():.2f})" + _thrust_limited_text(lim)),
           (bool((ok.max_dh_m <= GOAL_DH_M).all()),
            f"nonlinear max|ΔH| in the speed step ≤ {GOAL_DH_M:g} m: max {ok.max_dh_m.max():.2f} m "
            f"(file gains {ok.old_max_dh_m.max():.2f})"),
           (len(ok) == len(df), f"{len(ok)} of {len(df)} design points trimmed")]
    if "robust_pm_min_deg" in ok:
        out.append((bool((ok.robust_gm_min_db >= GM_MIN_DB).all()
                         and (ok.robust_pm_min_deg >= PM_MIN_DEG).all()),
                    f"robustness set: min GM {ok.robust_gm_min_db.min():.1f} dB, min PM "
                    f"{ok.robust_pm_min_deg.min():.1f}°, min disk margin "
                    f"{ok.robust_disk_margin.min():.2f}"))
    return out


def _thrust_limited_text(lim: pd.DataFrame) -> str:
    """The thrust-limited points of a goal line: the step's need against the engines."""
    if not len(lim):
        return ""
    return ("; thrust-limited (full-thrust excess power below the step's peak climb rate, "
            "the speed pays for the climb): " + "; ".join(
                f"{r.alt_m:.0f} m {r.tas_mps:.0f} m/s {r.mass_kg / 1000:.1f} t: P_s,max "
                f"{r.ps_max_mps:.2f} m/s < {r.ps_step_mps:.2f} m/s, energy balance ΔV "
                f"{r.dv_energy_kmh:.2f} km/h, flown {r.max_dv_kmh:.2f} km/h"
                for r in lim.itertuples()))


def _schedule_curves(res) -> dict[str, pd.DataFrame]:
    """The schedule evaluated along q̄ at each design mass (figure data)."""
    from fms_testbed.control.schedule import SCHEDULED

    df = res.points[res.points["qbar_pa"].notna()]
    q = np.linspace(df.qbar_pa.min() * 0.9, df.qbar_pa.max() * 1.1, 60)
    masses = sorted({round(m, -2) for m in df.mass_kg})
    rows = [{"qbar_pa": qq, "mass_kg": m, **res.schedule.values(qq, m)} for m in masses for qq in q]
    tab = pd.DataFrame(rows)
    return {k: tab[["qbar_pa", "mass_kg", k]].rename(columns={k: "value"})
            for k in SCHEDULED}


def bode_file(label: str) -> str:
    """File name of the Bode figure of the design point labelled ``label``
    (:meth:`~fms_testbed.sim.linearise.DesignPoint.label`)."""
    return "-".join(label.replace("/", "p").replace(".", "_").split()) + ".png"


def _loop_margins(row) -> pd.DataFrame:
    """Per broken loop: GM (dB), PM (deg), crossover (rad/s) of one ``points.csv`` row."""
    from fms_testbed.control.loops import BREAKS

    return pd.DataFrame([{"loop": b, "gm_db": row[f"gm_{b}_db"], "pm_deg": row[f"pm_{b}_deg"],
                          "wc_rps": row[f"wc_{b}_rps"]} for b in BREAKS])


def write_figures(res, name: str, tmp: Path) -> None:
    """Write into ``tmp`` the figures of ``res`` for aircraft ``name``: Nichols (all points),
    Bode at the smallest-PM point and at every point (``bode/``, :func:`bode_file`), steps at
    the worst points, the schedule."""
    from fms_testbed.evaluation.envelope_tuning import FIG_OMEGA_RPS
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.tuning import plot_bode_margins, plot_nichols, plot_schedule, plot_steps

    df = res.points[res.points["gm_min_db"].notna()].copy()
    df["label"] = [lab for lab in res.figures]
    freq = {lab: f["freq"] for lab, f in res.figures.items()}
    save(plot_nichols(freq, f"{name}: loops broken at six signals, {len(freq)} design points, "
                      f"scheduled gains\nsmallest GM {df.gm_min_db.min():.1f} dB, smallest PM "
                      f"{df.pm_min_deg.min():.1f}°"), tmp / "nichols.png")
    w = df.loc[df.pm_min_deg.idxmin()]
    save(plot_bode_margins(FIG_OMEGA_RPS, res.figures[w.label]["freq"], _loop_margins(w),
                           f"{name} at {w.label} (smallest phase margin of the grid): "
                           f"{w.pm_min_deg:.1f}°"), tmp / "bode-worst.png")
    (tmp / "bode").mkdir(exist_ok=True)
    for _, r in df.iterrows():          # one Bode figure per design point
        save(plot_bode_margins(FIG_OMEGA_RPS, res.figures[r.label]["freq"], _loop_margins(r),
                               f"{name} at {r.label}, scheduled gains: smallest GM "
                               f"{r.gm_min_db:.1f} dB, PM {r.pm_min_deg:.1f}°, disk margin "
                               f"{r.disk_margin:.2f}"), tmp / "bode" / bode_file(r.label))
    picks = {df.loc[df.max_dv_kmh.idxmax(), "label"], df.loc[df.max_dh_m.idxmax(), "label"]}
    save(plot_steps({lab: res.figures[lab]["runs"] for lab in picks},
                    f"{name}: nonlinear JSBSim steps at the points with the largest cross "
                    f"deviations\nmax|ΔV| {df.max_dv_kmh.max():.2f} km/h, max|ΔH| "
                    f"{df.max_dh_m.max():.2f} m (schedule)"), tmp / "steps.png")
    save(plot_schedule(df, _schedule_curves(res), f"{name}: tuned gains at the design points "
                       "and the schedule (piecewise linear in ln q̄, linear in mass)"),
         tmp / "schedule.png")


def _report(cfg, res, goals, args, points_md: str, campaign_md: str = "") -> str:
    load = os.getloadavg()
    terms = markdown_table(pd.DataFrame(res.schedule.table()))
    gl = "\n".join(f"- {'PASS' if ok else 'FAIL'}: {t}" for ok, t in goals)
    b0 = cfg.inner_loops.bank
    bank = (f"Bank loop (one gain set for the grid): file kp {b0.kp:g}, kd {b0.kd:g} → kp "
            f"{res.bank.kp:g}, kd {res.bank.kd:g}; smallest scaled slack of its GM/PM goals "
            f"{res.bank_slack[0]:.3f} → {res.bank_slack[1]:.3f} (against the goals plus the "
            "tuner's buffers 1 dB / 5°; ≥ 0: buffers kept). Nonlinear bank "
            "steps at the default condition: " + ", ".join(
                f"{math.degrees(r.spec.amplitude):.0f}° settles {r.settle_s:.1f} s "
                f"(spec {r.spec.settle_max_s:g}), overshoot {r.overshoot_pct:.1f} % "
                f"(spec {r.spec.overshoot_max_pct:g})" for r in res.bank_steps))
    figs = "\n".join(f"![{f}]({f})" for f in FIGURES)
    labels = list(res.figures)
    figs += ("\n\nBode of every broken loop at each design point (scheduled gains; the "
             "crossover frequencies dotted, GM/PM in the legend):\n\n"
             + "\n".join(f"![{lab}](bode/{bode_file(lab)})" for lab in labels))
    return (f"# Envelope tuning of the coupled law — {cfg.name}\n\n"
            f"Command: `fms-testbed tune --aircraft {args.aircraft} --envelope"
            f"{' --grid ' + args.grid if args.grid else ''} --workers {args.workers}`\n\n"
            f"{len(res.points)} design points; tuned on JSBSim's linearisations (SLSQP, hard "
            "goals as constraints), schedule fitted in (q̄, mass), every point checked with the "
            "scheduled gains on six broken loops and in the nonlinear JSBSim loop "
            "(+100 m and +10 % TAS steps).\n\n"
            f"Wall time: tuning {res.tune_wall_s:.0f} s, checks {res.check_wall_s:.0f} s on "
            f"{res.workers} workers (load average at the end {load[0]:.1f} / {load[1]:.1f} / "
            f"{load[2]:.1f}, {os.cpu_count()} cores).\n\n## Goals\n\n{gl}\n\n{bank}\n\n"
            "## Schedule\n\n"
            "Piecewise linear in ln q̄ per mass level, linear in mass between levels:\n\n"
            f"{terms}\n\n"
            f"## Points\n\n{points_md}\n\n## Figures\n\n{figs}\n"
            + (f"\n## Campaign check\n\nThe same procedure sample flown with the file gains "
               "and with this folder's `aircraft.yaml` (flights in `campaign/old`, "
               f"`campaign/new`):\n\n{campaign_md}\n![campaign shift](campaign/campaign-shift.png)\n"
               if campaign_md else ""))


def _check_options(args) -> None:
    """Options that fail before any tuning: workers, the scheduler's address, the campaign's
    wind and types."""
    if args.workers < 1:
        raise UserError("tune --envelope: --workers must be at least 1")
    if args.scheduler:
        from fms_testbed.campaign.executors import parse_scheduler

        parse_scheduler(args.scheduler)
    if args.verify_campaign:
        from fms_testbed.campaign.cases import parse_types
        from fms_testbed.cli.common import parse_wind

        parse_wind(args.campaign_wind)
        parse_types(args.campaign_types)


def _campaign(args, tmp: Path) -> tuple[list, str]:
    """``--verify-campaign``: the campaign check into ``tmp/campaign``; (goal lines, Markdown)."""
    from fms_testbed.evaluation.campaign_shift import goal_lines as campaign_goals

    print(f"campaign check: {args.aircraft} and the tuned aircraft.yaml, wind "
          f"{args.campaign_wind} kt, {args.campaign_turbulence} turbulence")
    shift, md = campaign_check(args.aircraft, str(tmp / "aircraft.yaml"), tmp / "campaign",
                               args.airports, args.campaign_limit, args.campaign_types,
                               args.workers, args.campaign_wind, args.campaign_turbulence,
                               args.scheduler)
    print(md)
    return campaign_goals(shift), md


def cmd_tune_envelope(args) -> int:
    """Tune over the grid, fit the schedule, check; write the run folder (module docstring)."""
    from fms_testbed.cli.coupled import _out_dir
    from fms_testbed.evaluation.envelope_tuning import default_grid, read_grid

    cfg = load_aircraft(args.aircraft)
    _check_options(args)
    points = read_grid(args.grid) if args.grid else default_grid(cfg)
    jobs = DaskJobs(args.scheduler) if args.scheduler else None
    try:
        if jobs is not None:
            args.workers = jobs.workers
        folder = OutputFolder(_out_dir(args.out, f"tune-envelope-{cfg.name}"),
                              getattr(args, "overwrite", False))
        rc = _tune_into(folder, cfg, points, args, jobs)
    finally:
        if jobs is not None:
            jobs.close()
    return rc


def _tune_into(folder: OutputFolder, cfg, points, args, jobs) -> int:
    """Tune, check and write the run folder ``folder``; the exit status (1: a goal failed)."""
    from fms_testbed.evaluation.envelope_tuning import (aircraft_with_schedule, points_table,
                                                        schedule_block, tune_envelope)

    tmp = folder.open()
    where = f"Dask workers at {args.scheduler}" if jobs is not None else "workers"
    print(f"tuning {cfg.name} at {len(points)} design points on {args.workers} {where}")
    res = tune_envelope(cfg, points, workers=args.workers, robust=not args.no_robust,
                        map_jobs=jobs)
    table = points_table(res)
    table.to_csv(tmp / "points.csv", index=False)
    (tmp / "schedule.yaml").write_text(yaml.safe_dump(
        {"coupled_law_schedule": schedule_block(res.schedule)}, sort_keys=False))
    (tmp / "aircraft.yaml").write_text(aircraft_with_schedule(cfg, res.schedule, res.bank))
    goals = goal_lines(table)
    show = [c for c in ("alt_m", "tas_mps", "mass_kg", "config", "status", "gm_min_db",
                        "pm_min_deg", "disk_margin", "max_dv_kmh", "max_dh_m", "old_max_dv_kmh",
                        "old_max_dh_m", "ps_max_mps", "ps_step_mps", "robust_pm_min_deg")
            if c in table]
    md = markdown_table(table[show])
    write_figures(res, cfg.name, tmp)
    campaign = ""
    if args.verify_campaign:
        more, campaign = _campaign(args, tmp)
        goals += more
    (tmp / "report.md").write_text(_report(cfg, res, goals, args, md, campaign))
    print(md)
    print("\nGoals:\n" + "\n".join(f"- {'PASS' if ok else 'FAIL'}: {t}" for ok, t in goals))
    print(f"\nbank loop: kp {res.bank.kp:g}, kd {res.bank.kd:g} (file {cfg.inner_loops.bank.kp:g}, "
          f"{cfg.inner_loops.bank.kd:g}); goal slack {res.bank_slack[0]:.3f} → "
          f"{res.bank_slack[1]:.3f}")
    print(f"wall time: tuning {res.tune_wall_s:.0f} s, checks {res.check_wall_s:.0f} s")
    print(f"written to {folder.out}/ (points.csv, schedule.yaml, aircraft.yaml, report.md, "
          f"{', '.join(FIGURES)})")
    folder.commit()
    return 0 if all(ok for ok, _ in goals) else 1


def cmd_analyse_jsbsim(args) -> int:
    """``analyse --plant jsbsim``: linearise the trimmed aircraft, print its modes checked
    against the nonlinear model and the closed loop against the point-mass model; exit 1 when
    the modes disagree (:data:`~fms_testbed.evaluation.linear_check.MODE_TOL_REL`)."""
    from fms_testbed.cli.coupled import _out_dir
    from fms_testbed.control.coupled_law import params_from_config
    from fms_testbed.core.units import KMH_MPS
    from fms_testbed.evaluation.linear_check import compare_point

    cfg = load_aircraft(args.aircraft)
    alt = args.alt if args.alt is not None else cfg.default_condition.alt_m
    tas = args.speed * KMH_MPS if args.speed else cfg.default_condition.tas_mps
    out = _out_dir(args.out, f"analyse-jsbsim-{cfg.name}")
    folder = OutputFolder(out, getattr(args, "overwrite", False))
    tmp = folder.open()
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.tuning import plot_linear_check

    chk = compare_point(cfg, alt, tas, params_from_config(cfg))
    for line in chk.lines:
        print(line)
    save(plot_linear_check(chk.t_s, chk.nonlinear, chk.linear, chk.title),
         tmp / "linear-vs-jsbsim.png")
    (tmp / "analysis.md").write_text(f"# {cfg.name}: linearised JSBSim at {alt:.0f} m / "
                                     f"{tas:.1f} m/s\n\n" + "\n".join(chk.lines) + "\n")
    print(f"\nwritten to {out}/ (analysis.md, linear-vs-jsbsim.png)")
    folder.commit()
    return 0 if chk.ok else 1
