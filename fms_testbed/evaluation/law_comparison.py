"""Compare the coupled law with the baselines on JSBSim, and with its ideal point-mass response.

For each scenario and each law the scenario is flown on JSBSim (the runner); the coupled law is
also flown on the lag-free point-mass plant (:mod:`.pointmass`) with the same commands — the
"ideal closed-loop response of the same law". Step metrics come from :mod:`.metrics`; the goals
of issue 3 are checked in :func:`check_goals`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from fms_testbed.config.aircraft import AircraftConfig, load_aircraft
from fms_testbed.core.atmosphere import cas_to_tas
from fms_testbed.config.scenario import Scenario
from fms_testbed.control import VERTICAL_LAWS
from fms_testbed.control.coupled_law import CoupledLaw, CoupledLawParams, params_from_config
from fms_testbed.control.metrics import find_steps, settling_time, step_metrics
from fms_testbed.core.units import mps_to_kmh
from fms_testbed.control.pointmass import CommandEvent, PointMassParams, second_order_step, simulate
from fms_testbed.loop.flight import fly
from fms_testbed.config.scenario import parse_scenario

LAWS = ("coupled", "pi", "tecs")


@dataclass
class ScenarioComparison:
    """All runs of one scenario: law → JSBSim DataFrame, plus the ideal point-mass run."""

    scenario: Scenario
    runs: dict[str, pd.DataFrame]
    ideal: pd.DataFrame
    status: dict[str, str] = field(default_factory=dict)


def initial_tas_mps(scn: Scenario) -> float:
    """Initial true airspeed of scenario ``scn``, m/s (CAS converted at the initial altitude)."""
    kind, spd = scn.initial.speed
    return float(cas_to_tas(spd, scn.initial.altitude_m)) if kind == "cas" else spd


def pointmass_events(scn: Scenario) -> list[CommandEvent]:
    """Altitude/speed events of scenario ``scn`` as point-mass command events.

    CAS is converted to TAS at the event's altitude target, or the last one before it.
    """
    out = []
    alt = scn.initial.altitude_m
    for ev in scn.events:
        a = ev.altitude_m
        kind, spd = ev.speed
        if a is None and spd is None:
            continue
        alt = a if a is not None else alt
        if spd is not None and kind == "cas":
            spd = float(cas_to_tas(spd, alt))
        w = ev.when
        out.append(CommandEvent(alt_m=a, tas_mps=spd, t_s=ev.t_s,
                                alt_above_m=w.alt_m_above if w else None,
                                alt_below_m=w.alt_m_below if w else None))
    return out


def ideal_response(scn: Scenario, params: CoupledLawParams) -> pd.DataFrame:
    """The coupled law flown on the lag-free point-mass plant with the scenario's commands.

    The law's inner-loop model is lag-free too (``ny_model_tau_s = 0``), as the plant's loops are.

    Parameters
    ----------
    scn : validated scenario;  params : coupled-law tuning
    """
    pm = PointMassParams(nx_idle=-0.3, nx_max=0.5)
    params = replace(params, ny_model_tau_s=0.0)
    return simulate(CoupledLaw(params=params), pm, scn.initial.altitude_m, initial_tas_mps(scn),
                    scn.duration_s, pointmass_events(scn))


def run_comparison(scn: Scenario, cfg: AircraftConfig | None = None,
                   laws: tuple[str, ...] = LAWS, params: CoupledLawParams | None = None,
                   seed: int | None = None) -> ScenarioComparison:
    """Fly ``scn`` with each law on JSBSim and the coupled law on the ideal point mass.

    Parameters
    ----------
    scn : validated scenario
    cfg : aircraft configuration (default: the scenario's aircraft)
    laws : law names from :data:`VERTICAL_LAWS`
    params : coupled-law tuning (default: from the config); the baselines use the same (T, ξ)
    seed : run seed
    """
    cfg = cfg or load_aircraft(scn.aircraft)
    params = params or params_from_config(cfg)
    runs, status = {}, {}
    for name in laws:
        law = VERTICAL_LAWS[name](params=params)
        df, summary = fly(scn, cfg=cfg, seed=seed, vertical_law=law, progress=False)
        runs[name] = df
        status[name] = summary["status"] if summary["status"] == "ok" else (
            f"{summary['status']}: {summary['reason']}")
    return ScenarioComparison(scn, runs, ideal_response(scn, params), status)


def stepped_channels(df: pd.DataFrame) -> list[str]:
    """Channels whose command changes during the run ``df`` (``"alt"``, ``"speed"``)."""
    out = []
    if find_steps(df, "cmd_alt_m"):
        out.append("alt")
    if find_steps(df, "cmd_tas_mps"):
        out.append("speed")
    return out


def pure_second_order_settling_s(T_s: float, xi: float, band_frac: float = 0.02) -> float:
    """Settling time (s) of 1/(T² p² + 2 ξ T p + 1) for a unit step, time constant ``T_s`` (s),
    damping ``xi``, band ``band_frac`` of the step (default 2 %)."""
    t = np.linspace(0.0, 40.0 * T_s, 40001)
    return settling_time(t, second_order_step(t, T_s, xi), 1.0, band_frac)


def comparison_rows(cmp: ScenarioComparison, cfg: AircraftConfig) -> list[dict]:
    """One table row per (law, stepped channel) of comparison ``cmp``: metrics plus the ideal
    response's settling; ``cfg`` gives the throttle limits."""
    rows = []
    lo, hi = cfg.inner_loops.throttle_min, cfg.inner_loops.throttle_max
    p = params_from_config(cfg)
    ideal_m = {ch: step_metrics(cmp.ideal, ch) for ch in stepped_channels(cmp.ideal)}
    for law, df in cmp.runs.items():
        if len(df) < 2 or not stepped_channels(df):
            rows.append({"scenario": cmp.scenario.name, "law": law, "status": cmp.status[law]})
            continue
        both = len(stepped_channels(df)) == 2
        for ch in stepped_channels(df):
            # overlapping steps (the paper's Fig. 2): the other channel is judged against the
            # ideal point-mass response, in which the channels are independent
            ref = cmp.ideal if both and ch == "speed" else None
            m = step_metrics(df, ch, throttle_min=lo, throttle_max=hi, reference=ref)
            im = ideal_m.get(ch)
            ideal_settle = im.settling_s if im else float("nan")
            rows.append({
                "scenario": cmp.scenario.name, "law": law, "status": cmp.status[law],
                "step": (f"alt {m.step:+.0f} m" if ch == "alt"
                         else f"speed {mps_to_kmh(m.step):+.0f} km/h"),
                "max_dV_kmh": mps_to_kmh(m.max_cross_dev) if ch == "alt" else float("nan"),
                "max_dH_m": m.max_cross_dev if ch == "speed" else float("nan"),
                "cross_ref": "ideal" if ref is not None else "command",
                "settling_s": m.settling_s, "ideal_settling_s": ideal_settle,
                "pure_2nd_order_settling_s": (
                    pure_second_order_settling_s(p.T_V_s, p.xi_V) if ch == "speed" else
                    pure_second_order_settling_s(p.T_H_s, p.xi_H)
                    if abs(m.step) <= p.dH_limit_m + 1e-6 else float("nan")),
                "settle_vs_ideal_pct": 100.0 * (m.settling_s - ideal_settle) / ideal_settle
                if ideal_settle and math.isfinite(ideal_settle) else float("nan"),
                "overshoot_pct": m.overshoot_pct,
                "throttle_activity_ps": m.throttle_activity_ps,
                "throttle_sat_pct": 100.0 * m.throttle_sat_frac,
                "ny_min": m.ny_min, "ny_max": m.ny_max,
            })
    return rows


@dataclass(frozen=True, slots=True)
class Goal:
    """One goal of the coupled-law comparison (docs/coupled-law.md) with its measured value."""

    name: str
    value: float
    limit: float
    unit: str
    ok: bool


def check_goals(table: pd.DataFrame) -> list[Goal]:
    """Check the issue-3 goals on a comparison table (rows from :func:`comparison_rows`).

    Goals: coupled max|ΔV| ≤ 1 km/h in the altitude step and ≥ 5× smaller than baseline (a);
    max|ΔH| ≤ 1.5 m in the speed step; settling within 10 % of the ideal point-mass response;
    for unclipped steps (speed steps, altitude steps ≤ dH_limit) settling within 20 % of the
    pure second order.

    Parameters
    ----------
    table : rows from :func:`comparison_rows` (each carries its own aircraft's
        pure-second-order settling)
    """
    goals = []
    if "step" not in table:  # no flight of the table measured a step (none ok, or none stepped)
        return goals
    t = table[(table["status"] == "ok") & table["step"].notna()]

    def pick(law, prefix):
        return t[(t["law"] == law) & t["step"].astype(str).str.startswith(prefix)]

    alt_c, alt_pi = pick("coupled", "alt"), pick("pi", "alt")
    for scen in alt_c["scenario"].unique():
        c = alt_c[alt_c["scenario"] == scen].iloc[0]
        goals.append(Goal(f"{scen}: coupled max|ΔV|", c["max_dV_kmh"], 1.0, "km/h",
                          c["max_dV_kmh"] <= 1.0))
        b = alt_pi[alt_pi["scenario"] == scen]
        if len(b):
            r = b.iloc[0]["max_dV_kmh"] / max(c["max_dV_kmh"], 1e-9)
            goals.append(Goal(f"{scen}: PI baseline / coupled max|ΔV|", r, 5.0, "×", r >= 5.0))
    for _, c in pick("coupled", "speed").iterrows():
        what = "max|H - H_ideal|" if c["cross_ref"] == "ideal" else "max|ΔH|"
        goals.append(Goal(f"{c['scenario']}: coupled {what} in the speed step", c["max_dH_m"],
                          1.5, "m", c["max_dH_m"] <= 1.5))
    for _, c in t[t["law"] == "coupled"].iterrows():
        d = abs(c["settle_vs_ideal_pct"])
        goals.append(Goal(f"{c['scenario']} ({c['step']}): settling vs ideal point mass", d,
                          10.0, "%", d <= 10.0))
        ref = c.get("pure_2nd_order_settling_s", float("nan"))
        if math.isfinite(ref):
            d2 = 100.0 * abs(c["settling_s"] - ref) / ref
            goals.append(Goal(f"{c['scenario']} ({c['step']}): settling vs pure 2nd order "
                              f"({ref:.1f} s)", d2, 20.0, "%", d2 <= 20.0))
    return goals


def envelope_scenario(cfg: AircraftConfig, alt_m: float, tas_mps: float, kind: str,
                      duration_s: float = 100.0) -> Scenario:
    """An unclipped step of ``cfg`` at ``alt_m`` (m), ``tas_mps`` (m/s): +100 m
    (``kind="alt"``) or +10 % TAS, flown for ``duration_s`` (s)."""
    ev = ({"t_s": 5.0, "alt_m": alt_m + 100.0} if kind == "alt"
          else {"t_s": 5.0, "tas_mps": 1.1 * tas_mps})
    return parse_scenario({
        "name": f"{cfg.name}-{alt_m:.0f}m-{mps_to_kmh(tas_mps):.0f}kmh-{kind}",
        "aircraft": cfg.source_file or cfg.name, "duration_s": duration_s, "hold": True,
        "initial": {"alt_m": alt_m, "tas_mps": tas_mps, "lat_deg": 47.0, "heading_deg": 90.0},
        "events": [ev]}, f"<envelope {cfg.name}>")


def envelope_rows(cfg: AircraftConfig, laws: tuple[str, ...] = ("coupled", "pi"),
                  seed: int | None = None) -> list[dict]:
    """Fly +100 m and +10 % speed steps at every envelope point of ``cfg`` with each law.

    Parameters
    ----------
    cfg : aircraft;  laws : law names;  seed : run seed

    Returns
    -------
    one row per (point, law) with settling (s), overshoot (%), the cross deviation (km/h in the
    altitude step, m in the speed step) and the throttle-saturation share (%)
    """
    params = params_from_config(cfg)
    lo, hi = cfg.inner_loops.throttle_min, cfg.inner_loops.throttle_max
    rows = []
    for pt in cfg.envelope:
        for law in laws:
            row = {"aircraft": cfg.name, "alt_m": pt.alt_m, "tas_kmh": mps_to_kmh(pt.tas_mps),
                   "law": law}
            for kind in ("alt", "speed"):
                scn = envelope_scenario(cfg, pt.alt_m, pt.tas_mps, kind)
                df, summary = fly(scn, cfg=cfg, seed=seed,
                                  vertical_law=VERTICAL_LAWS[law](params=params), progress=False)
                if summary["status"] != "ok":
                    row[f"{kind}_status"] = summary["reason"]
                    continue
                m = step_metrics(df, kind, throttle_min=lo, throttle_max=hi)
                row[f"{kind}_settling_s"] = m.settling_s
                row[f"{kind}_overshoot_pct"] = m.overshoot_pct
                row[f"{kind}_sat_pct"] = 100.0 * m.throttle_sat_frac
                if kind == "alt":
                    row["alt_step_max_dV_kmh"] = mps_to_kmh(m.max_cross_dev)
                else:
                    row["speed_step_max_dH_m"] = m.max_cross_dev
            rows.append(row)
    return rows
