"""The class-3 check of a whole cycle against an independent reading of the same records.

Runs ``procedures check`` on a database (or reads the ``procedures_check.parquet`` of a run
given with ``--run``), counts the class-3 findings of the coded-numbers check by kind and lists
the worst of each kind; then reads every leg record again *from its text* (the columns of the
ARINC-424 layout, not the package's parser) and recomputes each redundant number with another
geodesic (Vincenty's inverse, :func:`fms_testbed.core.geodesy.inverse`; the monitor uses
geographiclib) and the same tolerances. A transition is independently *suspect* when any of
its numbers disagrees beyond the tolerance. The false-positive rate is the share of the
transitions the independent reading finds clean that the monitor flags; the misses, the share
of the suspect ones it does not flag. A seeded sample stratified by procedure type and
verdict (``--per-stratum`` transitions each) is listed for review with its largest
disagreement.

    python bench/bench_coding.py [--db FILE] [--run DIR] [--workers 2] [--seed 7]
                                 [--per-stratum 5] [--airports A B ...]
                                 [--md procedures_coding.md] [--quick]

``--quick``: only the airports of ``bench_check.QUICK_AIRPORTS`` (the whole file is still read).
"""

from __future__ import annotations

import argparse
import math
import random
import sys
import tempfile
from collections import Counter
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from bench_check import QUICK_AIRPORTS  # noqa: E402

from fms_testbed.core.geodesy import inverse, wrap180, wrap360  # noqa: E402
from fms_testbed.core.units import NM_M  # noqa: E402
from fms_testbed.legs.types import LEG_TYPES  # noqa: E402
from fms_testbed.path.coding import TOL, variation_tol_deg  # noqa: E402
from fms_testbed.procedures.database import load_database  # noqa: E402


def _num(text: str, scale: float) -> float | None:
    """A numeric field of a record (blank: None), times ``scale``."""
    t = text.strip()
    if not t or not t.lstrip("-+").isdigit():
        return None
    return int(t) * scale


def raw_fields(line: str) -> dict:
    """The redundant numbers of a leg record, read from its 1-based columns: path terminator
    48-49, turn 44, radius 57-62 (thousandths NM), theta 63-66 and rho 67-70 (tenths), course
    71-74 (tenths; 'T' true), distance 75-78 (tenths NM; 'T' a time), all SI."""
    crs = line[70:74]
    dist = line[74:78]
    return {"pt": line[47:49], "turn": line[43:44],
            "radius_m": _num(line[56:62], 0.001 * NM_M),
            "theta_deg": _num(line[62:66], 0.1), "rho_m": _num(line[66:70], 0.1 * NM_M),
            "course_deg": _num(crs[:3] if crs.endswith("T") else crs,
                               1.0 if crs.endswith("T") else 0.1),
            "course_true": crs.endswith("T"),
            "distance_m": None if dist.startswith("T") else _num(dist, 0.1 * NM_M)}


def _variation(db, seq, rec) -> float:
    apt = db.airports.get(seq.airport)
    nav = db.find_fix(rec.navaid, seq.airport)
    if nav is not None and nav.section in ("D ", "PI"):
        return nav.magvar_deg
    return apt.magvar_deg if apt else 0.0


