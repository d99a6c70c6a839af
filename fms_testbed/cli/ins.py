"""``fms-testbed ins``: SINS error analysis along a flown or synthetic trajectory.

TARGET is a run directory (with ``timeseries.parquet``), a scenario file (flown first), or
``synthetic:stationary`` / ``synthetic:straight`` (level flight at 200 m/s, heading 45°).
"""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

from fms_testbed.cli.common import add_overwrite_option
from fms_testbed.core.errors import UserError
from fms_testbed.run.outputs import OutputFolder

log = logging.getLogger("fms_testbed.sensors.sins")


def _trajectory(args, run_dir: Path):
    from fms_testbed.sensors.sins import trajectory as tj

    target = args.target
    if target.startswith("synthetic:"):
        kind = target.split(":", 1)[1]
        if kind == "stationary":
            return tj.straight_level(args.duration_s, args.dt_s, lat_deg=args.lat_deg)
        if kind == "straight":
            return tj.straight_level(args.duration_s, args.dt_s, lat_deg=args.lat_deg,
                                     speed_mps=200.0, heading_deg=45.0)
        raise UserError(f"{target}: unknown synthetic trajectory (stationary, straight)")
    p = Path(target)
    if p.is_dir():
        return tj.from_run_dir(p)
    if p.is_file() and p.suffix in (".yaml", ".yml"):
        from fms_testbed.run import run_scenario

        out = run_dir / "run"
        log.info("flying %s first (output in %s)", p, out)
        res = run_scenario(p, out_dir=out, seed=args.seed, plots=False)
        df = res.df if hasattr(res, "df") else res[0]
        return tj.from_dataframe(df, where=str(p))
    raise UserError(f"{target}: not a run directory, a scenario .yaml, or synthetic:KIND")


def _handler(args) -> int:
    from fms_testbed.sensors.sins.analysis import SinsOptions, covariance_run, error_table, montecarlo_run
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.sins import plot_envelopes, plot_p95
    from fms_testbed.sensors.sins.presets import load_imu

    if args.n < 2:
        raise UserError(f"-n: need at least 2 realisations, got {args.n}")
    if not args.dt_s > 0:
        raise UserError(f"--dt-s: must be > 0, got {args.dt_s}")
    imu = load_imu(args.imu)
    opts = SinsOptions(method=args.method, vertical=args.vertical, baro_tau_s=args.baro_tau_s,
                       alignment=args.alignment)
    out = Path(args.out)
    folder = OutputFolder(out, getattr(args, "overwrite", False))  # checked before the work
    tmp = folder.open()
    traj = _trajectory(args, tmp).resample(args.dt_s)
    log.info("%s along %s: %d steps of %.3g s", imu.summary(), traj.label, len(traj), args.dt_s)
    t0 = time.perf_counter()
    cov = covariance_run(traj, imu, opts)
    t_cov = time.perf_counter() - t0
    results = {"covariance": cov}
    mc = None
    if args.mode == "montecarlo":
        t0 = time.perf_counter()
        mc = montecarlo_run(traj, imu, args.n, args.seed, opts)
        log.info("Monte-Carlo %d realisations: %.1f s", args.n, time.perf_counter() - t0)
        results[f"Monte-Carlo (N = {args.n})"] = mc
        mc.to_frame().to_csv(tmp / "ins_montecarlo_sigma.csv", index=False)
        mc.realisations_frame().to_parquet(tmp / "ins_realisations.parquet", index=False)
    cov.to_frame().to_csv(tmp / "ins_covariance_sigma.csv", index=False)
    main = mc if mc is not None else cov
    table = error_table(main, args.table_every_s)
    if mc is not None:
        ct = error_table(cov, args.table_every_s)
        table["h95_cov_m"], table["v95_cov_m"] = ct["h95_m"].to_numpy(), ct["v95_m"].to_numpy()
    table.to_csv(tmp / "ins_p95_table.csv", index=False)
    title = (f"{imu.name} along {traj.label} — {args.mode}, vertical {args.vertical}, "
             f"alignment {args.alignment}, {args.method}")
    h95 = main.h95_m[-1]
    end_min = (main.t_s[-1] - main.t_s[0]) / 60.0
    head = f"{title}\n95 % horizontal error {h95:.0f} m after {end_min:.0f} min"
    plots = [save(plot_envelopes(cov, mc, "position", head), tmp / "ins_position.png"),
             save(plot_envelopes(cov, mc, "attitude", head), tmp / "ins_attitude.png"),
             save(plot_p95(results, head), tmp / "ins_p95.png")]
    print(f"{imu.summary()}; covariance {t_cov:.1f} s")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print("wrote " + ", ".join(str(p) for p in plots))
    folder.commit()
    return 0


def register(subparsers) -> None:
    """Add the ``ins`` sub-command."""
    p = subparsers.add_parser(
        "ins", help="SINS error analysis (covariance / Monte-Carlo) along a trajectory",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("target", help="run directory, scenario .yaml, or synthetic:stationary|straight")
    from fms_testbed.sensors.sins.presets import list_presets

    p.add_argument("--imu", default="STIM300",
                   help=f"preset ({', '.join(list_presets())}) or an IMU .yaml file "
                        "(default STIM300)")
    p.add_argument("--mode", choices=("covariance", "montecarlo"), default="covariance",
                   help="covariance propagation only, or plus a vectorised Monte-Carlo")
    p.add_argument("-n", type=int, default=1000, help="Monte-Carlo realisations (default 1000)")
    p.add_argument("--out", default="results/ins", help="output folder")
    add_overwrite_option(p)
    p.add_argument("--seed", type=int, default=0, help="seed of the Monte-Carlo / flight")
    p.add_argument("--method", choices=("picard", "vanloan", "trapezoid"), default="picard")
    p.add_argument("--vertical", choices=("baro", "free"), default="baro",
                   help="baro-damped (default) or free (unstable) vertical channel")
    p.add_argument("--alignment", choices=("stationary", "none"), default="stationary",
                   help="initial attitude errors from a stationary self-alignment (default) or "
                        "independent of the sensor errors")
    p.add_argument("--baro-tau-s", type=float, default=60.0, help="baro loop time constant, s")
    p.add_argument("--dt-s", type=float, default=0.1, help="navigation step, s (default 0.1)")
    p.add_argument("--duration-s", type=float, default=3600.0,
                   help="length of a synthetic trajectory, s (default 3600)")
    p.add_argument("--lat-deg", type=float, default=45.0, help="latitude of synthetic trajectories")
    p.add_argument("--table-every-s", type=float, default=300.0,
                   help="row spacing of the 95 %% table, s")
    p.set_defaults(func=_handler)
