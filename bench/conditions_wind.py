"""Wind profile vs constant wind, and rebuilds on changed conditions (737, truth navigation).

Cases per procedure: (a) constant wind = the profile's wind at the start altitude, planned for
it; (b) the profile flown, planned for the profile; (c) the profile flown, planned for the
constant wind (forecast), rebuilds off; (d) as (c) with rebuilds on (default thresholds).
Usage: python bench/conditions_wind.py [cifp]"""
from report import CIFP  # noqa: E402  (bench/report.py)
import sys
from rebuild_switch import fly  # noqa: E402  (bench/rebuild_switch.py)
from fms_testbed.loop.procedure import prepare
from fms_testbed.procedures.database import load_database
from fms_testbed.core.wind import WindProfile
from fms_testbed.core.units import FT_M, KT_MPS

PROFILE = [{"alt_ft": 2000, "from_deg": 200, "speed_kt": 5},
           {"alt_ft": 12000, "from_deg": 290, "speed_kt": 60}]
prof = WindProfile.from_layers([(l["alt_ft"] * FT_M, l["from_deg"], l["speed_kt"] * KT_MPS) for l in PROFILE])
CASES = [("embedded", "KENV", "R26", {"transition": "BVL"}), ("cifp", "KENV", "ENV1", {"runway": "08"})]
dbs = {"embedded": load_database()}
if "cifp" in sys.argv:
    dbs["cifp"] = load_database(str(CIFP))


def run(db, proc, wind, forecast=None, rebuild=True):
    raw = {"aircraft": "737", "procedure": proc, "wind": wind}
    if forecast is not None:
        raw["forecast"] = {"wind": forecast}
    return fly(raw, db, rebuild)


for dbn, apt, proc, extra in CASES:
    if dbn not in dbs:
        continue
    p = {"airport": apt, "procedure": proc, **extra}
    # the start altitude of the built path (calm)
    _, _, fp0, _ = prepare({"aircraft": "737", "procedure": p}, db=dbs[dbn])
    a0 = fp0.path.legs[0].start.alt_m
    s0, f0 = prof.at(a0)
    const = {"from_deg": round(f0, 1), "speed_kt": round(s0 / KT_MPS, 1)}
    for label, kw in (("a const/const", dict(wind=const)),
                      ("b prof/prof", dict(wind=PROFILE)),
                      ("c prof/const, no rebuild", dict(wind=PROFILE, forecast=const, rebuild=False)),
                      ("d prof/const, rebuild", dict(wind=PROFILE, forecast=const))):
        res, fp = run(dbs[dbn], p, **kw)
        e = res.summary["errors"]["fte"]["all"]
        ev = [x for x in res.summary.get("guidance_events", []) if x["kind"] == "rebuild"]
        print(f"| {apt} {proc} | {label} | {a0 / FT_M:.0f} ft: {const['from_deg']:.0f}/{const['speed_kt']:.0f} kt "
              f"| {e['p95_m']} / {e['max_m']} | {res.df['roll_deg'].abs().max():.1f} | {len(ev)} | "
              f"{res.summary['status']} |", flush=True)
        for x in ev:
            print(f"    t={x['t_s']:.0f} s leg {x['leg'] + 1}: {x['detail']}")
