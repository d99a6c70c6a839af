"""Inner-loop step responses of every shipped aircraft at every envelope point, against its specs.

For each aircraft (``fms_testbed/data/aircraft/*.yaml``) and each point of its ``envelope``: the
bank, n_y (up and down) and n_x (up and down) steps of its ``inner_spec``, flown on JSBSim with
the aircraft's gains (what ``fms-testbed inner --aircraft NAME --envelope`` checks). Writes the
settling time (last time outside ±5 % of the step) and overshoot (% of the step) of every step
as a Markdown table to ``docs/results/inner_envelope.md``; ✗ marks a step outside the spec.

    python bench/bench_inner.py [--aircraft NAME ...] [--md inner_envelope.md]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.config.aircraft import list_aircraft, load_aircraft  # noqa: E402
from fms_testbed.sim.inner_steps import check_aircraft  # noqa: E402


def label(spec) -> str:
    """Column title of one step spec (unit in it)."""
    if spec.loop == "bank":
        return f"bank {math.degrees(spec.amplitude):.0f}°"
    return f"n_{spec.loop[1]} {spec.amplitude:+g} g"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", nargs="+", default=None, help="default: every shipped aircraft")
    ap.add_argument("--md", default="inner_envelope.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "the first envelope point of the C172P")
    args = ap.parse_args()
    names = args.aircraft or (["c172p"] if args.quick else list_aircraft())
    rows, header, n_bad, n_all = [], None, 0, 0
    t0 = time.perf_counter()
    for name in names:
        cfg = load_aircraft(name)
        for pt in cfg.envelope[:1] if args.quick else cfg.envelope:
            results = check_aircraft(cfg, pt)
            if header is None:
                header = ["aircraft", "alt m / TAS m/s"] + [label(r.spec) for r in results]
            cells = []
            for r in results:
                settle = "∞" if not math.isfinite(r.settle_s) else f"{r.settle_s:.2f} s"
                cells.append(f"{settle} / {r.overshoot_pct:.0f} %" + ("" if r.ok else " ✗"))
                n_bad += not r.ok
                n_all += 1
            rows.append([name, f"{pt.alt_m:.0f} / {pt.tas_mps:.0f}", *cells])
            print(" | ".join(rows[-1]), flush=True)
    wall = time.perf_counter() - t0
    report.write(args.md, report.table(header, rows),
                 note=f"Settling s / overshoot % of each step; ✗ = outside the aircraft's "
                      f"`inner_spec` ({n_bad} of {n_all} steps); ∞ = never settles within the "
                      f"run. {wall:.0f} s wall.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
