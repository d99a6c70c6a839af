"""``regress report DIR``: one self-contained HTML page (``DIR/report.html``, figures embedded
as PNG data) on a regression run.

Sections: the run (command, version, database and its SHA-256, size, speed); outcome counts
by status, by procedure type, by airport and by leg code; the FTE/TSE distributions; the worst
cases with their ground tracks; monitor findings by class; error classes (Danilin 1/2/3) with
the class-1 cross-check; for a test-database run, its outcomes against the database's manifest
(:mod:`.manifest`); the residual-error rate per Danilin phase; the cases that raised.

Residual-error rate (Danilin, seed 000: the residual error rate of each phase decides whether
the software goes on to the next): the share of the cases that were flown (or tried to be:
every case but those not built, :data:`~.rows.NOT_FLOWN`) that failed for a reason of the
software under test — error class 1 or 2, a timeout or an exception — with a 95 % Wilson
interval. Class 3 (database coding errors) are findings about the database, counted apart. In
the test-database phase (phase 1) the residual errors are instead the designed cases whose
outcome disagrees with the manifest (:mod:`.manifest`), and its criterion is that rate ≤ 2 %
with every designed case flown.

Class-1 cross-check: a failure in wind, turbulence or on a navigation source is class 1 by its
row; where the run also flew the same sequence with the same aircraft in nominal conditions and
that flight failed too, the conditions are not the cause: the report counts it as class 2.

Worst cases: the flown cases that are not ``ok``, most severe status first, then the largest
max TSE (all cases by max TSE when every case is ``ok``). Their tracks are drawn by flying them
again from the run's database (the same case id gives the same seed, so the same flight; the
report says whether the re-flown status and max TSE equal the recorded ones) unless
``--no-refly``.
"""

from __future__ import annotations

import base64
import html
import io
import logging
from functools import lru_cache
from pathlib import Path

import pandas as pd

from fms_testbed.campaign import figures
from fms_testbed.campaign.rows import ERROR_CLASSES, NOT_FLOWN, STATUSES
from fms_testbed.core.errors import UserError

log = logging.getLogger(__name__)

PHASES = (
    ("test database", "≈ 50 synthesised procedures; nominal and varied conditions",
     "residual-error rate = cases disagreeing with the test database's manifest / manifest "
     "cases ≤ 2 % (campaign/manifest.py: Danilin gives no figure; 2 % is one case of ~50), "
     "every manifest case flown"),
    ("integration", "≈ 100 airports, > 5,000 procedure flights under varied conditions",
     "≥ 100 airports and ≥ 5,000 flights"),
)
"""Danilin's phases: name, what the paper flies, the criterion a run is held to."""


def png_data_uri(fig, dpi: int = 90) -> str:
    """A Figure as a ``data:image/png;base64,…`` URI (the report embeds every figure).

    Parameters
    ----------
    fig : the matplotlib Figure; dpi : resolution, dots per inch
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def wilson_interval(k: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion k/n (scipy's ``binomtest``).

    Parameters
    ----------
    k : successes (here: residual errors); n : trials (cases flown)
    """
    from scipy.stats import binomtest

    if n == 0:
        return float("nan"), float("nan")
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


def refined_classes(df: pd.DataFrame) -> pd.Series:
    """The error class of each row after the class-1 cross-check (module docstring).

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    cls = df["error_class"].astype("Float64")
    if not len(df):
        return cls
    nominal = df["conditions_json"].map(_is_nominal).astype(bool)
    seq = ["airport", "type", "procedure", "runway", "transition", "aircraft"]
    nom = df[nominal].set_index(seq)["status"]
    nom = nom[~nom.index.duplicated()]
    idx = pd.MultiIndex.from_frame(df[seq])
    twin = pd.Series(nom.reindex(idx).to_numpy(), index=df.index)
    bad_twin = twin.notna() & (twin != "ok") & ~twin.isin(NOT_FLOWN)
    return cls.mask((cls == 1) & bad_twin, 2)


def _is_nominal(cond_json: str) -> bool:
    import json

    from fms_testbed.campaign.conditions import make_conditions

    return make_conditions(json.loads(cond_json), "conditions").nominal


def class_counts(df: pd.DataFrame) -> dict[str, int]:
    """Cases per error class after the cross-check, and the failures no class applies to.

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    cls = refined_classes(df)
    out = {f"{k}: {v.split(':')[0]}": int((cls == k).sum()) for k, v in ERROR_CLASSES.items()}
    out["refused by the monitor (impossible)"] = int((df["status"] == "impossible").sum())
    out["timeout / error"] = int(df["status"].isin(("timeout", "error")).sum())
    return out


