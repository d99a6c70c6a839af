"""SINS error-model speed figures (issue 5 goals), each a ratio or a time measured in this run.

1. Discretisation of the 33-state model at Δt = 0.1 s, tol 1e-12: adaptive Picard (numba, dense and
   block-structured) vs scipy Van Loan (66×66 expm) — goal: Picard ≥ 2× faster. Calls are
   interleaved in rounds; the median round is reported.
2. Monte-Carlo: N realisations over a straight-and-level trajectory at 10 Hz on one core
   (OpenBLAS limited to one thread) — goal: 1000 × 1 h ≤ 30 s.
3. Navigation step (F + Picard + factor + propagation + solution) vs 12 bare JSBSim steps
   (one 10 Hz navigation period at 120 Hz) — budget ≈ 70 µs. Medians of 5 interleaved rounds.
4. Closed loop with SINS injection: JSBSim frames per wall second of a scenario with
   ``navigation: {source: sins}`` over the bare JSBSim rate — goal ≥ 0.5. Each flight is timed
   interleaved with a bare instance in 10 s chunks (``interleave.py``; the machine is shared and
   separate runs vary by ±20 %).

    python bench/bench_sins.py [--mc-duration-s 3600] [-n 1000] [--sim-s 300] [--skip-jsbsim]
                               [--md sins_speed.md]

Writes the figures as a Markdown table to ``docs/results/sins_speed.md`` (``--md ''``: do not).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from fms_testbed.sensors.sins.analysis import SinsOptions, montecarlo_run, system_matrix
from fms_testbed.sensors.sins.discretize import discretize, discretize_sins, picard_order_used
from fms_testbed.sensors.sins.presets import load_imu
from fms_testbed.sensors.sins.trajectory import straight_level

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402


def _flight_F(imu):
    return system_matrix(0.82, 3000.0, np.array([150.0, 100.0, 5.0]), np.array([0.3, 0.05, 1.0]),
                         np.array([0.01, -0.02, 0.05]), np.array([0.5, 0.3, -10.2]), imu,
                         SinsOptions(vertical="free"))


def _per_call_us(fn, n):
    t0 = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t0) / n * 1e6


def bench_discretisation(imu, rounds: int = 7, n: int = 300) -> dict:
    """Median µs per call of each method, interleaved rounds, plus accuracy against Van Loan."""
    from fms_testbed.sensors.sins._blas import single_thread_blas

    F = _flight_F(imu)
    q = imu.q_psd
    Q = np.diag(q)
    fns = {"vanloan": lambda: discretize(F, Q, 0.1, method="vanloan"),
           "picard": lambda: discretize(F, Q, 0.1, method="picard"),
           "picard_structured": lambda: discretize_sins(F, q, 0.1)}
    times = {k: [] for k in fns}
    with single_thread_blas():
        for f in fns.values():
            f()
        for _ in range(rounds):
            for k, f in fns.items():
                times[k].append(_per_call_us(f, n))
    med = {k: statistics.median(v) for k, v in times.items()}
    pv, qv = discretize(F, Q, 0.1, method="vanloan")
    pp, qp = discretize(F, Q, 0.1)
    return {**med, "order": picard_order_used(F, Q, 0.1),
            "phi_rel": float(np.abs(pp - pv).max() / np.abs(pv).max()),
            "qk_rel": float(np.abs(qp - qv).max() / np.abs(qv).max())}


def bench_montecarlo(imu, n_real: int, duration_s: float) -> dict:
    traj = straight_level(duration_s, 0.1, speed_mps=200.0, heading_deg=45.0)
    montecarlo_run(straight_level(2.0, 0.1), imu, 10, seed=0)              # compile
    t0 = time.perf_counter()
    res = montecarlo_run(traj, imu, n_real, seed=0)
    wall = time.perf_counter() - t0
    return {"wall_s": wall, "steps": len(traj) - 1, "h95_end_m": float(res.h95_m[-1])}


def _bare_fdm_trimmed():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from interleave import trimmed_bare_fdm

    from fms_testbed.config.aircraft import load_aircraft

    return trimmed_bare_fdm(load_aircraft("737"), 3000.0, 120.0)


def _states(n: int):
    from fms_testbed.core.state import AircraftState

    tr = straight_level(n * 0.1 + 1, 0.1, speed_mps=200.0, heading_deg=30.0)
    f = float        # JSBSim reads give Python floats; numpy scalars would slow the maths
    return [AircraftState(
        t_s=f(tr.t_s[k]), lat_rad=f(tr.lat_rad[k]), lon_rad=f(tr.lon_rad[k]),
        alt_m=f(tr.alt_m[k]), tas_mps=200.0, cas_mps=170.0, gs_mps=200.0, vs_mps=0.0,
        v_enu_mps=tr.v_enu_mps[k].copy(), roll_rad=0.0, pitch_rad=0.0,
        heading_rad=f(tr.rpy_rad[k, 2]), track_rad=0.0, alpha_rad=0.0, beta_rad=0.0,
        gamma_rad=0.0, p_rps=f(tr.w_eb_b_rps[k, 0]), q_rps=f(tr.w_eb_b_rps[k, 1]),
        r_rps=f(tr.w_eb_b_rps[k, 2]), nx=0.0, ny=1.0, f_body_mps2=tr.f_b_mps2[k].copy(),
        mach=0.6, agl_m=3000.0, throttle=0.6, mass_kg=6e4) for k in range(n)]


def bench_nav_step(imu_name: str, with_jsbsim: bool, n: int = 1000, rounds: int = 5) -> dict:
    """Median (over interleaved rounds) µs per SinsNavigation.update and per 12 JSBSim steps."""
    from fms_testbed.navigation.sins import SinsNavigation

    states = _states(n)
    variants = {"picard": {"method": "picard"}, "vanloan": {"method": "vanloan"},
                "picard_hold1s": {"method": "picard", "matrices_dt_s": 1.0}}
    for extra in variants.values():                           # warm-up / compile
        nav = SinsNavigation.from_spec({"source": "sins", "imu": imu_name, **extra})
        for s in states[:20]:
            nav.update(s)
    fdm = _bare_fdm_trimmed() if with_jsbsim else None
    times = {k: [] for k in list(variants) + (["jsbsim12"] if fdm else [])}
    for _ in range(rounds):
        for name, extra in variants.items():
            nav = SinsNavigation.from_spec({"source": "sins", "imu": imu_name, **extra})
            m = n // 5 if name == "vanloan" else n
            t0 = time.perf_counter()
            for s in states[:m]:
                nav.update(s)
            times[name].append((time.perf_counter() - t0) / m * 1e6)
        if fdm is not None:
            run = fdm.run
            t0 = time.perf_counter()
            for _ in range(12 * n):
                run()
            times["jsbsim12"].append((time.perf_counter() - t0) / n * 1e6)
    out = {f"nav_step_{k}_us": statistics.median(v) for k, v in times.items() if k != "jsbsim12"}
    if fdm is not None:
        out["jsbsim_12_steps_us"] = statistics.median(times["jsbsim12"])
    return out


def bench_closed_loop(sim_s: float, imu_name: str) -> dict:
    """Closed-loop frames per wall second over bare JSBSim, each timed interleaved with a bare
    instance (``interleave.py``): truth navigation, SINS (matrices every step), SINS holding its
    matrices for 1 s."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from interleave import interleaved_ratio

    from fms_testbed.config.aircraft import load_aircraft
    from fms_testbed.loop.flight import Flight
    from fms_testbed.config.scenario import parse_scenario

    cfg = load_aircraft("737")

    def closed(nav):
        scn = {"name": "bench-sins", "aircraft": "737", "duration_s": sim_s, "hold": True,
               "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000.0, "tas_mps": 120.0,
                           "heading_deg": 90},
               "events": [{"t_s": 10, "heading_deg": 180}, {"t_s": 60, "alt_m": 3300.0}]}
        if nav:
            scn["navigation"] = nav
        res = interleaved_ratio(Flight(parse_scenario(scn), cfg=cfg, progress=False), cfg)
        assert res["summary"]["status"] == "ok", res["summary"]
        return res

    sins = {"source": "sins", "imu": imu_name, "seed": 1, "method": "picard", "dt_s": 0.1}
    closed(sins)  # warm-up: numba compile/cache load
    return {"truth": closed(None), "sins": closed(sins),
            "sins_hold": closed({**sins, "matrices_dt_s": 1.0})}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--imu", default="STIM300")
    ap.add_argument("-n", type=int, default=1000, help="Monte-Carlo realisations")
    ap.add_argument("--mc-duration-s", type=float, default=3600.0)
    ap.add_argument("--sim-s", type=float, default=300.0, help="closed-loop simulated time, s")
    ap.add_argument("--skip-jsbsim", action="store_true")
    ap.add_argument("--md", default="sins_speed.md",
                    help="Markdown table in docs/results/ ('' to skip)")
    report.add_quick(ap, "10 Monte-Carlo realisations of 10 min, 60 s closed loops")
    args = ap.parse_args()
    if args.quick:
        args.n, args.mc_duration_s, args.sim_s = 10, 600.0, 60.0
    imu = load_imu(args.imu)

    d = bench_discretisation(imu)
    print(f"[1] discretisation, 33 states, dt 0.1 s, tol 1e-12 ({d['order']} terms):")
    print(f"    scipy Van Loan      {d['vanloan']:8.1f} us/call")
    print(f"    Picard (dense)      {d['picard']:8.1f} us/call   ratio {d['vanloan'] / d['picard']:.1f}x")
    print(f"    Picard (structured) {d['picard_structured']:8.1f} us/call   ratio "
          f"{d['vanloan'] / d['picard_structured']:.1f}x   (goal >= 2x)")
    print(f"    agreement with Van Loan: Phi {d['phi_rel']:.1e}, Q_k {d['qk_rel']:.1e} (max-abs rel)")

    nav = bench_nav_step(args.imu, not args.skip_jsbsim)
    print("[3] navigation step (F + Picard + factor + propagate + solution), warm:")
    print(f"    SinsNavigation.update picard {nav['nav_step_picard_us']:.1f} us, "
          f"picard with matrices held 1 s {nav['nav_step_picard_hold1s_us']:.1f} us, "
          f"vanloan {nav['nav_step_vanloan_us']:.1f} us")
    if "jsbsim_12_steps_us" in nav:
        print(f"    12 bare JSBSim 737 steps     {nav['jsbsim_12_steps_us']:.1f} us  -> nav step = "
              f"{nav['nav_step_picard_us'] / nav['jsbsim_12_steps_us']:.2f} x one 10 Hz period "
              "of bare JSBSim")

    if not args.skip_jsbsim:
        c = bench_closed_loop(args.sim_s, args.imu)
        t, sn, sh = c["truth"], c["sins"], c["sins_hold"]
        print(f"[4] closed loop, 737, {args.sim_s:g} s simulated, 120 Hz frames per wall second, "
              "each interleaved with bare JSBSim in 10 s chunks:")
        print(f"    truth nav: {t['closed_fps']:.0f} fps, ratio / bare {t['ratio']:.2f}")
        print(f"    SINS ({args.imu}, matrices every 0.1 s): {sn['closed_fps']:.0f} fps, "
              f"ratio SINS closed loop / bare = {sn['ratio']:.2f} (goal >= 0.5)")
        print(f"    SINS with matrices held 1 s: {sh['closed_fps']:.0f} fps, ratio / bare = "
              f"{sh['ratio']:.2f}")

    m = bench_montecarlo(imu, args.n, args.mc_duration_s)
    print(f"[2] Monte-Carlo {args.n} realisations x {args.mc_duration_s:g} s at 10 Hz "
          f"({m['steps']} steps), one BLAS thread: {m['wall_s']:.1f} s (goal <= 30 s for 1000 x 1 h); "
          f"95% horizontal error at the end {m['h95_end_m']:.0f} m")

    rows = [["discretisation, scipy Van Loan (66×66 `expm`)", f"{d['vanloan']:.1f} µs per call",
             "1.0×", ""],
            [f"discretisation, Picard dense (numba, {d['order']} terms)",
             f"{d['picard']:.1f} µs per call", f"{d['vanloan'] / d['picard']:.1f}× faster", ""],
            ["discretisation, Picard block-structured (`discretize_sins`)",
             f"{d['picard_structured']:.1f} µs per call",
             f"**{d['vanloan'] / d['picard_structured']:.1f}× faster**", "≥ 2×"],
            ["agreement Picard / Van Loan (max-abs relative)",
             f"Φ {d['phi_rel']:.1e}, Q_k {d['qk_rel']:.1e}", "", "≤ 1e-12"],
            ["navigation step (F + Picard + factor + propagation + solution)",
             f"{nav['nav_step_picard_us']:.1f} µs", "", "≈ 70 µs"],
            ["navigation step, matrices held 1 s (`matrices_dt_s: 1`)",
             f"{nav['nav_step_picard_hold1s_us']:.1f} µs", "", ""],
            ["navigation step, `method: vanloan`", f"{nav['nav_step_vanloan_us']:.1f} µs", "", ""]]
    if "jsbsim_12_steps_us" in nav:
        rows.append(["12 bare JSBSim 737 frames (one 10 Hz period)",
                     f"{nav['jsbsim_12_steps_us']:.1f} µs",
                     f"nav step = {nav['nav_step_picard_us'] / nav['jsbsim_12_steps_us']:.2f}× it", ""])
    if not args.skip_jsbsim:
        rows += [["closed loop, truth navigation / bare JSBSim", "", f"{t['ratio']:.2f}", ""],
                 [f"closed loop, SINS ({args.imu}, matrices every 0.1 s) / bare JSBSim", "",
                  f"**{sn['ratio']:.2f}**", "≥ 0.5"],
                 ["closed loop, SINS with matrices held 1 s / bare JSBSim", "",
                  f"{sh['ratio']:.2f}", ""]]
    rows.append([f"Monte-Carlo {args.n} realisations × {args.mc_duration_s / 3600:g} h at 10 Hz, "
                 "one BLAS thread", f"**{m['wall_s']:.1f} s**", "", "≤ 30 s for 1000 × 1 h"])
    report.write(args.md, report.table(["what", "measured", "ratio", "goal"], rows),
                 note=f"IMU {args.imu}; 33-state model, Δt = 0.1 s, tolerance 1e-12; medians of "
                      "interleaved rounds; closed loops: 737, "
                      f"{args.sim_s:g} s simulated, each flight interleaved with bare JSBSim in "
                      "10 s chunks.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
