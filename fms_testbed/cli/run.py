"""``fms-testbed run`` / ``demo``: fly scenario files (plain or procedure flights); the outputs
of :meth:`fms_testbed.run.results.Results.save` (timeseries, summary, plots, tracks)."""

from __future__ import annotations

import sys
from pathlib import Path

from fms_testbed.cli.common import (add_override_options, add_overwrite_option, overrides_from_args,
                                    print_results)
from fms_testbed.run.outputs import check_out_dir
from fms_testbed.data import results_dir, scenarios_dir

DEMO_SCENARIO = "demo-sid.yaml"


TRUTH_MODELS = ("strapdown", "linear")


def add_truth_model_option(p) -> None:
    """Add ``--truth-model strapdown|linear`` (the INS units' truth side) to a parser."""
    p.add_argument("--truth-model", choices=TRUTH_MODELS,
                   help="truth side of the INS units: strapdown mechanisation of a simulated "
                        "IMU, or truth + the linear 33-state error model (default: the "
                        "source's, strapdown for ins_gnss, linear for sins)")


def with_truth_model(overrides: dict, args) -> dict:
    """``overrides`` with the ``--truth-model`` of ``args`` (when given)."""
    if getattr(args, "truth_model", None):
        overrides["navigation_truth_model"] = args.truth_model
    return overrides


def _fly(scenario, out: Path, args) -> int:
    """Fly a scenario (file or mapping) with the command's overrides; exit code from the status."""
    check_out_dir(out, getattr(args, "overwrite", False))      # before any work
    from fms_testbed.evaluation.outcome import EXIT_CODES
    from fms_testbed.run.api import run_scenario

    res = run_scenario(scenario, seed=args.seed,
                       overrides=with_truth_model(overrides_from_args(args), args), progress=None)
    res.save(out, csv=args.csv, plots=not getattr(args, "no_plots", False),
             overwrite=getattr(args, "overwrite", False))
    print_results(res)
    return EXIT_CODES[res.summary["status"]]


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


def register(sub) -> None:
    """Add ``run`` and ``demo`` to the CLI."""
    p = sub.add_parser("run", help="fly a scenario file")
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument("--out", help="output folder (default results/<scenario name>)")
    add_override_options(p)
    add_truth_model_option(p)
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("demo", help="fly the embedded demo (KJFK DEEZZ5 SID) into results/demo")
    p.add_argument("--out", help="output folder (default results/demo)")
    p.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_demo)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(1)
