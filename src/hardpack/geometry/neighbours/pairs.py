"""Pair lists: every pair (i, j, image n) with |x_j + L n - x_i| <= (1 + rel_gap)(r_i + r_j), or
<= a fixed cutoff.

The packing says what to search: the radii r are its shape's bounding radii
(``packing.shape.bounding_radii``: the radii of spheres; for other shapes the pairs are candidates whose
bounding spheres come within range), and images n exist only along the periodic axes of its boundary
(``packing.boundary.periodic_axes``; none in a spherical container, none across hard walls).
All periodic images are included, so a particle's contact with its own image (small cells, e.g. SLP
packings of N = 3^d spheres) and several images of the same neighbour are found, in cells of any shape.
Each unordered contact appears once: pairs with i < j (any n), and self-images i == j with n
lexicographically positive. The search is the hierarchical grid of :mod:`.grid` (Ogarko's Top-Down
search; one level for monodisperse packings and fixed cutoffs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours.grid import RANGE_PAD, Grid, build_grid, pair_kernel


@dataclass(frozen=True)
class PairList:
    """Pairs within range (:func:`pairs_within`), sorted by (i, j, shift); arrays have length M.

    Attributes
    ----------
    i, j : numpy.ndarray
        (M,) particle indices, i < j, or i == j for a particle and its own image.
    shift : numpy.ndarray
        (M, d) integer lattice image n of j.
    separation : numpy.ndarray
        (M, d) Cartesian x_j + lattice @ n - x_i, x the wrapped centres of
        :func:`wrapped_positions`.
    distance : numpy.ndarray
        (M,) |separation|.
    contact : numpy.ndarray
        (M,) r_i + r_j of the bounding radii (the sphere radii for spheres).
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    separation: np.ndarray
    distance: np.ndarray
    contact: np.ndarray

    def __len__(self) -> int:
        return len(self.i)

    @property
    def gap(self) -> np.ndarray:
        """Relative surface gap distance / (r_i + r_j) - 1 (negative for overlaps)."""
        return self.distance / self.contact - 1.0

    def subset(self, mask) -> PairList:
        """The pairs selected by ``mask``, in the same order.

        Parameters
        ----------
        mask : numpy.ndarray of bool, shape (M,), or of int
            Selection (a boolean mask or indices) of the pairs.

        Returns
        -------
        PairList
            The selected pairs with all their arrays.
        """
        return PairList(self.i[mask], self.j[mask], self.shift[mask], self.separation[mask],
                        self.distance[mask], self.contact[mask])


