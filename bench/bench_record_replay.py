"""A recorded flight replayed: fly 400 s on ins_gnss (STIM300, a 110° turn and an 800 m climb,
no baro, GNSS latency 0, per-step prediction) with ``navigation.record_sensors: true``, replay
its ``sensors/`` with ``fms-testbed nav-replay``'s function and print the replayed solution
minus the flight's own (docs/navigation.md, "Replay").

    python bench/bench_record_replay.py [--out /tmp/record-replay]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from fms_testbed.cli.nav_replay import replay_files
from fms_testbed.core.earth import ellipsoidal_height_m, radii_m
from fms_testbed.run.api import run_scenario

SCN = {"aircraft": "737", "duration_s": 400, "hold": True, "vertical_law": "coupled",
       "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400,
                   "heading_deg": 90},
       "events": [{"t_s": 20, "heading_deg": 200}, {"t_s": 90, "alt_m": 3800},
                  {"t_s": 200, "heading_deg": 20}],
       "navigation": {"source": "ins_gnss", "imu": "STIM300", "seed": 5, "record_sensors": True,
                      "baro": None, "gnss": {"latency_s": 0.0},
                      "filter": {"predict_interval_s": 0.0}}}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="/tmp/record-replay")
    out = Path(ap.parse_args().out)
    res = run_scenario(SCN, progress=None)
    res.save(out, plots=False, overwrite=True)
    s = out / "sensors"
    rp = replay_files(s / "imu.parquet", s / "gnss.parquet", s / "init.json", s / "truth.parquet")
    sol = rp["solution"].set_index("t_s")
    fl = res.to_pandas().drop_duplicates("t_s").set_index("t_s")
    t = np.array([x for x in sol.index if np.min(np.abs(fl.index - x)) < 1e-6])
    f = fl.iloc[[int(np.argmin(np.abs(fl.index - x))) for x in t]]
    lat = np.radians(f.nav_lat_deg.to_numpy())
    rm, rn = radii_m(lat)
    dn = np.radians(sol.loc[t, "nav_lat_deg"].to_numpy() - f.nav_lat_deg.to_numpy()) * rm
    de = np.radians(sol.loc[t, "nav_lon_deg"].to_numpy() - f.nav_lon_deg.to_numpy()) * rn * \
        np.cos(lat)
    dh = sol.loc[t, "nav_alt_m"].to_numpy() - np.array(
        [ellipsoidal_height_m(a, b) for a, b in zip(lat, f.nav_alt_m.to_numpy())])
    a = np.abs((sol.loc[t, "nav_heading_deg"].to_numpy() - f.nav_heading_deg.to_numpy() + 180)
               % 360 - 180)
    h = np.hypot(dn, de)
    print(f"replay - flight over {len(t)} steps: horizontal max {h.max():.4f} m (95 % "
          f"{np.percentile(h, 95):.4f} m), height max {np.abs(dh).max():.4f} m, heading median "
          f"{np.median(a):.5f} deg, max {a.max():.4f} deg at t = {t[np.argmax(a)]:.1f} s; "
          f"replay vs truth horizontal 95 % {rp['stats']['horizontal_m']['p95']:.2f} m")


if __name__ == "__main__":
    main()
