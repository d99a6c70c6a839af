"""``fms-testbed fly``: fly a real ARINC-424 procedure (from the command line or a scenario file).

    fms-testbed fly --db FILE --airport KSEA --procedure ISBRG1 --runway 34R --aircraft 737 \\
        [--transition T] [--wind 270/20] [--nav sins --imu PRESET] [--seed N] --out DIR
    fms-testbed fly --scenario scenarios/demo-sid.yaml [--out DIR]

Prints one line per result group (status, errors, RNP, constraints, sequencing) and writes
``timeseries.parquet``, ``summary.json`` and the plots into ``--out``. Exit code 0 when the
procedure was flown to its end, 1 otherwise, 2 on a user error.
"""

from __future__ import annotations

import re
from pathlib import Path

from .errors import UserError
from .paths import results_dir


def parse_wind(text: str) -> dict:
    """'DIR/SPEED' (deg true it blows from / kt) → the scenario's ``wind`` mapping."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*/\s*(\d+(?:\.\d*)?)\s*", text or "")
    if not m:
        raise UserError(f"--wind {text!r}: expected DIR/SPEED, e.g. 270/20 (deg true from, kt)")
    d, s = float(m.group(1)), float(m.group(2))
    if d > 360 or s > 200:
        raise UserError(f"--wind {text!r}: direction must be 0-360 deg and speed ≤ 200 kt")
    return {"from_deg": d, "speed_kt": s}


def scenario_from_args(args) -> dict:
    """The scenario mapping the command-line options describe."""
    if not (args.airport and args.procedure):
        raise UserError("fly needs --scenario FILE, or --airport and --procedure")
    proc = {"db": args.db or "embedded", "airport": args.airport.upper(),
            "procedure": args.procedure.upper()}
    if args.transition:
        proc["transition"] = args.transition.upper()
    if args.runway:
        proc["runway"] = args.runway.upper()
    if args.rnp is not None:
        proc["rnp_nm"] = args.rnp
    raw = {"aircraft": args.aircraft, "procedure": proc,
           "name": f"{proc['airport']}-{proc['procedure']}".lower()}
    if args.wind:
        raw["wind"] = parse_wind(args.wind)
    if args.nav == "sins":
        if not args.imu:
            raise UserError("--nav sins needs --imu PRESET")
        raw["navigation"] = {"source": "sins", "imu": args.imu}
    elif args.imu:
        raise UserError("--imu is only used with --nav sins")
    return raw


def _print(res) -> None:
    s = res.summary
    p = s["procedure"]
    print(f"{p['name']} ({p['type']}, {len(p['legs'])} legs, {p['length_nm']} NM, monitor "
          f"{p['monitor_status']}): {s['status']} ({s['reason']}), {s['duration_s']:.0f} s flown "
          f"in {s['wall_time_s']:.1f} s wall")
    e = s.get("errors", {})
    if e:
        f, t, n = e["fte"], e["tse"], e["nse"]
        print(f"  FTE95 {f['all']['p95_m']} m (straight {f['straight']['p95_m']} m), FTE max "
              f"{f['all']['max_m']} m; TSE95 {t['all']['p95_m']} m; NSE95 {n['all']['p95_m']} m")
        r = s["rnp"]
        print(f"  RNP {r['min_rnp_nm']} NM: {'contained' if r['contained'] else 'NOT contained'}"
              + (f" (legs {r['legs_not_contained']})" if r["legs_not_contained"] else ""))
    bad = [c for c in s.get("constraints", []) if c.get("ok") is False]
    print(f"  constraints: {len(s.get('constraints', []))} checked, {len(bad)} missed"
          + "".join(f"; leg {c['leg']} {c['fix']}: {c.get('why')}" for c in bad))
    q = s.get("sequencing", {})
    print(f"  sequencing: {q.get('legs_entered')}/{q.get('legs')} legs entered, skipped "
          f"{q.get('skipped')}, repeated {q.get('repeated')}")
    if res.out_dir is not None:
        print(f"  outputs in {res.out_dir}: " + ", ".join(["timeseries.parquet", "summary.json"]
                                                        + s.get("plots", [])))


def cmd_fly(args) -> int:
    """Fly one procedure."""
    from .fly import fly_procedure, load_procedure_scenario, prepare

    if args.scenario:
        scn, spec, fp, db = load_procedure_scenario(args.scenario)
        default = Path(args.scenario).stem
    else:
        raw = scenario_from_args(args)
        scn, spec, fp, db = prepare(raw, "<command line>")
        default = raw["name"]
    out = Path(args.out) if args.out else results_dir() / default
    res = fly_procedure(scn, spec, fp, db, out_dir=out, seed=args.seed, csv=args.csv,
                        plots=not args.no_plots, progress=None)
    _print(res)
    return 0 if res.summary["status"] == "ok" else 1


def register(sub) -> None:
    """Add ``fly`` to the CLI."""
    p = sub.add_parser("fly", help="fly a real ARINC-424 procedure (SID/STAR/approach) in JSBSim")
    p.add_argument("--scenario", help="procedure scenario YAML (with a 'procedure:' block)")
    p.add_argument("--db", help="ARINC-424 file (default: the embedded excerpt)")
    p.add_argument("--airport", help="ICAO airport, e.g. KSEA")
    p.add_argument("--procedure", help="procedure ident, e.g. ISBRG1 or R16CY")
    p.add_argument("--transition", help="en-route (SID/STAR) or approach transition")
    p.add_argument("--runway", help="runway, e.g. 34R (SID/STAR runway transition)")
    p.add_argument("--aircraft", default="737", help="aircraft name or YAML (default 737)")
    p.add_argument("--wind", help="steady wind DIR/SPEED, deg true from / kt, e.g. 270/20")
    p.add_argument("--nav", choices=("truth", "sins"), default="truth",
                   help="navigation source guidance flies on")
    p.add_argument("--imu", help="SINS preset (with --nav sins)")
    p.add_argument("--rnp", type=float, help="RNP, NM, where the record codes none")
    p.add_argument("--seed", type=int, default=0, help="seed for turbulence and sensor errors")
    p.add_argument("--out", help="output folder (default results/<airport>-<procedure>)")
    p.add_argument("--csv", action="store_true", help="also write timeseries.csv")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.set_defaults(func=cmd_fly)
