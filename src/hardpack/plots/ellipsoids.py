"""Figures of the ellipsoid study: phi_J and Z vs aspect ratio (after Donev 2006, Figs. 5.2-5.3)
and a rendered snapshot of a jammed packing (after Fig. 5.1)."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import EllipseCollection

from hardpack.geometry.ellipsoid_stats import near_sphere_contact_law
from hardpack.plots.style import figure
from hardpack.validation.rows import seed_statistics

#: isostatic contact numbers 2 f (Donev 2006, Sec. 5.2): f = 3 for ellipses, 5 for spheroids
#: (the spin about the symmetry axis is trivial), 6 for general ellipsoids
ISOSTATIC = {"ellipses": 6, "spheroids": 10, "ellipsoids": 12}
#: largest aspect ratio of the near-sphere fit of Eq. 5.30 drawn on the contact-number panel
NEAR_SPHERE_ALPHA_MAX = 1.3


def _per_alpha(summary, beta, name):
    """(alpha, mean, s.e.) of ``name`` over seeds for the samples of one beta."""
    mask = np.isclose(np.asarray(summary["beta"].values, float), beta)
    alphas = np.asarray(summary["alpha"].values, float)[mask]
    values = np.asarray(summary[name].values, float)[mask]
    rows = []
    for alpha in np.unique(alphas):
        mean, sem, _, _ = seed_statistics(values[alphas == alpha])
        rows.append((alpha, mean, 0.0 if not np.isfinite(sem) else sem))
    return np.array(rows).reshape(-1, 3)


def plot_jamming_vs_alpha(summary, dim: int = 3):
    """phi_J (left) and the mean contact number of the rattler-free backbone (right) vs the aspect
    ratio alpha, one curve per shape family beta (semiaxes 1 : alpha^beta : alpha), mean +- s.e.
    over seeds, with the isostatic 2 f lines and, per family, Z = 2d + Z_alpha sqrt(alpha - 1)
    (Donev 2006, Eq. 5.30) fitted to its packings with 1 < alpha <= 1.3 (dashed).

    Parameters
    ----------
    summary : xarray.Dataset
        One sample per packing with the variables ``beta``, ``alpha``, ``phi`` and ``z_mean``.
    dim : int, default 3
        2 for ellipses (one family, beta = 1), 3 for ellipsoids.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (left, right) = figure(1, 2, figsize=(7.2, 3.0))
    betas = np.unique(np.asarray(summary["beta"].values, float))
    for k, beta in enumerate(betas):
        label = "ellipses" if dim == 2 else rf"$\beta = {beta:g}$"
        for ax, name in ((left, "phi"), (right, "z_mean")):
            rows = _per_alpha(summary, beta, name)
            ax.errorbar(rows[:, 0], rows[:, 1], rows[:, 2], fmt="o-", ms=3.5, color=f"C{k}", label=label)
        _near_sphere_curve(right, summary, beta, dim, f"C{k}")
    lines = [(ISOSTATIC["ellipses"], "--", "isostatic (6)")] if dim == 2 else [
        (ISOSTATIC["spheroids"], ":", "isostatic, spheroids (10)"),
        (ISOSTATIC["ellipsoids"], "--", "isostatic, ellipsoids (12)"), (6, "-.", "spheres (6)")]
    for value, style, text in lines:
        right.axhline(value, color="0.4", ls=style, lw=1)
        right.annotate(text, (0.01, value), xycoords=("axes fraction", "data"), va="bottom", fontsize=6.5,
                       color="0.3")
    left.set_xlabel(r"aspect ratio $\alpha$")
    left.set_ylabel(r"jamming density $\phi_J$")
    right.set_xlabel(r"aspect ratio $\alpha$")
    right.set_ylabel(r"mean contact number $\bar Z$ (rattlers removed)")
    left.legend(loc="lower right")
    right.legend(loc="lower right", fontsize=6.5)
    fig.tight_layout()
    return fig


def _near_sphere_curve(ax, summary, beta, dim, color, alpha_max=NEAR_SPHERE_ALPHA_MAX):
    """Eq. 5.30 fitted to one family's packings with 1 < alpha <= alpha_max, drawn to alpha_max."""
    mask = np.isclose(np.asarray(summary["beta"].values, float), beta)
    alpha = np.asarray(summary["alpha"].values, float)[mask]
    z = np.asarray(summary["z_mean"].values, float)[mask]
    keep = np.isfinite(z)
    law = near_sphere_contact_law(alpha[keep], z[keep], dim, alpha_max)
    if law.n == 0:
        return
    grid = np.linspace(1.0, alpha_max, 60)
    ax.plot(grid, 2 * dim + law.z_alpha * np.sqrt(grid - 1.0), ls="--", lw=0.8, color=color,
            label=rf"Eq. 5.30: $Z_\alpha$ = {law.z_alpha:.3g}")