@dataclass(frozen=True)
class GridPairs:
    """Raw result of a grid search: candidate pairs i <= j with lattice images, and the work done
    (distance tests: Ogarko's T_cd; cell visits: T_ca, Eqs. 2.31-2.32).

    Attributes
    ----------
    i, j : numpy.ndarray of int, shape (M,)
        The pairs, i <= j.
    shift : numpy.ndarray of int, shape (M, d)
        Lattice image n of j.
    distance_tests : int
        Distance tests.
    cell_visits : int
        Cell visits.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    distance_tests: int
    cell_visits: int

    def __len__(self) -> int:
        return len(self.i)


@numba.njit(cache=True)
def _separations(x, lattice, i, j, shift):
    """separation[r] = x[j_r] + lattice @ shift[r] - x[i_r] and its length, in one pass."""
    m, d = shift.shape
    separation = np.empty((m, d))
    distance = np.empty(m)
    for r in range(m):
        acc = 0.0
        for k in range(d):
            s = x[j[r], k] - x[i[r], k]
            for b in range(d):
                s += lattice[k, b] * shift[r, b]
            separation[r, k] = s
            acc += s * s
        distance[r] = np.sqrt(acc)
    return separation, distance


def _pair_order(i, j, n, n_points: int) -> np.ndarray:
    """The permutation sorting rows by (i, j, n): one stable sort of the key i N + j, and a lexicographic
    sort only when some (i, j) occurs with several images (ranges wider than half the cell)."""
    key = i * np.int64(n_points) + j
    order = np.argsort(key, kind="stable")
    key = key[order]
    if np.any(key[1:] == key[:-1]):
        order = np.lexsort(tuple(n[:, k] for k in range(n.shape[1] - 1, -1, -1)) + (j, i))
    return order


def grid_pairs(grid: Grid) -> GridPairs:
    """Every pair with |x_j + L n - x_i| <= a_i + a_j (up to a relative 1e-9 of round-off margin) for the
    interaction radii a of ``grid``, once: i < j, or i == j with n lexicographically positive; sorted by
    (i, j, n).

    Parameters
    ----------
    grid : Grid
        The grid (:func:`hardpack.geometry.neighbours.grid.build_grid`).

    Returns
    -------
    GridPairs
        The pairs and the work done.
    """
    order = grid.order
    rows, tests, visits = pair_kernel(
        grid.frac[order], grid.x[order], grid.lattice, 1.0 / grid.heights, grid.periodic, grid.reach[order],
        grid.level.astype(np.int64)[order], grid.level_reach, grid.n_cells, grid.strides, grid.cell_offset,
        grid.cell_start, 1.0 + RANGE_PAD)
    p, q, n = order[rows[:, 0]], order[rows[:, 1]], rows[:, 2:]
    swap = p > q
    i, j = np.where(swap, q, p), np.where(swap, p, q)
    n[swap] *= -1
    order = _pair_order(i, j, n, grid.x.shape[0])
    return GridPairs(i[order], j[order], n[order], int(tests), int(visits))


def wrapped_positions(packing) -> np.ndarray:
    """The centres frac @ lattice.T that pair separations refer to: inside the unit cell along the periodic
    axes (``Packing.fractional``).

    Parameters
    ----------
    packing : Packing
        The packing.

    Returns
    -------
    numpy.ndarray of float, shape (N, d)
        The wrapped centres.
    """
    return packing.fractional() @ packing.lattice.T


def pairs_within(packing, rel_gap: float = 0.0, cutoff: float | None = None, *, levels=None) -> PairList:
    """All pairs with distance <= (1 + rel_gap)(r_i + r_j), or <= ``cutoff`` if given, with every image
    along the periodic axes of ``packing.boundary``; r the bounding radii of ``packing.shape`` (module
    docstring).

    Parameters
    ----------
    packing : hardpack.geometry.Packing
        The particles, their cell and boundary.
    rel_gap : float, default 0.0
        Relative gap tolerance, >= -1 (Donev's contact tolerance, e.g. 1e-9 for the contacts of an LS
        packing).
    cutoff : float, optional
        Absolute centre-distance range instead of the contact criterion (e.g. for g2 or the SLP
        influence sphere).
    levels : None, int or LevelAssignment, optional
        Grid levels (:func:`hardpack.geometry.neighbours.build_grid`; default Ogarko's optimal number).
        The pairs never depend on it.

    Returns
    -------
    PairList
        Each pair once (i < j, or i == j with a lexicographically positive image), sorted by
        (i, j, shift).

    Raises
    ------
    InvalidInputError
        If rel_gap is not finite or below -1, or the cutoff is not positive and finite.
    """
    if not np.isfinite(rel_gap) or rel_gap < -1:
        raise InvalidInputError(f"rel_gap must be a finite number >= -1, got {rel_gap}")
    radii = np.asarray(packing.shape.bounding_radii, dtype=float)
    if cutoff is None:
        reach = (1.0 + rel_gap) * radii
        if not reach.max() > 0:
            raise InvalidInputError(f"search cutoff must be positive and finite, got rel_gap = {rel_gap}")
    else:
        if not (np.isfinite(cutoff) and cutoff > 0):
            raise InvalidInputError(f"search cutoff must be positive and finite, got {cutoff}")
        reach = np.full(radii.size, 0.5 * cutoff)
    lattice = np.asarray(packing.lattice, dtype=float)
    grid = build_grid(packing.fractional(), lattice, reach, periodic=packing.boundary.periodic_axes(packing.dim),
                      levels=levels)
    found = grid_pairs(grid)
    ii, jj, shift = found.i, found.j, found.shift
    sep, dist = _separations(grid.x, grid.lattice, ii, jj, shift)
    contact = radii[ii] + radii[jj]
    limit = cutoff if cutoff is not None else (1.0 + rel_gap) * contact
    keep = dist <= limit
    return PairList(i=ii[keep], j=jj[keep], shift=shift[keep], separation=sep[keep], distance=dist[keep],
                    contact=contact[keep])
