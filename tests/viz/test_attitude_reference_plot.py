"""The flight-test attitude-reference figure (seed 004 Fig. 2): three panels (heading, roll,
pitch) with the error, the ±σ/±3σ envelopes and the goal lines; drawn from the timeseries and
the summary block, nothing computed; absent without the mode's columns."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

from fms_testbed.navigation.attitude_reference import attitude_reference_summary
from fms_testbed.viz.attitude_reference import plot_attitude_reference, plot_attitude_reference_run


def _df(n=301):
    t = np.linspace(0, 150, n)
    rng = np.random.default_rng(0)
    d = {"t_s": t}
    for a, s in (("roll", 0.003), ("pitch", 0.006), ("heading", 0.02)):
        d[f"att_ref_err_{a}_deg"] = np.full(n, 0.2)
        d[f"att_ref_est_{a}_deg"] = 0.2 + s * rng.standard_normal(n)
        d[f"att_ref_sigma_{a}_deg"] = np.full(n, s)
    return pd.DataFrame(d)


def test_figure_has_three_panels_goals_envelopes_and_units():
    df = _df()
    summary = {"scenario": "x", "attitude_reference": attitude_reference_summary(df)}
    fig = plot_attitude_reference(df, summary)
    assert isinstance(fig, Figure) and len(fig.axes) == 3
    for ax, (a, goal) in zip(fig.axes, (("heading", 0.06), ("roll", 0.01), ("pitch", 0.02))):
        assert a in ax.get_title(loc="left") and "deg" in ax.get_ylabel()
        ys = sorted(round(line.get_ydata()[0], 6) for line in ax.get_lines()
                    if line.get_linestyle() == "--")
        assert ys == [-goal, goal]
        assert sum(isinstance(c, PolyCollection) for c in ax.collections) == 2   # ±σ, ±3σ
        assert "max |error| after 60 s" in ax.get_title(loc="left")
    assert fig.axes[-1].get_xlabel() == "time, s"
    assert fig.axes[0].get_legend() is not None


def test_run_figures_only_in_the_mode():
    df = _df()
    assert set(plot_attitude_reference_run(df, {})) == {"attitude_reference"}
    assert plot_attitude_reference_run(df.drop(columns="att_ref_err_roll_deg"), {}) == {}