def _leg_errors(db, seq, rec, raw, prev, fix) -> list[tuple[str, float, float]]:
    """(kind, |error|, tolerance) of every redundant number of one leg (units: m or deg)."""
    out = []
    var = _variation(db, seq, rec)
    ctol = TOL.course_deg + variation_tol_deg(var, raw["course_true"])
    crs = None if raw["course_deg"] is None else wrap360(
        raw["course_deg"] + (0.0 if raw["course_true"] else var))
    if raw["pt"] in ("TF", "CF") and prev is not None:
        d, az1, az2 = inverse(prev.lat_deg, prev.lon_deg, fix.lat_deg, fix.lon_deg)
        if d >= 1.0:
            if raw["distance_m"] is not None:
                out.append(("distance", abs(raw["distance_m"] - d), TOL.distance_m))
            if crs is not None:
                e = abs(wrap180(crs - (az1 if raw["pt"] == "TF" else az2)))
                if not (raw["pt"] == "CF" and e > 90.0):
                    out.append(("course", e, ctol))
    elif raw["pt"] == "RF" and prev is not None:
        c = db.find_fix(rec.centre, seq.airport)
        if c is not None:
            d1, a1, _ = inverse(c.lat_deg, c.lon_deg, fix.lat_deg, fix.lon_deg)
            d0, a0, _ = inverse(c.lat_deg, c.lon_deg, prev.lat_deg, prev.lon_deg)
            if raw["radius_m"]:
                out.append(("rf_radius", max(abs(d0 - raw["radius_m"]),
                                             abs(d1 - raw["radius_m"])), TOL.radius_m))
            turn = raw["turn"] if raw["turn"] in "LR" and raw["turn"].strip() else (
                "R" if wrap180(a1 - a0) > 0 else "L")
            sweep = (a1 - a0) % 360.0 if turn == "R" else (a0 - a1) % 360.0
            if raw["distance_m"] is not None:
                arc = 0.5 * (d0 + d1) * math.radians(sweep)
                out.append(("distance", abs(raw["distance_m"] - arc), TOL.distance_m))
            if crs is not None:
                tan = wrap360(a1 + (90.0 if turn == "R" else -90.0))
                out.append(("rf_tangent", abs(wrap180(crs - tan)), ctol))
    return out


def independent(db, text_lines: list[str], airports: list[str]) -> dict:
    """Per transition (airport, procedure, transition, lines) of ``airports``, the worst
    (error / tol, error, tol, line) of each kind that exceeds its tolerance, from the
    records' text."""
    out = {}
    for airport in airports:
        for seq in db.sequences(airport):
            bad: dict[str, tuple] = {}
            prev = None
            for rec in seq.legs:
                raw = raw_fields(text_lines[rec.line - 1])
                fix = db.find_fix(rec.fix, airport)
                if fix is not None:
                    for kind, err, tol in _leg_errors(db, seq, rec, raw, prev, fix):
                        if err > tol and err / tol > bad.get(kind, (0,))[0]:
                            bad[kind] = (err / tol, err, tol, rec.line)
                prev = fix if LEG_TYPES[rec.path_term].ends_at_fix else None
            key = (airport, seq.proc_id, seq.transition, f"{seq.lines[0]}-{seq.lines[-1]}"
                   if seq.lines else "")
            out[key] = bad
    return out


def compare(df: pd.DataFrame, ind: dict) -> pd.DataFrame:
    """The check table with the independent verdict beside the monitor's."""
    df = df.copy()
    keys = list(zip(df["airport"], df["procedure"], df["transition"], df["lines"]))
    df["ind_kinds"] = [",".join(sorted(ind.get(k, {}))) for k in keys]
    df["ind_worst"] = [max((v[0] for v in ind.get(k, {}).values()), default=0.0) for k in keys]
    mon = df["coding"].fillna("").map(lambda s: set(x for x in s.split(",") if x)
                                      & {"distance", "course", "rf_radius", "rf_tangent"})
    df["mon_suspect"] = mon.map(bool)
    df["ind_suspect"] = df["ind_kinds"] != ""
    return df


def sample(df: pd.DataFrame, seed: int, per_stratum: int) -> pd.DataFrame:
    """A seeded sample stratified by procedure type × monitor verdict × independent verdict."""
    rng = random.Random(seed)
    parts = []
    for _, g in df.groupby(["type", "mon_suspect", "ind_suspect"]):
        idx = sorted(g.index)
        parts.append(df.loc[rng.sample(idx, min(per_stratum, len(idx)))])
    return pd.concat(parts) if parts else df.iloc[:0]


