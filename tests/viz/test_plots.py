"""Every plot function takes data and returns a Figure (nothing written); the plots of one
flight speak one unit system (NM, ft, kt; errors in m), engineering plots stay SI; every axis is
labelled with its unit and every figure has a title and a legend."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from matplotlib.figure import Figure

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.units import NM_M
from fms_testbed.data import scenarios_dir
from fms_testbed.evaluation.check import perf_for
from fms_testbed.path.monitor import check_path
from fms_testbed.path.segmentation import build_sequence
from fms_testbed.procedures.database import load_database
from fms_testbed.run import run_scenario
from fms_testbed.sensors.sins.analysis import SinsOptions, covariance_run
from fms_testbed.sensors.sins.presets import load_imu
from fms_testbed.sensors.sins.trajectory import straight_level
from fms_testbed.sim.inner_steps import StepResult, check_aircraft, specs_for
from fms_testbed.viz import control, inner, path as vpath, procedure, run as vrun, sins

UNIT = ("NM", "ft", "kt", "deg", "g", "s", "m", "min", "mrad", "km/h", "dB", "normalised",
        "rad/s", "0..1")


@pytest.fixture(scope="module")
def flight():
    return run_scenario(scenarios_dir() / "demo-sid.yaml", progress=False)


def _labels(fig: Figure) -> list[str]:
    return [lab for ax in fig.axes for lab in (ax.get_xlabel(), ax.get_ylabel()) if lab]


def _check(fig: Figure) -> None:
    """A Figure with a title, a legend somewhere and a unit in every axis label."""
    assert isinstance(fig, Figure)
    titles = [ax.get_title() for ax in fig.axes] + [fig._suptitle.get_text()
                                                     if fig._suptitle else ""]
    assert any(t.strip() for t in titles)
    assert any(ax.get_legend() is not None for ax in fig.axes)
    for lab in _labels(fig):
        assert any(u in lab.replace("[", " ").replace("]", " ").replace(",", " ").split()
                   or f", {u}" in lab or f"{u})" in lab for u in UNIT), lab


def test_flight_plots_return_figures_in_aviation_units(flight, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    figs = flight.plot()
    assert set(figs) == {"ground_track", "time_histories", "procedure_track",
                         "procedure_vertical", "procedure_errors"}
    for name, fig in figs.items():
        _check(fig)
        for lab in _labels(fig):
            assert "km" not in lab and "m/s" not in lab, (name, lab)
    labels = [lab for f in figs.values() for lab in _labels(f)]
    assert "east of start, NM" in labels and "altitude MSL, ft" in labels
    assert "speed, kt" in labels and "CAS, kt" in labels
    assert os.listdir(tmp_path) == []                         # plotting writes nothing
    # the legs are labelled on the ground track
    texts = [t.get_text() for t in figs["procedure_track"].axes[0].texts]
    path = flight.procedure.path.path
    assert sum(any(t.startswith(f"{lg.index + 1} {lg.path_term}") for t in texts)
               for lg in path.legs if lg.seg_count) == sum(1 for lg in path.legs if lg.seg_count)


def test_ground_track_in_nm_matches_the_distance_flown(flight):
    """The plotted track's length (NM) is the flown distance in the summary."""
    fig = vrun.plot_ground_track(flight.df, flight.summary)
    x, y = fig.axes[0].lines[0].get_data()
    length_nm = float(np.sum(np.hypot(np.diff(x), np.diff(y))))
    dist_nm = flight.summary["metrics"]["distance_flown_m"] / NM_M
    assert length_nm == pytest.approx(dist_nm, rel=0.01)


def test_built_path_plot_is_a_figure_in_nm_and_ft():
    db = load_database()
    perf = perf_for("737")
    p = check_path(build_sequence(db, db.select("KJFK", "DEEZZ5", "RW31L")[0], perf), perf)
    fig = vpath.plot_path(p)
    _check(fig)
    assert fig.axes[0].get_xlabel().endswith(", NM") and fig.axes[1].get_ylabel() == "altitude, ft"
    assert "NM" in fig.axes[0].get_title()


def test_control_plots_stay_si_as_the_paper(flight):
    runs = {"coupled": flight.df, "ideal": flight.df}
    for fig in (control.plot_comparison(runs, "t"), control.plot_paper_fig2(runs, "t")):
        _check(fig)
        assert any("km/h" in lab for lab in _labels(fig))
    w = np.logspace(-2, 1, 20)
    W = np.ones((4, 2, w.size), dtype=complex)
    _check(control.plot_bode_coupling(w, {"case": W}, "t"))
    t = np.linspace(0, 10, 11)
    sv = np.zeros((4, t.size))
    _check(control.plot_linear_steps(t, {"case": (sv, sv)}, 10.0, 100.0, "t"))
    _check(control.plot_tuning_overlay({"alt": flight.df, "speed": flight.df},
                                       {"alt": flight.df, "speed": flight.df}, "t"))


def test_sins_plots_return_figures():
    cov = covariance_run(straight_level(60.0, 1.0), load_imu("STIM300"), SinsOptions())
    for fig in (sins.plot_envelopes(cov, None, "position", "t"),
                sins.plot_envelopes(cov, None, "attitude", "t"),
                sins.plot_p95({"covariance": cov}, "t")):
        _check(fig)


def test_inner_step_plot_marks_the_spec_and_the_settling_time():
    cfg = load_aircraft("737")
    res = [r for r in check_aircraft(cfg) if r.spec.loop == "ny"]
    fig = inner.plot_loop_steps("ny", [("default", r) for r in res], "737")
    _check(fig)
    assert len(fig.axes) == 2                                 # up and down steps
    leg = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("settling limit" in t for t in leg) and any("settling band" in t for t in leg)
    assert ("PASS" in fig._suptitle.get_text()) == all(r.ok for r in res)
    # a response that never settles is said so, not drawn as 'inf'
    spec = specs_for(cfg)[0]
    t = np.linspace(0.05, 12.0, 240)
    bad = StepResult(spec, t, np.full_like(t, 0.5 * spec.amplitude), spec.amplitude,
                     math.inf, 0.0)
    fig = inner.plot_loop_steps("bank", [("stuck", bad)], "737")
    txt = fig._suptitle.get_text()
    assert "FAIL" in txt and "not settled" in txt and "inf" not in txt