def _shadow(packing):
    """Centres, widths, heights and angles (degrees) of the particles' orthographic shadows on the
    xy plane: the shadow of r^T X r <= 1 is the ellipse of the xy block of X^-1."""
    inverse = np.linalg.inv(packing.shape.shape_matrices())[:, :2, :2]
    values, vectors = np.linalg.eigh(inverse)
    axes = 2 * np.sqrt(values)
    angles = np.degrees(np.arctan2(vectors[:, 1, 1], vectors[:, 0, 1]))
    return axes[:, 1], axes[:, 0], angles


def plot_snapshot(packing, slab: float | None = None):
    """A picture of an ellipse or ellipsoid packing (after Donev 2006, Fig. 5.1).

    Ellipses are drawn as they are, coloured by the orientation of their long axis, with their
    periodic images across the cell's edges. Ellipsoids
    are drawn as their shadows on the xy plane, back to front, shaded by height, for the particles
    whose centres lie in a slab of the cell (default: the whole cell), so the front layer reads
    like a rendered picture.

    Parameters
    ----------
    packing : Packing
        A packing of ``Ellipsoids`` in an orthorhombic cell, d = 2 or 3.
    slab : float, optional
        Thickness of the slab of centres drawn (3D), from the top of the cell.

    Returns
    -------
    matplotlib.figure.Figure
    """
    box = np.diag(packing.lattice)
    pos = packing.positions - np.floor(packing.positions / box) * box
    images = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)], float) * box[:2]
    fig, ax = figure(1, 1, figsize=(4.6, 4.6 * box[1] / box[0]))
    if packing.dim == 2:
        shape = packing.shape
        long_axis = np.argmax(shape.semiaxes, axis=1)
        angle = np.degrees(shape.orientations) + 90.0 * long_axis
        colour = np.mod(angle, 180.0) / 180.0
        widths, heights = 2 * shape.semiaxes[:, 0], 2 * shape.semiaxes[:, 1]
        k = len(images)
        ax.add_collection(EllipseCollection(
            np.tile(widths, k), np.tile(heights, k), np.tile(np.degrees(shape.orientations), k), units="xy",
            offsets=(pos[None] + images[:, None]).reshape(-1, 2), offset_transform=ax.transData,
            array=np.tile(colour, k), cmap="twilight", edgecolors="k", linewidths=0.3))
    else:
        top = box[2]
        keep = pos[:, 2] >= top - (top if slab is None else slab)
        order = np.argsort(pos[keep, 2])
        widths, heights, angles = (v[keep][order] for v in _shadow(packing))
        depth = (pos[keep, 2][order] - pos[keep, 2].min()) / max(np.ptp(pos[keep, 2]), 1e-300)
        k, centres = len(images), pos[keep][order, :2]
        # back to front: every periodic copy of a layer before the next layer
        ax.add_collection(EllipseCollection(
            np.repeat(widths, k), np.repeat(heights, k), np.repeat(angles, k), units="xy",
            offsets=(centres[:, None] + images[None]).reshape(-1, 2), offset_transform=ax.transData,
            array=np.repeat(depth, k), cmap="viridis", edgecolors="k", linewidths=0.3))
    ax.set_xlim(0, box[0])
    ax.set_ylim(0, box[1])
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"{packing.shape.name}, N = {packing.n_particles}, $\\phi$ = {packing.phi:.4f}")
    return fig


