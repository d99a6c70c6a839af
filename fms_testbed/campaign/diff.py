"""``regress diff RUN_A RUN_B``: what changed between two regression runs.

Cases are matched by what they fly — airport, type, procedure, runway, transition, aircraft and
condition set (:attr:`~.cases.Case.key`) — not by case id, so two database cycles or two
versions of the testbed compare case by case. For each matched pair the diff reports:

* a status change (``ok`` → ``not_contained``, ...), always a change;
* a change of a compared column beyond its tolerance (:data:`DEFAULT_TOLERANCES`, overridden
  per column by ``--tolerance FILE``): ``|b - a| > abs + rel × |a|``; a value that appears or
  disappears (null on one side) is a change, null on both sides is not;
* whether the database records it uses changed (``records_sha256``; information only: a new
  cycle that recodes a procedure changes its records, and its flight is then compared as any
  other).

With ``--across-conditions`` the condition set is left out of the match: a run in calm air
against the same cases in a 30 kt wind (each run must then hold one condition set per
sequence and aircraft).

Cases only in one run are listed (a procedure added or removed by a new cycle, a narrower
selection) and count as changes. The tolerance file is a mapping of column to
``{abs: X, rel: Y}`` (or a bare number: ``abs``), e.g.::

    fte_p95_m: {abs: 2.0, rel: 0.05}
    tse_max_m: 5.0
    constraints_missed: 0

Like JSBSim's ``FindDifferences`` (``tests/JSBSim_utils.py``): one tolerance per column.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from fms_testbed.campaign.rows import ERROR_COLUMNS
from fms_testbed.config.yamlfile import read_mapping
from fms_testbed.core.errors import ConfigError, UserError

KEY = ("airport", "type", "procedure", "runway", "transition", "aircraft", "conditions")
"""Columns that match a case to its twin in the other run."""
KEY_ACROSS = KEY[:-1]
"""The match without the condition set (``--across-conditions``)."""

COMPARED = tuple(c for c in ERROR_COLUMNS if c.startswith(("fte", "tse"))) + (
    "constraints_checked", "constraints_missed", "legs_entered", "legs_skipped",
    "legs_repeated")
"""Columns compared with a tolerance (FTE/TSE statistics, constraints, sequencing)."""

DEFAULT_TOLERANCES: dict[str, dict[str, float]] = {
    **{c: {"abs": 1.0, "rel": 0.0} for c in COMPARED if c.endswith("_m")},
    **{c: {"abs": 0.0, "rel": 0.0} for c in COMPARED if not c.endswith("_m")},
}
"""Default tolerance per compared column: 1 m on FTE/TSE statistics (they are kept to 0.01 m),
none on counts."""


def read_tolerances(path: str | Path) -> dict[str, dict[str, float]]:
    """A tolerance file (module docstring), merged over :data:`DEFAULT_TOLERANCES`;
    :class:`ConfigError` naming the file and the field.

    Parameters
    ----------
    path : the YAML file
    """
    raw = read_mapping(Path(path), "tolerance file")
    out = {k: dict(v) for k, v in DEFAULT_TOLERANCES.items()}
    for col, val in raw.items():
        if col not in DEFAULT_TOLERANCES:
            raise ConfigError(f"{path}: field '{col}': not a compared column (compared: "
                              f"{', '.join(COMPARED)})")
        if isinstance(val, (int, float)) and not isinstance(val, bool):
            val = {"abs": val}
        if not isinstance(val, dict) or set(val) - {"abs", "rel"}:
            raise ConfigError(f"{path}: field '{col}': expected a number or {{abs: X, rel: Y}}")
        for k, v in val.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or v < 0:
                raise ConfigError(f"{path}: field '{col}.{k}': expected a number ≥ 0")
        out[col] = {"abs": float(val.get("abs", 0.0)), "rel": float(val.get("rel", 0.0))}
    return out


def beyond(a: np.ndarray, b: np.ndarray, abs_tol: float, rel_tol: float) -> np.ndarray:
    """Element-wise: ``b`` differs from ``a`` beyond ``abs_tol + rel_tol × |a|``, or one of
    them is null (NaN) and the other is not."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    na, nb = np.isnan(a), np.isnan(b)
    with np.errstate(invalid="ignore"):
        far = np.abs(b - a) > abs_tol + rel_tol * np.abs(a)
    return (na != nb) | (~na & ~nb & far)


