"""Approaches as flown (issue 12, item 3): a seeded sample of FAA CIFP approaches flown by the
737 with its approach settings (deceleration, flaps, gear, Vapp, terrain at the runway), and
how each crossed the threshold.

Selection (reproducible, no hand-picking): every approach procedure of the database is a
candidate, ranked by SHA-256 of ``"<seed>:<airport>:<procedure>"``; its approach transition is
the one ranked first the same way (``"<seed>:<airport>:<procedure>:<transition>"``), none when
it has none. The first ``--n`` candidates that build are flown (those refused at build time are
counted and listed); ``--missed K`` flies the first K of them again with ``procedure.missed``.

    python bench/approaches_as_flown.py [--db FILE] [--seed 3] [--n 24] [--missed 4]
                                        [--md approaches.md]

Goals (issue 12): threshold crossed at Vapp ± 5 kt, configured (landing flaps, gear down), on
the coded path angle ± 0.2° (mean over the last NM), at the TCH (± 25 ft here).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

CIFP = report.CIFP


def rank(*parts) -> str:
    """SHA-256 hex digest of the parts joined by ':' (the seeded order)."""
    return hashlib.sha256(":".join(str(p) for p in parts).encode()).hexdigest()


def candidates(db, seed: int) -> list[tuple[str, str, str | None]]:
    """(airport, procedure, approach transition or None) of every approach, in seeded order."""
    out = []
    for apt in db.airport_idents():
        procs: dict[str, set[str]] = {}
        for typ, proc, route, trans in db.procedure_index(apt):
            if typ != "F":
                continue
            procs.setdefault(proc, set())
            if route == "A" and trans:
                procs[proc].add(trans)
        for proc, trs in procs.items():
            tr = min(trs, key=lambda t: rank(seed, apt, proc, t)) if trs else None
            out.append((rank(seed, apt, proc), apt, proc, tr))
    out.sort()
    return [(a, p, t) for _, a, p, t in out]


def fly_one(db, apt: str, proc: str, trans: str | None, missed: bool) -> dict:
    """Build and fly one approach; the summary's threshold, errors and outcome."""
    from fms_testbed.core.errors import UserError
    from fms_testbed.loop.procedure import prepare
    from fms_testbed.run.api import fly_procedure

    spec = {"db": str(CIFP), "airport": apt, "procedure": proc}
    if trans:
        spec["transition"] = trans
    if missed:
        spec["missed"] = True
    row = {"airport": apt, "procedure": proc, "transition": trans, "missed": missed}
    try:
        scn, sp, fp, _ = prepare({"aircraft": "737", "procedure": spec}, db=db)
    except UserError as exc:
        row["refused"] = str(exc).splitlines()[0][:160]
        return row
    t0 = time.perf_counter()
    res = fly_procedure(scn, sp, fp, db, plots=False, progress=False)
    s = res.summary
    fte = ((s.get("errors") or {}).get("fte") or {}).get("all") or {}
    row.update(status=s["status"], reason=s["reason"][:160],
               wall_s=round(time.perf_counter() - t0, 1),
               fte95_m=fte.get("p95_m"), fte_max_m=fte.get("max_m"),
               legs=s["procedure"]["legs"], threshold=s.get("threshold"),
               config=[(e["t_s"], e["detail"]) for e in s.get("guidance_events", [])
                       if e.get("kind") == "config"],
               alt_min_agl_m=round(float(res.df["agl_m"].min()), 1)
               if "agl_m" in res.df else None,
               **config_transients(res))
    return row


def config_transients(res, window_s: float = 30.0) -> dict:
    """Largest |altitude − planned profile| (m) and |CAS − planned CAS| (kt) within
    ``window_s`` after each flap/gear change before the MAP (the laws see the changes as
    disturbances), and the largest of each from the FAF to the threshold."""
    import numpy as np

    from fms_testbed.core.units import KT_MPS

    prof = res.procedure.path.path.profile if res.procedure is not None else None
    sp = getattr(prof, "speed", None)
    df = res.df
    if sp is None or "along_m" not in df or res.flown_paths:
        return {}
    s, t = df["along_m"].to_numpy(), df["t_s"].to_numpy()
    before = s <= sp.map_m
    dh = np.abs(df["alt_m"].to_numpy() - prof.alt_at(s))
    dv = np.abs(df["cas_mps"].to_numpy() - np.array([sp.cas_at(x) for x in s])) / KT_MPS
    m = np.zeros(len(df), dtype=bool)
    for e in res.summary.get("guidance_events", []):
        if e.get("kind") == "config" and e.get("detail") != "go-around":
            m |= (t >= e["t_s"]) & (t <= e["t_s"] + window_s)
    m &= before
    fin = before & (s >= (sp.faf_m if sp.faf_m is not None else sp.map_m))
    out = {}
    if m.any():
        out.update(cfg_dh_max_m=round(float(dh[m].max()), 1),
                   cfg_dcas_max_kt=round(float(dv[m].max()), 2))
    if fin.any():
        out.update(final_dh_max_m=round(float(dh[fin].max()), 1),
                   final_dcas_max_kt=round(float(dv[fin].max()), 2))
    return out


def _f(v, fmt="{:+.1f}"):
    return "—" if v is None else fmt.format(v)


