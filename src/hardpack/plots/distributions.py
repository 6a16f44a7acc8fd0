"""Figure: sampled radii against the analytic size distribution."""

from __future__ import annotations

import numpy as np

from hardpack.distributions import Discrete, Distribution
from hardpack.plots.style import figure


def plot_size_distributions(samples: dict[str, tuple[np.ndarray, Distribution]]):
    """One panel per ensemble: histogram of sampled radii (density) and the analytic pdf.

    Discrete mixtures show sampled vs nominal number fractions as bars and markers.
    Returns the figure.

    Parameters
    ----------
    samples : dict of str to (numpy.ndarray, Distribution)
        Ensemble name -> (sampled radii, the distribution they were drawn from).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    n = len(samples)
    ncols = min(n, 3)
    nrows = -(-n // ncols)
    fig, axes = figure(nrows, ncols, figsize=(3.2 * ncols, 2.6 * nrows), squeeze=False)
    for ax, (name, (radii, dist)) in zip(axes.flat, samples.items()):
        radii = np.asarray(radii, float)
        if isinstance(dist, Discrete):
            sizes = np.asarray(dist.radii)
            counts = np.array([np.sum(np.isclose(radii, s)) for s in sizes]) / radii.size
            width = 0.05 * (sizes.max() if sizes.size == 1 else np.ptp(sizes))
            width = width or 0.05 * sizes.max()
            ax.bar(sizes, counts, width=width, color="C0", alpha=0.6, label=f"sampled (N={radii.size})")
            ax.plot(sizes, dist.fractions, "k_", markersize=14, mew=2, label="nominal fraction")
            ax.set_ylabel("number fraction")
        else:
            lo, hi = np.min(radii), np.max(radii)
            bins = np.linspace(lo, hi, min(40, max(8, radii.size // 20)) + 1)
            ax.hist(radii, bins=bins, density=True, color="C0", alpha=0.6, label=f"sampled (N={radii.size})")
            a = np.linspace(lo, hi, 400)
            ax.plot(a, dist.pdf(a), "k-", label="analytic pdf")
            ax.set_ylabel("pdf f(a)")
        ax.set_xlabel("radius a / <a>")
        ax.set_title(name)
        ax.legend()
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig
