"""Plots of the SINS error analysis (σ envelopes, realisations, 95 % position error).

Plotting never computes: it draws :class:`~.analysis.CovarianceResult` /
:class:`~.analysis.MonteCarloResult` objects and returns matplotlib Figures (the caller saves
them with :func:`fms_testbed.viz.figure.save`).

Units: engineering plots of the navigation error, in SI — position errors m, attitude errors
mrad, time min since the start.
"""

from __future__ import annotations

from matplotlib.figure import Figure

from fms_testbed.viz.figure import subplots

_ROWS = {
    "position": ((0, "east position error, m", 1.0), (1, "north position error, m", 1.0),
                 (2, "up position error, m", 1.0)),
    "attitude": ((6, "tilt about east ε_E, mrad", 1e3),
                 (7, "tilt about north ε_N, mrad", 1e3),
                 (8, "about up ε_U (heading), mrad", 1e3)),
}


def plot_envelopes(cov, mc, kind: str = "position", title: str = "") -> Figure:
    """Error components vs time: ±1σ/±3σ from covariance, Monte-Carlo realisations and ±3σ.

    Parameters
    ----------
    cov, mc : covariance and Monte-Carlo results (either may be None)
    kind : ``"position"`` (east/north/up errors, m) or ``"attitude"`` (tilts and heading, mrad)
    title : figure title
    """
    rows = _ROWS[kind]
    fig, axes = subplots(len(rows), 1, figsize=(9, 8), sharex=True)
    for ax, (i, label, sc) in zip(axes, rows):
        if mc is not None:
            tm = (mc.t_s - mc.t_s[0]) / 60.0
            for j in range(mc.samples.shape[2]):
                ax.plot(tm, mc.samples[:, i, j] * sc, color="0.6", lw=0.5,
                        label=f"realisations (first {mc.samples.shape[2]} of {mc.n_real})"
                        if j == 0 else None)
            ax.plot(tm, 3 * mc.sigma[:, i] * sc, "r--", lw=1.2,
                    label=f"±3σ Monte-Carlo (N = {mc.n_real})")
            ax.plot(tm, -3 * mc.sigma[:, i] * sc, "r--", lw=1.2)
        if cov is not None:
            tc = (cov.t_s - cov.t_s[0]) / 60.0
            ax.plot(tc, cov.sigma[:, i] * sc, "b-", lw=1.0, label="±1σ covariance")
            ax.plot(tc, -cov.sigma[:, i] * sc, "b-", lw=1.0)
            ax.plot(tc, 3 * cov.sigma[:, i] * sc, "k-", lw=1.5, label="±3σ covariance")
            ax.plot(tc, -3 * cov.sigma[:, i] * sc, "k-", lw=1.5)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper left", fontsize=8)
    axes[-1].set_xlabel("time since start, min")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_p95(results: dict, title: str = "") -> Figure:
    """95 % horizontal (radial) and vertical position error (m) vs time (min) for each named
    result (label → covariance or Monte-Carlo result)."""
    fig, (ax1, ax2) = subplots(2, 1, figsize=(9, 6), sharex=True)
    styles = {"covariance": "k-", "Monte-Carlo": "r--"}
    for name, res in results.items():
        t = (res.t_s - res.t_s[0]) / 60.0
        style = styles.get(name.split(" ")[0], "-")
        ax1.plot(t, res.h95_m, style, label=name)
        ax2.plot(t, res.v95_m, style, label=name)
    ax1.set_ylabel("95 % horizontal error, m")
    ax2.set_ylabel("95 % vertical error, m")
    ax2.set_xlabel("time since start, min")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


__all__ = ["plot_envelopes", "plot_p95"]
