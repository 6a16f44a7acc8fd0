"""Figure of the jamming study across dimensions: phi_J and the contact number vs d (Skoge et al.
2006 / Donev Table 11.1; isostatic Z = 2d)."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.validation.rows import seed_statistics
from hardpack.validation.targets import load_targets


def plot_jamming_vs_d(jammed: list, verdicts: list):
    """Left: LS phi_J (mean +- s.e. over seeds) of the monodisperse ensembles vs d, with the published
    values. Right: mean contact number after rattler removal vs d, with the isostatic 2d."""
    fig, (left, right) = figure(1, 2, figsize=(7.0, 3.0))
    for s in jammed:
        d = int(s["d"].values.ravel()[0])
        mean, sem, _, _ = seed_statistics(s["phi"].values)
        left.errorbar([d], [mean], [sem], fmt="o", color="C0",
                      label=f"LS, N = {int(s['N'].values.ravel()[0])}" if s is jammed[0] else None)
    targets = load_targets()
    pub = [(d, targets[f"donev-t11.1-phij-d{d}"].published) for d in range(3, 7)]
    left.plot(*zip(*pub), "k_", ms=14, mew=1.5, label="published (Skoge et al., Donev Table 11.1)")
    left.set_xlabel("dimension d")
    left.set_ylabel(r"jamming density $\phi_J$")
    left.set_yscale("log")
    left.legend(loc="upper right")
    dims = []
    for s in verdicts:
        d = int(s["d"].values.ravel()[0])
        dims.append(d)
        mean, sem, _, _ = seed_statistics(s["z_mean"].values)
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
