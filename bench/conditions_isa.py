"""Planned vs flown turn radius (holds) / bank (RF arcs) at ISA-20, ISA+0, ISA+20 (737, calm air,
truth navigation), and FTE95/max. Usage: python bench/conditions_isa.py [cifp]"""
from report import CIFP  # noqa: E402  (bench/report.py)
import sys
import numpy as np
from fms_testbed.loop.procedure import prepare
from fms_testbed.run import fly_procedure
from fms_testbed.procedures.database import load_database
from fms_testbed.core.segments import Arc
from fms_testbed.core.units import KT_MPS

CASES = [("embedded", "KBFI", "H14RZ", {"transition": "ZUVEN"}, "RF", ("leg",)),
         ("embedded", "KENV", "R26", {"transition": "BVL"}, "HF", ("turn", "hold")),
         ("cifp", "KENV", "ENV1", {"runway": "08"}, "HA", ("hold",))]
dbs = {"embedded": load_database()}
if "cifp" in sys.argv:
    dbs["cifp"] = load_database(str(CIFP))
rows = []
only = [a for a in sys.argv[1:] if a != "cifp"]
for dbn, apt, proc, extra, code, roles in CASES:
    if only and code not in only:
        continue
    if dbn not in dbs:
        continue
    for dev in (-20, 0, 20):
        raw = {"aircraft": "737", "procedure": {"airport": apt, "procedure": proc, **extra},
               "atmosphere": {"isa_dev_c": dev}}
        scn, spec, fp, d = prepare(raw, db=dbs[dbn])
        res = fly_procedure(scn, spec, fp, d, progress=False, plots=False)
        df = res.df
        k = next(lg.index for lg in fp.path.legs if lg.path_term == code)
        arcs = [s for s in fp.path.segments if s.leg_index == k and isinstance(s.geom, Arc)
                and s.role in roles and abs(s.geom.sweep_deg) > 60]
        r_plan = np.mean([s.geom.radius_m for s in arcs])
        v_plan = np.mean([s.speed_mps for s in arcs])
        b_plan = np.mean([s.bank_deg for s in arcs])
        on = df[(df["leg_code"] == code) & df["seg_role"].isin(roles) & (df["curvature_1pm"].abs() > 0)]
        trk = np.unwrap(np.radians(df["track_deg"].to_numpy()))
        rate = np.gradient(trk, df["t_s"].to_numpy())
        sel = on.index[np.abs(df.loc[on.index, "roll_deg"]) > 0.7 * b_plan]
        r_flown = np.median(df.loc[sel, "gs_mps"].to_numpy() / np.abs(rate[sel]))
        e = res.summary["errors"]["fte"]["all"]
        rows.append(dict(proc=f"{apt} {proc} {code}", isa=dev, tas_plan_kt=round(v_plan / KT_MPS, 1),
                         tas_flown_kt=round(float(np.median(on["tas_mps"])) / KT_MPS, 1),
                         cas_flown_kt=round(float(np.median(on["cas_mps"])) / KT_MPS, 1),
                         r_plan_m=round(r_plan), r_flown_m=round(float(r_flown)),
                         bank_plan_deg=round(b_plan, 1),
                         bank_flown_deg=round(float(np.median(np.abs(df.loc[sel, "roll_deg"]))), 1),
                         fte95_m=e["p95_m"], fte_max_m=e["max_m"], status=res.summary["status"]))
        print(rows[-1], flush=True)
print("| procedure | ISA | TAS plan / flown kt | CAS flown kt | R plan / flown m | bank plan / flown ° | FTE95 / max m | status |")
print("|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['proc']} | {r['isa']:+d} | {r['tas_plan_kt']} / {r['tas_flown_kt']} | {r['cas_flown_kt']} | "
          f"{r['r_plan_m']} / {r['r_flown_m']} | {r['bank_plan_deg']} / {r['bank_flown_deg']} | "
          f"{r['fte95_m']} / {r['fte_max_m']} | {r['status']} |")
