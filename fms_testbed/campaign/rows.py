"""One row per case: the columns of the ``flights/`` dataset, and how a flight becomes a row.

Column contract (:data:`SCHEMA`, written with this Arrow schema into every Parquet file, so the
dataset reads as one table with ``pandas.read_parquet(DIR / "flights")``). Lengths in m,
times in s, path length in NM, RNP in NM — the unit is in every name:

* identity — ``case_id``, ``airport``, ``type`` (SID/STAR/APPROACH), ``procedure``, ``runway``
  and ``transition`` (the transitions flown, '' for none), ``aircraft``, ``conditions`` (the
  condition set's name) and ``conditions_json`` (its canonical JSON), ``seed`` (the case's,
  from its id), ``campaign_seed``, ``records_sha256`` (the database lines it uses);
* outcome — ``status`` (:data:`STATUSES`), ``reason``, ``error_class`` (Danilin 1/2/3,
  :func:`error_class`; null where none applies), ``error_type`` and ``traceback`` (status
  ``error``: the exception's class and the last frames);
* procedure — ``sequence`` (the merged transition's name), ``leg_codes`` (path terminators in
  order, space-separated), ``n_legs``, ``length_nm``, ``start`` (runway/fix/...),
  ``monitor_status``, ``monitor_findings`` (count), ``finding_classes`` (their categories,
  sorted, comma-separated), ``findings`` ('; '-separated), ``defects`` (defect kinds of a
  degraded sequence);
* errors — ``{fte,tse,nse}[_straight|_turns]_{p95,max}_m`` from the summary's ``errors``
  (``all`` has no infix), ``rnp_contained``, ``legs_not_contained``, ``min_rnp_nm``;
  ``constraints_checked``, ``constraints_missed``; ``legs_entered``, ``legs_skipped``,
  ``legs_repeated`` (counts, from the summary's ``sequencing``); ``vpe_p95_m``, ``vpe_max_m``
  (vertical path error |h − h_profile(s)| where the planned profile is flown as a path: level
  and descending parts, :func:`add_path_errors`) and ``spd_err_p95_kt`` (|TAS − TAS target|,
  kt at this edge);
* time — ``sim_time_s`` (simulated), ``wall_s`` (the whole case in its worker: build, trim,
  flight, evaluation), ``loop_wall_s`` (the flight loop alone, the summary's
  ``loop_wall_time_s``). Wall times are the only columns that differ between two runs of the
  same cases (:data:`WALL_COLUMNS`).
"""

from __future__ import annotations

import pyarrow as pa

from fms_testbed.evaluation.outcome import ORDER

NOT_FLOWN = ("degraded", "impossible")
"""Statuses of a case that was not flown: ``degraded`` (a record of its own is rejected,
duplicated or out of place: the procedure is not built) and ``impossible`` (the builder or the
monitor refuses the procedure)."""
RUN_FAILURES = ("timeout", "error")
"""``timeout`` (``--case-timeout`` reached; what was flown is evaluated) and ``error`` (an
exception, or the worker process died: a bug, with its traceback)."""
STATUSES = ("ok",) + ORDER + tuple(s for s in NOT_FLOWN if s not in ORDER) + RUN_FAILURES
"""Every status a case can have: the flight outcomes of :mod:`fms_testbed.evaluation.outcome`,
then :data:`NOT_FLOWN`, then :data:`RUN_FAILURES`, each once (``degraded`` is also a flight
outcome there: a flight built from degraded records; a campaign does not fly those)."""

ERROR_CLASSES = {
    1: "current conditions: the flight failed in wind, turbulence or on a navigation source "
       "other than truth",
    2: "leg combination the monitor does not cover: the monitor passed the procedure, and it "
       "failed in nominal conditions (calm, truth)",
    3: "database coding error: a record of the procedure is rejected, duplicated or out of "
       "place",
}
"""Danilin's error classes (seed 000) as a case is assigned one (:func:`error_class`)."""

_STATS = [(q, part) for q in ("fte", "tse", "nse") for part in ("all", "straight", "turns")]


def stat_column(quantity: str, part: str, stat: str) -> str:
    """Column name of one error statistic, e.g. ('fte', 'straight', 'p95') → fte_straight_p95_m.

    Parameters
    ----------
    quantity : 'fte', 'tse' or 'nse'; part : 'all', 'straight' or 'turns'
    stat : 'p95' or 'max'
    """
    mid = "" if part == "all" else f"_{part}"
    return f"{quantity}{mid}_{stat}_m"


ERROR_COLUMNS = tuple(stat_column(q, part, s) for q, part in _STATS for s in ("p95", "max"))

