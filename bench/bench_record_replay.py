"""A recorded flight replayed: fly 400 s on ins_gnss (STIM300, a 110° turn and an 800 m climb,
no baro, GNSS latency 0, per-step prediction) with ``navigation.record_sensors: true``, replay
its ``sensors/`` with ``fms-testbed nav-replay``'s function and print the replayed solution
minus the flight's own (docs/navigation.md, "Replay").

    python bench/bench_record_replay.py [--out /tmp/record-replay]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import sys

import numpy as np

from fms_testbed.cli.nav_replay import replay_files
from fms_testbed.navigation.replay import solution_minus_flight
from fms_testbed.run.api import run_scenario

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

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
    report.add_quick(ap, "120 s of the flight")
    a = ap.parse_args()
    out = Path(a.out)
    res = run_scenario({**SCN, "duration_s": 120} if a.quick else SCN, progress=None)
    res.save(out, plots=False, overwrite=True)
    s = out / "sensors"
    rp = replay_files(s / "imu.parquet", s / "gnss.parquet", s / "init.json", s / "truth.parquet")
    d = solution_minus_flight(rp["solution"], res.to_pandas())
    h, dh, a = d.d_horizontal_m, d.d_alt_m.abs(), d.d_heading_deg.abs()
    print(f"replay - flight over {len(d)} steps: horizontal max {h.max():.4f} m (95 % "
          f"{np.percentile(h, 95):.4f} m), height max {dh.max():.4f} m, heading median "
          f"{a.median():.5f} deg, max {a.max():.4f} deg at t = {d.t_s[a.idxmax()]:.1f} s; "
          f"replay vs truth horizontal 95 % {rp['stats']['horizontal_m']['p95']:.2f} m")


if __name__ == "__main__":
    main()