def plot_laminate_family(family, searches=()):
    """Density of the laminate crystals vs the in-plane aspect ratio (after Donev 2006, Fig. 8.2),
    with the crystals found by small-cell searches from random starts (Sec. 8.2.1).

    Both prolate (alpha) and oblate (1 / alpha) sides are drawn on a logarithmic axis (phi(alpha)
    = phi(1 / alpha)): the unstretched laminate (dashed), the densest known crystal of each shape
    (solid: the laminate up to sqrt(3), the stretched laminate beyond), FCC and the maximum
    0.770732 with its 14 contacts. With searches, a second panel zooms on the dense end: each run
    is a marker at its aspect ratio (spread sideways by particles per cell), filled where it
    matches the densest known crystal.

    Parameters
    ----------
    family : xarray.Dataset
        :func:`hardpack.geometry.ellipsoid_crystals.laminate_family`.
    searches : sequence of xarray.Dataset
        :func:`hardpack.md.crystal_search.crystal_search` results, one per aspect ratio.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if searches:
        fig, (ax, zoom) = figure(2, 1, figsize=(5.0, 6.4), sharex=True, height_ratios=[1.0, 1.1])
    else:
        fig, ax = figure(1, 1, figsize=(5.0, 3.4))
    alpha = np.asarray(family["alpha"].values, float)
    order = np.argsort(alpha)
    alpha = alpha[order]
    both = np.concatenate([1 / alpha[::-1], alpha])
    panels = (ax, zoom) if searches else (ax,)
    for axis in panels:
        for name, style, label in (("phi_densest", "-", "densest known crystal (stretched beyond $\\sqrt{3}$)"),
                                   ("phi_laminate", "--", "laminate, unstretched")):
            values = np.asarray(family[name].values, float)[order]
            axis.plot(both, np.concatenate([values[::-1], values]), style, color="C0" if style == "-" else "C1",
                      label=label if axis is ax else None)
        axis.axhline(np.pi / np.sqrt(18), color="0.5", ls=":", lw=1,
                     label=r"FCC, $\pi/\sqrt{18}$" if axis is ax else None)
    peak = float(family.attrs.get("densest_alpha", np.sqrt(3)))
    densest = np.isclose(alpha, peak, atol=1e-12)
    if densest.any():
        phi = float(np.asarray(family["phi_laminate"].values, float)[order][densest][0])
        ax.plot([1 / peak, peak], [phi, phi], "o", color="C3", ms=5,
                label=rf"$\phi = {phi:.6f}$, 14 contacts")
    ax.set_xscale("log")
    ticks = [(1 / 3, "1/3"), (1 / np.sqrt(3), r"$1/\sqrt{3}$"), (1.0, "1"), (np.sqrt(3), r"$\sqrt{3}$"),
             (3.0, "3")]
    ticks = [(x, t) for x, t in ticks if both.min() * (1 - 1e-9) <= x <= both.max() * (1 + 1e-9)]
    ax.set_xticks([x for x, _ in ticks], [t for _, t in ticks])
    ax.minorticks_off()
    ax.set_ylabel(r"density $\phi$")
    ax.legend(loc="lower center", fontsize="small")
    if searches:
        low = _plot_searches(zoom, searches)
        zoom.set_ylim(min(low, np.pi / np.sqrt(18)) - 0.005, 0.775)
        zoom.set_ylabel(r"density $\phi$ (dense end)")
        zoom.set_title("random starts in small deforming cells (filled: the densest known crystal)", fontsize="small")
        zoom.legend(loc="lower left", fontsize="small")
    panels[-1].set_xlabel(r"aspect ratio $\alpha$ (oblate $< 1 <$ prolate)")
    fig.tight_layout()
    return fig


def _plot_searches(ax, searches) -> float:
    """Markers of the crystal-search runs, one colour and sideways offset per particles per cell,
    and a black cross at each run's polished density (when the search has it); returns the lowest
    density drawn."""
    ns = sorted({int(n) for ds in searches for n in ds["n"].values})
    markers = "sD^vo"
    low, polished = np.inf, False
    for k, n in enumerate(ns):
        offset = 1.0 + 0.015 * (k - (len(ns) - 1) / 2)
        colour, marker = f"C{k + 4}", markers[k % len(markers)]
        ax.plot([], [], marker, ms=4, mfc="none", color=colour, label=f"{n} per cell")
        for ds in searches:
            if n not in ds["n"].values:
                continue
            phi = np.asarray(ds["phi"].sel(n=n).values, float)
            match = np.asarray(ds["laminate"].sel(n=n).values, bool)
            x = np.full(phi.shape, float(ds.attrs["alpha"]) * offset)
            ax.plot(x[~match], phi[~match], marker, ms=4, mfc="none", color=colour)
            ax.plot(x[match], phi[match], marker, ms=4, color=colour)
            low = min(low, float(np.nanmin(phi)))
            if "phi_polished" in ds and np.isfinite(ds["phi_polished"].sel(n=n).values).any():
                ax.plot(x, np.asarray(ds["phi_polished"].sel(n=n).values, float), "+", ms=5, color="k",
                        label=None if polished else "polished (SLP, deforming cell)")
                polished = True
    return low