def residual(df: pd.DataFrame) -> dict:
    """Residual-error rate of a run (module docstring).

    Parameters
    ----------
    df : the ``flights`` table (:data:`~fms_testbed.campaign.rows.SCHEMA`)
    """
    tried = df[~df["status"].isin(NOT_FLOWN)]
    cls = refined_classes(tried)
    k = int(((cls == 1) | (cls == 2)).sum() + tried["status"].isin(("timeout", "error")).sum())
    n = len(tried)
    lo, hi = wilson_interval(k, n)
    return {"flown": n, "residual_errors": k, "rate": k / n if n else float("nan"),
            "ci_low": lo, "ci_high": hi, "class3": int(((df["status"] == "degraded")
                                   | (df["monitor_status"] == "coding_suspect")).sum())}


def phase_row(folder: Path, df: pd.DataFrame, info: dict) -> dict:
    """One row of the phase table.

    Parameters
    ----------
    folder : the run's folder; df : its ``flights`` table; info : its ``run.json``
    """
    r = residual(df)
    n_air = df["airport"].nunique()
    n_proc = len(df.groupby(["airport", "procedure"]))
    phase = info.get("phase") or "?"
    crit = {"integration": n_air >= 100 and len(df) >= 5000}
    basis = "class 1/2, timeouts, errors over the cases flown"
    mc = manifest_check(df, info) if phase == "test database" else None
    if mc is not None:
        # phase 1: the residual errors are the cases that disagree with the manifest
        r = {**r, "residual_errors": mc.disagreements, "rate": mc.rate, "ci_low": mc.ci_low,
             "ci_high": mc.ci_high}
        crit["test database"] = mc.criterion_met
        basis = f"disagreements with the manifest over its {mc.cases} cases"
    elif phase == "test database":
        basis += " (no test-database manifest: criterion not assessed)"
    return {"run": folder.name, "phase": phase,
            "criterion met": {True: "yes", False: "no"}.get(crit.get(phase), "—"),
            "airports": n_air, "procedures": n_proc, "cases": len(df), "flown": r["flown"],
            "residual errors": r["residual_errors"],
            "residual-error rate": f"{100 * r['rate']:.2f} % "
                                   f"[{100 * r['ci_low']:.2f}, {100 * r['ci_high']:.2f}]",
            "counted as": basis, "class 3 found": r["class3"]}


def manifest_check(df: pd.DataFrame, info: dict):
    """The test-database manifest check of a run (:mod:`.manifest`), None when the run's
    database has no manifest.

    Parameters
    ----------
    df : the run's ``flights`` table; info : its ``run.json``
    """
    from fms_testbed.campaign.manifest import check_manifest, find_manifest, read_manifest

    path = find_manifest(info)
    if path is None:
        return None
    m = read_manifest(path, (info.get("database") or {}).get("sha256"))
    return check_manifest(df, m, info.get("status") == "complete")


def _manifest_section(df: pd.DataFrame, info: dict) -> list[str]:
    mc = manifest_check(df, info)
    if mc is None:
        return []
    t = mc.table
    bad = t[t["agrees"] != "yes"]
    head = (f"<p>{mc.cases} designed cases, {mc.disagreements} disagree with the manifest "
            f"({100 * mc.rate:.1f} % [{100 * mc.ci_low:.1f}, {100 * mc.ci_high:.1f}]), "
            f"{mc.missing} without a row; phase-1 criterion (≤ 2 %, every case flown): "
            f"<b>{'met' if mc.criterion_met else 'not met'}</b>.</p>")
    out = ["<h2>Test database: outcomes against the manifest</h2>", head]
    out += [f"<p class='note'>{html.escape(n)}</p>" for n in mc.notes]
    if len(bad):
        out += ["<h3>Disagreements</h3>", _table(bad)]
    out += ["<details><summary>every designed case</summary>", _table(t), "</details>"]
    return out


