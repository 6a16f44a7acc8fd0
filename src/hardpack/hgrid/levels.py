"""Level assignment of an HGrid by "equal particles per cell" (Ogarko ch. 2.1, Eqs. 2.6-2.8, Appendix
L1492-1532; Ogarko & Luding, Comput. Phys. Commun. 183, 931 (2012); note 002_ogarko.md sec. 1.3).

Given the actual radii, a box volume V and the dimension d, particles are sorted by radius and filled
into levels greedily: particle i joins the current level h unless N_h(i)/N^c_h(i) > m (Eq. 2.8), where
N_h(i) counts the particles on level h including i and N^c_h(i) = V/(2 r_i)^d is the number of cells
if the cell size is the diameter of particle i (the largest so far on the level). Otherwise i opens
level h + 1. Each level's cell size is the diameter of its largest particle, so a particle's level
obeys the insertion rule h(p) = min{h : s_h >= 2 r_p} (Eq. 2.3) and equal radii always share a level.
A level always accepts its first particle (otherwise a particle whose single-particle occupancy
already exceeds m could never be placed).

For a target number of levels L the text scans m upward in steps dm and keeps the smallest m that
gives L levels (so the last level holds more particles). The number of levels is non-increasing in
m, so here that smallest m is found by bisection to relative precision 1e-12 (exact up to round-off,
instead of the text's dm = 1e-3 grid). The cost of contact detection is then T_CD ~ N L (m + K)
(Eq. 2.7, K ~ 0.3 in ch. 2.1); the "optimal number of levels" (ONL) minimises L (m + K) (L1199-1204).
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
    the threshold m used, and the realised particles per cell m_h = N_h (s_h^d / V) per level."""

    level: np.ndarray
    cell_sizes: np.ndarray
    m: float
    m_per_level: np.ndarray

    @property
    def n_levels(self) -> int:
        return int(self.cell_sizes.size)


class _Groups:
    """Radii grouped into distinct values (ascending) with counts."""

    def __init__(self, radii, volume, d):
        r = np.asarray(radii, dtype=float)
        if r.ndim != 1 or r.size == 0 or not (np.isfinite(r).all() and (r > 0).all()):
            raise InvalidInputError("radii must be a non-empty 1-d array of positive finite values")
        if int(d) != d or d < 1:
            raise InvalidInputError(f"dimension d must be a positive integer, got {d!r}")
        if not (np.isfinite(volume) and volume > 0):
            raise InvalidInputError(f"box volume must be positive and finite, got {volume!r}")
        self.radii, self.volume, self.d = r, float(volume), int(d)
        self.values, self.index, counts = np.unique(r, return_inverse=True, return_counts=True)
        self.counts = counts.astype(float)
        self.dpow = (2.0 * self.values) ** d
        self.ends = np.empty(self.values.size + 1, dtype=np.int64)

    def n_levels(self, m: float) -> int:
        return _assign(self.dpow, self.counts, self.volume, m, self.ends)

    def assignment(self, m: float) -> LevelAssignment:
        L = self.n_levels(m)
        ends = self.ends[:L].copy()
        group_level = np.repeat(np.arange(L), np.diff(np.concatenate([[0], ends])))
        cells = 2.0 * self.values[ends - 1]
        per_level = np.bincount(group_level, weights=self.counts, minlength=L)
        m_h = per_level * cells**self.d / self.volume
        return LevelAssignment(group_level[self.index], cells, float(m), m_h)


def assign_with_threshold(radii, volume: float, d: int, m: float) -> LevelAssignment:
    """Greedy assignment for a given threshold m of particles per cell (Eq. 2.8): the map m -> L(m)."""
    if not (np.isfinite(m) and m >= 0):
        raise InvalidInputError(f"threshold m must be >= 0 and finite, got {m!r}")
    return _Groups(radii, volume, d).assignment(float(m))


def assign_levels(radii, volume: float, d: int, n_levels: int) -> LevelAssignment:
    """Equal-particles-per-cell assignment with (at most) ``n_levels`` levels, using the smallest m that
    gives that many (Appendix L1492-1532). If no m gives exactly n_levels (the count jumps over it)
    the result has the next smaller number of levels; it never exceeds the number of distinct radii."""
    if int(n_levels) != n_levels or n_levels < 1:
        raise InvalidInputError(f"n_levels must be a positive integer, got {n_levels!r}")
    groups = _Groups(radii, volume, d)
    # m large enough that everything fits on one level
    hi = groups.counts.sum() * groups.dpow[-1] / groups.volume
    lo = 0.0
    if groups.n_levels(lo) <= n_levels:
        return groups.assignment(lo)
    while hi - lo > 1e-12 * hi:
        mid = 0.5 * (lo + hi)
        if groups.n_levels(mid) <= n_levels:
            hi = mid
        else:
            lo = mid
    return groups.assignment(hi)


def optimal_levels(radii, volume: float, d: int, K: float = 0.3, max_levels: int = 30) -> LevelAssignment:
    """Assignment with the optimal number of levels (ONL), minimising L (m(L) + K) (Eq. 2.7, L1194-1204;
    K = 0.3 as fitted in ch. 2.1)."""
    if not (K >= 0):
        raise InvalidInputError(f"K must be >= 0, got {K}")
    best = None
    for L in range(1, int(max_levels) + 1):
        if best is not None and L * K >= best.n_levels * (best.m + K):
            break  # L (m + K) >= L K cannot beat the best any more
        a = assign_levels(radii, volume, d, L)
        if a.n_levels < L:  # no m gives L levels
            continue
        if best is None or L * (a.m + K) < best.n_levels * (best.m + K):
            best = a
    return best
