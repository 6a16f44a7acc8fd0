"""Hierarchical-grid (HGrid) neighbour search for polydisperse spheres in a periodic orthorhombic box
(Ogarko ch. 2.1, L880-1056, Eqs. 2.1-2.5; Ogarko & Luding, Comput. Phys. Commun. 183, 931 (2012);
note 002_ogarko.md sec. 1.1-1.2).

Finds every pair (i < j) with |x_i - x_j| <= r_i + r_j + skin (minimum image). ``skin = 0`` is contact
detection; a positive skin gives Verlet-style neighbour lists.

Data structure. L levels (regular grids), level h with nominal cell size s_h = the largest
(skin-inflated) diameter on it; particles are put on levels by "equal particles per cell"
(:mod:`hardpack.hgrid.levels`, Eqs. 2.6-2.8; the optimal number of levels minimises L (m + K),
Eq. 2.7), so a particle's level obeys the insertion rule h(p) = min{h : s_h >= 2 r_p + skin} (Eq. 2.3).
Each level has n_{h,k} = floor(box_k / s_h) cells per side (so the actual cell length is >= s_h and
the periodic wrap is exact), numbered with axis 0 fastest. A level whose dense grid would exceed
8 N + 64 cells gets proportionally fewer, larger cells (only for pathological radius sets: one tiny
particle alone on a level). For the pair search the particles are sorted by (level, cell), so each
cell - and each run of consecutive cells along axis 0 - holds a contiguous range of particles
(``start[c]..start[c+1]-1``, a compressed-row layout; Ogarko uses a hash table of linked lists).
:func:`insert` / :func:`overlaps_any` keep linked lists instead (``head`` per cell, ``nxt`` per
particle), for incremental use such as :mod:`hardpack.hgrid.rsa`.

Search (Top-Down, the text's recommended variant, L3323). For each particle p on level h:
1. same level: its own cell (the particles after p) and the (3^d - 1)/2 "forward" neighbour cells of
   the half stencil (13 in 3D), so each pair is tested once;
2. every lower level j < h: all cells of the box [x_p - beta, x_p + beta]^d with
   beta = r_p + rho_j + skin, rho_j the largest radius on level j (Eq. 2.4 with the level's actual
   largest radius instead of s_j / 2: equal without skin, never smaller than needed);
3. narrow phase: the exact distance test.
Cells are visited a row (along axis 0) at a time, one contiguous particle range per row (split at the
periodic boundary), which is what makes the cell accesses cheap; the periodic image of a row is a
fixed shift, so the minimum image is needed only when a search box spans a whole row. Cross-level
pairs are found only from the larger particle, so the list has no duplicates.

The single-level grid (the linked-cell method, LC) is the same code with L = 1 (cell size = largest
diameter); it is the reference of the speed-up benchmark (``benchmarks/bench_hgrid.py``).

Restriction: the half stencil and the minimum image need at least 3 cells of the top level per box
side, i.e. box_k >= 3 (2 r_max + skin); smaller boxes are refused (use
:func:`hardpack.geometry.neighbours.pairs_within`, which handles any cell and periodic self-images).
Results are returned in terms of the caller's indices, sorted by (i, j).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.hgrid.levels import LevelAssignment, assign_levels, optimal_levels

#: a level's dense cell array is capped at CELLS_PER_PARTICLE * N + 64 cells
CELLS_PER_PARTICLE = 8


@dataclass(frozen=True)
class HGrid:
    """Level structure of a hierarchical grid (no particle content).

    box (d,) side lengths; level[i] of every particle; ncell (L, d) cells per side per level;
    reach[h] = largest radius on level h (without skin); skin; head_offset (L + 1,) offsets of each
    level's cells in the flat cell arrays (``start`` of the pair search, ``head`` of the linked lists);
    assignment: the underlying level assignment.
    """

    box: np.ndarray
    level: np.ndarray
    ncell: np.ndarray
    reach: np.ndarray
    skin: float
    head_offset: np.ndarray
    assignment: LevelAssignment

    @property
    def n_levels(self) -> int:
        return int(self.ncell.shape[0])

    @property
    def cell_length(self) -> np.ndarray:
        """(L, d) actual cell lengths box_k / n_{h,k} (>= the nominal size s_h)."""
        return self.box[None, :] / self.ncell

    def empty_lists(self):
        """(head, nxt) linked-list arrays with no particle inserted."""
        return -np.ones(int(self.head_offset[-1]), np.int64), -np.ones(self.level.size, np.int64)


def _check_box(box, d) -> np.ndarray:
    b = np.asarray(box, dtype=float)
    if b.ndim == 2:
        if b.shape != (d, d) or np.any(np.abs(b - np.diag(np.diag(b))) > 0):
            raise InvalidInputError(
                "the HGrid needs an orthorhombic periodic box: give the side lengths (d,) or a diagonal "
                "lattice matrix; for sheared cells use hardpack.geometry.neighbours.pairs_within"
            )
        b = np.diag(b).copy()
    if b.shape != (d,) or not (np.isfinite(b).all() and (b > 0).all()):
        raise InvalidInputError(f"box must be {d} positive finite side lengths, got {box!r}")
    return b


def _check_particles(positions, radii):
    x = np.asarray(positions, dtype=float)
    r = np.asarray(radii, dtype=float)
    if x.ndim != 2 or x.shape[0] == 0 or x.shape[1] < 1:
        raise InvalidInputError(f"positions must be an (N, d) array with N >= 1, got shape {x.shape}")
    if r.shape != (x.shape[0],):
        raise InvalidInputError(f"radii must have shape ({x.shape[0]},) to match positions, got {r.shape}")
    if not (np.isfinite(x).all() and np.isfinite(r).all() and (r > 0).all()):
        raise InvalidInputError("positions must be finite and radii positive and finite")
    return x, r


def plan(radii, box, *, skin: float = 0.0, n_levels: int | None = None, K: float = 0.3) -> HGrid:
    """Levels and cells for these radii in this periodic box.

    n_levels: None for the optimal number of levels (minimum of L (m + K), Eq. 2.7, K = 0.3 as
    fitted in ch. 2.1, L1194-1204), 1 for the single-level linked-cell grid, or any L (the smallest
    threshold m giving L levels, Appendix L1492-1532).
    """
    r = np.asarray(radii, dtype=float)
    if r.ndim != 1 or r.size == 0 or not (np.isfinite(r).all() and (r > 0).all()):
        raise InvalidInputError("radii must be a non-empty 1-d array of positive finite values")
    if not (np.isfinite(skin) and skin >= 0):
        raise InvalidInputError(f"skin must be a finite distance >= 0, got {skin!r}")
    b = np.asarray(box, dtype=float)
    d = b.shape[0] if b.ndim >= 1 else 0
    b = _check_box(b, d)
    inflated = r + skin / 2
    volume = float(np.prod(b))
    if n_levels is None:
        assignment = optimal_levels(inflated, volume, d, K=K)
    else:
        assignment = assign_levels(inflated, volume, d, n_levels)
    sizes = assignment.cell_sizes
    if np.any(b < 3 * sizes[-1]):
        raise InvalidInputError(
            f"box sides {b} are below 3 x (largest diameter + skin) = {3 * sizes[-1]:.6g}: the HGrid's half "
            "stencil needs 3 top-level cells per side; use more particles or "
            "hardpack.geometry.neighbours.pairs_within for small cells"
        )
    ncell = np.floor(b[None, :] / sizes[:, None]).astype(np.int64)
    limit = CELLS_PER_PARTICLE * r.size + 64
    for h in range(ncell.shape[0]):
        total = float(np.prod(ncell[h].astype(float)))
        if total > limit:
            shrink = (total / limit) ** (1.0 / d)
            ncell[h] = np.maximum(3, np.floor(ncell[h] / shrink)).astype(np.int64)
    level = assignment.level.astype(np.int64)
    reach = np.zeros(ncell.shape[0])
    np.maximum.at(reach, level, r)
    offsets = np.concatenate([[0], np.cumsum(np.prod(ncell, axis=1))]).astype(np.int64)
    return HGrid(b, level, ncell, reach, float(skin), offsets, assignment)


# --- kernels (plain arrays) ------------------------------------------------------------------------


# Helpers take whole arrays plus indices (pos, p; ncell, h) rather than row views.


@numba.njit(cache=True, inline="always")
def cell_of(pos, p, box, ncell, h, cell):
    """Integer cell coordinates of particle p (position wrapped into [0, box)) on level h."""
    for k in range(pos.shape[1]):
        c = int(np.floor(pos[p, k] / box[k] * ncell[h, k]))
        if c < 0:
            c = 0
        elif c >= ncell[h, k]:
            c = ncell[h, k] - 1
        cell[k] = c


@numba.njit(cache=True, inline="always")
def _flat(cell, ncell, h):
    """Flat index on level h of an unwrapped cell with coordinates in [-n, 2n) (one periodic wrap)."""
    idx = 0
    stride = 1
    for k in range(cell.shape[0]):
        c = cell[k]
        if c < 0:
            c += ncell[h, k]
        elif c >= ncell[h, k]:
            c -= ncell[h, k]
        idx += c * stride
        stride *= ncell[h, k]
    return idx


@numba.njit(cache=True)
def insert(p, pos, box, ncell, head_offset, level, head, nxt, cell):
    """Push particle p (position pos[p], wrapped) onto the list of its cell on its level; ``cell`` is
    (d,) int64 scratch space."""
    h = level[p]
    cell_of(pos, p, box, ncell, h, cell)
    c = head_offset[h] + _flat(cell, ncell, h)
    nxt[p] = head[c]
    head[c] = p


@numba.njit(cache=True, inline="always")
def _box_range(x, beta, box, ncell, h, lo, hi, full):
    """Cells [lo, hi] (unwrapped, inclusive) of level h covering [x - beta, x + beta]; the whole row
    (and full[k] = True) if that is as wide as the box."""
    for k in range(x.shape[0]):
        lo[k] = int(np.floor((x[k] - beta) / box[k] * ncell[h, k]))
        hi[k] = int(np.floor((x[k] + beta) / box[k] * ncell[h, k]))
        full[k] = hi[k] - lo[k] + 1 >= ncell[h, k]
        if full[k]:
            lo[k] = 0
            hi[k] = ncell[h, k] - 1


@numba.njit(cache=True, inline="always")
def _image_shift(cell, ncell, h, box, full, shift):
    """Offset of the periodic image in the unwrapped cell ``cell`` of level h (coordinates in [-n, 2n)),
    0 on axes where the search covers the whole row (``full``). Returns True if any axis is full (then
    the minimum image must be applied)."""
    any_full = False
    for k in range(cell.shape[0]):
        if full[k]:
            shift[k] = 0.0
            any_full = True
        elif cell[k] < 0:
            shift[k] = -box[k]
        elif cell[k] >= ncell[h, k]:
            shift[k] = box[k]
        else:
            shift[k] = 0.0
    return any_full


@numba.njit(cache=True, inline="always")
def _next_cell(cell, lo, hi, first):
    """Odometer step over axes first..d-1 of the cell range [lo, hi] (first = 1: the rows along
    axis 0); False when the range is done."""
    for k in range(first, cell.shape[0]):
        cell[k] += 1
        if cell[k] <= hi[k]:
            return True
        cell[k] = lo[k]
    return False


@numba.njit(cache=True)
def overlaps_any(x, r, pos, radii, box, ncell, head_offset, reach, head, nxt):
    """True if the sphere (x, r) overlaps (distance < sum of radii) any inserted particle, on any level."""
    d = x.shape[0]
    lo = np.empty(d, np.int64)
    hi = np.empty(d, np.int64)
    full = np.empty(d, np.bool_)
    cell = np.empty(d, np.int64)
    for j in range(ncell.shape[0]):
        _box_range(x, r + reach[j], box, ncell, j, lo, hi, full)
        cell[:] = lo
        while True:
            q = head[head_offset[j] + _flat(cell, ncell, j)]
            while q >= 0:
                r2 = 0.0
                for k in range(d):
                    dx = pos[q, k] - x[k]
                    dx -= box[k] * np.floor(dx / box[k] + 0.5)
                    r2 += dx * dx
                s = r + radii[q]
                if r2 < s * s:
                    return True
                q = nxt[q]
            if not _next_cell(cell, lo, hi, 0):
                break
    return False


@numba.njit(cache=True)
def _grow(buf, m, extra):
    """A copy of buf[:m] with room for at least ``extra`` more entries (doubling)."""
    new = np.empty(max(2 * buf.shape[0], m + extra), np.int64)
    new[:m] = buf[:m]
    return new


@numba.njit(cache=True, inline="always")
def _row_parts(base, a, b, n0, box0, start, part_q, part_shift):
    """Particles of the cells a..b (unwrapped on axis 0, -n0 <= a <= b < 2 n0, b - a < n0) of the row
    whose first cell has flat index ``base``: up to 3 contiguous ranges part_q[2i]..part_q[2i+1] - 1 with
    axis-0 image shifts part_shift[i] (cells are stored with axis 0 fastest and particles sorted by
    cell, so consecutive cells of a row hold consecutive particles). Returns (parts, particles)."""
    n = 0
    total = 0
    for piece in range(3):
        if piece == 0:
            lo, hi, s = a + n0, min(b, -1) + n0, -box0
        elif piece == 1:
            lo, hi, s = max(a, 0), min(b, n0 - 1), 0.0
        else:
            lo, hi, s = max(a, n0) - n0, b - n0, box0
        if lo <= hi:
            q0, q1 = start[base + lo], start[base + hi + 1]
            if q1 > q0:
                part_q[2 * n] = q0
                part_q[2 * n + 1] = q1
                part_shift[n] = s
                total += q1 - q0
                n += 1
    return n, total


@numba.njit(cache=True, inline="always")
def _scan(p, q0, q1, pos, radii, box, skin, shift, min_image, buf_i, buf_j, m):
    """Narrow phase of p against particles q0..q1-1 displaced by ``shift`` (and by the minimum image if
    ``min_image``): write every q with |x_q + shift - x_p| <= r_p + r_q + skin at buf[m...] (the
    buffers must have room for q1 - q0 more); returns the new count."""
    d = pos.shape[1]
    for q in range(q0, q1):
        r2 = 0.0
        for k in range(d):
            dx = pos[q, k] - pos[p, k] + shift[k]
            if min_image:
                dx -= box[k] * np.floor(dx / box[k] + 0.5)
            r2 += dx * dx
        s = radii[p] + radii[q] + skin
        if r2 <= s * s:
            buf_i[m] = p
            buf_j[m] = q
            m += 1
    return m


@numba.njit(cache=True)
def _pairs_kernel(pos, radii, level, box, ncell, head_offset, reach, skin, start, rows):
    """Top-Down HGrid search (module docstring) over particles sorted by (level, cell): the particles
    of flat cell c are start[c]..start[c+1]-1. Cells are visited row by row along axis 0. ``rows``:
    the forward rows of the half stencil (:func:`forward_rows`). Returns (i, j, distance tests, cells
    visited)."""
    n, d = pos.shape
    buf_i = np.empty(max(16, 4 * n), np.int64)
    buf_j = np.empty(max(16, 4 * n), np.int64)
    m = 0
    tests = 0
    visits = 0
    home = np.empty(d, np.int64)
    cell = np.empty(d, np.int64)
    lo = np.empty(d, np.int64)
    hi = np.empty(d, np.int64)
    full = np.zeros(d, np.bool_)
    shift = np.zeros(d)
    x = np.empty(d)
    part_q = np.empty(6, np.int64)
    part_shift = np.empty(3)
    for p in range(n):
        h = level[p]
        n0 = ncell[h, 0]
        cell_of(pos, p, box, ncell, h, home)
        for k in range(d):
            x[k] = pos[p, k]
            full[k] = False
            shift[k] = 0.0
        # 1. same level: own cell after p, the next cell along axis 0, and the forward rows
        cell[0] = 0
        for k in range(1, d):
            cell[k] = home[k]
        base = head_offset[h] + _flat(cell, ncell, h)
        q1 = start[base + home[0] + 1]
        if m + (q1 - p - 1) > buf_i.shape[0]:  # (the buffers are rebound only here and below, which keeps
            buf_i = _grow(buf_i, m, q1 - p - 1)  # the loops free of reference counting)
            buf_j = _grow(buf_j, m, q1 - p - 1)
        tests += q1 - p - 1
        m = _scan(p, p + 1, q1, pos, radii, box, skin, shift, False, buf_i, buf_j, m)
        visits += 2 + 3 * rows.shape[0]
        for r in range(-1, rows.shape[0]):
            if r < 0:
                a = home[0] + 1
                b = a
            else:
                a = home[0] - 1
                b = home[0] + 1
                cell[0] = 0
                for k in range(1, d):
                    cell[k] = home[k] + rows[r, k - 1]
                _image_shift(cell, ncell, h, box, full, shift)
                base = head_offset[h] + _flat(cell, ncell, h)
            parts, total = _row_parts(base, a, b, n0, box[0], start, part_q, part_shift)
            if parts > 0:
                if m + total > buf_i.shape[0]:
                    buf_i = _grow(buf_i, m, total)
                    buf_j = _grow(buf_j, m, total)
                tests += total
                for t in range(parts):
                    shift[0] = part_shift[t]
                    m = _scan(p, part_q[2 * t], part_q[2 * t + 1], pos, radii, box, skin, shift, False,
                              buf_i, buf_j, m)
        # 2. lower levels: box search with beta = r_p + rho_j + skin (Eq. 2.4), row by row
        for j in range(h):
            _box_range(x, radii[p] + reach[j] + skin, box, ncell, j, lo, hi, full)
            for k in range(d):
                cell[k] = lo[k]
            cell[0] = 0
            while True:
                min_image = _image_shift(cell, ncell, j, box, full, shift)
                base = head_offset[j] + _flat(cell, ncell, j)
                visits += hi[0] - lo[0] + 1
                parts, total = _row_parts(base, lo[0], hi[0], ncell[j, 0], box[0], start, part_q, part_shift)
                if parts > 0:
                    if m + total > buf_i.shape[0]:
                        buf_i = _grow(buf_i, m, total)
                        buf_j = _grow(buf_j, m, total)
                    tests += total
                    for t in range(parts):
                        shift[0] = part_shift[t]
                        m = _scan(p, part_q[2 * t], part_q[2 * t + 1], pos, radii, box, skin, shift, min_image,
                                  buf_i, buf_j, m)
                if not _next_cell(cell, lo, hi, 1):
                    break
    return buf_i[:m].copy(), buf_j[:m].copy(), tests, visits


@numba.njit(cache=True)
def _sort_keys(pos, box, ncell, head_offset, level):
    keys = np.empty(pos.shape[0], np.int64)
    cell = np.empty(pos.shape[1], np.int64)
    for p in range(pos.shape[0]):
        h = level[p]
        cell_of(pos, p, box, ncell, h, cell)
        keys[p] = head_offset[h] + _flat(cell, ncell, h)
    return keys


def forward_rows(d: int) -> np.ndarray:
    """Offsets o' in {-1, 0, 1}^(d-1) of axes 1..d-1 whose first non-zero entry is positive: (3^(d-1) - 1)/2
    rows of 3 cells along axis 0. With the next cell along axis 0 they form the half stencil of
    (3^d - 1)/2 neighbour cells (L2334-2337): of every offset o != 0 exactly one of o, -o is in it."""
    offs = [o for o in itertools.product((-1, 0, 1), repeat=d - 1) if any(o) and next(v for v in o if v) > 0]
    return np.array(offs, dtype=np.int64).reshape(-1, d - 1)


@dataclass(frozen=True)
class PairSearch:
    """Result of :func:`neighbour_pairs`: pairs i < j (sorted), the work done, and the grid used.

    distance_tests: narrow-phase distance evaluations (the cost model's T_cd, Eq. 2.31);
    cell_visits: cell-list heads read (T_ca, Eq. 2.32).
    """

    i: np.ndarray
    j: np.ndarray
    distance_tests: int
    cell_visits: int
    grid: HGrid

    def __len__(self) -> int:
        return int(self.i.size)


def wrap(positions, box) -> np.ndarray:
    """Positions mapped into [0, box) per axis."""
    return positions - box * np.floor(positions / box)


def neighbour_pairs(positions, radii, box, *, skin: float = 0.0, n_levels: int | None = None,
                    K: float = 0.3, grid: HGrid | None = None) -> PairSearch:
    """All pairs i < j with minimum-image distance <= r_i + r_j + skin, by the Top-Down HGrid search.

    box: (d,) side lengths or a diagonal (d, d) lattice matrix (periodic in every direction).
    n_levels: None (optimal), 1 (single-level linked cells) or a fixed number; see :func:`plan`.
    grid: a plan from :func:`plan` for these radii, box and skin (skips the level assignment).
    """
    x, r = _check_particles(positions, radii)
    d = x.shape[1]
    b = _check_box(box, d)
    if grid is None:
        grid = plan(r, b, skin=skin, n_levels=n_levels, K=K)
    elif grid.level.size != r.size or not np.array_equal(grid.box, b) or grid.skin != skin:
        raise InvalidInputError("grid was planned for other radii, box or skin; call plan() again")
    x = wrap(x, b)
    keys = _sort_keys(x, b, grid.ncell, grid.head_offset, grid.level)
    order = np.argsort(keys, kind="stable")
    start = np.searchsorted(keys[order], np.arange(grid.head_offset[-1] + 1))
    xs, rs, ls = np.ascontiguousarray(x[order]), r[order], grid.level[order]
    pi, pj, tests, visits = _pairs_kernel(xs, rs, ls, b, grid.ncell, grid.head_offset, grid.reach, grid.skin,
                                          start, forward_rows(d))
    i, j = order[pi], order[pj]
    i, j = np.minimum(i, j), np.maximum(i, j)
    srt = np.lexsort((j, i))
    return PairSearch(i[srt], j[srt], int(tests), int(visits), grid)