_S, _I, _F, _B = pa.string(), pa.int64(), pa.float64(), pa.bool_()
SCHEMA = pa.schema(
    [("case_id", _S), ("airport", _S), ("type", _S), ("procedure", _S), ("runway", _S),
     ("transition", _S), ("aircraft", _S), ("conditions", _S), ("conditions_json", _S),
     ("seed", _I), ("campaign_seed", _I), ("records_sha256", _S),
     ("status", _S), ("reason", _S), ("error_class", pa.int8()), ("error_type", _S),
     ("traceback", _S),
     ("sequence", _S), ("leg_codes", _S), ("n_legs", _I), ("length_nm", _F), ("start", _S),
     ("monitor_status", _S), ("monitor_findings", _I), ("finding_classes", _S),
     ("findings", _S), ("defects", _S)]
    + [(c, _F) for c in ERROR_COLUMNS]
    + [("rnp_contained", _B), ("legs_not_contained", _S), ("min_rnp_nm", _F),
       ("constraints_checked", _I), ("constraints_missed", _I),
       ("legs_entered", _I), ("legs_skipped", _I), ("legs_repeated", _I),
       ("vpe_p95_m", _F), ("vpe_max_m", _F), ("spd_err_p95_kt", _F),
       ("sim_time_s", _F), ("wall_s", _F), ("loop_wall_s", _F)])
"""Arrow schema of the ``flights/`` dataset (module docstring)."""
COLUMNS = tuple(SCHEMA.names)
WALL_COLUMNS = ("wall_s", "loop_wall_s")
"""Columns that depend on the machine and its load, not on the case."""


def error_class(status: str, nominal: bool) -> int | None:
    """Danilin's error class of a case (:data:`ERROR_CLASSES`).

    ``degraded`` → 3; a flight outcome other than ``ok`` → 1 in non-nominal conditions, 2 in
    nominal ones (a flown procedure has passed the monitor); None otherwise (``ok``; a procedure
    the monitor refuses, which is a coding error or a limit of the builder and is reviewed
    apart; ``timeout``/``error``, faults of the run itself). The report cross-checks class 1
    against the nominal flight of the same sequence where the run has one.

    Parameters
    ----------
    status : the case's status (:data:`STATUSES`)
    nominal : the condition set is calm air with navigation = truth
    """
    if status == "degraded":
        return 3
    if status in ORDER:
        return 2 if nominal else 1
    return None


def blank_row(case) -> dict:
    """A row with the case's identity and every other column null (``''`` for text).

    Parameters
    ----------
    case : the :class:`~fms_testbed.campaign.cases.Case`
    """
    row = {c: None for c in COLUMNS}
    row.update(case_id=case.case_id, airport=case.airport, type=case.type,
               procedure=case.procedure, runway=case.runway, transition=case.transition,
               aircraft=case.aircraft, conditions=case.conditions.name,
               conditions_json=case.conditions.canonical(), seed=case.seed,
               campaign_seed=case.campaign_seed, records_sha256=case.records_sha256,
               reason="", error_type="", traceback="", sequence="", leg_codes="", start="",
               monitor_status="", finding_classes="", findings="", defects="",
               legs_not_contained="")
    return row


def failed_row(case, status: str, reason: str, error_type: str = "",
               traceback: str = "") -> dict:
    """The row of a case that has no flight to evaluate (not built, raised, worker died).

    Parameters
    ----------
    case : the case; status : its status (:data:`STATUSES`); reason : why, one line
    error_type : the exception's class name (status ``error``)
    traceback : the exception's last frames (status ``error``)
    """
    row = blank_row(case)
    row.update(status=status, reason=reason, error_type=error_type, traceback=traceback,
               error_class=error_class(status, case.conditions.nominal))
    return row


def add_sequence(row: dict, seq) -> None:
    """Set the merged sequence's name, leg codes and defect kinds (known before building).

    Parameters
    ----------
    row : the row, updated in place; seq : the merged database sequence
    """
    row["sequence"] = seq.name
    row["leg_codes"] = " ".join(lg.path_term for lg in seq.legs)
    row["n_legs"] = len(seq.legs)
    row["defects"] = ",".join(sorted({d.kind for d in seq.defects}))


