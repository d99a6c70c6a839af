"""Two whole-database checks compared row by row: the same statuses, or each difference listed.

    python bench/compare_checks.py BEFORE_DIR AFTER_DIR [--what "the builder as pure moves"]
                                   [--md procedures_refactor.md]

``BEFORE_DIR`` and ``AFTER_DIR`` are ``procedures check`` output folders (their
``procedures_check.parquet``). Rows are matched on (airport, procedure, transition, type, route
type, file lines); the page gives the number of rows, of status changes (each listed with both
statuses), of rows whose findings changed (each listed with what left and what came), and the
largest change of a path's length.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402

KEY = ["airport", "procedure", "transition", "type", "route_type", "lines"]


def compare(before: pd.DataFrame, after: pd.DataFrame) -> dict:
    """Row-by-row differences of two check tables (module docstring)."""
    m = before.merge(after, on=KEY, suffixes=("_a", "_b"))
    st = m[m["status_a"] != m["status_b"]]
    fd = m[m["findings_a"] != m["findings_b"]]
    changes = []
    for r in fd.itertuples():
        fa, fb = set(r.findings_a.split("; ")), set(r.findings_b.split("; "))
        changes.append((f"{r.airport} {r.type} {r.procedure} {r.transition or '(common)'}",
                        "; ".join(sorted(fa - fb)) or "—", "; ".join(sorted(fb - fa)) or "—"))
    return {"rows": (len(before), len(after), len(m)), "status": st, "findings": changes,
            "length_nm": float((m["length_nm_a"] - m["length_nm_b"]).abs().max())}


def _quick_pair() -> tuple[str, str]:
    """Two ``procedures check`` runs of KDLS on the FAA cycle beside the repository, in a
    temporary folder (the quick mode's inputs)."""
    import tempfile

    tmp = Path(tempfile.mkdtemp(prefix="compare-checks-"))
    for name in ("before", "after"):
        report.run_cli(["procedures", "check", "--db", str(report.CIFP), "--airports", "KDLS",
                        "--no-progress", "--out", str(tmp / name)],
                       expect=tmp / name / "procedures_check.parquet", ok_codes=(0, 1))
    return str(tmp / "before"), str(tmp / "after")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", nargs="?")
    ap.add_argument("after", nargs="?")
    ap.add_argument("--what", default="", help="what changed between the two runs")
    ap.add_argument("--md", default="procedures_refactor.md")
    report.add_quick(ap, "check one airport twice (the same code: no difference) and compare")
    a = ap.parse_args(argv)
    if a.quick:
        a.before, a.after = _quick_pair()
    elif not (a.before and a.after):
        ap.error("BEFORE_DIR and AFTER_DIR are required (or --quick)")
    before = pd.read_parquet(Path(a.before) / "procedures_check.parquet")
    after = pd.read_parquet(Path(a.after) / "procedures_check.parquet")
    report.refuse_degenerate(before["status"].value_counts().to_dict(), what=a.before)
    report.refuse_degenerate(after["status"].value_counts().to_dict(), what=a.after)
    c = compare(before, after)
    nb, na, nm = c["rows"]
    rows = [["rows before / after / matched", f"{nb:,} / {na:,} / {nm:,}"],
            ["status changes", f"{len(c['status'])}"],
            ["rows whose findings changed", f"{len(c['findings'])}"],
            ["largest change of a path's length", f"{c['length_nm']:.6f} NM"]]
    st_rows = [[f"{r.airport} {r.type} {r.procedure} {r.transition or '(common)'}",
                r.status_a, r.status_b] for r in c["status"].itertuples()]
    body = "\n".join([report.table(["metric", "result"], rows), "",
                      "**Status changes**\n",
                      report.table(["transition", "before", "after"], st_rows) if st_rows
                      else "none", "",
                      "**Findings that changed** (left, came)\n",
                      report.table(["transition", "before only", "after only"], c["findings"])
                      if c["findings"] else "none"])
    print(body)
    report.write(a.md, body, note=a.what)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
