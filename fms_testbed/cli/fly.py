"""``fms-testbed fly``: fly a real ARINC-424 procedure (from the command line or a scenario file).

    fms-testbed fly --db FILE --airport KSEA --procedure ISBRG1 --runway 34R --aircraft 737 \\
        [--transition T] [--wind 270/20] [--nav sins --imu PRESET] [--seed N] [--takeoff] --out DIR
    fms-testbed fly --scenario scenarios/demo-sid.yaml [--out DIR]

Prints one line per result group (status, errors, RNP, constraints, sequencing) and writes
``timeseries.parquet``, ``summary.json``, the plots (NM, ft, kt) and, for Google Earth/QGIS,
``track.geojson`` and ``track.kml`` (the designed path leg by leg, the flown 3-D track, the
navigation track where it differs) into ``--out``. ``--takeoff`` starts a SID at rest on its
runway's threshold with a takeoff roll (``procedure.start: takeoff``) instead of airborne over
the departure end. Exit code 0 when the
procedure was flown to its end, 1 otherwise, 2 on a user error.
"""

from __future__ import annotations

from pathlib import Path

from fms_testbed.cli.common import (add_override_options, add_overwrite_option, out_path,
                                    overrides_from_args, print_results)
from fms_testbed.run.outputs import check_out_dir
from fms_testbed.core.errors import UserError
from fms_testbed.data import results_dir

KIND = "fly"
"""``run.json`` ``kind`` of a ``fly`` output folder."""


def scenario_from_args(args) -> dict:
    """The procedure scenario mapping the command-line options describe."""
    if not (args.airport and args.procedure):
        raise UserError("fly needs --scenario FILE, or --airport and --procedure")
    proc = {"db": args.db or "embedded", "airport": args.airport.upper(),
            "procedure": args.procedure.upper()}
    if args.transition:
        proc["transition"] = args.transition.upper()
    if args.runway:
        proc["runway"] = args.runway.upper()
    return {"aircraft": args.aircraft or "737", "procedure": proc,
            "name": f"{proc['airport']}-{proc['procedure']}".lower()}


def cmd_fly(args) -> int:
    """Fly one procedure (from the options or a scenario file, with the same overrides)."""
    if args.scenario:
        if args.airport or args.procedure or args.transition or args.runway or args.db:
            raise UserError("--scenario names the procedure; --db/--airport/--procedure/"
                            "--transition/--runway are not used with it")
        scenario, default = Path(args.scenario), Path(args.scenario).stem
    else:
        scenario = scenario_from_args(args)
        default = scenario["name"]
    out = out_path(args.out, results_dir() / default)
    inputs = [args.scenario or (scenario["procedure"]["db"] if args.db else None)]
    check_out_dir(out, args.overwrite, KIND, inputs)            # before any work
    from fms_testbed.evaluation.outcome import EXIT_CODES
    from fms_testbed.run.api import run_scenario

    from fms_testbed.cli.run import with_truth_model
    overrides = with_truth_model(overrides_from_args(args), args)
    if args.takeoff:
        overrides.setdefault("procedure", {})["start"] = "takeoff"
    res = run_scenario(scenario, seed=args.seed, overrides=overrides, progress=None)
    res.save(out, csv=args.csv, plots=not args.no_plots, overwrite=args.overwrite, kind=KIND)
    print_results(res)
    if res.summary.get("takeoff"):
        print(takeoff_line(res.summary["takeoff"]))
    return EXIT_CODES[res.summary["status"]]


def takeoff_line(to: dict) -> str:
    """One line on a takeoff start (the summary's ``takeoff`` block; m, kt and ft at this edge)."""
    from fms_testbed.core.units import FT_M, KT_MPS

    t, ev = to["times_s"], to["events"]
    parts = [f"takeoff {to['runway']}: VR {to['vr_cas_mps'] / KT_MPS:.0f} kt, "
             f"V2 {to['v2_cas_mps'] / KT_MPS:.0f} kt"]
    if "ground_roll_m" in to:
        parts.append(f"ground roll {to['ground_roll_m']:.0f} m, lift-off at {t['liftoff']:.1f} s")
    if "time_to_v2_s" in to:
        parts.append(f"V2 at {to['time_to_v2_s']:.1f} s")
    if "handover_s" in to:
        parts.append(f"handover at {to['handover_s']:.1f} s, "
                     f"{ev['handover']['height_m'] / FT_M:.0f} ft above the runway")
    parts.append(f"centreline within {to['max_centreline_dev_ground_m']:.1f} m on the ground")
    return "  " + ", ".join(parts)


def register(sub) -> None:
    """Add ``fly`` to the CLI."""
    p = sub.add_parser("fly", help="fly a real ARINC-424 procedure (SID/STAR/approach) in JSBSim")
    p.add_argument("--scenario", help="procedure scenario YAML (with a 'procedure:' block)")
    p.add_argument("--db", help="ARINC-424 file (default: the embedded excerpt)")
    p.add_argument("--airport", help="ICAO airport, e.g. KSEA")
    p.add_argument("--procedure", help="procedure ident, e.g. ISBRG1 or R16CY")
    p.add_argument("--transition", help="en-route (SID/STAR) or approach transition")
    p.add_argument("--runway", help="runway, e.g. 34R (SID/STAR runway transition)")
    add_override_options(p)
    from fms_testbed.cli.run import add_truth_model_option
    add_truth_model_option(p)
    p.add_argument("--takeoff", action="store_true",
                   help="SIDs: start at rest on the runway threshold with a takeoff roll "
                        "(procedure.start: takeoff; default: airborne over the runway end)")
    p.add_argument("--out", help="output folder (default results/<airport>-<procedure>)")
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_fly)
