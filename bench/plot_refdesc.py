"""docs/figures/navigation/ins_drift_x{2,10}.png: the reference-description monitor against
majority voting in scenarios/ins-drift-x2.yaml and ins-drift-x10.yaml (seed 0).

    python bench/plot_refdesc.py [--from DIR_X2 DIR_X10]   # fly them, or read their --out folders
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario
from fms_testbed.viz.figure import save
from fms_testbed.viz.reference_description import plot_reference_comparison

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

OUT = report.FIGURES / "navigation"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--from", dest="dirs", nargs=2, type=Path, default=None)
    report.add_quick(ap, "the two scenarios cut to 15 min (the fault at 10 min)")
    a = ap.parse_args()
    cut = {"duration_s": 900.0} if a.quick else None
    for k, name in enumerate(("ins-drift-x2", "ins-drift-x10")):
        if a.dirs is not None:
            df = pd.read_parquet(a.dirs[k] / "timeseries.parquet")
        else:
            df = run_scenario(scenarios_dir() / f"{name}.yaml", seed=0, progress=False,
                              overrides=cut).df
        fig = plot_reference_comparison(df, f"{name}.yaml: INS 2 gyro drift "
                                            f"x{name.split('x')[-1]} at t = 10 min, GNSS outage "
                                            "45-50 min", fault_t_s=600.0)
        print(save(fig, OUT / f"{name.replace('-', '_')}.png", dpi=100))


if __name__ == "__main__":
    main()
