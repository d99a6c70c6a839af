"""``regress report``: a self-contained HTML page (no external resource) with every figure
embedded, the re-flown worst cases equal to their recorded rows, the class-1 cross-check and the
residual-error rate; headless Chromium renders every figure (skipped where it is absent)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from fms_testbed.campaign.report import refined_classes, residual, wilson_interval
from fms_testbed.campaign.store import read_flights

from campaign_helpers import regress

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def report(small_run):
    assert regress("report", str(small_run), "--worst", "2", "--with", str(small_run)) == 0
    return small_run / "report.html"


def test_report_is_self_contained(report):
    text = report.read_text()
    imgs = re.findall(r'<img [^>]*src="([^"]+)"', text)
    assert len(imgs) >= 8 and all(s.startswith("data:image/png;base64,") for s in imgs)
    assert not re.search(r'(src|href)="(https?:|//|file:)', text)
    assert text.count("re-flown: same status and max TSE as recorded") == 2
    assert text.count("<td>small-2w</td>") == 2       # the phase table: this run and --with
    for section in ("Outcomes", "FTE / TSE", "Worst cases", "Monitor findings",
                    "Error classes", "Residual-error rate per Danilin phase"):
        assert f"<h2>{section}" in text


def test_residual_error_rate_counts_classes_one_and_two(small_run):
    df = read_flights(small_run)
    r = residual(df)
    tried = df[~df["status"].isin(("degraded", "impossible"))]
    bad = tried["status"] != "ok"
    assert r["flown"] == len(tried) and r["residual_errors"] == int(bad.sum())
    assert r["ci_low"] <= r["rate"] <= r["ci_high"]
    lo, hi = wilson_interval(0, 50)
    assert lo == 0.0 and 0.05 < hi < 0.09          # rule of three: ≈ 3/50


def test_class_one_with_a_failing_nominal_twin_counts_as_class_two(small_run):
    df = read_flights(small_run)
    cls = refined_classes(df)
    wind = df["conditions"] != "calm"
    seq = ["procedure", "runway", "transition"]
    calm = df[~wind].set_index(seq)["status"]
    class1 = df.index[wind & (df["error_class"] == 1)]
    assert len(class1), "the small set has failures in wind"
    for i in class1:
        twin = calm.loc[tuple(df.loc[i, seq])]
        assert cls[i] == (2 if twin != "ok" else 1)
    assert (cls[~wind].fillna(-1).tolist()
            == df.loc[~wind, "error_class"].fillna(-1).tolist())


@pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium is not installed "
                                              "(apt-get install chromium)")
def test_chromium_renders_every_figure(report, tmp_path):
    res = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                          f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom",
                          report.as_uri()], capture_output=True, text=True, timeout=120)
    dom = res.stdout
    n = re.search(r'data-figures="(\d+)"', dom)
    ok = re.search(r'data-figures-rendered="(\d+)"', dom)
    assert n and ok, f"the page's render check did not run: {res.stderr[-500:]}"
    assert int(n.group(1)) >= 8 and ok.group(1) == n.group(1)


def test_report_of_a_run_with_no_row_yet(small_run, tmp_path):
    out = tmp_path / "empty"
    out.mkdir()
    shutil.copy(small_run / "run.json", out / "run.json")      # says complete; no flights/
    shutil.copy(small_run / "plan.parquet", out / "plan.parquet")
    assert regress("report", str(out)) == 0
    page = (out / "report.html").read_text()
    assert "No case written yet" in page
    assert "incomplete: 0 of 20 planned cases written; 20 missing" in page