def worst_cases(df: pd.DataFrame, n: int) -> pd.DataFrame:
    """The ``n`` worst flown cases (module docstring).

    Parameters
    ----------
    df : the ``flights`` table; n : how many
    """
    flown = df[~df["status"].isin(NOT_FLOWN)].copy()
    bad = flown[flown["status"] != "ok"]
    pool = bad if len(bad) else flown
    pool = pool.assign(_sev=pool["status"].map(STATUSES.index),
                       _tse=pool["tse_max_m"].fillna(-1.0))
    return pool.sort_values(["_sev", "_tse"], ascending=[True, False], kind="stable").head(n)


@lru_cache(maxsize=2)
def _index(path: str):
    from fms_testbed.procedures.index import load_index

    return load_index(path)


def _track(row, info: dict) -> tuple[str | None, str]:
    """The re-flown ground-track figure of a case (data URI) and a note."""
    from fms_testbed.campaign.cases import case_from_row
    from fms_testbed.campaign.worker import fly_on
    from fms_testbed.viz.procedure import plot_ground_track

    dbinfo = info.get("database", {})
    ix = _index(dbinfo.get("path"))
    if ix.sha256 != dbinfo.get("sha256"):
        return None, f"not re-flown: {ix.path} changed since the run"
    again, res = fly_on(case_from_row(row), ix.db, str(ix.path))
    if res is None:
        return None, f"not re-flown: {again['reason']}"
    same = again["status"] == row["status"] and (
        again["tse_max_m"] == row["tse_max_m"]
        or (pd.isna(again["tse_max_m"]) and pd.isna(row["tse_max_m"])))
    note = ("re-flown: same status and max TSE as recorded" if same else
            f"re-flown: now {again['status']}, max TSE {again['tse_max_m']} m (recorded "
            f"{row['status']}, {row['tse_max_m']} m): the code or the machine changed since")
    fig = plot_ground_track(res.df, res.summary, res.procedure.path, tuple(res.flown_paths))
    return png_data_uri(fig), note