def _indexed(df: pd.DataFrame, where: str, key: tuple[str, ...]) -> pd.DataFrame:
    dup = df.duplicated(list(key), keep=False)
    if dup.any():
        first = df[dup].iloc[0]
        hint = ("; the run has several condition sets: compare it without --across-conditions"
                if "conditions" not in key else "")
        raise UserError(f"{where}: {int(dup.sum())} rows share a case key, e.g. "
                        + " ".join(str(first[k]) for k in key if first[k]) + hint)
    return df.set_index(list(key))


@dataclass
class DiffResult:
    """What :func:`diff_runs` found (module docstring).

    Attributes
    ----------
    run_a, run_b : the folders compared
    matched : cases in both runs
    only_a, only_b : key columns and status of the cases in one run only
    status_changes : key, ``status_a``, ``status_b``, ``reason_b``
    value_changes : key, ``column``, ``a``, ``b``, ``delta`` (b − a)
    records_changed : matched cases whose database records differ
    tolerances : the tolerance per compared column
    key : the columns cases were matched by
    """

    run_a: str
    run_b: str
    matched: int
    only_a: pd.DataFrame
    only_b: pd.DataFrame
    status_changes: pd.DataFrame
    value_changes: pd.DataFrame
    records_changed: int
    tolerances: dict = field(default_factory=dict)
    key: tuple[str, ...] = KEY

    @property
    def changed_cases(self) -> int:
        """Matched cases with a status change or a value change beyond tolerance."""
        keys = set(map(tuple, self.status_changes[list(self.key)].to_numpy())) | \
            set(map(tuple, self.value_changes[list(self.key)].to_numpy()))
        return len(keys)

    @property
    def clean(self) -> bool:
        """Nothing changed beyond tolerance and no case is in one run only."""
        return not (len(self.only_a) or len(self.only_b) or len(self.status_changes)
                    or len(self.value_changes))

    def headline(self) -> str:
        """One line: matched, changed, only in A/B, records changed."""
        return (f"{self.matched} cases matched: {self.changed_cases} changed beyond tolerance "
                f"({len(self.status_changes)} status changes, {len(self.value_changes)} value "
                f"changes); {len(self.only_a)} only in A, {len(self.only_b)} only in B; "
                f"{self.records_changed} with changed database records")

    def _tables(self):
        yield "status changes", self.status_changes
        yield "value changes beyond tolerance", self.value_changes
        yield "only in A", self.only_a
        yield "only in B", self.only_b

    def text(self, limit: int = 50) -> str:
        """The diff as plain-text tables (at most ``limit`` rows each)."""
        lines = [f"A: {self.run_a}", f"B: {self.run_b}", self.headline()]
        for title, df in self._tables():
            if len(df):
                lines += ["", f"{title} ({len(df)}):",
                          df.head(limit).to_string(index=False, na_rep="—")]
                if len(df) > limit:
                    lines.append(f"… {len(df) - limit} more")
        return "\n".join(lines)

    def markdown(self, limit: int = 50) -> str:
        """The diff as a Markdown summary (for a CI job summary or a docs page)."""
        out = ["# regress diff", "", f"- A: `{self.run_a}`", f"- B: `{self.run_b}`",
               f"- {self.headline()}", f"- verdict: {'no change' if self.clean else 'CHANGED'}"]
        trans = _transitions(self.status_changes)
        if len(trans):
            out += ["", "## Status transitions", "", _md(trans)]
        for title, df in self._tables():
            if len(df):
                out += ["", f"## {title[0].upper()}{title[1:]} ({len(df)})", "",
                        _md(df.head(limit))]
                if len(df) > limit:
                    out.append(f"\n… {len(df) - limit} more")
        return "\n".join(out) + "\n"


