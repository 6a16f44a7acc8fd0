"""Figures of the BCMD free-energy study."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.validation.freeenergy import TARGETS


def plot_fcc_finite_size(summaries: dict):
    """BCMD free energies of FCC vs ln N / N (the leading finite-size term), with published values."""
    fig, axes = figure(1, len(summaries), figsize=(4.2 * len(summaries), 3.4), squeeze=False)
    for ax, (state, ds) in zip(axes.flat, summaries.items()):
        value, lines, var, label = TARGETS[state]
        n = ds["n_particles"].values.astype(float)
        x = np.log(n) / n
        ax.plot(x, ds[var].values, "o", color="C0", label="hardpack BCMD (each seed)")
        ax.axhline(value, color="C3", ls="--", label=f"published {value} (ch. 6 {lines})")
        ax.set_xlim(left=0)
        ax.set_xlabel(r"$\ln N / N$")
        ax.set_ylabel(label.replace("FCC ", "") + r" [$k_BT$ per particle]")
        ax.set_title(f"FCC, {'phi = 0.545' if state == 'melting' else 'delta = 1e-6'}")
        ax.legend()
    fig.tight_layout()
    return fig