def flown_row(case, summary: dict) -> dict:
    """The row of a flown case from its flight summary.

    Parameters
    ----------
    case : the case
    summary : the flight's :class:`~fms_testbed.run.results.Summary` (after
        :func:`~fms_testbed.evaluation.outcome.decide`)
    """
    row = blank_row(case)
    proc = summary.get("procedure", {})
    findings = proc.get("findings", [])
    row.update(
        status=summary["status"], reason=summary["reason"],
        error_class=error_class(summary["status"], case.conditions.nominal),
        sequence=proc.get("name", ""), leg_codes=" ".join(proc.get("legs", [])),
        n_legs=len(proc.get("legs", [])), length_nm=proc.get("length_nm"),
        start=proc.get("start") or "", monitor_status=proc.get("monitor_status") or "",
        monitor_findings=len(findings),
        finding_classes=",".join(sorted({f.split(": ")[1] for f in findings
                                         if f.count(": ") >= 2})),
        findings="; ".join(findings),
        sim_time_s=summary.get("duration_s"), loop_wall_s=summary.get("loop_wall_time_s"))
    errors = summary.get("errors") or {}
    for q, part in _STATS:
        st = errors.get(q, {}).get(part, {})
        for s in ("p95", "max"):
            row[stat_column(q, part, s)] = st.get(f"{s}_m")
    rnp = summary.get("rnp")
    if rnp is not None:
        row["rnp_contained"] = bool(rnp["contained"])
        row["legs_not_contained"] = " ".join(str(k) for k in rnp["legs_not_contained"])
        row["min_rnp_nm"] = rnp.get("min_rnp_nm")
    cons = summary.get("constraints", [])
    row["constraints_checked"] = len(cons)
    row["constraints_missed"] = sum(1 for c in cons if c.get("ok") is False)
    q = summary.get("sequencing") or {}
    row["legs_entered"] = q.get("legs_entered")
    row["legs_skipped"] = len(q.get("skipped", []))
    row["legs_repeated"] = len(q.get("repeated", []))
    return row


def table(rows: list[dict]) -> pa.Table:
    """Rows as an Arrow table with :data:`SCHEMA` (a missing or extra column is an error).

    Parameters
    ----------
    rows : row mappings (:data:`COLUMNS` exactly)
    """
    for r in rows:
        if set(r) != set(COLUMNS):
            bad = sorted(set(r) ^ set(COLUMNS))
            raise ValueError(f"case {r.get('case_id')}: row columns differ from the schema: "
                             f"{bad}")
    return pa.Table.from_pylist(rows, schema=SCHEMA)


__all__ = ["COLUMNS", "ERROR_CLASSES", "ERROR_COLUMNS", "NOT_FLOWN", "RUN_FAILURES", "SCHEMA",
           "STATUSES", "WALL_COLUMNS", "add_sequence", "blank_row", "error_class",
           "failed_row", "flown_row", "stat_column", "table"]


def add_path_errors(row: dict, df, profile) -> None:
    """Set ``vpe_p95_m``, ``vpe_max_m`` and ``spd_err_p95_kt`` of a flown case from its
    timeseries (module docstring); left null where the flight has no samples for them.

    The vertical path error is ``h − h_p(s)`` with ``h_p`` the planned profile interpolated at
    the distance flown along the path, taken where the profile does not climb (a climb is flown
    at the best rate to its target, not along the profile).

    Parameters
    ----------
    row : the row, updated in place;  df : the flight's timeseries (``alt_m``, ``along_m``,
        ``tas_mps``, ``cmd_tas_mps``);  profile : the built path's planned profile
        (``along_m``, ``alt_m`` arrays, m) or None
    """
    import numpy as np

    from fms_testbed.core.units import KT_MPS

    if df is None or len(df) == 0:
        return
    if "cmd_tas_mps" in df:
        e = np.abs(df["tas_mps"].to_numpy() - df["cmd_tas_mps"].to_numpy())
        e = e[np.isfinite(e)]
        if len(e):
            row["spd_err_p95_kt"] = float(np.percentile(e, 95) / KT_MPS)
    if profile is None or "along_m" not in df:
        return
    s_p, h_p = np.asarray(profile.along_m, float), np.asarray(profile.alt_m, float)
    s = df["along_m"].to_numpy()
    ok = np.isfinite(s) & (s >= s_p[0]) & (s <= s_p[-1])
    if len(s_p) < 2 or not ok.any():
        return
    seg = np.clip(np.searchsorted(s_p, s[ok], side="right") - 1, 0, len(s_p) - 2)
    flat = h_p[seg + 1] <= h_p[seg] + 1e-6
    e = np.abs(df["alt_m"].to_numpy()[ok] - np.interp(s[ok], s_p, h_p))[flat]
    if len(e):
        row["vpe_p95_m"] = float(np.percentile(e, 95))
        row["vpe_max_m"] = float(e.max())
