"""CLI for the coupled thrust/elevator law: ``compare``, ``analyse``, ``tune``.

* ``fms-testbed compare [SCENARIO ...]`` flies each scenario with the coupled law and the
  baselines on JSBSim (plus the ideal point-mass response), prints and saves the comparison table
  and the goal checks, and plots (``--paper-plot``: the paper's Fig. 2 layout).
* ``fms-testbed analyse --aircraft NAME`` builds the linear closed loop with python-control,
  prints the decoupling and pole placement, and plots Bode magnitudes and steps with lags.
* ``fms-testbed tune --aircraft NAME`` optimises (T_V, ξ_V, T_H, ξ_H) on JSBSim and writes the
  gains in the aircraft-config format plus a report with plots (``--write`` updates the file).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.cli.common import WIND_HELP, bounded_int, markdown_table, parse_wind
from fms_testbed.cli.common import add_overwrite_option
from fms_testbed.core.errors import UserError
from fms_testbed.run.outputs import OutputFolder
from fms_testbed.core.units import KMH_MPS
from fms_testbed.data import results_dir, scenarios_dir

DEFAULT_SCENARIOS = ("coupled-altitude-step", "coupled-speed-step", "paper-fig2")


def _out_dir(arg: str | None, what: str) -> Path:
    if arg:
        return Path(arg)
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    return results_dir() / f"{what}-{stamp}"


def _scenario_path(name: str) -> Path:
    p = Path(name)
    if p.suffix in (".yaml", ".yml"):
        return p
    cand = scenarios_dir() / f"{name}.yaml"
    if not cand.exists():
        raise UserError(f"no scenario '{name}' (looked for {p} and {cand})")
    return cand


# --- compare -----------------------------------------------------------------------------------

def _compare_scenario(scn, args, laws, tmp: Path) -> list[dict]:
    """Fly one scenario with each law; save its plots and timeseries into ``tmp``; return its
    comparison rows."""
    from fms_testbed.control.coupled_law import params_from_config
    from fms_testbed.evaluation.law_comparison import comparison_rows, run_comparison
    from fms_testbed.viz.control import plot_comparison, plot_paper_fig2
    from fms_testbed.viz.figure import save

    cfg = load_aircraft(scn.aircraft)
    params = _with_settings(params_from_config(cfg), args.set or [])
    cmp = run_comparison(scn, cfg, laws, params, seed=args.seed)
    scn_rows = comparison_rows(cmp, cfg)
    runs = dict(cmp.runs)
    runs["ideal"] = cmp.ideal
    head = _headline(scn_rows)
    title = f"{scn.name} — {cfg.name}: {scn.description or ''}" + (f"\n{head}" if head else "")
    save(plot_comparison(runs, title), tmp / f"{scn.name}-comparison.png")
    if args.paper_plot or scn.name == "paper-fig2":
        fig2 = {k: runs[k] for k in ("coupled", "ideal", "pi") if k in runs}
        save(plot_paper_fig2(fig2, f"{scn.name} — {cfg.name} (layout of the paper's Fig. 2)"
                             + (f"\n{head}" if head else "")),
             tmp / f"{scn.name}-paper-fig2.png")
    for law, df in cmp.runs.items():
        df.to_parquet(tmp / f"{scn.name}-{law}.parquet", index=False)
    return scn_rows


def cmd_compare(args) -> int:
    """Fly scenarios with each law; print/save the table, the goal checks and plots."""
    from fms_testbed.control import VERTICAL_LAWS
    from fms_testbed.evaluation.law_comparison import check_goals
    from fms_testbed.config.scenario import load_scenario

    laws = tuple(s.strip() for s in args.laws.split(",") if s.strip())
    bad = [x for x in laws if x not in VERTICAL_LAWS]
    if bad:
        raise UserError(f"--laws: unknown law(s) {', '.join(bad)}; known: {', '.join(VERTICAL_LAWS)}")
    if args.envelope:
        return _compare_envelope(args, laws)
    names = args.scenarios or list(DEFAULT_SCENARIOS)
    overrides = {"aircraft": args.aircraft} if args.aircraft else {}
    if args.turbulence:
        overrides["turbulence"] = {"severity": args.turbulence}
    if args.wind:
        overrides["wind"] = parse_wind(args.wind)
    scns = [load_scenario(_scenario_path(n), overrides) for n in names]
    for n, scn in zip(names, scns):
        if not any(e.altitude_m is not None or e.speed[1] is not None for e in scn.events):
            raise UserError(f"{n}: no event steps the altitude or the speed; compare measures "
                            "the laws on altitude and speed steps (events with alt_m/alt_ft or "
                            "tas_*/cas_*)")
    if args.small_step and not args.scenarios:
        s0 = scns[0]
        small = s0.model_copy(update={"name": "altitude-step-100m", "events": [
            e.model_copy(update={"alt_m": s0.initial.altitude_m + 100.0, "alt_ft": None})
            for e in s0.events]})
        scns.insert(1, small)
    out = _out_dir(args.out, "compare")
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    rows = []
    for scn in scns:
        rows.extend(_compare_scenario(scn, args, laws, tmp))
    table = pd.DataFrame(rows)
    goals = check_goals(table) if "coupled" in laws else []
    table.to_csv(tmp / "comparison.csv", index=False)
    show = table.drop(columns=[c for c in ("status",) if c in table and (table[c] == "ok").all()])
    md = markdown_table(show)
    gl = "\n".join(f"- {'PASS' if g.ok else 'FAIL'}: {g.name} = {g.value:.3g} {g.unit} "
                   f"(goal {'≤' if g.unit != '×' else '≥'} {g.limit:g} {g.unit})" for g in goals)
    (tmp / "comparison.md").write_text(f"# Coupled law vs baselines\n\n{md}\n\n## Goals\n\n{gl}\n")
    (tmp / "goals.json").write_text(json.dumps([asdict(g) for g in goals], indent=2,
                                               default=float))
    print(md)
    if gl:
        print("\nGoals:\n" + gl)
    print(f"\nwritten to {out}/ (comparison.csv, comparison.md, *.png, *.parquet)")
    failed = sorted({f"{r['scenario']}/{r['law']}: "
                     f"{r['status'] if r.get('status') != 'ok' else 'no step flown'}"
                     for r in rows if r.get("status") != "ok" or "step" not in r})
    if failed:
        print("\nflights not ok (no goals checked on them): " + ", ".join(failed))
    folder.commit()
    return 0 if all(g.ok for g in goals) and not failed else 1


def _headline(rows: list[dict]) -> str:
    """The figures that matter of one scenario's comparison rows: each law's cross deviation
    (max |ΔV| in an altitude step, km/h; max |ΔH| in a speed step, m)."""
    parts = []
    for key, what, unit in (("max_dV_kmh", "max|ΔV| in the altitude step", "km/h"),
                            ("max_dH_m", "max|ΔH| in the speed step", "m")):
        vals = [(r["law"], r[key]) for r in rows if math.isfinite(r.get(key, math.nan))]
        if vals:
            parts.append(f"{what}: " + ", ".join(f"{law} {v:.3g}" for law, v in vals)
                         + f" {unit}")
    return "; ".join(parts)


def _with_settings(params, settings: list[str]):
    """Apply ``--set KEY=VALUE`` overrides to :class:`CoupledLawParams` (type from the field)."""
    from dataclasses import fields, replace

    types = {f.name: f.type for f in fields(params)}
    kw = {}
    for item in settings:
        key, sep, val = item.partition("=")
        if not sep or key not in types:
            raise UserError(f"--set {item!r}: expected KEY=VALUE with KEY one of "
                            f"{', '.join(types)}")
        t = types[key]
        try:
            if t in (bool, "bool"):
                if val.lower() not in ("true", "false", "1", "0", "yes", "no"):
                    raise ValueError(val)
                kw[key] = val.lower() in ("true", "1", "yes")
            elif t in (float, "float"):
                kw[key] = float(val)
            else:
                kw[key] = val
        except ValueError:
            raise UserError(f"--set {item!r}: {val!r} is not a valid {t}") from None
    try:
        return replace(params, **kw)
    except ValueError as exc:
        raise UserError(f"--set: {exc}") from None


def _compare_envelope(args, laws) -> int:
    """``compare --envelope``: +100 m and +10 % steps at every envelope point of each aircraft."""
    from fms_testbed.config.aircraft import list_aircraft
    from fms_testbed.evaluation.law_comparison import envelope_rows

    if args.scenarios:
        raise UserError("compare --envelope takes no scenarios (it builds its own steps)")
    names = [args.aircraft] if args.aircraft else list_aircraft()
    out = _out_dir(args.out, "envelope")
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    rows = []
    for name in names:
        rows.extend(envelope_rows(load_aircraft(name), laws, seed=args.seed))
    table = pd.DataFrame(rows)
    tmp = folder.open()
    table.to_csv(tmp / "envelope.csv", index=False)
    md = markdown_table(table)
    (tmp / "envelope.md").write_text(f"# Coupled law across the envelope\n\n{md}\n")
    print(md)
    print(f"\nwritten to {out}/ (envelope.csv, envelope.md)")
    folder.commit()
    return 0


# --- analyse -----------------------------------------------------------------------------------

def _analyse_case(label: str, p, V0: float, case: tuple, w, t, args):
    """One linear case of ``analyse``: closed loop with lags (s) and n_x choice ``case``;
    prints its decoupling and poles; returns (W(jω), steps, report entry)."""
    from fms_testbed.control import linear

    tx, ty, meas = case
    sys = linear.closed_loop(p, V0, tx, ty, use_measured_nx=meas)
    r = linear.decoupling_report(sys, p, w)
    fr = linear.frequency_response(sys, w)
    sv, sh = linear.step_responses(sys, t, args.dv * KMH_MPS, args.dh)
    rep = {
        "max|W_V,Hcmd|/max|W_V,Vcmd|": r.off_V_from_H, "max|W_H,Vcmd|/max|W_H,Hcmd|":
            r.off_H_from_V, "pole_error_rps": r.pole_error,
        "poles_rps": [complex(x) for x in np.sort_complex(r.poles)],
        "dc_gain": r.dc_gain.tolist(),
        f"max|dV| in {args.dh:g} m step, km/h": float(np.abs(sh[0]).max() / KMH_MPS),
        f"max|dH| in {args.dv:g} km/h step, m": float(np.abs(sv[1]).max())}
    print(f"\n[{label}]")
    print(f"  cross terms: |W_V,Hcmd|/|W_V,Vcmd| = {r.off_V_from_H:.3g}, "
          f"|W_H,Vcmd|/|W_H,Hcmd| = {r.off_H_from_V:.3g}")
    print(f"  poles: {', '.join(f'{x.real:.4f}{x.imag:+.4f}j' for x in np.sort_complex(r.poles))}")
    print(f"  desired (T, xi) poles: "
          f"{', '.join(f'{x.real:.4f}{x.imag:+.4f}j' for x in np.sort_complex(r.desired_poles))}"
          f"  -> max distance {r.pole_error:.2g} rad/s")
    print(f"  max|dV| during a {args.dh:g} m step: {np.abs(sh[0]).max() / KMH_MPS:.3g} km/h; "
          f"max|dH| during a {args.dv:g} km/h step: {np.abs(sv[1]).max():.3g} m")
    return fr, (sv, sh), rep


def cmd_analyse(args) -> int:
    """Linear analysis of the closed loop: decoupling, poles, Bode and step plots with lags
    (``--plant jsbsim``: :func:`fms_testbed.cli.tune_envelope.cmd_analyse_jsbsim`)."""
    if getattr(args, "plant", "pointmass") == "jsbsim":
        from fms_testbed.cli.tune_envelope import cmd_analyse_jsbsim

        return cmd_analyse_jsbsim(args)
    from fms_testbed.control.coupled_law import params_from_config
    from fms_testbed.viz.control import plot_bode_coupling, plot_linear_steps
    from fms_testbed.viz.figure import save

    cfg = load_aircraft(args.aircraft)
    p = params_from_config(cfg)
    V0 = args.speed * KMH_MPS if args.speed else cfg.default_condition.tas_mps
    out = _out_dir(args.out, f"analyse-{cfg.name}")
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    if args.identify:
        from fms_testbed.evaluation.law_tuning import OperatingPoint, identify_lags

        alt = args.alt if args.alt is not None else cfg.default_condition.alt_m
        args.tau_nx, args.tau_ny = identify_lags(cfg, OperatingPoint(alt, V0))
        print(f"identified inner-loop lags on JSBSim: tau_nx {args.tau_nx:.2f} s, "
              f"tau_ny {args.tau_ny:.2f} s")
    cases = {"no lags (paper)": (0.0, 0.0, True),
             f"lags nx {args.tau_nx:g} s, ny {args.tau_ny:g} s, measured n_x":
                 (args.tau_nx, args.tau_ny, True),
             f"lags nx {args.tau_nx:g} s, ny {args.tau_ny:g} s, commanded n_x":
                 (args.tau_nx, args.tau_ny, False)}
    w = np.logspace(-3, 1.5, 300)
    t = np.linspace(0.0, 120.0, 2401)
    freq, steps, report = {}, {}, {}
    print(f"{cfg.name}: T_V {p.T_V_s} s, xi_V {p.xi_V}, T_H {p.T_H_s} s, xi_H {p.xi_H}, "
          f"V0 {V0 / KMH_MPS:.0f} km/h")
    for label, (tx, ty, meas) in cases.items():
        freq[label], steps[label], report[label] = _analyse_case(label, p, V0, (tx, ty, meas),
                                                                 w, t, args)
    worst = max(report.values(), key=lambda r: r["max|W_V,Hcmd|/max|W_V,Vcmd|"])
    lag_label = max(report, key=lambda k: report[k]["max|W_V,Hcmd|/max|W_V,Vcmd|"])
    save(plot_bode_coupling(w, freq, f"{cfg.name}: closed-loop W(jω) at {V0 / KMH_MPS:.0f} km/h "
                            f"— diagonal and cross terms\nlargest cross term |W_V,Hcmd|/|W_V,Vcmd| "
                            f"= {worst['max|W_V,Hcmd|/max|W_V,Vcmd|']:.2g} ({lag_label})"),
         tmp / "bode.png")
    dv_key = f"max|dV| in {args.dh:g} m step, km/h"
    save(plot_linear_steps(t, steps, args.dv * KMH_MPS, args.dh,
                           f"{cfg.name}: linear closed-loop steps, with and without inner-loop "
                           f"lags\nmax|ΔV| in the {args.dh:g} m step: " + ", ".join(
                               f"{r[dv_key]:.2g}" for r in report.values()) + " km/h"),
         tmp / "steps.png")
    (tmp / "analysis.json").write_text(json.dumps(report, indent=2, default=str))
    print(f"\nwritten to {out}/ (bode.png, steps.png, analysis.json)")
    folder.commit()
    return 0


# --- tune ----------------------------------------------------------------------------------

def _tune_report(cfg, args, res, op, alt: float, tas: float, hist: pd.DataFrame) -> str:
    """``report.md`` of a single-point ``tune`` (altitude m, TAS m/s)."""
    from fms_testbed.evaluation.law_tuning import gains_yaml

    b = res.best
    start, best = res.start.row(), b.row()
    keys = [k for k in best if k not in ("note",)]
    tab = pd.DataFrame({"start": [start.get(k) for k in keys], "tuned": [best.get(k) for k in keys]},
                       index=keys)
    report = (f"# Tuning of the coupled law — {cfg.name}\n\n"
              f"Operating point {alt:.0f} m, {tas / KMH_MPS:.0f} km/h TAS; altitude step {op.dH_m:g} m, "
              f"speed step {op.speed_step_mps / KMH_MPS:.0f} km/h; {len(res.history)} evaluations on "
              f"{args.plant} (bounded Nelder-Mead). Criteria: see `fms_testbed/evaluation/law_tuning.py` (module docstring)."
              f"\n\nIdentified inner-loop lags: n_x {res.lags_s[0]:.2f} s, n_y "
              f"{res.lags_s[1]:.2f} s.\n\n```yaml\n{gains_yaml(b.params)}\n```\n\n"
              f"{markdown_table(tab.reset_index().rename(columns={'index': 'quantity'}))}\n\n"
              f"![tuned vs linear](tuned-vs-linear.png)\n\n## History\n\n{markdown_table(hist)}\n")
    return report


def _no_envelope_options(args) -> None:
    """A single-point ``tune`` refuses the options of ``tune --envelope``."""
    given = [o for o, on in (("--verify-campaign", args.verify_campaign),
                             ("--scheduler", args.scheduler), ("--grid", args.grid),
                             ("--airports", args.airports)) if on]
    if given:
        raise UserError(f"tune: {', '.join(given)} need --envelope")


def cmd_tune(args) -> int:
    """Optimise the law's (T, ξ) on JSBSim; write gains, report and plots
    (``--envelope``: :func:`fms_testbed.cli.tune_envelope.cmd_tune_envelope`)."""
    if getattr(args, "envelope", False):
        from fms_testbed.cli.tune_envelope import cmd_tune_envelope

        return cmd_tune_envelope(args)
    _no_envelope_options(args)
    from fms_testbed.viz.control import plot_tuning_overlay
    from fms_testbed.viz.figure import save
    from fms_testbed.evaluation.law_tuning import (OperatingPoint, gains_yaml, linear_prediction, tune,
                                 write_gains_to_config)

    cfg = load_aircraft(args.aircraft)
    alt = args.alt if args.alt is not None else cfg.default_condition.alt_m
    tas = args.speed * KMH_MPS if args.speed else cfg.default_condition.tas_mps
    budget = 8 if args.quick else args.max_evals
    if budget > 60:
        raise UserError("tune: --max-evals is capped at 60 JSBSim evaluations")
    duration = 60.0 if args.quick else 100.0
    op = OperatingPoint(alt, tas, dH_m=args.dh, dV_mps=args.dv * KMH_MPS if args.dv else 0.0)
    out = _out_dir(args.out, f"tune-{cfg.name}")
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    print(f"tuning {cfg.name} at {alt:.0f} m / {tas / KMH_MPS:.0f} km/h TAS: {op.dH_m:g} m and "
          f"{op.speed_step_mps / KMH_MPS:.0f} km/h steps, budget {budget} evaluations ({args.plant})")

    def show(ev):
        r = ev.row()
        print(f"  T_V {r['T_V_s']:5.2f} xi_V {r['xi_V']:4.2f} T_H {r['T_H_s']:5.2f} "
              f"xi_H {r['xi_H']:4.2f} -> cost {r['cost']:7.3f} {r['note']}")

    res = tune(cfg, op, max_evals=budget, duration_s=duration, plant=args.plant, progress=show)
    b = res.best
    hist = pd.DataFrame([e.row() for e in res.history])
    hist.to_csv(tmp / "history.csv", index=False)
    (tmp / "gains.yaml").write_text(
        f"# tuned by `fms-testbed tune --aircraft {args.aircraft}` at {alt:.0f} m / "
        f"{tas / KMH_MPS:.0f} km/h; paste into aircraft/{cfg.name}.yaml\n{gains_yaml(b.params)}\n")
    lin = linear_prediction(b.params, op, res.lags_s[0], res.lags_s[1], duration)
    save(plot_tuning_overlay(b.runs, lin,
                             f"{cfg.name}: tuned law on {args.plant} vs linear prediction "
                             f"(lags nx {res.lags_s[0]:.2f} s, ny {res.lags_s[1]:.2f} s)\n"
                             f"cost {b.cost:.3f} (start {res.start.cost:.3f}): T_V "
                             f"{b.params.T_V_s:.2f} s, ξ_V {b.params.xi_V:.2f}, T_H "
                             f"{b.params.T_H_s:.2f} s, ξ_H {b.params.xi_H:.2f}",
                             plant={"jsbsim": "JSBSim"}.get(args.plant, "point mass")),
         tmp / "tuned-vs-linear.png")
    report = _tune_report(cfg, args, res, op, alt, tas, hist)
    (tmp / "report.md").write_text(report)
    print(f"\nbest: {gains_yaml(b.params)}  (cost {b.cost:.3f}, start {res.start.cost:.3f})")
    if args.write:
        if not cfg.source_file:
            raise UserError(f"{cfg.name}: no source file to write the gains to")
        write_gains_to_config(cfg.source_file, b.params)
        print(f"gains written to {cfg.source_file}")
    print(f"written to {out}/ (gains.yaml, report.md, history.csv, tuned-vs-linear.png)")
    folder.commit()
    return 0


def register(subparsers) -> None:
    """Add ``compare``, ``analyse`` and ``tune`` to the ``fms-testbed`` parser."""
    _register_compare(subparsers)
    _register_analyse(subparsers)
    _register_tune(subparsers)


def _register_compare(subparsers) -> None:
    p = subparsers.add_parser(
        "compare", help="coupled law vs baselines on JSBSim: table, goals, plots",
        description="Fly scenarios with the coupled law and the baselines (PI autothrottle, TECS) "
                    "on JSBSim, plus the coupled law's ideal point-mass response; print and save "
                    "the comparison table and the issue-3 goal checks. Exit 1 if a goal fails.")
    p.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                   help=f"scenario files or shipped names (default: {', '.join(DEFAULT_SCENARIOS)}"
                        " plus a 100 m altitude step)")
    p.add_argument("--aircraft", help="fly the scenarios with this aircraft instead")
    p.add_argument("--laws", default="coupled,pi,tecs", help="comma-separated laws")
    p.add_argument("--paper-plot", action="store_true",
                   help="also draw every scenario in the paper's Fig. 2 layout")
    p.add_argument("--envelope", action="store_true",
                   help="instead: +100 m and +10 %% speed steps at every envelope point of every "
                        "aircraft (or --aircraft)")
    p.add_argument("--no-small-step", dest="small_step", action="store_false",
                   help="skip the extra 100 m (unclipped) altitude step")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a coupled-law parameter for this comparison (repeatable), "
                        "e.g. form=paper, use_measured_nx=false, ny_trim_tau_s=0, T_V_s=8")
    p.add_argument("--turbulence", choices=("light", "moderate", "severe"),
                   help="fly the scenarios in turbulence (seeded by --seed)")
    p.add_argument("--wind", metavar="FROM_DEG/SPEED_KT", help=WIND_HELP)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", help="output folder (default results/compare-<time>)")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_compare)


def _register_analyse(subparsers) -> None:
    p = subparsers.add_parser(
        "analyse", help="linear analysis of the coupled law (python-control)",
        description="Closed-loop transfer matrix W(p) of the linearised point mass + law: "
                    "decoupling, pole placement, and the effect of inner-loop lags.")
    p.add_argument("--aircraft", required=True)
    p.add_argument("--alt", type=float, help="altitude, m (only for --identify)")
    p.add_argument("--speed", type=float, help="trim TAS, km/h (default: aircraft default)")
    p.add_argument("--tau-nx", type=float, default=1.0, help="n_x realisation lag, s")
    p.add_argument("--tau-ny", type=float, default=0.5, help="n_y realisation lag, s")
    p.add_argument("--identify", action="store_true",
                   help="identify the lags from JSBSim inner-loop steps instead")
    p.add_argument("--dh", type=float, default=100.0, help="altitude step for the plots, m")
    p.add_argument("--dv", type=float, default=50.0, help="speed step for the plots, km/h")
    p.add_argument("--out", help="output folder (default results/analyse-<aircraft>-<time>)")
    add_overwrite_option(p)
    p.add_argument("--plant", choices=("pointmass", "jsbsim"), default="pointmass",
                   help="jsbsim: linearise the trimmed JSBSim aircraft (FGLinearization), print "
                        "its modes checked against the nonlinear model, the loops' margins and "
                        "the point-mass comparison")
    p.set_defaults(func=cmd_analyse)


def _register_tune(subparsers) -> None:
    p = subparsers.add_parser(
        "tune", help="tune the coupled law's (T_V, xi_V, T_H, xi_H) on JSBSim",
        description="Bounded Nelder-Mead over (T_V, xi_V, T_H, xi_H) on the JSBSim closed loop "
                    "(altitude and speed steps) against settling, overshoot, interaction, "
                    "throttle activity and limits; writes gains.yaml, report.md and plots.")
    p.add_argument("--aircraft", required=True)
    p.add_argument("--alt", type=float, help="operating altitude, m (default: aircraft default)")
    p.add_argument("--speed", type=float, help="operating TAS, km/h (default: aircraft default)")
    p.add_argument("--dh", type=float, default=100.0, help="altitude step, m (≤ dH limit)")
    p.add_argument("--dv", type=float, help="speed step, km/h (default 10 %% of the speed)")
    p.add_argument("--max-evals", type=int, default=40, help="evaluation budget (≤ 60)")
    p.add_argument("--quick", action="store_true", help="8 evaluations of 60 s runs")
    p.add_argument("--plant", choices=("jsbsim", "pointmass"), default="jsbsim")
    p.add_argument("--write", action="store_true",
                   help="write the tuned coupled_law block into the aircraft's YAML file")
    p.add_argument("--envelope", action="store_true",
                   help="tune over a grid of design points into a gain schedule in (dynamic "
                        "pressure, mass): margins on every loop, robustness, nonlinear checks; "
                        "writes points.csv, schedule.yaml, aircraft.yaml, report.md, figures")
    p.add_argument("--grid", metavar="FILE.yaml",
                   help="with --envelope: design points (points: [{alt_m, tas_mps, mass_kg, "
                        "config: clean|approach}]) instead of the default grid")
    ex = p.add_mutually_exclusive_group()
    ex.add_argument("--workers", type=int, default=2, help="with --envelope: local processes")
    ex.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                    help="with --envelope: run the design points (and the campaign check) on "
                         "this Dask scheduler instead of the local pool")
    p.add_argument("--no-robust", action="store_true",
                   help="with --envelope: skip the robustness set (mass, CG, actuator delay)")
    p.add_argument("--verify-campaign", action="store_true",
                   help="with --envelope: fly a procedure sample in wind and turbulence with "
                        "the file gains and the tuned aircraft.yaml; the distribution shift "
                        "into the report (campaign/)")
    p.add_argument("--airports", nargs="+", metavar="ICAO",
                   help="with --verify-campaign: airports of the embedded excerpt (default all)")
    p.add_argument("--campaign-limit", type=bounded_int(1, 100_000), metavar="N",
                   help="with --verify-campaign: fly only the first N cases")
    p.add_argument("--campaign-types", default="STAR,APPROACH",
                   help="with --verify-campaign: procedure types (default STAR,APPROACH)")
    p.add_argument("--campaign-wind", default="270/30", metavar="FROM/SPEED",
                   help="with --verify-campaign: steady wind, deg/kt (default 270/30)")
    p.add_argument("--campaign-turbulence", default="moderate",
                   choices=("light", "moderate", "severe"),
                   help="with --verify-campaign: turbulence severity (default moderate)")
    p.add_argument("--out", help="output folder (default results/tune-<aircraft>-<time>)")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_tune)
