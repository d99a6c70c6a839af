"""``fms-testbed inner``: check (and optionally tune) an aircraft's inner loops on JSBSim.

    fms-testbed inner --aircraft NAME [--envelope] [--tune] [--out DIR]

Steps each inner loop (bank, n_y up and down, n_x up and down) from trim at the aircraft's
default condition (``--envelope``: at every envelope point) and compares settling time and
overshoot with the aircraft's ``inner_spec``. Writes into ``--out`` (default
``results/inner-NAME``):

* ``inner_steps.csv`` and ``inner_steps.md`` — one row per (condition, step): ``alt_m``,
  ``tas_mps``, ``loop``, ``bank_step_deg`` or ``load_step_g``, ``settle_s`` (empty when the
  response never settles in the run), ``settle_max_s``, ``overshoot_pct``,
  ``overshoot_max_pct``, ``ok``;
* ``inner_<loop>.png`` — one step-response figure per loop (:mod:`fms_testbed.viz.inner`);
* with ``--tune``, ``inner_loops.yaml`` — the tuned gains in the aircraft-file format.

Prints a short table (altitude m, TAS km/h). Exit code 0 when every step meets its spec, 1
otherwise, 2 on a user error.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
import yaml

from fms_testbed.cli.common import add_overwrite_option, markdown_table, text_table
from fms_testbed.core.units import mps_to_kmh
from fms_testbed.data import results_dir
from fms_testbed.run.outputs import OutputFolder

LOOPS = ("bank", "ny", "nx")


def step_rows(results: list[tuple[object, object]]) -> pd.DataFrame:
    """The table of ``(envelope point, StepResult)`` pairs, units in the column names."""
    rows = []
    for pt, r in results:
        s = r.spec
        bank = s.loop == "bank"
        rows.append({
            "alt_m": pt.alt_m, "tas_mps": pt.tas_mps, "loop": s.loop,
            "bank_step_deg": round(math.degrees(s.amplitude), 3) if bank else math.nan,
            "load_step_g": math.nan if bank else s.amplitude,
            "settle_s": round(r.settle_s, 3) if math.isfinite(r.settle_s) else math.nan,
            "settle_max_s": s.settle_max_s, "overshoot_pct": round(r.overshoot_pct, 2),
            "overshoot_max_pct": s.overshoot_max_pct, "ok": bool(r.ok)})
    return pd.DataFrame(rows)


def human_table(df: pd.DataFrame) -> pd.DataFrame:
    """The terminal view of :func:`step_rows`: condition (altitude m, TAS km/h as every
    engineering command prints speeds), step with its unit, settling and overshoot against the
    spec, PASS/FAIL."""
    step = [f"{b:+g} deg" if math.isfinite(b) else f"{g:+g} g"
            for b, g in zip(df["bank_step_deg"], df["load_step_g"])]
    settle = [f"{s:.2f}" if math.isfinite(s) else "not settled" for s in df["settle_s"]]
    return pd.DataFrame({
        "alt, m": [f"{a:.0f}" for a in df["alt_m"]],
        "TAS, km/h": [f"{mps_to_kmh(v):.0f}" for v in df["tas_mps"]],
        "loop": df["loop"], "step": step, "settle, s": settle,
        "spec, s": [f"≤ {v:g}" for v in df["settle_max_s"]],
        "overshoot, %": [f"{v:.1f}" for v in df["overshoot_pct"]],
        "spec, %": [f"≤ {v:g}" for v in df["overshoot_max_pct"]],
        "result": ["PASS" if ok else "FAIL" for ok in df["ok"]]})


def cmd_inner(args) -> int:
    """Check (and optionally tune) the inner loops of an aircraft against the step specs."""
    from fms_testbed.config.aircraft import load_aircraft
    from fms_testbed.sim.inner_steps import check_aircraft, replace_gains, tune_loop
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.inner import plot_loop_steps

    cfg = load_aircraft(args.aircraft)
    out = Path(args.out) if args.out else results_dir() / f"inner-{cfg.name}"
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    written = []
    if args.tune:
        for loop in LOOPS:
            g, cost = tune_loop(cfg, loop)
            cfg = replace_gains(cfg, loop, g)
            print(f"tuned {loop}: kp {g.kp:.4g}, ki {g.ki:.4g}, kd {g.kd:.4g} (cost {cost:.3f})")
        gains = yaml.safe_dump({"inner_loops": cfg.inner_loops.model_dump()}, sort_keys=False)
        (tmp / "inner_loops.yaml").write_text(
            f"# tuned by `fms-testbed inner --aircraft {args.aircraft} --tune`; paste into the "
            f"aircraft file\n{gains}")
        written.append("inner_loops.yaml")
    points = list(cfg.envelope) if args.envelope else [cfg.default_condition]
    results = [(pt, r) for pt in points for r in check_aircraft(cfg, pt)]
    df = step_rows(results)
    df.to_csv(tmp / "inner_steps.csv", index=False)
    (tmp / "inner_steps.md").write_text(
        f"# Inner-loop steps — {cfg.name}\n\nSettling: last time outside ±5 % of the step "
        f"around the target (— : not settled within the run); overshoot in % of the step.\n\n"
        f"{markdown_table(df)}\n")
    written += ["inner_steps.csv", "inner_steps.md"]
    for loop in LOOPS:
        runs = [(f"{pt.alt_m:.0f} m, {pt.tas_mps:.0f} m/s", r) for pt, r in results
                if r.spec.loop == loop]
        if runs:
            written.append(save(plot_loop_steps(loop, runs, cfg.name),
                                tmp / f"inner_{loop}.png").name)
    ok = bool(df["ok"].all())
    print(f"{cfg.name}: inner-loop steps at {len(points)} condition(s) — "
          f"{int(df['ok'].sum())}/{len(df)} meet the spec")
    print(text_table(human_table(df), right=("alt, m", "TAS, km/h", "step", "settle, s",
                                              "overshoot, %")))
    print(f"written to {out}/ ({', '.join(written)})")
    folder.commit()
    return 0 if ok else 1


def register(sub) -> None:
    """Add ``inner`` to the CLI."""
    p = sub.add_parser("inner", help="check the inner loops of an aircraft against the step specs",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--aircraft", required=True, help="aircraft name or YAML file")
    p.add_argument("--tune", action="store_true", help="search the gains first (Nelder-Mead)")
    p.add_argument("--envelope", action="store_true", help="check at every envelope point")
    p.add_argument("--out", help="output folder (default results/inner-<aircraft>)")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_inner)
