"""Actual ISA+20 (or -20), path planned for the ISA (forecast isa_dev_c 0): rebuild off vs on.
737, truth navigation, calm air. Usage: python bench/conditions_misplan.py"""
from report import CIFP  # noqa: E402  (bench/report.py)
from rebuild_switch import fly  # noqa: E402  (bench/rebuild_switch.py)
from fms_testbed.core.units import KT_MPS
from fms_testbed.procedures.database import load_database
cifp = load_database(str(CIFP))
emb = load_database()
for db, p, code in ((emb, {"airport": "KENV", "procedure": "R26", "transition": "BVL"}, "HF"),
                    (cifp, {"airport": "KENV", "procedure": "ENV1", "runway": "08"}, "HA")):
    for dev in (20, -20):
        for rebuild in (False, True):
            raw = {"aircraft": "737", "procedure": p, "atmosphere": {"isa_dev_c": dev},
                   "forecast": {"isa_dev_c": 0}}
            res, _ = fly(raw, db, rebuild)
            df = res.df
            on = df[(df.leg_code == code) & (df.seg_role.isin(["hold", "turn"])) & (df.curvature_1pm.abs() > 0)]
            e = res.summary["errors"]["fte"]["all"]
            ev = [x for x in res.summary["guidance_events"] if x["kind"] == "rebuild"]
            print(f"| {p['airport']} {p['procedure']} {code} | ISA{dev:+d} planned ISA | {'on' if rebuild else 'off'} | "
                  f"{on.tas_mps.median() / KT_MPS:.1f} | {on.cas_mps.median() / KT_MPS:.1f} | "
                  f"{on.roll_deg.abs().quantile(0.5):.1f} / {on.roll_deg.abs().max():.1f} | "
                  f"{on.fte_m.abs().quantile(0.95):.1f} / {on.fte_m.abs().max():.1f} | {e['p95_m']} / {e['max_m']} | {len(ev)} |", flush=True)
            for x in ev:
                print(f"    t={x['t_s']:.0f} s leg {x['leg'] + 1}: {x['detail']}")