def table(rows: list[dict]) -> list[str]:
    """Markdown rows of the flown flights."""
    out = ["| approach | status | CAS − Vapp, kt | height − TCH, ft | angle − VPA, ° | "
           "configured | FTE95 / max, m | after config changes: max \\|Δh\\| m / "
           "\\|ΔCAS\\| kt | threshold |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "refused" in r:
            continue
        t = r.get("threshold") or {}
        name = f"{r['airport']} {r['procedure']}" + (f" {r['transition']}" if r["transition"]
                                                    else "")
        if r["missed"]:
            name += " (missed)"
        ok = "ok" if t.get("ok") else ("not ok" if t.get("crossed") else
                                       (t.get("reason") or "no runway"))
        out.append(f"| {name} | {r['status']} | {_f(t.get('cas_minus_vapp_kt'))} | "
                   f"{_f(t.get('height_minus_tch_ft'))} | "
                   f"{_f(t.get('path_angle_minus_vpa_deg'), '{:+.2f}')} | "
                   f"{'yes' if t.get('configured') else ('no' if t.get('crossed') else '—')} | "
                   f"{_f(r.get('fte95_m'), '{:.1f}')} / {_f(r.get('fte_max_m'), '{:.1f}')} | "
                   f"{_f(r.get('cfg_dh_max_m'), '{:.1f}')} / "
                   f"{_f(r.get('cfg_dcas_max_kt'), '{:.1f}')} | {ok} |")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(CIFP))
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--n", type=int, default=24)
    ap.add_argument("--missed", type=int, default=4)
    ap.add_argument("--md", default="approaches.md", help="report in docs/results/ ('' none)")
    ap.add_argument("--json", default=None, help="also write every row as JSON here")
    report.add_quick(ap, "2 approaches, 1 with its missed approach")
    a = ap.parse_args(argv)
    if a.quick:
        a.n, a.missed = 2, 1
    from fms_testbed.path.plan import load_db

    db = load_db(a.db)
    rows, refused = [], []
    for apt, proc, tr in candidates(db, a.seed):
        if len(rows) >= a.n:
            break
        r = fly_one(db, apt, proc, tr, False)
        (refused if "refused" in r else rows).append(r)
        print(json.dumps({k: r.get(k) for k in ("airport", "procedure", "transition", "status",
                                                  "fte95_m", "refused")}), flush=True)
    missed = []
    for r0 in rows[:a.missed]:
        r = fly_one(db, r0["airport"], r0["procedure"], r0["transition"], True)
        missed.append(r)
        print(json.dumps({k: r.get(k) for k in ("airport", "procedure", "status", "reason")}),
              flush=True)
    crossed = [r for r in rows if (r.get("threshold") or {}).get("crossed")]

    def share(key, tol):
        v = [abs(r["threshold"][key]) for r in crossed if r["threshold"].get(key) is not None]
        return (sum(x <= tol for x in v), len(v), max(v) if v else None)

    note = (f"On the FAA CIFP `{Path(a.db).name}`: candidates ranked by SHA-256 of "
            "`seed:airport:procedure`, the first that build flown by the 737 in calm air, truth "
            "navigation (seed 0).")
    lines = [f"- flown: {len(rows)}, refused at build time: {len(refused)}, threshold crossed: "
             f"{len(crossed)} (the others end at a MAP before the threshold or have no runway)"]
    for key, tol, lab in (("cas_minus_vapp_kt", 5.0, "CAS within 5 kt of Vapp"),
                          ("path_angle_minus_vpa_deg", 0.2, "path angle within 0.2° of the VPA"),
                          ("height_minus_tch_ft", 25.0, "height within 25 ft of the TCH")):
        k, n, mx = share(key, tol)
        lines.append(f"- {lab}: {k}/{n} (largest |error| {_f(mx, '{:.2f}')})")
    conf = [r for r in crossed if r["threshold"].get("configured") is not None]
    lines.append(f"- configured (landing flaps, gear down) at the threshold: "
                 f"{sum(bool(r['threshold']['configured']) for r in conf)}/{len(conf)}")
    lines.append(f"- status ok: {sum(r['status'] == 'ok' for r in rows)}/{len(rows)}")
    f95 = [r["fte95_m"] for r in rows if r.get("fte95_m") is not None]
    fmx = [r["fte_max_m"] for r in rows if r.get("fte_max_m") is not None]
    if f95:
        lines.append(f"- FTE95: median {sorted(f95)[len(f95) // 2]:.1f} m, largest "
                     f"{max(f95):.1f} m; max FTE largest {max(fmx):.1f} m")
    tr = [r for r in rows if r.get("cfg_dh_max_m") is not None]
    if tr:
        lines.append(f"- within 30 s after a flap/gear change (flights not rebuilt in flight, "
                     f"{len(tr)}): |altitude − planned profile| ≤ "
                     f"{max(r['cfg_dh_max_m'] for r in tr):.1f} m, |CAS − planned CAS| ≤ "
                     f"{max(r['cfg_dcas_max_kt'] for r in tr):.1f} kt (the CAS target is read "
                     f"10 s ahead, so part of this is the lead)")
    lines += ["", *table(rows), ""]
    if missed:
        lines += ["## With the missed approach (`--missed`)", "",
                  "| approach | status | legs flown | configuration changes | reason |",
                  "|---|---|---|---|---|"]
        for r in missed:
            if "refused" in r:
                lines.append(f"| {r['airport']} {r['procedure']} | refused | | | "
                             f"{r['refused']} |")
                continue
            ch = ", ".join(d for _, d in r["config"] if d in ("go-around", "gear up") or
                           d.startswith("flaps"))
            lines.append(f"| {r['airport']} {r['procedure']} {r['transition'] or ''} | "
                         f"{r['status']} | {' '.join(r['legs'])} | {ch} | {r['reason']} |")
        lines.append("")
    if refused:
        lines += ["## Refused at build time", ""]
        lines += [f"- {r['airport']} {r['procedure']} {r['transition'] or ''}: {r['refused']}"
                  for r in refused]
        lines.append("")
    report.write(a.md, "\n".join(lines), note=note)
    if a.json:
        Path(a.json).write_text(json.dumps({"rows": rows, "missed": missed,
                                            "refused": refused}, indent=1, default=str))
    print("\n".join(lines[:10]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
