"""Figure of the jamming study across dimensions: phi_J and the contact number vs d (Skoge et al.
2006 / Donev Table 11.1; isostatic Z = 2d)."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.validation.packings import LS_TARGETS
from hardpack.validation.rows import mean_sem


def plot_jamming_vs_d(jammed: list, verdicts: list):
    """Left: LS phi_J (mean +- s.e. over seeds) of the monodisperse ensembles vs d, with the published
    values. Right: mean contact number after rattler removal vs d, with the isostatic 2d."""
    fig, (left, right) = figure(1, 2, figsize=(7.0, 3.0))
    for s in jammed:
        d = int(s["d"].values.ravel()[0])
        mean, sem = mean_sem(s["phi"].values)
        left.errorbar([d], [mean], [sem], fmt="o", color="C0",
                      label=f"LS, N = {int(s['N'].values.ravel()[0])}" if s is jammed[0] else None)
    pub = sorted((d, v[0]) for (kind, d), v in LS_TARGETS.items() if kind == "monodisperse")
    left.plot(*zip(*pub), "k_", ms=14, mew=1.5, label="published (Skoge et al., Donev Table 11.1)")
    left.set_xlabel("dimension d")
    left.set_ylabel(r"jamming density $\phi_J$")
    left.set_yscale("log")
    left.legend(loc="upper right")
    dims = []
    for s in verdicts:
        d = int(s["d"].values.ravel()[0])
        dims.append(d)
        mean, sem = mean_sem(s["z_mean"].values)
        right.errorbar([d], [mean], [sem], fmt="o", color="C1",
                       label="LS, rattlers removed" if s is verdicts[0] else None)
    if dims:
        grid = np.arange(min(dims), max(dims) + 1)
        right.plot(grid, 2 * grid, "k_", ms=14, mew=1.5, label="isostatic $2d$")
    right.set_xlabel("dimension d")
    right.set_ylabel(r"mean contact number $\bar Z$")
    right.legend(loc="upper left")
    fig.tight_layout()
    return fig
