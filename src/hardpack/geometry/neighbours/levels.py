"""Hierarchical levels by Ogarko's rules (Ogarko, dissertation, Sec. 2.1.2-2.1.3 and the appendix of
ch. 2.1; Ogarko & Luding, Comput. Phys. Commun. 183, 931 (2012)).

Every particle carries a radius r_i (for neighbour search the interaction radius: pairs are closer than
r_i + r_j). Levels h = 0, 1, ... have cell sizes s_0 < s_1 < ...; a particle lives on the lowest level whose
cells hold it, the insertion rule h(p) = min{h : s_h >= 2 r_p} (Eq. 2.3), so within a level the linked-cell
method applies; levels nobody lives on are dropped and each level's cell size is then the diameter of its
largest particle (the appendix's N^c_h counts cells of that size). Everything below assigns levels this way
(:func:`insertion_levels`); the rules differ in the cell sizes they offer.

Equal particles per cell (hypothesis Eq. 2.6; the static grid and RSA): particles are
sorted by radius and filled into levels greedily, particle i joining the current level h unless
N_h(i) / N^c_h(i) > m (Eq. 2.8), where N_h(i) counts the particles on level h including i and
N^c_h(i) = V / (2 r_i)^d is the number of cells if the cell size is the diameter of particle i (the largest
so far on the level). Otherwise i opens level h + 1. Each level's cell size is the diameter of its largest
particle, so the insertion rule holds and equal radii always share a level. A level always accepts its
first particle (otherwise a particle whose single-particle occupancy already exceeds m could never be placed).

For a target number of levels L the appendix scans m upward in steps dm and keeps the smallest m that
gives L levels (so the last level holds more particles). The number of levels is non-increasing in m, so
here that smallest m is found by bisection to relative precision 1e-12 (exact up to round-off, instead of
the text's dm = 1e-3 grid). The cost of contact detection is then T_CD ~ N L (m + K) (Eq. 2.7, K ~ 0.3
fitted in Sec. 2.1.3); the optimal number of levels (ONL) minimises L (m + K).

Geometric cell sizes s_{h+1} = q s_h (Eq. 2.43, the tree-like distribution of Sec. 2.2.5), anchored at the
smallest diameter so that level h holds the radii in [r_min q^h, r_min q^(h+1)): the MD engine's
bounding-sphere grid, which searches every level from every particle (both directions, not Top-Down) and
rebuilds one particle at a time, so its cost per level is not Eq. 2.7's. Measured on its NVE collision rate
(3D, N = 1e4, phi = 0.5): q = 2 against equal particles per cell with K = 0.3 (bidisperse 1.4: 1 level
against 2; uniform volume omega = 10: 2 against 5), the equal-occupancy levels were 15-33 % slower.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from hardpack.errors import InvalidInputError


@numba.njit(cache=True)
def _assign(group_dpow, group_count, volume, m, ends):
    """Greedy level fill over groups of equal radii (ascending). ends[h] = exclusive end group of level h.
    A group is never split (equal radii share a level). Returns the number of levels."""
    n_levels = 0
    count = 0.0
    for g in range(group_dpow.size):
        new_count = count + group_count[g]
        if count > 0 and new_count * group_dpow[g] / volume > m:
            ends[n_levels] = g
            n_levels += 1
            new_count = group_count[g]
        count = new_count
    ends[n_levels] = group_dpow.size
    return n_levels + 1


@dataclass(frozen=True)
class LevelAssignment:
    """level[i] (0-based) of every particle (input order), cell_sizes[h] (= largest diameter on level h),
    the threshold m used, and the realised particles per cell m_h = N_h (s_h^d / V) per level.

    Attributes
    ----------
    level : numpy.ndarray of int, shape (N,)
        Level of every particle.
    cell_sizes : numpy.ndarray of float, shape (L,)
        Cell size of every level, ascending.
    m : float
        The threshold of particles per cell.
    m_per_level : numpy.ndarray of float, shape (L,)
        Realised particles per cell of every level.
    """

    level: np.ndarray
    cell_sizes: np.ndarray
    m: float
    m_per_level: np.ndarray

    @property
    def n_levels(self) -> int:
        return int(self.cell_sizes.size)


def insertion_levels(radii, cell_sizes) -> np.ndarray:
    """Level of insertion h(p) = min{h : s_h >= 2 r_p} (Eq. 2.3) for ascending cell sizes; a diameter
    above the largest cell size gets len(cell_sizes).

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    cell_sizes : array_like of float, shape (L,)
        Ascending cell sizes.

    Returns
    -------
    numpy.ndarray of int, shape (N,)
        The levels.
    """
    return np.searchsorted(np.asarray(cell_sizes, dtype=float), 2.0 * np.asarray(radii, dtype=float),
                           side="left")


def _from_cell_sizes(radii, volume: float, d: int, cell_sizes, m: float) -> LevelAssignment:
    """Levels by the insertion rule (Eq. 2.3) for these cell sizes, empty levels dropped and each cell size
    shrunk to the largest diameter on its level."""
    level = insertion_levels(radii, cell_sizes)
    counts = np.bincount(level)
    occupied = counts > 0
    level = (np.cumsum(occupied) - 1)[level]
    counts = counts[occupied]
    sizes = np.array([2.0 * radii[level == h].max() for h in range(counts.size)])
    return LevelAssignment(level, sizes, float(m), counts * sizes**d / volume)


def _check_radii(radii, volume, d) -> np.ndarray:
    r = np.asarray(radii, dtype=float)
    if r.ndim != 1 or r.size == 0 or not (np.isfinite(r).all() and (r > 0).all()):
        raise InvalidInputError("radii must be a non-empty 1-d array of positive finite values")
    if int(d) != d or d < 1:
        raise InvalidInputError(f"dimension d must be a positive integer, got {d!r}")
    if not (np.isfinite(volume) and volume > 0):
        raise InvalidInputError(f"box volume must be positive and finite, got {volume!r}")
    return r


class _Groups:
    """Radii grouped into distinct values (ascending) with counts."""

    def __init__(self, radii, volume, d):
        r = _check_radii(radii, volume, d)
        self.radii, self.volume, self.d = r, float(volume), int(d)
        self.values, counts = np.unique(r, return_counts=True)
        self.counts = counts.astype(float)
        self.dpow = (2.0 * self.values) ** d
        self.ends = np.empty(self.values.size + 1, dtype=np.int64)

    def n_levels(self, m: float) -> int:
        return _assign(self.dpow, self.counts, self.volume, m, self.ends)

    def assignment(self, m: float) -> LevelAssignment:
        L = self.n_levels(m)
        return _from_cell_sizes(self.radii, self.volume, self.d, 2.0 * self.values[self.ends[:L] - 1], m)

    def with_levels(self, n_levels: int) -> LevelAssignment:
        """The assignment of the smallest m giving at most ``n_levels`` levels (bisection)."""
        hi = self.counts.sum() * self.dpow[-1] / self.volume  # everything fits on one level
        lo = 0.0
        if self.n_levels(lo) <= n_levels:
            return self.assignment(lo)
        while hi - lo > 1e-12 * hi:
            mid = 0.5 * (lo + hi)
            if self.n_levels(mid) <= n_levels:
                hi = mid
            else:
                lo = mid
        return self.assignment(hi)


def assign_with_threshold(radii, volume: float, d: int, m: float) -> LevelAssignment:
    """Greedy assignment for a given threshold m of particles per cell (Eq. 2.8): the map m -> L(m).

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    volume : float
        Volume of the cell.
    d : int
        Dimension.
    m : float
        Threshold of particles per cell, >= 0.

    Returns
    -------
    LevelAssignment
        The assignment.
    """
    if not (np.isfinite(m) and m >= 0):
        raise InvalidInputError(f"threshold m must be >= 0 and finite, got {m!r}")
    return _Groups(radii, volume, d).assignment(float(m))


def _check_n_levels(n_levels) -> int:
    if isinstance(n_levels, bool) or int(n_levels) != n_levels or n_levels < 1:
        raise InvalidInputError(f"n_levels must be a positive integer, got {n_levels!r}")
    return int(n_levels)


def assign_levels(radii, volume: float, d: int, n_levels: int) -> LevelAssignment:
    """Equal-particles-per-cell assignment with (at most) ``n_levels`` levels, using the smallest m that
    gives that many (appendix of ch. 2.1). If no m gives exactly n_levels (the count jumps over it)
    the result has the next smaller number of levels; it never exceeds the number of distinct radii.

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    volume : float
        Volume of the cell.
    d : int
        Dimension.
    n_levels : int
        Number of levels wanted, >= 1.

    Returns
    -------
    LevelAssignment
        The assignment.
    """
    return _Groups(radii, volume, d).with_levels(_check_n_levels(n_levels))


def optimal_levels(radii, volume: float, d: int, K: float = 0.3, max_levels: int = 30) -> LevelAssignment:
    """Assignment with the optimal number of levels (ONL), minimising L (m(L) + K) (Eq. 2.7; K = 0.3 as
    fitted in Sec. 2.1.3).

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    volume : float
        Volume of the cell.
    d : int
        Dimension.
    K : float, optional
        Cost ratio of a cell visit to a distance test.
    max_levels : int, optional
        Most levels tried.

    Returns
    -------
    LevelAssignment
        The assignment.
    """
    if not (np.isfinite(K) and K >= 0):
        raise InvalidInputError(f"K must be a finite number >= 0, got {K!r}")
    groups = _Groups(radii, volume, d)
    best = None
    for L in range(1, int(max_levels) + 1):
        if best is not None and L * K >= best.n_levels * (best.m + K):
            break  # L (m + K) >= L K cannot beat the best any more
        if L > groups.values.size:
            break  # equal radii share a level: no more levels than distinct radii
        a = groups.with_levels(L)
        if a.n_levels < L:  # no m gives L levels
            continue
        if best is None or L * (a.m + K) < best.n_levels * (best.m + K):
            best = a
    return best


def geometric_levels(radii, volume: float, d: int, ratio: float) -> LevelAssignment:
    """Levels of cell sizes in geometric progression s_{h+1} = ratio s_h (Eq. 2.43), anchored at the
    smallest diameter: level h holds the radii in [r_min ratio^h, r_min ratio^(h+1)) (module docstring).
    ``m`` of the result is the largest realised occupancy m_h.

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    volume : float
        Volume of the cell.
    d : int
        Dimension.
    ratio : float
        Ratio of successive cell sizes, > 1.

    Returns
    -------
    LevelAssignment
        The assignment.
    """
    r = _check_radii(radii, volume, d)
    if not (np.isfinite(ratio) and ratio > 1):
        raise InvalidInputError(f"the ratio of successive cell sizes must be > 1, got {ratio!r}")
    r_min, r_max = r.min(), r.max()
    n_bounds = int(np.ceil(np.log(r_max / r_min) / np.log(ratio))) + 2
    # s_h just below 2 r_min ratio^(h+1): then 2 r <= s_h exactly when r < r_min ratio^(h+1)
    sizes = np.nextafter(2.0 * r_min * ratio ** np.arange(1, n_bounds + 1), 0.0)
    a = _from_cell_sizes(r, float(volume), int(d), sizes, 0.0)
    return LevelAssignment(a.level, a.cell_sizes, float(a.m_per_level.max()), a.m_per_level)


def choose_levels(radii, volume: float, d: int, levels=None, K: float = 0.3) -> LevelAssignment:
    """The level assignment a grid uses: ``levels`` None for the optimal number of levels
    (:func:`optimal_levels`), an integer L for :func:`assign_levels` (1: the single-level linked-cell grid),
    or a :class:`LevelAssignment` computed before for the same radii (returned as it is).

    Parameters
    ----------
    radii : array_like of float, shape (N,)
        Particle radii.
    volume : float
        Volume of the cell.
    d : int
        Dimension.
    levels : None, int or LevelAssignment, optional
        As above.
    K : float, optional
        Cost ratio of :func:`optimal_levels`.

    Returns
    -------
    LevelAssignment
        The assignment.
    """
    if isinstance(levels, LevelAssignment):
        if levels.level.shape != np.shape(radii):
            raise InvalidInputError(
                f"the level assignment is for {levels.level.size} particles, not {np.size(radii)}: "
                "assign the levels again for these radii")
        return levels
    if levels is None:
        return optimal_levels(radii, volume, d, K=K)
    return assign_levels(radii, volume, d, levels)
