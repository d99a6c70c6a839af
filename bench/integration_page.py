"""The integration-phase results page (issue 13): one calm run and the same run in a 30 kt wind,
summarised from their ``flights/`` datasets into ``docs/results/integration.md`` and two figures.

Nothing is flown here: the runs are made with the commands in ``docs/regression.md`` (section
"The integration phase"), then

    python bench/integration_page.py [--calm results/integration]
                                     [--wind results/integration-wind30]
                                     [--code-commit SHA] [--md integration.md]

reads them through the library (:func:`fms_testbed.campaign.store.read_flights`,
:func:`fms_testbed.campaign.report.residual`, :func:`fms_testbed.campaign.diff.diff_runs`) and
writes the page. Every figure on it is computed from the two datasets; a run still in progress
is reported as such (its case count against the planned count in ``run.json``).

Goals quoted (issue 12/13): FTE95 ≤ 150 m and max FTE ≤ 185 m; constraints within 50 ft / 5 kt;
≥ 100 airports and ≥ 5,000 flights in one resumable run.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

from fms_testbed.campaign import figures  # noqa: E402
from fms_testbed.campaign.diff import diff_runs  # noqa: E402
from fms_testbed.campaign.report import class_counts, residual  # noqa: E402
from fms_testbed.campaign.rows import NOT_FLOWN  # noqa: E402
from fms_testbed.campaign.store import read_flights, read_run_json  # noqa: E402

FTE95_GOAL_M = 150.0
FTE_MAX_GOAL_M = 185.2
FIGURES = report.FIGURES / "regression"


def _pct(k: int, n: int) -> str:
    return f"{100.0 * k / n:.1f} %" if n else "–"


def run_summary(folder: Path) -> tuple[dict, pd.DataFrame]:
    """Headline quantities of one run folder (every one computed from its flights table).

    Parameters
    ----------
    folder : a ``regress run`` output folder (``run.json`` + ``flights/``)

    Returns
    -------
    (dict of label → value, the flights table)
    """
    info = read_run_json(folder) or {}
    df = read_flights(folder)
    flown = df[~df["status"].isin(NOT_FLOWN)]
    defined = flown[flown["fte_p95_m"].notna()]
    within = ((defined["fte_p95_m"] <= FTE95_GOAL_M) & (defined["fte_max_m"] <= FTE_MAX_GOAL_M))
    checked = int(flown["constraints_checked"].sum())
    missed = int(flown["constraints_missed"].sum())
    r = residual(df)
    sessions = info.get("sessions", [])
    elapsed = sum(s.get("elapsed_s") or 0.0 for s in sessions)
    n_sessions = sum(s.get("cases_flown") or 0 for s in sessions)
    planned = (info.get("cases") or {}).get("count")
    out = {
        "status of the run": f"{info.get('status', '?')} ({len(df)} of {planned} cases)",
        "airports / procedures": f"{df['airport'].nunique()} / "
                                 f"{len(df.groupby(['airport', 'procedure']))}",
        "cases flown (not refused)": f"{len(flown)}",
        "ok": f"{int((df['status'] == 'ok').sum())} ({_pct(int((df['status'] == 'ok').sum()), len(df))})",
        "FTE95 ≤ 150 m and max ≤ 185 m (flights with a defined path)":
            f"{int(within.sum())} of {len(defined)} ({_pct(int(within.sum()), len(defined))})",
        "coded constraints met (50 ft, 5 kt)":
            f"{checked - missed} of {checked} ({_pct(checked - missed, checked)})",
        "RNP contained": f"{int(flown['rnp_contained'].sum())} of {len(flown)}",
        "median FTE95 / max FTE, m": f"{defined['fte_p95_m'].median():.1f} / "
                                     f"{defined['fte_max_m'].median():.1f}",
        "worst max FTE, m": f"{defined['fte_max_m'].max():.0f}",
        "residual-error rate (Danilin classes 1+2, timeouts, errors) [95 % CI]":
            f"{r['residual_errors']} of {r['flown']} = {100 * r['rate']:.2f} % "
            f"[{100 * r['ci_low']:.2f}, {100 * r['ci_high']:.2f}]",
        "class 3 (database coding) found": f"{r['class3']}",
        "flights per hour (2 workers, whole run incl. planning)":
            f"{3600.0 * n_sessions / elapsed:.0f}" if elapsed else "–",
        "median flight-loop wall time / simulated time":
            f"{flown['loop_wall_s'].median():.2f} s / {flown['sim_time_s'].median():.0f} s",
        "per-case overhead Σ(wall − loop) / Σ loop":
            f"{100 * (flown['wall_s'].sum() - flown['loop_wall_s'].sum()) / flown['loop_wall_s'].sum():.1f} %",
    }
    return out, df


def status_table(df: pd.DataFrame) -> str:
    """Cases per procedure type and status (Markdown)."""
    c = figures.status_counts(df, "type")
    c["total"] = c.sum(axis=1)
    c.loc["all"] = c.sum(axis=0)
    return report.table(["type", *c.columns], [[i, *map(int, r)] for i, r in c.iterrows()])


def fte_percentiles(df: pd.DataFrame) -> str:
    """FTE95 and max FTE percentiles per type (Markdown), m."""
    flown = df[~df["status"].isin(NOT_FLOWN) & df["fte_p95_m"].notna()]
    rows = []
    for t, g in [("all", flown), *flown.groupby("type")]:
        q95 = np.nanpercentile(g["fte_p95_m"], [50, 90, 99])
        qmx = np.nanpercentile(g["fte_max_m"], [50, 90, 99])
        rows.append([t, len(g), *(f"{v:.1f}" for v in q95), *(f"{v:.0f}" for v in qmx),
                     f"{g['fte_max_m'].max():.0f}"])
    return report.table(["type", "flights", "FTE95 p50", "FTE95 p90", "FTE95 p99",
                         "max FTE p50", "max FTE p90", "max FTE p99", "max FTE worst"], rows)


def worst_table(df: pd.DataFrame, n: int = 15) -> str:
    """The ``n`` flights with the largest max FTE and every flight not ok (up to ``n``)."""
    flown = df[~df["status"].isin(NOT_FLOWN)]
    bad = flown[flown["status"] != "ok"].sort_values("fte_max_m", ascending=False).head(n)
    rows = [[r.airport, r.procedure, f"{r.runway} {r.transition}".strip(), r.type, r.status,
             f"{r.fte_p95_m:.0f}", f"{r.fte_max_m:.0f}", str(r.reason)[:110]]
            for r in bad.itertuples()]
    return report.table(["airport", "procedure", "transitions", "type", "status", "FTE95 m",
                         "max FTE m", "reason"], rows)


def diff_section(calm: Path, wind: Path) -> str:
    """The calm → wind diff: headline, status transitions, largest FTE growth."""
    d = diff_runs(calm, wind, across_conditions=True)
    out = [f"{d.headline()}.", ""]
    trans = (d.status_changes.groupby(["status_a", "status_b"]).size().rename("cases")
             .reset_index().sort_values("cases", ascending=False))
    if len(trans):
        out += ["Status transitions, calm → 30 kt wind:", "",
                report.table(["calm", "wind", "cases"],
                             trans.itertuples(index=False, name=None)), ""]
    fte = d.value_changes[d.value_changes["column"] == "fte_max_m"]
    if len(fte):
        top = fte.sort_values("delta", ascending=False).head(10)
        out += ["Largest growth of the max FTE in the wind (m):", "",
                report.table(["airport", "procedure", "runway", "transition", "calm", "wind"],
                             [[r.airport, r.procedure, r.runway, r.transition, f"{r.a:.0f}",
                               f"{r.b:.0f}"] for r in top.itertuples()]), ""]
    return "\n".join(out)


def _quick_runs() -> tuple[Path, Path]:
    """The quick mode's two runs: KDLS of the FAA cycle beside the repository, calm and in a
    30 kt wind from 270°, in a temporary folder."""
    import tempfile

    tmp = Path(tempfile.mkdtemp(prefix="integration-page-"))
    for name, wind in (("calm", []), ("wind", ["--wind", "270/30"])):
        report.run_cli(["regress", "run", "--db", str(report.CIFP), "--airports", "KDLS",
                        *wind, "--workers", "2", "--no-progress", "--out", str(tmp / name)],
                       expect=tmp / name / "run.json", ok_codes=(0, 1))
    return tmp / "calm", tmp / "wind"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--calm", type=Path, default=report.REPO / "results" / "integration")
    p.add_argument("--wind", type=Path, default=report.REPO / "results" / "integration-wind30")
    p.add_argument("--code-commit", default="",
                   help="the commit the runs were flown with (stated on the page)")
    p.add_argument("--md", default="integration.md")
    p.add_argument("--figures", type=Path, default=FIGURES)
    report.add_quick(ap=p, what="fly KDLS calm and in a 30 kt wind (regress run) and write "
                                "the page from those runs")
    a = p.parse_args(argv)
    if a.quick:
        a.calm, a.wind = _quick_runs()

    calm_sum, calm = run_summary(a.calm)
    runs = [("calm", a.calm, calm_sum, calm)]
    if (a.wind / "flights").exists():
        wind_sum, wind = run_summary(a.wind)
        runs.append(("30 kt wind from 270°", a.wind, wind_sum, wind))
    info = read_run_json(a.calm) or {}
    body = ["Flown with fms-testbed " + str(info.get("version", "?"))
            + (f" at commit `{a.code_commit}`" if a.code_commit else "")
            + f"; database `{Path(info.get('database', {}).get('path', '?')).name}` "
              f"(SHA-256 `{info.get('database', {}).get('sha256', '?')[:16]}…`), 737, truth "
              "navigation, every transition of the sampled airports at least once.", ""]
    labels = list(calm_sum)
    body += [report.table(["", *[r[0] for r in runs]],
                          [[k, *[r[2][k] for r in runs]] for k in labels]), ""]
    for name, folder, _, df in runs:
        body += [f"### Outcomes, {name}", "", status_table(df), "",
                 f"FTE percentiles, {name} (m):", "", fte_percentiles(df), "",
                 f"Error classes, {name} (after the class-1 cross-check against the calm twin):",
                 "", report.table(["class", "cases"], class_counts(df).items()), "",
                 f"Flights not ok, {name}, largest max FTE first (at most 15):", "",
                 worst_table(df), ""]
    if len(runs) == 2:
        body += ["### Calm against wind (`regress diff --across-conditions`)", "",
                 diff_section(a.calm, a.wind), ""]
    a.figures.mkdir(parents=True, exist_ok=True)
    for name, fig in (("integration_outcomes_by_type.png", figures.plot_outcomes_by_type(calm)),
                      ("integration_fte.png", figures.plot_error_distributions(calm))):
        fig.savefig(a.figures / name, dpi=90)
        print(f"figure written to {a.figures / name}")
    report.write(a.md, "\n".join(body))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
