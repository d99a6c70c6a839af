"""The coupled law's measured figures, from the ``fms-testbed compare`` command itself.

Runs, each in a temporary folder, and writes Markdown into ``docs/results/``:

1. ``fms-testbed compare`` (coupled law vs the PI and TECS baselines on JSBSim, and the ideal
   point mass): the command's own ``comparison.md`` table and goal checks →
   ``coupled_law.md``.
2. ``fms-testbed compare --envelope`` (+100 m and +10 % TAS steps at every envelope point of
   every shipped aircraft) → ``coupled_envelope.md``.
3. The ablation: ``compare --laws coupled --no-small-step coupled-altitude-step
   coupled-speed-step`` as shipped and with one ``--set`` each → ``coupled_ablation.md``.

    python bench/bench_compare.py [--aircraft 737] [--skip-envelope] [--skip-ablation]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

#: (label, --set arguments) of the ablation
ABLATION = (
    ("as shipped (exact eq. 7/8, measured n_x, n_y tracking integrator)", []),
    ("`form=paper` (small-angle eq. 19)", ["form=paper"]),
    ("`use_measured_nx=false` (integrator state in the damping term)", ["use_measured_nx=false"]),
    ("`ny_trim_tau_s=0` (no n_y tracking-error integrator)", ["ny_trim_tau_s=0"]),
)


def fms_testbed(args: list[str], out: Path, expect: str) -> tuple[int, float]:
    """Run ``fms-testbed ARGS --out OUT``; (exit code, wall s). Exit 1 with ``OUT/expect``
    written (a goal failed) is a result; anything else stops the bench."""
    rc, wall, _ = report.run_cli([*args, "--out", str(out)], expect=out / expect, ok_codes=(0, 1))
    return rc, wall


def body_of(md_file: Path) -> str:
    """A command's Markdown without its top-level title; its sections become bold lines."""
    lines = md_file.read_text().splitlines()
    out = []
    for line in lines:
        if line.startswith("# "):
            continue
        if line.startswith("## "):
            out.append(f"**{line[3:].strip()}**")
            continue
        out.append(line)
    return "\n".join(out).strip()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aircraft", help="fly the comparison with this aircraft (default: the "
                                       "scenarios' 737)")
    ap.add_argument("--skip-envelope", action="store_true")
    ap.add_argument("--skip-ablation", action="store_true")
    report.add_quick(ap, "the altitude step of the coupled law, no envelope, one ablation row")
    args = ap.parse_args()
    extra = ["--aircraft", args.aircraft] if args.aircraft else []
    first = ["--laws", "coupled", "coupled-altitude-step"] if args.quick else []
    if args.quick:
        args.skip_envelope = True
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rc, wall = fms_testbed(["compare", *first, *extra], tmp / "compare", "comparison.md")
        cmd = " ".join(["fms-testbed compare", *extra])
        report.write("coupled_law.md", body_of(tmp / "compare" / "comparison.md"),
                     note=f"`{cmd}` ({wall:.0f} s wall, exit code {rc}): each scenario flown "
                          "with each law on JSBSim and with the coupled law on the lag-free "
                          "point mass (`ideal`). Settling: 2 % band of the step; `cross_ref` "
                          "`ideal`: the other channel compared with the ideal trajectory "
                          "(overlapping steps of `paper-fig2`).")
        if not args.skip_envelope:
            rc, wall = fms_testbed(["compare", "--envelope", *extra], tmp / "envelope",
                                   "envelope.md")
            cmd = " ".join(["fms-testbed compare --envelope", *extra])
            report.write("coupled_envelope.md", body_of(tmp / "envelope" / "envelope.md"),
                         note=f"`{cmd}` ({wall:.0f} s wall): +100 m and +10 % TAS steps at every "
                              "envelope point, each aircraft with its tuned gains.")
        if not args.skip_ablation:
            rows = []
            for label, sets in ABLATION[:1] if args.quick else ABLATION:
                out = tmp / f"ablation-{len(rows)}"
                argv = ["compare", "--laws", "coupled", "--no-small-step",
                        "coupled-altitude-step", "coupled-speed-step", *extra]
                for s in sets:
                    argv += ["--set", s]
                fms_testbed(argv, out, "comparison.csv")
                t = pd.read_csv(out / "comparison.csv")
                dv = t.loc[t["scenario"] == "coupled-altitude-step", "max_dV_kmh"].max()
                dh = t.loc[t["scenario"] == "coupled-speed-step", "max_dH_m"].max()
                rows.append([label, f"{dv:.3f}", f"{dh:.3f}"])
            report.write("coupled_ablation.md", report.table(
                ["variant (`--set KEY=VALUE`)", "max|ΔV| in the +500 m step, km/h",
                 "max|ΔH| in the +50 km/h step, m"], rows),
                note="`fms-testbed compare --laws coupled --no-small-step coupled-altitude-step "
                     "coupled-speed-step [--set KEY=VALUE]`, one run per variant.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
