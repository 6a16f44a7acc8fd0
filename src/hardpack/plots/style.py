"""The house style of hardpack figures and an atomic PDF + PNG writer."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from hardpack.io.atomic import atomic_path  # noqa: E402

RC = {
    "figure.figsize": (5.0, 3.6),
    "figure.dpi": 150,
    "font.size": 9,
    "axes.labelsize": 9,
    "axes.titlesize": 9,
    "legend.fontsize": 7.5,
    "legend.frameon": False,
    "axes.grid": True,
    "grid.alpha": 0.25,
    "lines.linewidth": 1.3,
    "savefig.bbox": "tight",
}


def figure(nrows: int = 1, ncols: int = 1, **kwargs):
    """A figure in the house style (``plt.subplots`` arguments).

    Parameters
    ----------
    nrows, ncols : int, optional
        Grid of axes.
    **kwargs
        Further arguments of :func:`matplotlib.pyplot.subplots`.

    Returns
    -------
    fig : matplotlib.figure.Figure
        The figure.
    axes : matplotlib.axes.Axes or numpy.ndarray of them
        Its axes.
    """
    with plt.rc_context(RC):
        return plt.subplots(nrows, ncols, **kwargs)


def save(fig, *paths) -> None:
    """Write the figure to each path (format from the suffix) atomically, then close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, closed afterwards.
    *paths : str or os.PathLike
        Output files.
    """
    with plt.rc_context(RC):
        for path in paths:
            with atomic_path(path, fsync=False) as tmp:
                fig.savefig(tmp, format=Path(path).suffix.lstrip("."))
    plt.close(fig)