def _transitions(status_changes: pd.DataFrame) -> pd.DataFrame:
    if not len(status_changes):
        return status_changes
    return (status_changes.groupby(["status_a", "status_b"]).size()
            .rename("cases").reset_index().sort_values("cases", ascending=False))


def _md(df: pd.DataFrame) -> str:
    def cell(v) -> str:
        if isinstance(v, float):
            return "—" if not math.isfinite(v) else f"{v:.4g}"
        return str(v).replace("|", "\\|")

    cols = list(df.columns)
    rows = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    rows += ["| " + " | ".join(cell(v) for v in r) + " |" for r in df.itertuples(index=False)]
    return "\n".join(rows)


def diff_frames(a: pd.DataFrame, b: pd.DataFrame, tolerances: dict | None = None,
                names: tuple[str, str] = ("A", "B"), key: tuple[str, ...] = KEY) -> DiffResult:
    """Compare two ``flights`` tables (module docstring).

    Parameters
    ----------
    a, b : the tables (A is the reference)
    tolerances : per compared column ``{abs, rel}`` (default :data:`DEFAULT_TOLERANCES`)
    names : what to call A and B in the result
    key : the columns that match a case (:data:`KEY`, or :data:`KEY_ACROSS`)
    """
    tol = tolerances or DEFAULT_TOLERANCES
    ia, ib = _indexed(a, names[0], key), _indexed(b, names[1], key)
    both = ia.index.intersection(ib.index, sort=False).sort_values()
    only_a = ia.loc[ia.index.difference(ib.index).sort_values(), ["status"]].reset_index()
    only_b = ib.loc[ib.index.difference(ia.index).sort_values(), ["status"]].reset_index()
    pa_, pb_ = ia.loc[both], ib.loc[both]
    st = pa_["status"].to_numpy() != pb_["status"].to_numpy()
    status_changes = pd.DataFrame({"status_a": pa_["status"].to_numpy()[st],
                                   "status_b": pb_["status"].to_numpy()[st],
                                   "reason_b": pb_["reason"].to_numpy()[st]},
                                  index=both[st]).reset_index()
    changes = []
    for col in COMPARED:
        t = tol[col]
        va, vb = pa_[col].to_numpy(dtype=float), pb_[col].to_numpy(dtype=float)
        m = beyond(va, vb, t["abs"], t["rel"])
        if m.any():
            changes.append(pd.DataFrame({"column": col, "a": va[m], "b": vb[m],
                                         "delta": vb[m] - va[m]}, index=both[m]).reset_index())
    cols = list(key) + ["column", "a", "b", "delta"]
    value_changes = (pd.concat(changes, ignore_index=True)[cols] if changes
                     else pd.DataFrame(columns=cols))
    records = int((pa_["records_sha256"].to_numpy() != pb_["records_sha256"].to_numpy()).sum())
    return DiffResult(names[0], names[1], len(both), only_a, only_b, status_changes,
                      value_changes, records, tol, tuple(key))


def diff_runs(run_a: str | Path, run_b: str | Path, tolerances: dict | None = None,
              across_conditions: bool = False) -> DiffResult:
    """Compare the ``flights/`` datasets of two campaign folders (module docstring); a folder
    with a damaged part file is refused in one line naming the file and the cases
    (:func:`~.audit.read_checked`).

    Parameters
    ----------
    run_a, run_b : the campaign folders (A is the reference)
    tolerances : per compared column ``{abs, rel}`` (default :data:`DEFAULT_TOLERANCES`)
    across_conditions : match cases without their condition set (:data:`KEY_ACROSS`)
    """
    from fms_testbed.campaign.audit import read_checked

    a, b = (read_checked(r, refuse_damage=True)[0] for r in (run_a, run_b))
    return diff_frames(a, b, tolerances, (str(run_a), str(run_b)),
                       KEY_ACROSS if across_conditions else KEY)


__all__ = ["COMPARED", "DEFAULT_TOLERANCES", "KEY", "KEY_ACROSS", "DiffResult", "beyond",
           "diff_frames",
           "diff_runs", "read_tolerances"]
