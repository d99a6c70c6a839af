"""``fms-testbed imu-test``: the static drift test of a MEMS gyro with the three-stage compensation
of Vorobyov et al. (seed 000).

    fms-testbed imu-test --imu STIM210 [--duration-h 2] [--temperature-profile FILE|warmup|ramp]
        [--stages none,temperature,run-to-run,slow-drift] [--seed N] [--allan] --out DIR

Writes into ``--out``: ``accumulated_angle.csv`` (``t_s`` and ``angle_<stage>_<axis>_deg``, one
row per second, or per ⌈duration / 360,000⌉ s beyond 100 h), ``summary.json`` (per stage and axis the residual zero signal and mean drift in
°/s and the angle in °; the seed's figures next to the measured ones; the seed; with ``--allan``
the fitted ARW °/√h and bias instability °/h vs the preset's) and the plots
``zero_signal_vs_temperature.png``, ``residual_after_run_to_run.png``, ``accumulated_angle.png``
(and ``allan.png``). Exit code 0; 2 on a user error (unknown preset, bad profile file, unknown
stage).
"""

from __future__ import annotations

import json
from pathlib import Path

from fms_testbed.cli.common import SEED, add_overwrite_option, out_path
from fms_testbed.core.errors import UserError
from fms_testbed.run.outputs import OutputFolder
from fms_testbed.data import results_dir

DEFAULT_STAGES = "none,temperature,run-to-run,slow-drift"
MIN_DURATION_S = 60.0
"""Shortest test, s (the run-to-run stage averages the first 60 s after switch-on)."""
BYTES_PER_PROFILE_S = 150
"""Memory of the test per second of its duration, bytes: the 1-s temperature grid, its
hysteresis state and the play operator's working list (the samples are streamed in chunks and
the kept series is bounded, so nothing else grows with the duration); an upper bound of the
peak RSS's growth between a 100-h and a 1,000-h test (docs/mems.md)."""
FIXED_B = 640 * 2 ** 20
"""Memory of the test that does not grow with the duration, bytes: the chunks of every stage,
the kept series of :data:`~fms_testbed.sensors.mems.static_test.MAX_SERIES_ROWS` rows, the
CSV and the plots (an upper bound of the peak RSS over the interpreter's)."""
MEMORY_SHARE = 0.5
"""Share of the machine's available memory a test may take."""


