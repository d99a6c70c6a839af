"""Fly ≥ 30 real procedures from the FAA CIFP and print the issue-6 goal table.

Selection (reproducible, no hand-picking of results): for each airport in ``AIRPORTS`` in order,
the first SID that has a runway transition (flown from its first runway transition through the
common route), the first STAR that has a runway transition (common route + first runway
transition; no en-route transition), and the first RNAV approach ('R…', or RNAV (RNP) 'H…')
with an RF leg in its final or in an approach transition (that transition + final, to the MAP),
else the first RNAV approach with its first transition. Narrow-body jet (737), calm air, navigation = truth, seed 0.

    python bench/fly_table.py [--db FILE] [--aircraft 737] [--max N] [--out results/fly_table]
                              [--md fly_table.md]

``--db`` defaults to the FAA CIFP beside the repository (``../shared/data/cifp/FAACIFP18_230126``).
Writes ``table.json`` into ``--out`` and the table as Markdown to ``docs/results/fly_table.md``
(``--md ''``: do not).

Columns: FTE95 straight / all and FTE max (m), worst altitude and speed constraint miss (ft, kt
beyond the tolerance-free limit), legs entered / legs, status. Goals: FTE95 ≤ 30 m straight,
≤ 150 m all, max ≤ 185 m (0.1 NM), every constraint met, no leg skipped or repeated.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

AIRPORTS = ("KSEA", "KJFK", "KDEN", "KSFO", "KLAX", "KATL", "KORD", "KPHX", "KLAS", "KBOS",
            "KDCA", "KMSP", "KSLC", "KPDX", "KIAD", "KCLT", "KDFW", "KIAH", "KMIA", "KEWR")
CIFP = report.CIFP


def pick(db, airport: str) -> list[dict]:
    """Procedure specs for one airport (module docstring rule)."""
    from fms_testbed.core.errors import UserError

    try:
        seqs = db.sequences(airport)
    except UserError:  # airport without procedures in this cycle
        return []
    out = []
    for kind in ("D", "E"):
        for s in seqs:
            if s.proc_type == kind and s.transition.startswith("RW"):
                out.append({"airport": airport, "procedure": s.proc_id, "runway": s.transition})
                break
    out.extend(pick_approach(seqs, airport))
    return out


def _has_rf(seq) -> bool:
    return any(lg.path_term == "RF" for lg in seq.legs if not lg.missed_approach_start)


def pick_approach(seqs, airport: str) -> list[dict]:
    """The first RNAV approach (ident 'R…' or RNAV(RNP) 'H…', file order) with an RF leg in its
    final or in one of its approach transitions (that transition is flown), else the first
    RNAV approach with its first transition."""
    ids = list(dict.fromkeys(s.proc_id for s in seqs if s.proc_type == "F"
                             and s.proc_id[:1] in ("R", "H")))
    fallback = None
    for pid in ids:
        parts = [s for s in seqs if s.proc_type == "F" and s.proc_id == pid]
        finals = [s for s in parts if s.route_type != "A"]
        trans = [s for s in parts if s.route_type == "A"]
        if not finals:
            continue
        rf_trans = [t for t in trans if _has_rf(t)]
        spec = {"airport": airport, "procedure": pid}
        if rf_trans or _has_rf(finals[0]):
            if rf_trans or trans:
                spec["transition"] = (rf_trans or trans)[0].transition
            return [spec]
        if fallback is None:
            if trans:
                spec["transition"] = trans[0].transition
            fallback = spec
    return [fallback] if fallback else []


def worst_misses(cons: list[dict]) -> tuple[float, float]:
    """Largest altitude miss (ft) and speed miss (kt) beyond the coded limit (0 when met)."""
    alt = spd = 0.0
    for c in cons:
        a = c.get("alt_ft")
        lo, hi = (c.get("window_ft") or [None, None])
        if a is not None and lo is not None:
            alt = max(alt, lo - a)
        if a is not None and hi is not None:
            alt = max(alt, a - hi)
        if "cas_kt" in c:
            lim = float(str(c["speed_limit_kt"]).lstrip("+-@"))
            d = c["speed_limit_kt"][0]
            if d in "-@" or d.isdigit():
                spd = max(spd, c["cas_kt"] - lim)
            if d in "+@" or d.isdigit():
                spd = max(spd, lim - c["cas_kt"])
    return alt, spd


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(CIFP),
                    help="ARINC-424 file (default: the FAA CIFP beside the repository)")
    ap.add_argument("--aircraft", default="737")
    ap.add_argument("--max", type=int, default=45, help="stop after this many procedures")
    ap.add_argument("--out", default="results/fly_table", help="folder for table.json")
    ap.add_argument("--md", default="fly_table.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "3 procedures")
    args = ap.parse_args()
    if args.quick:
        args.max = 3
        args.out = "results/quick/fly_table"
    if not Path(args.db).exists():
        raise SystemExit(f"{args.db}: no such ARINC-424 file (give --db)")
    logging.basicConfig(level=logging.WARNING)
    from fms_testbed.procedures.database import load_database
    from fms_testbed.core.errors import UserError
    from fms_testbed.loop.procedure import prepare
    from fms_testbed.run import fly_procedure

    db = load_database(args.db)
    specs = [s for a in AIRPORTS for s in pick(db, a)][:args.max]
    rows = []
    t0 = time.perf_counter()
    hdr = (f"{'procedure':34s} {'type':8s} {'legs':>4s} {'NM':>6s} {'FTE95 str':>9s} "
           f"{'FTE95':>7s} {'FTEmax':>7s} {'alt miss':>8s} {'spd miss':>8s} {'legs ok':>7s} status")
    print(hdr)
    for spec in specs:
        raw = {"aircraft": args.aircraft, "procedure": {"db": args.db, **spec}}
        try:
            scn, ps, fp, _ = prepare(raw, db=db)
            res = fly_procedure(scn, ps, fp, db, progress=False)
        except UserError as exc:
            rows.append({**spec, "status": "not built", "reason": str(exc)})
            print(f"{spec['airport']} {spec['procedure']} {spec.get('runway', '')}"
                  f"{spec.get('transition', '')}: not built: {exc}")
            continue
        s = res.summary
        e = s["errors"]
        am, sm = worst_misses(s["constraints"])
        q = s["sequencing"]
        row = {**spec, "name": s["procedure"]["name"], "type": s["procedure"]["type"],
               "legs": s["procedure"]["legs"], "length_nm": s["procedure"]["length_nm"],
               "fte95_straight_m": e["fte"]["straight"]["p95_m"], "fte95_m": e["fte"]["all"]["p95_m"],
               "fte_max_m": e["fte"]["all"]["max_m"], "alt_miss_ft": round(am), "spd_miss_kt":
               round(sm, 1), "constraints": len(s["constraints"]),
               "constraints_met": s["constraints_met"], "legs_entered": q["legs_entered"],
               "skipped": q["skipped"], "repeated": q["repeated"], "status": s["status"],
               "reason": s["reason"], "duration_s": s["duration_s"]}
        rows.append(row)
        legs_ok = f"{q['legs_entered']}/{q['legs']}" + ("" if not (q["skipped"] or q["repeated"])
                                                         else "!")
        def num(v, w):
            return f"{v:{w}.1f}" if v is not None else f"{'n/a':>{w}s}"
        print(f"{row['name'][:34]:34s} {row['type']:8s} {len(row['legs']):4d} "
              f"{row['length_nm']:6.1f} {num(row['fte95_straight_m'], 9)} "
              f"{num(row['fte95_m'], 7)} {num(row['fte_max_m'], 7)} {am:8.0f} {sm:8.1f} "
              f"{legs_ok:>7s} "
              f"{s['status']}" + ("" if s["status"] == "ok" else f" ({s['reason']})"), flush=True)
    flown = [r for r in rows if "fte95_m" in r]
    headings = [r["name"] for r in flown if r["fte95_m"] is None]
    if headings:
        print(f"no path-defined leg (heading legs only, no FTE): {', '.join(headings)}")
    scored = [r for r in flown if r["fte95_m"] is not None]
    ok = [r for r in flown if r["status"] == "ok"]
    print(f"\n{len(rows)} procedures, {len(flown)} flown, {len(ok)} completed, "
          f"{time.perf_counter() - t0:.0f} s wall")
    if flown:
        def frac(cond):
            return f"{sum(1 for r in flown if cond(r))}/{len(flown)}"
        def frac_s(cond):
            return f"{sum(1 for r in scored if cond(r))}/{len(scored)}"
        print(f"FTE95 straight ≤ 30 m: {frac_s(lambda r: (r['fte95_straight_m'] or 0) <= 30)}; "
              f"FTE95 ≤ 150 m: {frac_s(lambda r: r['fte95_m'] <= 150)}; "
              f"FTE max ≤ 185 m: {frac_s(lambda r: r['fte_max_m'] <= 185.2)}; "
              f"constraints met (±50 ft, ±5 kt): {frac(lambda r: r['constraints_met'])}; "
              f"no leg skipped/repeated: {frac(lambda r: not r['skipped'] and not r['repeated'])}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "table.json").write_text(json.dumps(rows, indent=1, default=str) + "\n")
    print(f"table written to {out / 'table.json'}")
    report.write(args.md, markdown(rows, time.perf_counter() - t0),
                 note=f"Database `{Path(args.db).name}`, aircraft {args.aircraft}, calm air, "
                      "navigation = truth, seed 0; selection rule in the script's docstring "
                      "(no hand-picking).")


def markdown(rows: list[dict], wall_s: float) -> str:
    """The per-procedure table and the goal summary as Markdown."""
    def num(v, fmt=".2f"):
        return "n/a" if v is None else format(v, fmt)

    body = []
    for r in rows:
        if "fte95_m" not in r:
            name = " ".join(x for x in (r["airport"], r["procedure"], r.get("runway", ""),
                                        r.get("transition", "")) if x)
            body.append([name, "", "", "", "", "", "", "", "", "", f"not built: {r['reason']}"])
            continue
        q = f"{r['legs_entered']}/{len(r['legs'])}" + ("" if not (r["skipped"] or r["repeated"])
                                                       else " (!)")
        body.append([r["name"], r["type"], " ".join(r["legs"]), num(r["length_nm"], ".1f"),
                     num(r["fte95_straight_m"]), num(r["fte95_m"]), num(r["fte_max_m"]),
                     r["alt_miss_ft"], num(r["spd_miss_kt"], ".1f"), q,
                     r["status"] + ("" if r["status"] == "ok" else f" ({r['reason']})")])
    flown = [r for r in rows if "fte95_m" in r]
    scored = [r for r in flown if r["fte95_m"] is not None]

    def worst(key):
        r = max(scored, key=lambda r: r[key] or 0.0)
        return f"worst {r[key]:.2f} m, {r['name']}"

    def count(rs, cond):
        return f"{sum(1 for r in rs if cond(r))}/{len(rs)}"

    n_cons = sum(r["constraints"] for r in flown)
    goals = [
        ["FTE95 ≤ 30 m on straight segments",
         count(scored, lambda r: (r["fte95_straight_m"] or 0) <= 30) + f" ({worst('fte95_straight_m')})"],
        ["FTE95 ≤ 150 m including turns",
         count(scored, lambda r: r["fte95_m"] <= 150) + f" ({worst('fte95_m')})"],
        ["max FTE ≤ 0.1 NM (185 m)",
         count(scored, lambda r: r["fte_max_m"] <= 185.2) + f" ({worst('fte_max_m')})"],
        ["every altitude and speed constraint met (50 ft, 5 kt)",
         count(flown, lambda r: r["constraints_met"]) + f" procedures ({n_cons} constraints)"],
        ["no leg skipped or flown twice",
         count(flown, lambda r: not r["skipped"] and not r["repeated"])],
        ["flown to the end (status ok)", count(flown, lambda r: r["status"] == "ok")],
    ]
    no_fte = [r["name"] for r in flown if r["fte95_m"] is None]
    text = [f"{len(rows)} procedures selected, {len(flown)} flown, {wall_s:.0f} s wall.\n",
            report.table(["goal", "result"], goals), "",
            report.table(["procedure", "type", "legs", "NM", "FTE95 straight, m", "FTE95, m",
                          "FTE max, m", "worst alt miss, ft", "worst speed miss, kt",
                          "legs entered", "status"], body), "",
            "\"alt miss\"/\"speed miss\": the largest excursion beyond a coded altitude window / "
            "speed limit over the procedure's constrained fixes (0 when inside); the compliance "
            "check allows 50 ft and 5 kt."]
    if no_fte:
        text.append(f"\nNo FTE (heading legs only, no defined ground track): {', '.join(no_fte)}.")
    return "\n".join(text)


if __name__ == "__main__":
    main()