def markdown(df: pd.DataFrame, summary: dict, smp: pd.DataFrame) -> str:
    """Counts by kind, the agreement with the independent reading, the worst findings and the
    sample."""
    n = len(df)
    clean = df[~df["ind_suspect"]]
    susp = df[df["ind_suspect"]]
    fp = int(clean["mon_suspect"].sum())
    miss = int((~susp["mon_suspect"]).sum())
    st = summary["by_status"]
    rows = [["transitions", f"{n:,}"],
            ["status coding_suspect", f"{st.get('coding_suspect', 0):,}"],
            ["class 3 found (coded numbers or loops)", f"{summary['class3_transitions']:,}"],
            ["independently suspect (records' text, Vincenty)", f"{len(susp):,}"],
            ["flagged by the monitor, independently clean (false positives)",
             f"{fp} of {len(clean):,} = {100 * fp / max(len(clean), 1):.3f} %"],
            ["independently suspect, not flagged (misses)",
             f"{miss} of {len(susp):,} = {100 * miss / max(len(susp), 1):.2f} %"]]
    kinds = [[k, f"{v:,}"] for k, v in sorted(summary["class3_by_kind"].items())]
    worst = []
    for r in df.sort_values("ind_worst", ascending=False).head(12).itertuples():
        f = next((x for x in str(r.findings).split("; ") if " coding: " in x), "")
        worst.append([f"{r.airport} {r.type} {r.procedure} {r.transition or '(common)'}",
                      f"{r.ind_worst:.1f}", f.split(" coding: ", 1)[-1]])
    smp_rows = [[f"{r.airport} {r.type} {r.procedure} {r.transition or '(common)'}",
                 r.status, r.ind_kinds or "—", "yes" if r.mon_suspect == r.ind_suspect
                 else "**no**"] for r in smp.itertuples()]
    return "\n".join([
        report.table(["metric", "result"], rows), "",
        "**Class-3 findings by kind** (transitions with at least one)\n",
        report.table(["kind", "transitions"], kinds), "",
        "**The largest disagreements** (error over its tolerance, the monitor's finding)\n",
        report.table(["transition", "error / tolerance", "finding"], worst), "",
        "**Seeded stratified sample** (procedure type × monitor verdict × independent "
        "verdict)\n",
        report.table(["transition", "status", "independent kinds", "verdicts agree"],
                     smp_rows)])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--db", default=str(report.CIFP))
    ap.add_argument("--run", default=None, help="a procedures check folder to read")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--per-stratum", type=int, default=5)
    ap.add_argument("--airports", nargs="*", default=None, help="only these airports")
    ap.add_argument("--md", default="procedures_coding.md")
    report.add_quick(ap, "the airports " + " ".join(QUICK_AIRPORTS) + " only")
    a = ap.parse_args(argv)
    if a.quick and not a.airports:
        a.airports = QUICK_AIRPORTS
    import json
    tmp = None
    if a.run is None:
        tmp = tempfile.TemporaryDirectory()
        a.run = str(Path(tmp.name) / "check")
        cmd = ["procedures", "check", "--db", a.db, "--workers", str(a.workers),
               "--no-progress", "--out", a.run]
        report.run_cli(cmd + (["--airports", *a.airports] if a.airports else []),
                       expect=Path(a.run) / "summary.json")
    df = pd.read_parquet(Path(a.run) / "procedures_check.parquet")
    summary = json.loads((Path(a.run) / "summary.json").read_text())
    db = load_database(a.db)
    lines = [ln.rstrip("\r") for ln in Path(a.db).read_text(encoding="latin-1").split("\n")]
    ind = independent(db, lines, sorted(set(df["airport"])))
    df = compare(df, ind)
    report.refuse_degenerate(Counter(df["status"]), what="procedures check")
    smp = sample(df, a.seed, a.per_stratum)
    body = markdown(df, summary, smp)
    print(body)
    report.write(a.md, body, note="Tolerances: `fms_testbed.path.coding.TOL` (docs/"
                 "procedures.md, The coded-numbers check).")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
