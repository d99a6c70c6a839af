"""docs/figures/navigation/ins_drift_x{2,10}.png: the reference-description monitor against
majority voting in scenarios/ins-drift-x2.yaml and ins-drift-x10.yaml (seed 0).

    python bench/plot_refdesc.py [--from DIR_X2 DIR_X10]   # fly them, or read their --out folders
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from fms_testbed.data import scenarios_dir
from fms_testbed.run import run_scenario
from fms_testbed.viz.figure import save
from fms_testbed.viz.reference_description import plot_reference_comparison

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures" / "navigation"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--from", dest="dirs", nargs=2, type=Path, default=None)
    a = ap.parse_args()
    for k, name in enumerate(("ins-drift-x2", "ins-drift-x10")):
        if a.dirs is not None:
            df = pd.read_parquet(a.dirs[k] / "timeseries.parquet")
        else:
            df = run_scenario(scenarios_dir() / f"{name}.yaml", seed=0, progress=False).df
        fig = plot_reference_comparison(df, f"{name}.yaml: INS 2 gyro drift "
                                            f"x{name.split('x')[-1]} at t = 10 min, GNSS outage "
                                            "45-50 min", fault_t_s=600.0)
        print(save(fig, OUT / f"{name.replace('-', '_')}.png", dpi=100))


if __name__ == "__main__":
    main()
