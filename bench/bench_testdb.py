"""Phase 1 of Danilin's method: fly the synthetic test database and compare every outcome with
the outcome it was designed to have (its manifest).

    python bench/bench_testdb.py [--out DIR] [--workers 1] [--md testdb.md]

Writes the test database with ``fms-testbed regress testdb --out DIR/testdb.dat`` (the 132-column
file and ``DIR/testdb.dat.manifest.json``), flies it with ``fms-testbed regress run --db
DIR/testdb.dat --workers N --out DIR/run`` (737, calm air, truth navigation; resumed when
``DIR/run`` already holds it) and checks the run against the manifest
(:mod:`fms_testbed.campaign.manifest`). The table lists, per procedure, what it was designed to
give and what the run gave; the headline is phase 1's residual-error rate (disagreements over
the manifest's cases, 95 % Wilson interval) against the criterion ≤ 2 %. Expectations are the
manifest's (``fms_testbed/procedures/testdb.py``), never taken from a run.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="working folder (default: a temporary one)")
    ap.add_argument("--workers", type=int, default=1, help="local workers (default 1)")
    ap.add_argument("--md", default="testdb.md", help="table in docs/results/ ('' to skip)")
    report.add_quick(ap, "the first 6 cases of the test database")
    args = ap.parse_args()

    from fms_testbed.campaign.manifest import PHASE1_MAX_RATE, check_run
    from fms_testbed.campaign.store import read_flights, read_run_json
    from fms_testbed.legs.types import LEG_TYPES

    work = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="testdb-"))
    work.mkdir(parents=True, exist_ok=True)
    db = work / "testdb.dat"
    run = work / "run"
    report.run_cli(["regress", "testdb", "--out", str(db)], expect=db)
    _, wall, out = report.run_cli(["regress", "run", "--db", str(db), "--workers",
                                   str(args.workers), "--no-progress", "--out", str(run),
                                   *(["--limit", "6"] if args.quick else [])])
    print(out.strip())
    info = read_run_json(run)
    df = read_flights(run)
    mc = check_run(run)
    if mc is None:
        raise SystemExit(f"{run}: no manifest found for {info['database']['path']}")
    t = mc.table

    # coverage measured from the run's rows: the path terminators each flown case flew
    flown = df[df["status"].isin(["ok", "diverged", "incomplete", "envelope_exceeded",
                                  "not_contained", "constraints_missed"])]
    cover = Counter(c for legs in flown["leg_codes"] for c in set(legs.split()))
    missing = sorted(set(LEG_TYPES) - set(cover))
    coding = Counter(zip(t["coding"], t["agrees"]))
    rows = [
        ("designed cases (valid / miscoded)",
         f"{len(t)} ({(t['coding'] == 'valid').sum()} / {(t['coding'] == 'miscoded').sum()})",
         "≈ 50"),
        ("valid cases agreeing (flown ok, monitor as designed)",
         f"{coding[('valid', 'yes')]} of {coding[('valid', 'yes')] + coding[('valid', 'NO')]}",
         "all"),
        ("miscoded cases agreeing (refused or flagged as designed)",
         f"{coding[('miscoded', 'yes')]} of "
         f"{coding[('miscoded', 'yes')] + coding[('miscoded', 'NO')]}", "all"),
        ("path terminators flown (of 23)",
         f"{len(cover)}" + (f" (not flown: {', '.join(missing)})" if missing else ""), "23"),
        ("**phase-1 residual-error rate** (disagreements / designed cases)",
         f"**{100 * mc.rate:.1f} %** [{100 * mc.ci_low:.1f}, {100 * mc.ci_high:.1f}] "
         f"({mc.disagreements} of {mc.cases})", f"≤ {100 * PHASE1_MAX_RATE:.0f} %"),
        ("criterion met", "yes" if mc.criterion_met else "**no**", "yes"),
        ("flights / elapsed time of the run (every session)",
         f"{sum(x['cases_flown'] for x in info['sessions'])} cases, "
         f"{sum(x['elapsed_s'] for x in info['sessions']):.0f} s on "
         f"{info['sessions'][0]['workers']} worker(s) (a shared, loaded machine)", "–"),
    ]
    body = [report.table(("quantity", "measured", "goal"), rows), "",
            "Per procedure (expected = the manifest's design intent; outcome = this run):", ""]
    per = []
    for _, r in t.iterrows():
        what = r["why not"] if r["agrees"] != "yes" else r["reason / findings"]
        what = (what or "").replace("\n", " ")
        what = what if len(what) <= 160 else what[:157] + "…"
        flew = isinstance(r["status"], str)           # a case outside --limit has no row
        per.append((r["procedure"], r["coding"], r["legs"], r["expected"],
                    f"{r['status']} / {r['monitor']}" if flew else "not flown", r["agrees"], what))
    body.append(report.table(("procedure", "coding", "legs flown", "expected",
                              "status / monitor", "agrees", "why not / what it said"), per))
    note = ("Phase 1 of Danilin's method (seed 000): the synthesised test database "
            "(`fms-testbed regress testdb`) flown with the 737 in calm air on truth navigation, "
            "each outcome compared with the manifest written beside the database. Criterion "
            "(docs/regression.md, \"Phase 1\"): residual-error rate ≤ 2 % with every designed "
            f"case flown. Database SHA-256 {info['database']['sha256'][:16]}….")
    report.write(args.md, "\n".join(body), note)
    return 0


if __name__ == "__main__":
    sys.exit(main())