_CSS = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{font-size:1.5em} h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ccc}
table.t{border-collapse:collapse;font-size:0.85em;margin:0.5em 0}
table.t td,table.t th{border:1px solid #ccc;padding:2px 6px;text-align:left}
table.t th{background:#f2f2f2} img{max-width:100%;display:block;margin:0.5em 0}
code{background:#f5f5f5;padding:0 3px} .note{color:#555;font-size:0.85em}
"""
_RENDER_CHECK = """<script>
window.addEventListener('load', function () {
  var imgs = document.images, ok = 0;
  for (var i = 0; i < imgs.length; i++) { if (imgs[i].naturalWidth > 0) ok++; }
  document.body.setAttribute('data-figures', imgs.length);
  document.body.setAttribute('data-figures-rendered', ok);
  document.getElementById('render-check').textContent =
    ok + ' of ' + imgs.length + ' figures rendered in this browser';
});
</script>"""


def _table(df: pd.DataFrame) -> str:
    return df.to_html(index=False, escape=True, na_rep="—", classes="t", border=0,
                      float_format=lambda v: f"{v:.4g}")


def _img(fig, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="{png_data_uri(fig)}">'


def written_status(found, info: dict) -> tuple[str, str]:
    """('complete' or 'incomplete', one line) counted from the data: the cases of the plan with
    a row in a kept part, the missing ones, the damaged parts and the duplicate and foreign
    rows they hold (:mod:`.audit`; a folder without a plan is counted against ``run.json``'s
    case count).

    Parameters
    ----------
    found : the folder's :class:`~.audit.Audit`; info : its ``run.json``
    """
    n_plan = len(found.planned) if found.planned is not None else \
        (info.get("cases") or {}).get("count")
    n = len(found.written)
    missing = found.missing if found.planned is not None else []
    done = not found.damaged and n_plan is not None and n == n_plan and not missing
    text = f"{n} of {n_plan if n_plan is not None else '?'} planned cases written"
    if missing:
        text += f"; {len(missing)} missing (e.g. {', '.join(missing[:3])})"
    elif n_plan is not None and n < n_plan:
        text += f"; {n_plan - n} missing (the folder has no plan.parquet to name them)"
    if found.damaged:
        text += (f"; {len(found.damaged)} damaged part file(s) set aside ("
                 + ", ".join(f"{d.path.name}: {d.reason}" for d in found.damaged[:3])
                 + f"), holding {found.duplicate_rows} duplicate and {found.foreign_rows} "
                   "foreign row(s)")
    return ("complete" if done else "incomplete"), text


def _head(folder: Path, df: pd.DataFrame, info: dict, status_line: str) -> list[str]:
    e = html.escape
    db = info.get("database", {})
    sess = (info.get("sessions") or [{}])[-1]
    rows = (("command", " ".join(map(str, info.get("command", [])))),
            ("fms-testbed", info.get("version")),
            ("database", f"{db.get('path')} (SHA-256 {db.get('sha256')})"),
            ("status", status_line), ("phase", info.get("phase")),
            ("last session", f"{sess.get('cases_flown')} cases in {sess.get('elapsed_s')} s, "
                             f"{sess.get('flights_per_hour')} flights/h, workers "
                             f"{sess.get('workers')}, scheduler {sess.get('scheduler')}"),
            ("finished (UTC)", info.get("finished_utc")))
    return [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>regress report: {e(folder.name)}</title><style>{_CSS}</style></head>"
            f"<body><h1>Regression run <code>{e(folder.name)}</code></h1>",
            "<table class='t'>" + "".join(f"<tr><th>{e(k)}</th><td>{e(str(v))}</td></tr>"
                                          for k, v in rows) + "</table>"]


def _outcome_sections(df: pd.DataFrame, info: dict, worst: int, refly: bool) -> list[str]:
    counts = df["status"].value_counts().reindex([s for s in STATUSES
                                                  if s in set(df["status"])])
    parts = ["<h2>Outcomes</h2>", _table(pd.DataFrame({
        "status": counts.index, "cases": counts.to_numpy(),
        "share": [f"{100 * v / len(df):.1f} %" for v in counts.to_numpy()]}))]
    if not len(df):
        return parts + ["<p>No case written yet.</p>"]
    parts += [_img(figures.plot_outcomes_by_type(df), "outcome by type"),
              _img(figures.plot_outcomes_by_airport(df), "outcome by airport"),
              _img(figures.plot_outcomes_by_leg_code(df), "outcome by leg code"),
              "<h2>FTE / TSE</h2>",
              _img(figures.plot_error_distributions(df), "FTE/TSE distributions")]
    parts += _worst_section(df, info, worst, refly)
    parts += ["<h2>Monitor findings</h2>", _img(figures.plot_findings(df), "findings")]
    fc = figures.finding_counts(df)
    if len(fc):
        parts.append(_table(fc.rename_axis("class").reset_index(name="cases")))
    parts += _class_section(df)
    if info.get("phase") == "test database":
        parts += _manifest_section(df, info)
    return parts


def _phase_section(folder: Path, df: pd.DataFrame, info: dict, others) -> list[str]:
    rows = [phase_row(folder, df, info)] + [phase_row(f, d, i) for f, d, i in others]
    return ["<h2>Residual-error rate per Danilin phase</h2>",
            "<p class='note'>Residual errors: class 1 or 2 failures, timeouts and exceptions, "
            "over the cases flown (all but those not built); for the test-database phase, "
            "the cases whose outcome disagrees with the database's manifest, over the "
            "manifest's cases. 95 % Wilson interval in brackets. Class 3 (database coding "
            "errors) counted apart.</p>",
            _table(pd.DataFrame(rows)),
            _table(pd.DataFrame(PHASES, columns=["phase", "Danilin (seed 000)",
                                                 "criterion here"]))]


def _raised_section(df: pd.DataFrame) -> list[str]:
    err = df[df["status"] == "error"]
    if not len(err):
        return []
    parts = ["<h2>Cases that raised</h2>", _table(
        err.groupby(["error_type"]).agg(cases=("case_id", "size"),
                                        example=("reason", "first")).reset_index())]
    tb = err["traceback"].dropna()
    tb = tb[tb != ""]
    if len(tb):
        parts.append(f"<pre>{html.escape(tb.iloc[0])}</pre>")
    return parts


def build_html(folder: Path, df: pd.DataFrame, info: dict, worst: int = 6,
               others: list[tuple[Path, pd.DataFrame, dict]] = (), refly: bool = True,
               status_line: str | None = None) -> str:
    """The report page (module docstring) as HTML text.

    Parameters
    ----------
    folder : the run's folder; df : its ``flights`` table; info : its ``run.json``
    worst : worst cases drawn
    others : (folder, flights, run.json) of other runs for the phase table
    refly : fly the worst cases again to draw their tracks
    status_line : the run's status counted from its data (:func:`written_status`; default:
        the rows of ``df`` against ``run.json``'s case count)
    """
    if status_line is None:
        status_line = (f"{len(df)} of {info.get('cases', {}).get('count')} planned cases "
                       "written")
    parts = _head(folder, df, info, status_line)
    parts += _outcome_sections(df, info, worst, refly)
    parts += _phase_section(folder, df, info, others)
    parts += _raised_section(df)
    parts += ["<p class='note' id='render-check'></p>", _RENDER_CHECK, "</body></html>"]
    return "\n".join(parts)


def _worst_section(df: pd.DataFrame, info: dict, n: int, refly: bool) -> list[str]:
    w = worst_cases(df, n)
    shown = pd.DataFrame({
        "case": [_label(r) for _, r in w.iterrows()], "case_id": w["case_id"],
        "status": w["status"],
        "reason": [r if len(r) <= 140 else r[:137] + "…" for r in w["reason"].fillna("")],
        "FTE95, m": w["fte_p95_m"], "TSE95, m": w["tse_p95_m"], "max TSE, m": w["tse_max_m"]})
    out = [f"<h2>Worst cases ({len(w)})</h2>", _table(shown)]
    if not refly:
        return out + ["<p class='note'>Tracks not drawn (--no-refly).</p>"]
    for _, row in w.iterrows():
        try:
            uri, note = _track(row, info)
        except UserError as exc:
            uri, note = None, f"not re-flown: {exc}"
        out.append(f"<h3>{html.escape(_label(row))}: {html.escape(row['status'])}</h3>"
                   f"<p class='note'>{html.escape(note)}</p>")
        if uri:
            out.append(f'<img alt="track of {html.escape(row["case_id"])}" src="{uri}">')
    return out


def _label(row) -> str:
    return " ".join(str(row[c]) for c in ("airport", "type", "procedure", "runway",
                                          "transition", "aircraft", "conditions") if row[c])


def _class_section(df: pd.DataFrame) -> list[str]:
    counts = class_counts(df)
    cls = refined_classes(df)
    moved = int(((df["error_class"] == 1) & (cls == 2)).sum())
    text = "".join(f"<li><b>{k}</b>: {html.escape(v)}</li>" for k, v in ERROR_CLASSES.items())
    return ["<h2>Error classes</h2>", f"<ul>{text}</ul>",
            f"<p class='note'>Cross-check: {moved} failure(s) in non-nominal conditions whose "
            "nominal flight also failed are counted as class 2.</p>",
            _img(figures.plot_error_classes(counts), "error classes")]


def write_report(folder: str | Path, worst: int = 6, others: list = (),
                 refly: bool = True) -> tuple[Path, str]:
    """Write ``DIR/report.html`` (module docstring) from the rows of the part files that read
    and belong to the run (:mod:`.audit`; damage is stated in the page); return its path and
    the status line counted from the data.

    Parameters
    ----------
    folder : the campaign folder; worst : worst cases drawn
    others : other campaign folders for the phase table
    refly : fly the worst cases again to draw their tracks
    """
    from fms_testbed.campaign.audit import read_checked

    folder = Path(folder)
    df, info, found = read_checked(folder)
    status, line = written_status(found, info)
    info = {**info, "status": "complete" if status == "complete" else "running"}
    more = []
    for o in others:
        odf, oinfo, ofound = read_checked(o)
        ostatus = written_status(ofound, oinfo)[0]
        more.append((Path(o), odf, {**oinfo, "status": "complete" if ostatus == "complete"
                                    else "running"}))
    text = build_html(folder, df, info, worst, more, refly, f"{status}: {line}")
    out = folder / "report.html"
    tmp = folder / ".report.html.tmp"
    try:
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(out)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise UserError(f"{out}: cannot write the report: {exc.strerror or exc}") from None
    return out, f"{status}: {line}"


__all__ = ["PHASES", "build_html", "written_status", "class_counts", "manifest_check", "phase_row", "png_data_uri",
           "refined_classes", "residual", "wilson_interval", "worst_cases", "write_report"]
