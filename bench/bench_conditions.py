"""Flying in the actual conditions (docs/flying.md, "Temperature", "Wind over altitude"): four
measured tables, each written to ``docs/results/``.

    python bench/bench_conditions.py [--only trim isa misplan wind] [--quick]

- ``trim`` → ``conditions_trim.md``: the 737 straight and level at 250 kt CAS, 3,000 m, ISA−20/0/+20:
  JSBSim's temperature, the trimmed and the flown TAS against the planner's CAS → TAS.
- ``isa`` → ``conditions_isa.md``: holds (KENV R26 HF, embedded database; KENV ENV1 RW08 HA, FAA
  cycle) and an RF approach (KBFI H14RZ ZUVEN) at ISA−20/0/+20: planned vs flown TAS, turn radius
  (ground speed / track rate on the turns) and bank.
- ``misplan`` → ``conditions_misplan.md``: ISA±20 flown on a path planned for the ISA, the in-flight
  rebuild on changed conditions off and on.
- ``wind`` → ``conditions_wind.md``: a wind profile (200°/5 kt at 2,000 ft → 290°/60 kt at 12,000 ft)
  against a constant wind, planned for each, rebuilds off and on.

737, truth navigation. ``--quick``: one case of each table (embedded database only).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402
from rebuild_switch import fly  # noqa: E402

from fms_testbed.core.atmosphere import cas_to_tas, pressure_altitude_m  # noqa: E402
from fms_testbed.core.segments import Arc  # noqa: E402
from fms_testbed.core.units import FT_M, KT_MPS  # noqa: E402
from fms_testbed.core.wind import WindProfile  # noqa: E402
from fms_testbed.loop.procedure import prepare  # noqa: E402
from fms_testbed.procedures.database import load_database  # noqa: E402

ISA_DEVS_C = (-20, 0, 20)
#: (database, airport, procedure, selection, leg code, segment roles of its turns)
TURN_CASES = [("embedded", "KENV", "R26", {"transition": "BVL"}, "HF", ("turn", "hold")),
              ("embedded", "KBFI", "H14RZ", {"transition": "ZUVEN"}, "RF", ("leg",)),
              ("cifp", "KENV", "ENV1", {"runway": "08"}, "HA", ("hold",))]
PROFILE = [{"alt_ft": 2000, "from_deg": 200, "speed_kt": 5},
           {"alt_ft": 12000, "from_deg": 290, "speed_kt": 60}]
WIND_CASES = [("cifp", "KENV", "ENV1", {"runway": "08"}), ("embedded", "KENV", "R26",
                                                            {"transition": "BVL"})]


def trim_table(devs) -> tuple[list, list]:
    """The trim check: (header, rows)."""
    from fms_testbed.config.scenario import parse_scenario
    from fms_testbed.loop.flight import Flight

    rows = []
    for dev in devs:
        scn = parse_scenario({"name": f"isa{dev}", "aircraft": "737", "duration_s": 60,
                              "hold": True, "atmosphere": {"isa_dev_c": dev},
                              "initial": {"alt_m": 3000, "cas_kt": 250, "heading_deg": 90}})
        f = Flight(scn, progress=False)
        df, summ = f.run()
        last = df.iloc[-1]
        want = float(cas_to_tas(250 * KT_MPS, 3000, dev))
        rows.append([f"{dev:+d}", f"{f.aircraft['atmosphere/T-R'] / 1.8:.2f}",
                     f"{want / KT_MPS:.2f}", f"{summ['trim']['tas_mps'] / KT_MPS:.2f}",
                     f"{last.tas_mps / KT_MPS:.2f}", f"{last.cas_mps / KT_MPS:.2f}",
                     f"{summ['trim']['throttle']:.3f}", f"{pressure_altitude_m(3000, dev):.0f}",
                     f"{f.aircraft['atmosphere/pressure-altitude'] * FT_M:.0f}", summ["status"]])
        print(" | ".join(rows[-1]), flush=True)
    return (["ISA dev, °C", "JSBSim T, K", "planned TAS, kt", "trimmed TAS, kt", "flown TAS, kt",
             "flown CAS, kt", "throttle", "pressure alt. (planner), m",
             "pressure alt. (JSBSim), m", "status"], rows)


def _turns(res, fp, code: str, roles) -> dict:
    """Planned and flown TAS, radius and bank on the turns of the first ``code`` leg."""
    df = res.df
    k = next(lg.index for lg in fp.path.legs if lg.path_term == code)
    arcs = [s for s in fp.path.segments if s.leg_index == k and isinstance(s.geom, Arc)
            and s.role in roles and abs(s.geom.sweep_deg) > 60]
    b_plan = float(np.mean([s.bank_deg for s in arcs]))
    on = df[(df["leg_code"] == code) & df["seg_role"].isin(roles) & (df["curvature_1pm"].abs() > 0)]
    rate = np.gradient(np.unwrap(np.radians(df["track_deg"].to_numpy())), df["t_s"].to_numpy())
    sel = on.index[np.abs(df.loc[on.index, "roll_deg"]) > 0.7 * b_plan]
    return {"tas_plan_kt": float(np.mean([s.speed_mps for s in arcs])) / KT_MPS,
            "tas_flown_kt": float(np.median(on["tas_mps"])) / KT_MPS,
            "cas_flown_kt": float(np.median(on["cas_mps"])) / KT_MPS,
            "r_plan_m": float(np.mean([s.geom.radius_m for s in arcs])),
            "r_flown_m": float(np.median(df.loc[sel, "gs_mps"].to_numpy() / np.abs(rate[sel]))),
            "bank_plan_deg": b_plan,
            "bank_flown_deg": float(np.median(np.abs(df.loc[sel, "roll_deg"])))}


def isa_table(dbs, cases, devs) -> tuple[list, list]:
    """Holds and an RF at each ISA deviation: (header, rows)."""
    rows = []
    for dbn, apt, proc, extra, code, roles in cases:
        for dev in devs:
            raw = {"aircraft": "737", "procedure": {"airport": apt, "procedure": proc, **extra},
                   "atmosphere": {"isa_dev_c": dev}}
            res, fp = fly(raw, dbs[dbn], True)
            t, e = _turns(res, fp, code, roles), res.summary["errors"]["fte"]["all"]
            rows.append([f"{apt} {proc} {code}", f"{dev:+d}",
                         f"{t['tas_plan_kt']:.1f} / {t['tas_flown_kt']:.1f}",
                         f"{t['cas_flown_kt']:.1f}", f"{t['r_plan_m']:.0f} / {t['r_flown_m']:.0f}",
                         f"{t['bank_plan_deg']:.1f} / {t['bank_flown_deg']:.1f}",
                         f"{e['p95_m']} / {e['max_m']}", res.summary["status"]])
            print(" | ".join(rows[-1]), flush=True)
    return (["procedure", "ISA dev, °C", "TAS plan / flown, kt", "CAS flown, kt",
             "R plan / flown, m", "bank plan / flown, °", "FTE95 / max, m", "status"], rows)


def _rebuilds(res) -> str:
    ev = [x for x in res.summary.get("guidance_events", []) if x["kind"] == "rebuild"]
    return f"{len(ev)}" + (" (" + ", ".join(f"{x['t_s']:.0f} s" for x in ev) + ")" if ev else "")


def misplan_table(dbs, cases, devs) -> tuple[list, list]:
    """ISA±20 flown on a path planned for the ISA, rebuild off/on: (header, rows)."""
    rows = []
    for dbn, apt, proc, extra, code, roles in cases:
        for dev in devs:
            for rebuild in (False, True):
                raw = {"aircraft": "737", "procedure": {"airport": apt, "procedure": proc,
                                                        **extra},
                       "atmosphere": {"isa_dev_c": dev}, "forecast": {"isa_dev_c": 0}}
                res, fp = fly(raw, dbs[dbn], rebuild)
                t, e = _turns(res, fp, code, roles), res.summary["errors"]["fte"]["all"]
                rows.append([f"{apt} {proc} {code}", f"ISA{dev:+d}, planned ISA",
                             "on" if rebuild else "off", f"{t['tas_flown_kt']:.1f}",
                             f"{t['cas_flown_kt']:.1f}", f"{e['p95_m']} / {e['max_m']}",
                             _rebuilds(res), res.summary["status"]])
                print(" | ".join(rows[-1]), flush=True)
    return (["procedure", "day / plan", "rebuild", "TAS on the turns, kt", "CAS on the turns, kt",
             "FTE95 / max, m", "rebuilds", "status"], rows)


def wind_table(dbs, cases) -> tuple[list, list]:
    """Profile vs constant wind, planned for each, rebuilds off/on: (header, rows)."""
    prof = WindProfile.from_layers([(w["alt_ft"] * FT_M, w["from_deg"], w["speed_kt"] * KT_MPS)
                                    for w in PROFILE])
    rows = []
    for dbn, apt, proc, extra in cases:
        p = {"airport": apt, "procedure": proc, **extra}
        _, _, fp0, _ = prepare({"aircraft": "737", "procedure": p}, db=dbs[dbn])
        a0 = fp0.path.legs[0].start.alt_m
        s0, f0 = prof.at(a0)
        const = {"from_deg": round(f0, 1), "speed_kt": round(s0 / KT_MPS, 1)}
        c = f"constant {const['from_deg']:03.0f}/{const['speed_kt']:.0f} kt"
        for plan, flown, wind, forecast, rebuild in (
                (c, "the same constant wind", const, None, True),
                ("the profile", "the profile", PROFILE, None, True),
                (c, "the profile, rebuild off", PROFILE, const, False),
                (c, "the profile, rebuild on", PROFILE, const, True)):
            raw = {"aircraft": "737", "procedure": p, "wind": wind}
            if forecast is not None:
                raw["forecast"] = {"wind": forecast}
            res, _ = fly(raw, dbs[dbn], rebuild)
            e = res.summary["errors"]["fte"]["all"]
            rows.append([f"{apt} {proc}", plan, flown, _rebuilds(res),
                         f"{e['p95_m']} / {e['max_m']}", f"{res.df['roll_deg'].abs().max():.1f}",
                         res.summary["status"]])
            print(" | ".join(rows[-1]), flush=True)
    return (["procedure", "planned for", "flown in", "rebuilds on conditions", "FTE95 / max, m",
             "max bank, °", "status"], rows)


PAGES = {"trim": "conditions_trim.md", "isa": "conditions_isa.md",
         "misplan": "conditions_misplan.md", "wind": "conditions_wind.md"}
"""The page each table is written to (in docs/results/)."""
NOTES = {
    "trim": "737 straight and level, 250 kt CAS at 3,000 m (geometric), 60 s; planned TAS = the "
            "planner's CAS → TAS on the day (`core.atmosphere.cas_to_tas`).",
    "isa": "737, calm air, truth navigation. R flown = ground speed / track rate on the turns of "
           "the hold (RF) with bank > 0.7 × planned; TAS planned is the builder's for the turn, "
           "flown the median on it.",
    "misplan": "737, calm air, truth navigation; the path planned for ISA+0 (`forecast`), flown "
               "on the ISA±20 day; rebuild off = the condition monitor's thresholds infinite "
               "(`bench/rebuild_switch.py`).",
    "wind": "737, truth navigation; wind profile " + ", ".join(
        f"{w['from_deg']}°/{w['speed_kt']} kt at {w['alt_ft']:,} ft" for w in PROFILE)
        + " (linear between); the constant wind is the profile's at the path's start altitude.",
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=list(NOTES), default=list(NOTES))
    ap.add_argument("--db", default=str(report.CIFP), help="the FAA CIFP (ENV1 cases)")
    report.add_quick(ap, "one case of each table, embedded database only")
    a = ap.parse_args(argv)
    dbs = {"embedded": load_database()}
    if not a.quick:
        dbs["cifp"] = load_database(a.db)
    devs = (20,) if a.quick else ISA_DEVS_C
    turns = [c for c in TURN_CASES if c[0] in dbs][:1 if a.quick else None]
    winds = [c for c in WIND_CASES if c[0] in dbs][:1 if a.quick else None]
    make = {"trim": lambda: trim_table(devs), "isa": lambda: isa_table(dbs, turns, devs),
            "misplan": lambda: misplan_table(dbs, turns[:1] if a.quick else
                                             [turns[0], turns[-1]], (20, -20)[:len(devs)]),
            "wind": lambda: wind_table(dbs, winds)}
    for name in a.only:
        header, rows = make[name]()
        report.refuse_degenerate(Counter(r[-1] for r in rows), what=name)
        report.write(PAGES[name], report.table(header, rows), note=NOTES[name])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
