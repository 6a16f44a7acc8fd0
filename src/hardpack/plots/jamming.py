"""Figures of the jamming studies: phi_J and the contact number vs d (Skoge et al. 2006 / Donev
Table 11.1; isostatic Z = 2d), and a jammed disk packing in its (possibly sheared) cell with its
contact forces (after Donev 2006, Fig. 4.15)."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.patches import Circle, Polygon

from hardpack.plots.style import figure
from hardpack.validation.rows import seed_statistics
from hardpack.validation.targets import load_targets


def plot_jamming_vs_d(jammed: list, verdicts: list):
    """Left: LS phi_J (mean +- s.e. over seeds) of the monodisperse ensembles vs d, with the published
    values. Right: mean contact number after rattler removal vs d, with the isostatic 2d.

    Parameters
    ----------
    jammed : list of xarray.Dataset
        Summaries of the monodisperse LS ensembles.
    verdicts : list of xarray.Dataset
        Their jamming-verdict summaries.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
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


def plot_jammed_disks(packing, verdict):
    """A jammed disk packing in its periodic cell with the contact forces of its jamming verdict
    (after Donev 2006, Fig. 4.15: a strictly jammed packing from the deforming-cell LS).

    Disks whose centres lie in the cell are drawn, with the images that reach into it; the cell is
    the parallelogram of the lattice vectors; each contact is a line between the centres whose
    width grows with its force; rattlers are grey.

    Parameters
    ----------
    packing : Packing
        A periodic disk packing (d = 2), any cell shape.
    verdict : xarray.Dataset
        Its ``hardpack verify`` output (``contact_i``, ``contact_j``, ``contact_shift``, ``force``,
        ``rattler``; attribute ``verdict``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    lattice = np.asarray(packing.lattice, float)
    frac = np.linalg.solve(lattice, packing.positions.T).T
    centres = (frac - np.floor(frac)) @ lattice.T
    rattler = np.asarray(verdict["rattler"].values, bool)
    shifts = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)], float) @ lattice.T
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float) @ lattice.T
    fig, ax = figure(1, 1, figsize=(4.6, 4.6))
    disks, colours = [], []
    for shift in shifts:
        for x, r, rat in zip(centres + shift, packing.radii, rattler):
            disks.append(Circle(x, r))
            colours.append("0.75" if rat else "C0")
    ax.add_collection(PatchCollection(disks, facecolors=colours, edgecolors="k", linewidths=0.4, alpha=0.55))
    i, j = verdict["contact_i"].values, verdict["contact_j"].values
    shift = np.asarray(verdict["contact_shift"].values, float)
    force = np.asarray(verdict["force"].values, float)
    start = centres[i]
    end = centres[j] + shift @ lattice.T
    scale = force / force.max() if force.size and force.max() > 0 else np.zeros_like(force)
    segments = [np.array([a, b]) + s for a, b in zip(start, end) for s in shifts]
    widths = np.repeat(0.4 + 2.6 * scale, len(shifts))
    ax.add_collection(LineCollection(segments, linewidths=widths, colors="C3"))
    ax.add_patch(Polygon(corners, closed=True, fill=False, edgecolor="k", linewidth=1.2))
    low, high = corners.min(axis=0), corners.max(axis=0)
    pad = 0.08 * (high - low).max()
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"N = {packing.n_particles}, $\\phi$ = {packing.phi:.4f}, {verdict.attrs.get('verdict', '')}; "
                 f"{int(rattler.sum())} rattlers", fontsize=8)
    return fig
