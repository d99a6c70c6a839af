"""``fms-testbed run`` / ``demo`` / ``inner``: fly scenario files, check inner loops."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from .errors import UserError
from .paths import results_dir, scenarios_dir

DEMO_SCENARIO = "demo-sid.yaml"


def _has_procedure(path: Path) -> bool:
    """True when the scenario file has a ``procedure:`` block (flown by the procedure guidance)."""
    import yaml

    try:
        raw = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError):
        return False  # the scenario loader reports it with file and line
    return isinstance(raw, dict) and "procedure" in raw


def _fly_file(path: Path, out: Path, args) -> int:
    """Fly a scenario file: a procedure flight when it has a ``procedure:`` block."""
    if _has_procedure(path):
        from .cli_fly import _print as print_fly
        from .fly import fly_procedure, load_procedure_scenario

        scn, spec, fp, db = load_procedure_scenario(path)
        res = fly_procedure(scn, spec, fp, db, out_dir=out, seed=args.seed, csv=args.csv,
                            plots=not getattr(args, "no_plots", False), progress=None)
        print_fly(res)
        return 0 if res.summary["status"] == "ok" else 1
    from .runner import run_scenario

    res = run_scenario(path, out_dir=out, seed=args.seed, csv=args.csv,
                       plots=not getattr(args, "no_plots", False), progress=None)
    _print_summary(res)
    return 0 if res.summary["status"] == "ok" else 1


def _print_summary(res) -> None:
    s = res.summary
    print(f"{s['scenario']}: {s['status']} ({s['reason']}), {s['duration_s']:.0f} s flown in "
          f"{s['wall_time_s']:.1f} s wall ({s['real_time_factor']}x real time)")
    if res.out_dir is not None:
        print(f"outputs in {res.out_dir}: timeseries.parquet, summary.json, "
              + ", ".join(s.get("plots", [])))


def cmd_run(args) -> int:
    """Fly one scenario file (a procedure flight when it has a ``procedure:`` block)."""
    scn = Path(args.scenario)
    out = Path(args.out) if args.out else results_dir() / scn.stem
    return _fly_file(scn, out, args)


def cmd_demo(args) -> int:
    """Fly the embedded demo (a real SID from the embedded database) into results/demo."""
    scn = scenarios_dir() / DEMO_SCENARIO
    if not scn.exists():
        raise UserError(f"demo scenario {scn} is missing (is the package installed from a clone "
                        "with `pip install -e .`, or FMS_TESTBED_HOME set?)")
    out = Path(args.out) if args.out else results_dir() / "demo"
    return _fly_file(scn, out, args)


def cmd_inner(args) -> int:
    """Check (and optionally tune) the inner loops of an aircraft against the step specs."""
    from .aircraft import load_aircraft
    from .inner_steps import check_aircraft, replace_gains, tune_loop

    cfg = load_aircraft(args.aircraft)
    if args.tune:
        for loop in ("ny", "nx", "bank"):
            g, cost = tune_loop(cfg, loop)
            cfg = replace_gains(cfg, loop, g)
            print(f"{loop}: kp {g.kp:.4g}, ki {g.ki:.4g}, kd {g.kd:.4g} (cost {cost:.3f})")
    rows = []
    ok = True
    for pt in cfg.envelope if args.envelope else [cfg.default_condition]:
        for r in check_aircraft(cfg, pt):
            ok &= r.ok
            rows.append({"alt_m": pt.alt_m, "tas_mps": pt.tas_mps, "loop": r.spec.loop,
                         "step": r.spec.amplitude, "settle_s": round(r.settle_s, 2),
                         "settle_max_s": r.spec.settle_max_s,
                         "overshoot_pct": round(r.overshoot_pct, 1),
                         "overshoot_max_pct": r.spec.overshoot_max_pct, "ok": r.ok})
    for row in rows:
        print(json.dumps(row))
    if args.tune:
        print("inner_loops gains (paste into aircraft file):")
        print(json.dumps(cfg.inner_loops.model_dump(), indent=1))
    return 0 if ok else 1


def register(sub) -> None:
    """Add ``run``, ``demo`` and ``inner`` to the CLI."""
    p = sub.add_parser("run", help="fly a scenario file")
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument("--out", help="output folder (default results/<scenario name>)")
    p.add_argument("--seed", type=int, default=0, help="seed for turbulence and sensor errors")
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("demo", help="fly the embedded demo (KJFK DEEZZ5 SID) into results/demo")
    p.add_argument("--out", help="output folder (default results/demo)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--csv", action="store_true")
    p.set_defaults(func=cmd_demo)
    p = sub.add_parser("inner", help="check the inner loops of an aircraft against the step specs")
    p.add_argument("--aircraft", required=True, help="aircraft name or YAML file")
    p.add_argument("--tune", action="store_true", help="search the gains first (Nelder-Mead)")
    p.add_argument("--envelope", action="store_true", help="check at every envelope point")
    p.set_defaults(func=cmd_inner)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(1)
