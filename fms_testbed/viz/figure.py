"""Figures without pyplot: no backend is chosen or switched, so importing the plots leaves a
notebook's (or an application's) matplotlib backend as it was."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure


def subplots(*args, figsize: tuple[float, float] = (8.0, 6.0), **kwargs):
    """``pyplot.subplots`` without pyplot: a new :class:`~matplotlib.figure.Figure` and its axes.

    Parameters
    ----------
    figsize : figure size, inches (width, height)
    args, kwargs : passed to :meth:`Figure.subplots` (nrows, ncols, sharex, gridspec_kw, ...)
    """
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(*args, **kwargs)


def save(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    """Write a figure to ``path`` (PNG unless the suffix says otherwise); return the path.

    Parameters
    ----------
    fig : the figure
    path : the file to write (its folder is made if missing)
    dpi : resolution, dots per inch
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    return path
