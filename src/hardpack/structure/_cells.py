"""Numba cell list over fractional coordinates, exhaustive over all periodic images, any d.

Cells are a regular n_1 x ... x n_d grid in fractional coordinates s = lattice^-1 x of the
(possibly sheared) cell. The distance between the planes s_a = c and s_a = c + 1/n_a is
h_a / n_a (h_a = perpendicular cell width), so every point within ``cutoff`` of a point in cell
c lies in a cell c + m with |m_a| <= K_a = ceil(cutoff n_a / h_a). A stencil offset m maps to
the neighbour cell (c + m) mod n and the lattice image floor((c + m) / n); this map is one to
one, so visiting every offset of the stencil visits each (particle, image) pair exactly once,
self-images and several images of one neighbour included, even when 2 K_a + 1 > n_a.

Unordered pairs: an ordered visit (i, j, image) is kept for i < j, and for i == j (self-image,
image != 0) with weight 1/2 because (i, i, n) and (i, i, -n) are both visited.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numba
import numpy as np

N_CHUNKS = 64  # work chunks for prange (each with its own accumulator; deterministic sums)


@dataclass(frozen=True)
class CellGrid:
    """Particles sorted into fractional cells, with the stencil for a given cutoff."""

    x: np.ndarray  # (N, d) wrapped Cartesian positions
    lattice: np.ndarray  # (d, d), columns are the lattice vectors
    n_cells: np.ndarray  # (d,) cells per lattice direction
    strides: np.ndarray  # (d,) flat-index strides
    cell_start: np.ndarray  # (n_total + 1,) CSR offsets into ``order``
    order: np.ndarray  # particle indices sorted by cell
    offsets: np.ndarray  # (n_offsets, d) stencil


def build_grid(packing, cutoff: float, per_cutoff: int = 2) -> CellGrid:
    """Cells of width >= cutoff / per_cutoff (at least one cell per direction)."""
    s = packing.fractional()
    lat = np.ascontiguousarray(packing.lattice, dtype=float)
    heights = packing.heights
    d = packing.dim
    n_cells = np.maximum(1, np.floor(heights * per_cutoff / cutoff)).astype(np.int64)
    # a grid much finer than the particle count only adds empty cells: coarsen it
    excess = np.prod(n_cells.astype(float)) / (4.0 * packing.n_particles)
    if excess > 1.0:
        n_cells = np.maximum(1, np.floor(n_cells / excess ** (1.0 / d))).astype(np.int64)
    strides = np.ones(d, dtype=np.int64)
    for a in range(d - 2, -1, -1):
        strides[a] = strides[a + 1] * n_cells[a + 1]
    coords = np.minimum((s * n_cells).astype(np.int64), n_cells - 1)
    flat = coords @ strides
    order = np.argsort(flat, kind="stable").astype(np.int64)
    counts = np.bincount(flat, minlength=int(np.prod(n_cells)))
    cell_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    reach = np.ceil(cutoff * n_cells / heights).astype(np.int64)
    offsets = np.array(list(itertools.product(*[range(-k, k + 1) for k in reach])), dtype=np.int64)
    return CellGrid(
        x=np.ascontiguousarray(s @ lat.T), lattice=lat, n_cells=n_cells, strides=strides,
        cell_start=cell_start, order=order, offsets=offsets.reshape(-1, d),
    )


@numba.njit(cache=True)
def _unravel(flat, n_cells, strides, out):
    for a in range(n_cells.size):
        out[a] = (flat // strides[a]) % n_cells[a]


@numba.njit(cache=True)
def _neighbour_cell(c, m, n_cells, strides, lattice, shift_vec):
    """Flat index of cell c + m (wrapped) and the Cartesian image shift it carries."""
    d = n_cells.size
    flat = 0
    for a in range(d):
        shift_vec[a] = 0.0
    for a in range(d):
        t = c[a] + m[a]
        img = t // n_cells[a]  # floor division (numba follows Python semantics)
        flat += (t - img * n_cells[a]) * strides[a]
        for b in range(d):
            shift_vec[b] += lattice[b, a] * img
    return flat


@numba.njit(cache=True, parallel=True)
def pair_histograms(x, radii, lattice, n_cells, strides, cell_start, order, offsets,
                    cutoff, dr, n_r, dx, n_x, contact_tol, self_images):
    """Histograms of unordered pair distances r and scaled distances r / (r_i + r_j).

    Bins are [k dr, (k + 1) dr), k < n_r (and likewise for x). Pairs with |r/(r_i+r_j) - 1| <=
    contact_tol are contacts: counted separately and left out of both histograms. Self-image
    pairs are included only if ``self_images``. Returns (hist_r, hist_x, n_contacts) as floats
    (self-image pairs carry weight 1/2 per ordered visit).
    """
    d = x.shape[1]
    n_total = cell_start.size - 1
    hr = np.zeros((N_CHUNKS, n_r))
    hx = np.zeros((N_CHUNKS, n_x))
    nc = np.zeros(N_CHUNKS)
    cut2 = cutoff * cutoff
    for chunk in numba.prange(N_CHUNKS):
        c = np.empty(d, dtype=np.int64)
        shift = np.empty(d)
        for cell in range(chunk, n_total, N_CHUNKS):
            if cell_start[cell] == cell_start[cell + 1]:
                continue
            _unravel(cell, n_cells, strides, c)
            for o in range(offsets.shape[0]):
                nb = _neighbour_cell(c, offsets[o], n_cells, strides, lattice, shift)
                zero_shift = True
                for a in range(d):
                    if shift[a] != 0.0:
                        zero_shift = False
                for p in range(cell_start[cell], cell_start[cell + 1]):
                    i = order[p]
                    for q in range(cell_start[nb], cell_start[nb + 1]):
                        j = order[q]
                        if j < i:
                            continue
                        w = 1.0
                        if j == i:
                            if zero_shift or not self_images:
                                continue
                            w = 0.5
                        r2 = 0.0
                        for a in range(d):
                            t = x[j, a] + shift[a] - x[i, a]
                            r2 += t * t
                        if r2 > cut2:
                            continue
                        r = np.sqrt(r2)
                        xs = r / (radii[i] + radii[j])
                        if abs(xs - 1.0) <= contact_tol:
                            nc[chunk] += w
                            continue
                        k = int(r / dr)
                        if k < n_r:
                            hr[chunk, k] += w
                        k = int(xs / dx)
                        if k < n_x:
                            hx[chunk, k] += w
    return hr.sum(axis=0), hx.sum(axis=0), nc.sum()


@numba.njit(cache=True, parallel=True)
def window_counts(centres_frac, x, lattice, n_cells, strides, cell_start, order, offsets,
                  window_radii):
    """Number of particle centres (all periodic images) within each window radius of each centre.

    ``window_radii`` must be sorted ascending; returns counts (M, n_radii) with counts[m, k] =
    #{images with |x - centre_m| < window_radii[k]}.
    """
    d = x.shape[1]
    m_total = centres_frac.shape[0]
    n_rad = window_radii.size
    out = np.zeros((m_total, n_rad), dtype=np.int64)
    rmax2 = window_radii[-1] ** 2
    for m in numba.prange(m_total):
        c = np.empty(d, dtype=np.int64)
        shift = np.empty(d)
        centre = np.zeros(d)
        for a in range(d):
            for b in range(d):
                centre[a] += lattice[a, b] * centres_frac[m, b]
            c[a] = min(int(centres_frac[m, a] * n_cells[a]), n_cells[a] - 1)
        hist = np.zeros(n_rad + 1, dtype=np.int64)
        for o in range(offsets.shape[0]):
            nb = _neighbour_cell(c, offsets[o], n_cells, strides, lattice, shift)
            for q in range(cell_start[nb], cell_start[nb + 1]):
                j = order[q]
                r2 = 0.0
                for a in range(d):
                    t = x[j, a] + shift[a] - centre[a]
                    r2 += t * t
                if r2 >= rmax2:
                    continue
                hist[np.searchsorted(window_radii, np.sqrt(r2), side="right")] += 1
        acc = 0
        for k in range(n_rad):
            acc += hist[k]
            out[m, k] = acc
    return out
