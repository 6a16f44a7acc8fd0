"""Periodic pair search: every pair (i, j, image n) with |x_j + L n - x_i| <= (1 + rel_gap)(r_i + r_j).

All periodic images are included, so a particle's contact with its own image (small cells, e.g.
SLP packings of N = 3^d spheres) and several images of the same neighbour are found. Each
unordered contact appears once: pairs with i < j (any n), and self-images i == j with n
lexicographically positive.

Two search paths (both scipy's cKDTree):
- orthorhombic cells with cutoff below half the smallest cell width: a periodic tree with
  ``boxsize`` (minimum image is then exact), O(N log N);
- any other cell: the tree of the wrapped centres queried against one tree of all their
  lattice-shifted images n with |n_k| <= ceil(cutoff / h_k) (h_k = perpendicular cell width),
  which is exhaustive.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from hardpack.errors import InvalidInputError


@dataclass(frozen=True)
class PairList:
    """Pairs within range. ``separation[k] = x_j + lattice @ shift[k] - x_i`` (Cartesian)."""

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray  # (M, d) integer lattice images
    separation: np.ndarray  # (M, d)
    distance: np.ndarray  # (M,)
    contact: np.ndarray  # (M,) r_i + r_j

    def __len__(self) -> int:
        return len(self.i)

    @property
    def gap(self) -> np.ndarray:
        """Relative surface gap distance / (r_i + r_j) - 1 (negative for overlaps)."""
        return self.distance / self.contact - 1.0


def pairs_within(packing, rel_gap: float = 0.0, cutoff: float | None = None) -> PairList:
    """All pairs with distance <= (1 + rel_gap)(r_i + r_j), or <= ``cutoff`` if given.

    ``rel_gap`` is the relative gap tolerance (Donev's contact tolerance, e.g. 1e-9 for contacts
    of an LS packing); ``cutoff`` an absolute centre-distance range (e.g. for g2 or the SLP
    influence sphere).
    """
    if not np.isfinite(rel_gap) or rel_gap < -1:
        raise InvalidInputError(f"rel_gap must be a finite number >= -1, got {rel_gap}")
    lat = packing.lattice
    d = packing.dim
    radii = packing.radii
    s = packing.fractional()
    x = s @ lat.T
    rmax = radii.max()
    search = cutoff if cutoff is not None else (1.0 + rel_gap) * 2.0 * rmax
    if not np.isfinite(search) or search <= 0:
        raise InvalidInputError(f"search cutoff must be positive and finite, got {search}")
    heights = packing.heights

    if packing.is_orthorhombic and search < 0.5 * heights.min():
        box = np.diag(lat).copy()
        xt = np.where(x >= box, 0.0, x)  # guard the [0, box) requirement of boxsize trees
        tree = cKDTree(xt, boxsize=box)
        ij = tree.query_pairs(search, output_type="ndarray")
        ii, jj = ij[:, 0], ij[:, 1]
        dx = xt[jj] - xt[ii]
        shift = -np.round(dx / box).astype(np.int64)
        sep = dx + shift * box
    else:
        ks = np.ceil(search / heights).astype(int)
        shifts = np.array(list(itertools.product(*[range(-k, k + 1) for k in ks])), dtype=np.int64)
        n_particles = len(x)
        images = (x[None, :, :] + (shifts @ lat.T)[:, None, :]).reshape(-1, d)
        sdm = cKDTree(x).sparse_distance_matrix(cKDTree(images), search, output_type="ndarray")
        ii = sdm["i"].astype(np.int64)
        jj = sdm["j"].astype(np.int64) % n_particles
        shift = shifts[sdm["j"] // n_particles]
        # every shift is visited, so (i, j, n) and (j, i, -n) both appear: keep i < j, and a
        # self-image (i, i, n) once, for n lexicographically positive (n = 0 is the particle itself)
        nonzero = shift != 0
        first = np.argmax(nonzero, axis=1)
        lex_positive = nonzero.any(axis=1) & (shift[np.arange(len(shift)), first] > 0)
        keep = (ii < jj) | ((ii == jj) & lex_positive)
        ii, jj, shift = ii[keep], jj[keep], shift[keep]
        sep = x[jj] + shift @ lat.T - x[ii]

    dist = np.sqrt(np.einsum("ij,ij->i", sep, sep))
    contact = radii[ii] + radii[jj]
    limit = cutoff if cutoff is not None else (1.0 + rel_gap) * contact
    keep = dist <= limit
    order = np.lexsort((jj[keep], ii[keep]))
    return PairList(
        i=ii[keep][order],
        j=jj[keep][order],
        shift=shift[keep][order],
        separation=sep[keep][order],
        distance=dist[keep][order],
        contact=contact[keep][order],
    )
