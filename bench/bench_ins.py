"""SINS position-error growth of IMU presets, from the ``fms-testbed ins`` command itself.

For each ``--imus`` preset, with the default stationary self-alignment and with
``--alignment none``: ``fms-testbed ins synthetic:straight --imu PRESET --table-every-s 900``
(1 h straight and level at 200 m/s, heading 45°, 45° N, baro-damped vertical channel,
covariance propagation). Writes the 95 % horizontal position error every 15 min, read from the
command's ``ins_p95_table.csv``, as Markdown to ``docs/results/ins_growth.md``.

    python bench/bench_ins.py [--imus HG9900 STIM300] [--md ins_growth.md]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402


def p95_table(imu: str, alignment: str, out: Path) -> pd.DataFrame:
    """The command's ``ins_p95_table.csv`` (t_min, h95_m, v95_m)."""
    argv = ["ins", "synthetic:straight", "--imu", imu, "--table-every-s", "900",
            "--alignment", alignment, "--out", str(out)]
    report.run_cli(argv, expect=out / "ins_p95_table.csv")
    return pd.read_csv(out / "ins_p95_table.csv")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--imus", nargs="+", default=["HG9900", "STIM300"])
    ap.add_argument("--md", default="ins_growth.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "one IMU")
    args = ap.parse_args()
    if args.quick:
        args.imus = args.imus[:1]
    rows, header = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for imu in args.imus:
            aligned = p95_table(imu, "stationary", Path(tmp) / f"{imu}-stationary")
            raw = p95_table(imu, "none", Path(tmp) / f"{imu}-none")
            if header is None:
                header = ["IMU, 95 % horizontal position error, m"] + [
                    f"{t:g} min" for t in aligned["t_min"]]
            rows.append([f"`{imu}`"] + [f"{h:,.0f} ({n:,.0f})" for h, n in
                                        zip(aligned["h95_m"], raw["h95_m"])])
            rows.append([f"`{imu}` vertical"] + [f"{v:,.1f}" for v in aligned["v95_m"]])
            print(rows[-2], rows[-1], flush=True)
    report.write(args.md, report.table(header, rows),
                 note="`fms-testbed ins synthetic:straight --imu PRESET --table-every-s 900` "
                      "(covariance): 1 h straight and level at 200 m/s, heading 45°, "
                      "baro-damped vertical channel, stationary self-alignment at the start "
                      "attitude; in brackets the same with `--alignment none`.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
