"""Navigation errors reach the true track: one RNP approach flown on truth and on SINS presets.

Flies ``scenarios/approach-kbfi-h14rz-rf.yaml`` (KBFI H14RZ ZUVEN, RNAV (RNP) with RF legs,
embedded database, 737, calm air) with ``run_scenario`` and ``navigation`` set to truth and to
``{source: sins, imu: PRESET}`` for each ``--imus`` preset (seed ``--seed``), and writes FTE95,
NSE95, TSE95 and the RNP verdict from each flight's summary as Markdown to
``docs/results/fly_nav.md``. Guidance keeps the *navigation* solution on the path, so FTE stays
small while the aircraft drifts with the navigation error: TSE ≈ the cross-track part of NSE.

    python bench/bench_fly_nav.py [--imus HG1700 ADIS16488 consumer_MEMS] [--seed 0]
                                  [--md fly_nav.md]
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.data import scenarios_dir  # noqa: E402
from fms_testbed.run import run_scenario  # noqa: E402

SCENARIO = "approach-kbfi-h14rz-rf.yaml"


def row(label: str, s) -> list[str]:
    """FTE95, NSE95, TSE95 (m) and the RNP verdict of one flight's summary."""
    e, rnp = s["errors"], s["rnp"]

    def p95(kind):
        v = e[kind]["all"]["p95_m"]
        return "n/a" if v is None else f"{v:,.1f}"

    verdict = ("contained" if rnp["contained"] else
               "NOT contained (legs " + ", ".join(str(i) for i in rnp["legs_not_contained"]) + ")")
    return [label, p95("fte"), p95("nse"), p95("tse"), f"{rnp['min_rnp_nm']:g} NM: {verdict}",
            f"{s['status']}"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--imus", nargs="+", default=["HG1700", "ADIS16488", "consumer_MEMS"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--md", default="fly_nav.md", help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "truth and one IMU")
    args = ap.parse_args()
    if args.quick:
        args.imus = args.imus[:1]
    logging.basicConfig(level=logging.WARNING)
    path = scenarios_dir() / SCENARIO
    rows = []
    for imu in [None, *args.imus]:
        nav = {"source": "truth"} if imu is None else {"source": "sins", "imu": imu}
        res = run_scenario(path, seed=args.seed, overrides={"navigation": nav}, progress=False)
        rows.append(row("truth" if imu is None else f"SINS `{imu}`", res.summary))
        print(" | ".join(rows[-1]), flush=True)
    report.write(args.md, report.table(
        ["navigation", "FTE95, m", "NSE95, m", "TSE95, m", "RNP", "status"], rows),
        note=f"`{SCENARIO}` (KBFI H14RZ ZUVEN, RF legs, embedded database), 737, calm air, seed "
             f"{args.seed}; SINS with the default stationary alignment and baro-damped vertical "
             "channel; legs numbered from 0.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
