"""``fms-testbed run`` / ``demo`` / ``inner``: fly scenario files, check inner loops."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from fms_testbed.cli.common import add_override_options, overrides_from_args, print_results
from fms_testbed.data import results_dir, scenarios_dir

DEMO_SCENARIO = "demo-sid.yaml"


def _fly(scenario, out: Path, args) -> int:
    """Fly a scenario (file or mapping) with the command's overrides; exit code from the status."""
    from fms_testbed.run.api import run_scenario

    res = run_scenario(scenario, out_dir=out, seed=args.seed, overrides=overrides_from_args(args),
                       csv=args.csv, plots=not getattr(args, "no_plots", False), progress=None)
    print_results(res)
    return 0 if res.summary["status"] == "ok" else 1


def cmd_run(args) -> int:
    """Fly one scenario file (a procedure flight when it has a ``procedure:`` block)."""
    scn = Path(args.scenario)
    out = Path(args.out) if args.out else results_dir() / scn.stem
    return _fly(scn, out, args)


def cmd_demo(args) -> int:
    """Fly the embedded demo (a real SID from the embedded database) into results/demo."""
    scn = scenarios_dir() / DEMO_SCENARIO
    out = Path(args.out) if args.out else results_dir() / "demo"
    return _fly(scn, out, args)


def cmd_inner(args) -> int:
    """Check (and optionally tune) the inner loops of an aircraft against the step specs."""
    from fms_testbed.config.aircraft import load_aircraft
    from fms_testbed.sim.inner_steps import check_aircraft, replace_gains, tune_loop

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
    add_override_options(p)
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("demo", help="fly the embedded demo (KJFK DEEZZ5 SID) into results/demo")
    p.add_argument("--out", help="output folder (default results/demo)")
    p.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.set_defaults(func=cmd_demo)
    p = sub.add_parser("inner", help="check the inner loops of an aircraft against the step specs")
    p.add_argument("--aircraft", required=True, help="aircraft name or YAML file")
    p.add_argument("--tune", action="store_true", help="search the gains first (Nelder-Mead)")
    p.add_argument("--envelope", action="store_true", help="check at every envelope point")
    p.set_defaults(func=cmd_inner)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(1)