def available_memory_b() -> int | None:
    """``MemAvailable`` of ``/proc/meminfo``, bytes (None where it cannot be read)."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def check_duration(duration_h: float, rate_hz: float, memory_b: int | None) -> float:
    """The test length, s, after the bounds: at least :data:`MIN_DURATION_S`, and at most
    T_max = (:data:`MEMORY_SHARE` · available − :data:`FIXED_B`) / :data:`BYTES_PER_PROFILE_S`
    (a one-line refusal naming the limit otherwise). The samples are streamed, so the rate
    does not enter the memory bound; it is named in the refusal.

    Parameters
    ----------
    duration_h : ``--duration-h``, h
    rate_hz : the preset's output rate, Hz
    memory_b : available memory, bytes (None: unknown, only the lower bound applies)
    """
    import math

    if not (math.isfinite(duration_h) and duration_h * 3600.0 >= MIN_DURATION_S):
        raise UserError(f"--duration-h {duration_h:g}: must be a finite number of hours >= "
                        f"{MIN_DURATION_S / 3600.0:.4f} ({MIN_DURATION_S:.0f} s)")
    if memory_b is not None:
        limit_h = max(0.0, MEMORY_SHARE * memory_b - FIXED_B) / BYTES_PER_PROFILE_S / 3600.0
        if duration_h > limit_h:
            raise UserError(f"--duration-h {duration_h:g}: longer than this machine can hold "
                            f"in memory: at most {limit_h:.0f} h at {rate_hz:g} Hz "
                            f"({BYTES_PER_PROFILE_S} B per second of test and "
                            f"{FIXED_B / 2**20:.0f} MiB, {MEMORY_SHARE:.0%} of "
                            f"{memory_b / 2**30:.1f} GiB available)")
    return duration_h * 3600.0


def _write(res, stages, tmp: Path) -> dict:
    """Write the CSV, the plots and ``summary.json`` of a test into ``tmp``; the summary."""
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.mems import (plot_accumulated_angle, plot_allan,
                                      plot_residual_after_run_to_run,
                                      plot_zero_signal_vs_temperature)

    res.angle_frame().to_csv(tmp / "accumulated_angle.csv", index=False, float_format="%.7g")
    plots = {"accumulated_angle.png": plot_accumulated_angle}
    if res.calibration is not None:
        plots["zero_signal_vs_temperature.png"] = plot_zero_signal_vs_temperature
    if {"temperature", "run-to-run"} & set(stages):
        plots["residual_after_run_to_run.png"] = plot_residual_after_run_to_run
    if res.allan is not None:
        plots["allan.png"] = plot_allan
    for name, plot in plots.items():
        save(plot(res), tmp / name)
    summary = res.summary()
    summary["outputs"] = ["accumulated_angle.csv", "summary.json", *sorted(plots)]
    (tmp / "summary.json").write_text(json.dumps(summary, indent=1, allow_nan=False) + "\n")
    return summary


def cmd_imu_test(args) -> int:
    """Run the static test, write the CSV, the summary and the plots; print one line per stage."""
    from fms_testbed.sensors.mems.compensation import parse_stages
    from fms_testbed.sensors.mems.preset import load_mems
    from fms_testbed.sensors.mems.static_test import run_static_test

    stages = parse_stages(args.stages)
    duration_s = check_duration(args.duration_h, load_mems(args.imu).sample_rate_hz,
                                available_memory_b())
    out = out_path(args.out, results_dir() / f"imu-test-{Path(args.imu).stem}")
    inputs = [f for f in (args.imu, args.temperature_profile) if f and Path(f).suffix]
    folder = OutputFolder(out, getattr(args, "overwrite", False), "imu-test", inputs)  # first
    res = run_static_test(args.imu, duration_s, args.temperature_profile, stages,
                          args.seed, allan=args.allan)
    try:
        with folder as tmp:
            summary = _write(res, stages, tmp)
            folder.set_run_info(seed=args.seed)
    except OSError as exc:
        raise UserError(f"--out {out}: cannot write the outputs: {exc.strerror or exc}") from None
    print(f"{res.imu}: {res.duration_s / 3600:g} h static at {res.rate_hz:g} Hz, profile "
          f"{res.profile.name}, seed {res.seed} ({res.wall_time_s:.1f} s)")
    for st, r in res.stage.items():
        print(f"  {st:11s} residual zero signal max {r.residual_max_deg_per_s.max():.5f} deg/s, "
              f"angle {', '.join(f'{v:.2f}' for v in r.angle_deg)} deg (x, y, z)")
    if res.allan is not None:
        a = res.allan
        print(f"  Allan ({res.allan_signal}): ARW {', '.join(f'{v:.4f}' for v in a.arw_deg_per_sqrt_h)}"
              f" deg/sqrt(h), bias instability "
              f"{', '.join(f'{v:.3f}' for v in a.bias_instability_deg_per_h)} deg/h")
    print(f"  outputs in {out}: {', '.join(summary['outputs'])}")
    return 0


def register(sub) -> None:
    """Add ``imu-test`` to the CLI."""
    p = sub.add_parser("imu-test", help="static MEMS gyro drift test with the three-stage "
                                        "compensation (temperature, run-to-run, slow drift)")
    p.add_argument("--imu", default="STIM210", help="MEMS gyro preset or YAML file "
                                                    "(default STIM210)")
    p.add_argument("--duration-h", type=float, default=2.0,
                   help="test length, h (default 2; at least 60 s; streamed in chunks, at "
                        "most what half the available memory holds at 150 B per second of test "
                        "plus 640 MiB)")
    p.add_argument("--temperature-profile", default="warmup",
                   help="warmup (switch-on self-heating, default), ramp (thermal cycle over the "
                        "operating range), constant, or a CSV file with t_s,temperature_degC")
    p.add_argument("--stages", default=DEFAULT_STAGES,
                   help=f"compensation stages to apply and report, comma-separated "
                        f"(default {DEFAULT_STAGES})")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the calibration and test runs "
                                                        "(default 0)")
    p.add_argument("--allan", action="store_true",
                   help="fit ARW and bias instability from the overlapping Allan deviation")
    p.add_argument("--out", help="output folder (default results/imu-test-<imu>)")
    add_overwrite_option(p)
    p.set_defaults(func=cmd_imu_test)
