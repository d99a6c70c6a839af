"""SIDs started with a takeoff roll (``procedure.start: takeoff``): the shipped aircraft take off
from KSEA RW16L on the BANGR9 departure (ARRIE transition, FAA CIFP cycle 2301) in calm air
and in wind, and fly it to its end; one table row per flight and a figure of the takeoffs.

    python bench/takeoff_start.py [--db FILE] [--fig docs/figures/takeoff_start.png]

Columns: ground roll (threshold to lift-off, m), times after brake release to VR, lift-off,
V2, handover (s), height at the departure end (ft), largest centreline deviation on the wheels
and in the air before the handover (m), FTE95 of the whole SID (m), status.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

CIFP = report.CIFP
SID = {"airport": "KSEA", "procedure": "BANGR9", "runway": "RW16L", "transition": "ARRIE"}
CASES = [("737", None), ("global5000", None), ("c172p", None),
         ("737", (250.0, 15.0)), ("737", (340.0, 10.0))]


def fly(db, aircraft: str, wind):
    """One takeoff flight: (results, built path)."""
    from fms_testbed.loop.procedure import prepare
    from fms_testbed.run import fly_procedure

    proc = {**SID, "start": "takeoff"}
    if aircraft == "c172p":
        proc["climb_top_ft"] = 6000.0          # below its 13,500 ft ceiling
    raw = {"aircraft": aircraft, "procedure": proc}
    if wind:
        raw["wind"] = {"from_deg": wind[0], "speed_kt": wind[1]}
    scn, spec, fp, d = prepare(raw, db=db)
    return fly_procedure(scn, spec, fp, d, progress=False, plots=False)


def row(aircraft: str, wind, res) -> str:
    from fms_testbed.core.units import FT_M

    s = res.summary
    to, t = s["takeoff"], s["takeoff"]["times_s"]
    w = "calm" if wind is None else f"{wind[0]:03.0f}/{wind[1]:.0f} kt"
    return (f"| {aircraft} | {w} | {to['ground_roll_m']:.0f} | {t['rotate']:.1f} | "
            f"{t['liftoff']:.1f} | {t['v2']:.1f} | {t['handover']:.1f} | "
            f"{to['der_height_m'] / FT_M:.0f} | {to['max_centreline_dev_ground_m']:.1f} | "
            f"{to['max_centreline_dev_air_m']:.1f} | "
            f"{s['errors']['fte']['all']['p95_m']:.1f} | {s['status']} |")


def figure(flights, path: Path) -> None:
    """Height above the runway and CAS over the distance from the threshold, to the handover
    (plotting only: every value comes from the flights' summaries and timeseries)."""
    import matplotlib.pyplot as plt
    import numpy as np

    from fms_testbed.core.geodesy import inverse
    from fms_testbed.core.units import FT_M, KT_MPS

    fig, (ax_h, ax_v) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    for aircraft, wind, res in flights:
        if wind is not None:
            continue
        to = res.summary["takeoff"]
        df = res.df[res.df["t_s"] <= to["handover_s"] + 1e-6]
        lat0, lon0 = df["lat_deg"].iloc[0], df["lon_deg"].iloc[0]
        d = np.array([inverse(lat0, lon0, la, lo)[0]
                      for la, lo in zip(df["lat_deg"], df["lon_deg"])])
        h = df["alt_m"] - df["alt_m"].iloc[0]
        line, = ax_h.plot(d, h / FT_M, label=f"{aircraft}: roll {to['ground_roll_m']:.0f} m")
        ax_v.plot(d, df["cas_mps"] / KT_MPS, color=line.get_color(), label=aircraft)
        lo = to["events"]["liftoff"]["along_m"]
        ax_h.axvline(lo, color=line.get_color(), ls=":", lw=1)
        ho = to["events"]["handover"]
        ax_h.plot(ho["along_m"], ho["height_m"] / FT_M, "o", color=line.get_color())
    der = flights[0][2].summary["takeoff"]["events"]["der"]["along_m"]
    for ax in (ax_h, ax_v):
        ax.axvline(der, color="black", lw=1)
    ax_h.axhline(400, color="grey", ls="--", lw=1, label="400 ft (LNAV, lowest handover)")
    ax_h.set_ylabel("height above the runway, ft")
    ax_h.set_title("Takeoff roll start, KSEA RW16L (BANGR9), calm air\nlift-off (dotted), "
                   f"runway end (black, {der:.0f} m), handover to the guidance (dot)",
                   fontsize=10)
    ax_h.legend(fontsize=8)
    ax_v.set_ylabel("CAS, kt")
    ax_v.set_xlabel("distance from the threshold (straight line), m")
    ax_v.legend(fontsize=8)
    for ax in (ax_h, ax_v):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", default=str(CIFP), help="the FAA CIFP file")
    ap.add_argument("--fig", help="write the figure here (PNG)")
    report.add_quick(ap, "the 737 in calm air only")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from fms_testbed.procedures.database import load_database

    db = load_database(args.db)
    print("| aircraft | wind | ground roll, m | VR, s | lift-off, s | V2, s | handover, s | "
          "height at DER, ft | centreline wheels, m | centreline air, m | FTE95, m | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    flights = []
    for aircraft, wind in CASES[:1] if args.quick else CASES:
        res = fly(db, aircraft, wind)
        flights.append((aircraft, wind, res))
        print(row(aircraft, wind, res), flush=True)
    if args.fig:
        import matplotlib
        matplotlib.use("Agg")
        figure(flights, Path(args.fig))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
