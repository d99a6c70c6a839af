"""``fms-testbed nav-replay``: the INS/GNSS filter on recorded IMU and GNSS files, no truth
needed (file formats: :mod:`fms_testbed.navigation.replay_io`)::

    fms-testbed nav-replay --imu imu.csv --gnss gnss.csv --init init.json [--truth truth.csv]
        [--imu-preset NAME] --out DIR

Writes an atomic run folder: ``timeseries.parquet`` (the solution at every navigation step,
its σ and the estimated sensor biases), ``summary.json`` (inputs, GNSS measurements used and
rejected, and with ``--truth`` the error statistics), with ``--truth`` the plots
``errors.png`` and ``track.png``, and ``run.json``. A bad file gives one line (file, column,
row) and exit 2.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def replay_files(imu, gnss, init, truth=None, imu_preset: str | None = None) -> dict:
    """Replay the files and return {solution, errors, stats, summary} (errors and stats None
    without a truth file).

    Parameters
    ----------
    imu, gnss, init : the IMU, GNSS and init files;  truth : the truth file or None
    imu_preset : IMU preset (overrides the init's ``imu``)

    Raises
    ------
    UserError : a bad file or field (one line), no IMU preset
    """
    from fms_testbed.config.navigation import GnssBlock
    from fms_testbed.core.errors import UserError
    from fms_testbed.navigation.ins_gnss import gnss_spec
    from fms_testbed.navigation.replay import Replay, error_stats, error_table
    from fms_testbed.navigation.replay_io import read_gnss, read_imu, read_init, read_truth
    from fms_testbed.sensors.sins.presets import load_imu

    t, inc = read_imu(imu)
    G = read_gnss(gnss)
    ini = read_init(init)
    tr = read_truth(truth) if truth else None
    name = imu_preset or ini.get("imu")
    if not name:
        raise UserError(f"{init}: field 'imu' missing (or give --imu-preset NAME)")
    try:
        spec = gnss_spec(GnssBlock.model_validate(ini.get("gnss", {})))
    except ValueError as exc:
        raise UserError(f"{init}: field 'gnss': {str(exc).splitlines()[1].strip()}") from None
    rp = Replay(load_imu(name), spec, ini)
    sol = rp.run(t, inc, G)
    err = stats = None
    if tr is not None:
        err = error_table(sol, tr)
        stats = error_stats(err, sol) if len(err) else None
    summary = {"kind": "nav-replay", "imu_preset": name, "imu_samples": int(len(t)),
               "gnss_fixes": int(len(G)), "duration_s": round(float(t[-1] - t[0]), 3),
               "gnss_used": {k: v[0] for k, v in rp.counts.items()},
               "gnss_rejected": {k: v[1] for k, v in rp.counts.items()},
               "events": rp.events, "errors": stats}
    return {"solution": sol, "errors": err, "stats": stats, "summary": summary, "truth": tr}


def cmd_nav_replay(args) -> int:
    """Run the replay into ``--out`` (atomic)."""
    from fms_testbed.run.outputs import OutputFolder, check_out_dir, file_sha256
    from fms_testbed.core.jsonio import dumps

    check_out_dir(args.out, args.overwrite)
    res = replay_files(args.imu, args.gnss, args.init, args.truth, args.imu_preset)
    folder = OutputFolder(args.out, args.overwrite)
    with folder as tmp:
        res["solution"].to_parquet(tmp / "timeseries.parquet", index=False)
        (tmp / "summary.json").write_text(dumps(res["summary"]))
        if res["errors"] is not None and len(res["errors"]):
            _plots(res, tmp)
        folder.set_run_info(kind="nav-replay", status="ok", inputs={
            k: {"path": str(p), "sha256": file_sha256(p)} for k, p in
            (("imu", args.imu), ("gnss", args.gnss), ("init", args.init), ("truth", args.truth))
            if p})
    _print(res, args.out)
    return 0


def _plots(res: dict, folder: Path) -> None:
    from fms_testbed.viz.figure import save
    from fms_testbed.viz.replay import plot_errors, plot_track

    err, sol = res["errors"], res["solution"]
    sig = sol.set_index("t_s").loc[err["t_s"]].reset_index()
    h = res["stats"]["horizontal_m"]["p95"]
    save(plot_errors(err, sig, f"Replayed INS/GNSS solution - truth (horizontal 95 %: {h:.2f} m)"),
         folder / "errors.png")
    save(plot_track(sol, res["truth"], "Replayed track"), folder / "track.png")


def _print(res: dict, out) -> None:
    s = res["summary"]
    print(f"nav-replay: {s['imu_samples']} IMU samples over {s['duration_s']:.1f} s, "
          f"{s['gnss_fixes']} GNSS fixes (position used {s['gnss_used']['gnss_pos']}, "
          f"rejected {s['gnss_rejected']['gnss_pos']})")
    if res["stats"]:
        st = res["stats"]
        print(f"  horizontal error 95 % {st['horizontal_m']['p95']:.2f} m, max "
              f"{st['horizontal_m']['max']:.2f} m; heading RMS {st['rms']['heading_deg']:.3f} deg")
    print(f"  outputs in {out}")


def register(sub) -> None:
    """Add ``nav-replay`` to the CLI."""
    p = sub.add_parser("nav-replay", help="run the INS/GNSS filter on recorded IMU/GNSS files")
    p.add_argument("--imu", required=True, help="IMU file, CSV or Parquet (rates or increments)")
    p.add_argument("--gnss", required=True, help="GNSS file, CSV or Parquet")
    p.add_argument("--init", required=True, help="initial state JSON")
    p.add_argument("--truth", help="truth file (error statistics and plots)")
    p.add_argument("--imu-preset", help="IMU preset (overrides the init file's 'imu')")
    p.add_argument("--out", required=True, help="output folder")
    from fms_testbed.cli.common import add_overwrite_option
    add_overwrite_option(p)
    p.set_defaults(func=cmd_nav_replay)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(1)
