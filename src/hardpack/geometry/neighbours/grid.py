"""The hierarchical cell grid: one regular grid per level over the fractional coordinates of a periodic
cell of any shape, with the numba kernels that traverse it.

Particles carry an interaction radius a_i: the pairs sought are those with |x_j + L n - x_i| <= a_i + a_j
(a = r for contacts, (1 + gap) r for near contacts, cutoff / 2 for a fixed range, r + skin / 2 for a
neighbour list with a skin). They are put on levels by Ogarko's rules (:mod:`.levels`; Ogarko,
dissertation, Sec. 2.1.2-2.1.3): level h has the nominal cell size s_h = the largest diameter 2 a on it, a
particle lives on the lowest level whose cells hold it (Eq. 2.3), and the levels balance the particles per
cell (Eqs. 2.6-2.8). Equal interaction radii (monodisperse packings, fixed ranges) give one level, the
linked-cell grid.

Level h is a regular grid of n_{h,k} cells along lattice vector k in fractional coordinates s = L^-1 x. The
planes s_k = c and s_k = c + 1/n lie h_k / n apart (h_k the perpendicular width of the cell), so
n_{h,k} = floor(per_cell h_k / s_h) makes every cell at least s_h / per_cell wide, and every point within
beta of a point with fractional coordinates s lies in a cell c with
floor((s_k - beta / h_k) n_k) <= c_k <= floor((s_k + beta / h_k) n_k): Ogarko's search box (Eqs. 2.4-2.5) in
fractional coordinates. Cell indices are unbounded integers: cell c is the stored cell c mod n seen through
the lattice image floor(c / n). Visiting every c of such a range therefore visits each (particle, image)
once, self-images and several images of one neighbour included, even when the range is wider than the
cell (small cells, sheared cells). A level with more than ``max_cells_per_particle`` cells per particle
on it gets proportionally fewer, larger cells (:func:`cell_counts`).

Axes without periodic images (hard walls, a spherical container: ``periodic[k]`` False) have no
images: their cell index is clamped to [0, n_k - 1], for points and search ranges alike, so a point
outside the cell along such an axis (an overlapping configuration) sits in the nearest boundary cell
and is still found.

Particles are sorted by (level, cell): those of flat cell c (levels one after the other, each in C order)
are order[cell_start[c]:cell_start[c + 1]] (compressed rows; Ogarko uses a hash table of linked lists).
Incremental use (random sequential addition, :mod:`.rsa`; the neighbour lists of the deforming-cell MD,
whose points move between cells) keeps linked lists over the same cells instead (:func:`point_cell`,
:func:`link_point`, :func:`unlink_point`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numba
import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours.levels import LevelAssignment, choose_levels

#: cells per particle above which a level's grid is coarsened (static grids)
MAX_CELLS_PER_PARTICLE = 4.0
#: relative safety margin of the search ranges against round-off (cells within beta (1 + RANGE_PAD))
RANGE_PAD = 1e-9
N_CHUNKS = 64  # work chunks for prange (each with its own accumulator; deterministic sums)


def cell_counts(heights, cell_size, count, max_cells_per_particle: float) -> np.ndarray:
    """Cells per lattice direction of every level: (L, d) integers >= 1.

    Level h gets n_{h,k} = floor(h_k / cell_size[h]) cells along lattice vector k (cells at least
    ``cell_size[h]`` wide); a level whose grid would have more than ``max_cells_per_particle`` cells per
    particle on it (``count[h]`` of them) is coarsened by the same factor in every direction.

    Parameters
    ----------
    heights : array_like of float, shape (d,)
        Perpendicular widths h_k of the cell (:func:`perpendicular_widths`).
    cell_size : array_like of float, shape (L,)
        Smallest cell width of every level.
    count : array_like of int, shape (L,)
        Particles on every level.
    max_cells_per_particle : float
        Cap on the cells per particle of a level.

    Returns
    -------
    numpy.ndarray of int64, shape (L, d)
        n_{h,k}.
    """
    heights = np.asarray(heights, dtype=float)
    size = np.asarray(cell_size, dtype=float).reshape(-1)
    count = np.asarray(count, dtype=float).reshape(-1)
    d = heights.size
    n = np.maximum(np.floor(heights[None, :] / size[:, None]), 1).astype(np.int64)
    for h in range(n.shape[0]):
        excess = np.prod(n[h].astype(float)) / (max_cells_per_particle * count[h])
        if excess > 1.0:
            n[h] = np.maximum(np.floor(n[h] / excess ** (1.0 / d)), 1).astype(np.int64)
    return n


def c_strides(n_cells: np.ndarray) -> np.ndarray:
    """Flat-index strides (C order: the last lattice direction fastest) of every level, (L, d).

    Parameters
    ----------
    n_cells : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction of every level.

    Returns
    -------
    numpy.ndarray of int64, shape (L, d)
        The strides.
    """
    strides = np.ones_like(n_cells)
    for a in range(n_cells.shape[1] - 2, -1, -1):
        strides[:, a] = strides[:, a + 1] * n_cells[:, a + 1]
    return strides


@dataclass(frozen=True)
class Grid:
    """Particles of a periodic cell sorted into the cells of their levels (module docstring).

    ``x`` are the wrapped Cartesian centres frac @ lattice.T that pair separations refer to;
    ``periodic[k]`` says whether lattice vector k is a period (images exist along it);
    ``level_reach[h]`` is the largest interaction radius on level h; ``n_cells[h, k]`` the cells of
    level h along lattice vector k; ``strides`` their flat-index strides and ``cell_offset[h]`` the
    first flat index of level h.

    Attributes
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    heights : numpy.ndarray of float, shape (d,)
        Perpendicular widths h_k.
    periodic : numpy.ndarray of bool, shape (d,)
        The lattice vectors that are periods.
    frac : numpy.ndarray of float, shape (N, d)
        Fractional coordinates.
    x : numpy.ndarray of float, shape (N, d)
        Wrapped Cartesian centres.
    reach : numpy.ndarray of float, shape (N,)
        Interaction radii.
    levels : LevelAssignment
        The level of every point.
    level_reach : numpy.ndarray of float, shape (L,)
        Largest interaction radius on every level.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level.
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level (the last entry: the total number of cells).
    cell_start : numpy.ndarray of int64, shape (n_total + 1,)
        Start of every cell's points in ``order``.
    order : numpy.ndarray of int64, shape (N,)
        Point indices sorted by flat cell.
    """

    lattice: np.ndarray  # (d, d), columns are the lattice vectors
    heights: np.ndarray  # (d,)
    periodic: np.ndarray  # (d,) bool
    frac: np.ndarray  # (N, d) in [0, 1)
    x: np.ndarray  # (N, d)
    reach: np.ndarray  # (N,) interaction radii
    levels: LevelAssignment
    level_reach: np.ndarray  # (L,)
    n_cells: np.ndarray  # (L, d)
    strides: np.ndarray  # (L, d)
    cell_offset: np.ndarray  # (L + 1,)
    cell_start: np.ndarray  # (n_total + 1,)
    order: np.ndarray  # (N,) particle indices sorted by flat cell

    @property
    def n_levels(self) -> int:
        return int(self.n_cells.shape[0])

    @property
    def level(self) -> np.ndarray:
        return self.levels.level



def _flat_cells(frac, level, n_cells, strides, cell_offset) -> np.ndarray:
    """Flat cell index of fractional points (M, d) on the given levels (M,): floor(s n) clamped to
    [0, n - 1] (points outside [0, 1) only along axes without images)."""
    n = n_cells[level]
    coords = np.clip(np.floor(frac * n), 0, n - 1).astype(np.int64)
    return cell_offset[level] + np.sum(coords * strides[level], axis=1)


def perpendicular_widths(lattice) -> np.ndarray:
    """h_k = 1 / |row k of lattice^-1|: the distance between the faces of the cell spanned by the others.

    Parameters
    ----------
    lattice : array_like of float, shape (d, d)
        Cell, lattice vectors as columns.

    Returns
    -------
    numpy.ndarray of float, shape (d,)
        h_k.
    """
    return 1.0 / np.linalg.norm(np.linalg.inv(lattice), axis=1)


def build_grid(frac, lattice, reach, *, periodic=None, levels=None, K: float = 0.3, per_cell: int = 1,
               max_cells_per_particle: float = MAX_CELLS_PER_PARTICLE) -> Grid:
    """Sort points with interaction radii ``reach`` into the hierarchical grid (module docstring).

    frac: (N, d) fractional coordinates, in [0, 1) along the periodic axes (e.g. ``Packing.fractional()``);
    lattice: (d, d) with the lattice vectors as columns. periodic: (d,) booleans, the lattice vectors that
    are periods (default: all; e.g. ``Packing.boundary.periodic_axes(d)``). levels: None for the optimal
    number of levels (Eq. 2.7 with this K), an integer L (1: the single-level linked-cell grid) or a
    :class:`LevelAssignment` of these radii. per_cell: cells per nominal cell size (2 halves the cells:
    fewer distance tests for long ranges).

    Parameters
    ----------
    frac : array_like of float, shape (N, d)
        Fractional coordinates, in [0, 1) along the periodic axes.
    lattice : array_like of float, shape (d, d)
        Cell, lattice vectors as columns.
    reach : array_like of float, shape (N,)
        Positive interaction radii.
    periodic : array_like of bool, shape (d,), optional
        Lattice vectors that are periods (default: all).
    levels : None, int or LevelAssignment, optional
        Levels (above).
    K : float, optional
        Cost ratio of Ogarko's Eq. 2.7 for the optimal number of levels.
    per_cell : int, optional
        Cells per nominal cell size.
    max_cells_per_particle : float, optional
        Cap on the cells per particle of a level (:func:`cell_counts`).

    Returns
    -------
    Grid
        The sorted grid.

    Raises
    ------
    InvalidInputError
        For non-positive radii, or coordinates outside [0, 1) along a periodic axis.
    """
    frac = np.ascontiguousarray(frac, dtype=float)
    lattice = np.ascontiguousarray(lattice, dtype=float)
    reach = np.ascontiguousarray(reach, dtype=float)
    n, d = frac.shape
    if reach.shape != (n,) or not (np.isfinite(reach).all() and (reach > 0).all()):
        raise InvalidInputError(f"interaction radii must be {n} positive finite numbers")
    periodic = np.ones(d, dtype=bool) if periodic is None else np.asarray(periodic)
    if periodic.shape != (d,) or periodic.dtype != bool:
        raise InvalidInputError(f"periodic must be {d} booleans (one per lattice vector), got {periodic!r}")
    wrapped = frac[:, periodic]
    if not (np.isfinite(frac).all() and (wrapped >= 0).all() and (wrapped < 1).all()):
        raise InvalidInputError("fractional coordinates must be finite and in [0, 1) along the periodic axes: "
                                "wrap them (Packing.fractional() does)")
    heights = perpendicular_widths(lattice)
    volume = float(abs(np.linalg.det(lattice)))
    assignment = choose_levels(reach, volume, d, levels, K)
    level = assignment.level.astype(np.int64)
    count = np.bincount(level, minlength=assignment.n_levels)
    n_cells = cell_counts(heights, assignment.cell_sizes / per_cell, count, max_cells_per_particle)
    strides = c_strides(n_cells)
    cell_offset = np.concatenate([[0], np.cumsum(np.prod(n_cells, axis=1))]).astype(np.int64)
    flat = _flat_cells(frac, level, n_cells, strides, cell_offset)
    cell_start = np.concatenate([[0], np.cumsum(np.bincount(flat, minlength=int(cell_offset[-1])))])
    return Grid(lattice=lattice, heights=heights, periodic=periodic, frac=frac, x=frac @ lattice.T, reach=reach,
                levels=assignment, level_reach=0.5 * assignment.cell_sizes, n_cells=n_cells,
                strides=strides, cell_offset=cell_offset, cell_start=cell_start.astype(np.int64),
                order=np.argsort(flat, kind="stable").astype(np.int64))


def stencil(grid: Grid, cutoff: float, level: int = 0) -> np.ndarray:
    """Offsets m (n_offsets, d) with |m_k| <= ceil(cutoff n_k / h_k): the cells of ``level`` that can
    hold a point within ``cutoff`` of some point of a given cell.

    Parameters
    ----------
    grid : Grid
        The grid.
    cutoff : float
        Largest distance searched.
    level : int, optional
        The level.

    Returns
    -------
    numpy.ndarray of int64, shape (n_offsets, d)
        The cell offsets.
    """
    reach = np.ceil(cutoff * grid.n_cells[level] / grid.heights).astype(np.int64)
    offsets = np.array(list(itertools.product(*[range(-k, k + 1) for k in reach])), dtype=np.int64)
    return offsets.reshape(-1, grid.heights.size)


# --- cell arithmetic (numba) -----------------------------------------------------------------------


@numba.njit(cache=True)
def search_range(s, beta, inv_heights, n_cells, h, lo, hi):
    """Unbounded cells [lo, hi] of level h holding every point within beta of fractional point s.

    Parameters
    ----------
    s : numpy.ndarray of float, shape (d,)
        Fractional point.
    beta : float
        Search radius.
    inv_heights : numpy.ndarray of float, shape (d,)
        1 / h_k.
    n_cells : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction of every level.
    h : int
        The level.
    lo, hi : numpy.ndarray of int64, shape (d,)
        Receive the range.
    """
    for k in range(s.shape[0]):
        w = beta * inv_heights[k]
        lo[k] = int(np.floor((s[k] - w) * n_cells[h, k]))
        hi[k] = int(np.floor((s[k] + w) * n_cells[h, k]))


@numba.njit(cache=True)
def clamp_range(periodic, n_cells, h, lo, hi):
    """Clamp the cell range [lo, hi] of level h to the stored cells [0, n - 1] along the axes without
    images (``periodic[k]`` False), where cell indices are clamped the same way.

    Parameters
    ----------
    periodic : numpy.ndarray of bool, shape (d,)
        The lattice vectors that are periods.
    n_cells : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction of every level.
    h : int
        The level.
    lo, hi : numpy.ndarray of int64, shape (d,)
        The range, clamped in place.
    """
    for k in range(lo.shape[0]):
        if not periodic[k]:
            top = n_cells[h, k] - 1
            lo[k] = min(max(lo[k], 0), top)
            hi[k] = min(max(hi[k], 0), top)


@numba.njit(cache=True)
def image_cell(c, n_cells, strides, cell_offset, h, image):
    """Flat index of the stored cell behind unbounded cell c of level h; ``image`` receives the lattice
    image floor(c / n) it is seen through.

    Parameters
    ----------
    c : numpy.ndarray of int64, shape (d,)
        Unbounded cell indices.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level.
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level.
    h : int
        The level.
    image : numpy.ndarray of int64, shape (d,)
        Receives the lattice image.

    Returns
    -------
    int
        The flat cell index.
    """
    flat = cell_offset[h]
    for k in range(c.shape[0]):
        t = c[k]
        im = t // n_cells[h, k]  # floor division (numba follows Python semantics)
        image[k] = im
        flat += (t - im * n_cells[h, k]) * strides[h, k]
    return flat


@numba.njit(cache=True)
def next_cell(c, lo, hi):
    """Odometer step over the cell range [lo, hi]; False when the range is done.

    Parameters
    ----------
    c : numpy.ndarray of int64, shape (d,)
        Current cell, advanced in place (axis 0 fastest).
    lo, hi : numpy.ndarray of int64, shape (d,)
        The range.

    Returns
    -------
    bool
        False when the range is exhausted.
    """
    for k in range(c.shape[0]):
        c[k] += 1
        if c[k] <= hi[k]:
            return True
        c[k] = lo[k]
    return False


@numba.njit(cache=True)
def point_cell(s, n_cells, strides, cell_offset, h, wrap):
    """Flat index of the stored cell of level h that holds fractional point s, any s: the point is
    seen as its image s - floor(s) in [0, 1) (``wrap`` receives floor(s)), and a point of the
    unbounded cell c is at its own position plus the lattice image floor(c / n) - floor(s).

    Parameters
    ----------
    s : numpy.ndarray of float, shape (d,)
        Fractional point.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level.
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level.
    h : int
        The level.
    wrap : numpy.ndarray of int64, shape (d,)
        Receives floor(s).

    Returns
    -------
    int
        The flat cell index.
    """
    flat = cell_offset[h]
    for k in range(s.shape[0]):
        w = np.floor(s[k])
        wrap[k] = int(w)
        c = min(int((s[k] - w) * n_cells[h, k]), n_cells[h, k] - 1)  # s - w rounds up to 1 at worst
        flat += c * strides[h, k]
    return flat


@numba.njit(cache=True)
def link_point(head, nxt, p, flat):
    """Put point p first in the linked list of cell ``flat`` (``head[flat]`` its first point,
    ``nxt[p]`` the one after p, -1 ends a list).

    Parameters
    ----------
    head : numpy.ndarray of int64, shape (n_total,)
        First point of every cell (-1: empty); modified in place.
    nxt : numpy.ndarray of int64, shape (N,)
        Next point of every point's cell; modified in place.
    p : int
        The point.
    flat : int
        Its flat cell index.
    """
    nxt[p] = head[flat]
    head[flat] = p


@numba.njit(cache=True)
def unlink_point(head, nxt, p, flat):
    """Take point p out of the linked list of cell ``flat`` (:func:`link_point`); it must be there.

    Parameters
    ----------
    head : numpy.ndarray of int64, shape (n_total,)
        First point of every cell; modified in place.
    nxt : numpy.ndarray of int64, shape (N,)
        Next point of every point's cell; modified in place.
    p : int
        The point.
    flat : int
        Its flat cell index.
    """
    q = head[flat]
    if q == p:
        head[flat] = nxt[p]
        return
    while nxt[q] != p:
        q = nxt[q]
    nxt[q] = nxt[p]


@numba.njit(cache=True)
def _grow(buf, m):
    """A copy of the rows buf[:m] with twice the room."""
    new = np.empty((2 * buf.shape[0], buf.shape[1]), np.int64)
    for r in range(m):
        for k in range(buf.shape[1]):
            new[r, k] = buf[r, k]
    return new


@numba.njit(cache=True)
def pair_kernel(frac, x, lattice, inv_heights, periodic, reach, level, level_reach, n_cells, strides,
                cell_offset, cell_start, pad):
    """Every pair of points with |x_q + lattice @ n - x_p| <= (a_p + a_q) pad, each once (Top-Down,
    Ogarko Sec. 2.1.2): a point searches its own level and every lower one, in the cells of the search
    box of half-width beta = a_p + (largest a on that level) (Eq. 2.4, with the level's actual largest
    radius). On its own level it keeps partners q > p and its own images n with the first non-zero n_k
    positive. Along axes without images (``periodic[k]`` False) the range is clamped to the stored cells.

    The points must be sorted by flat cell (the arrays in the order of the grid's ``order``;
    ``cell_start`` indexes them directly). Cells are visited a row (along the last lattice direction,
    whose cells are consecutive in the flat index) at a time: a row is at most a few contiguous runs of
    points, one per lattice image along that direction. Returns (rows (p, q, n_0..n_{d-1}) in sorted
    indices, distance tests, cell visits), rows in arbitrary order.

    Parameters
    ----------
    frac, x : numpy.ndarray of float, shape (N, d)
        Fractional and Cartesian coordinates, sorted by flat cell.
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    inv_heights : numpy.ndarray of float, shape (d,)
        1 / h_k.
    periodic : numpy.ndarray of bool, shape (d,)
        The lattice vectors that are periods.
    reach : numpy.ndarray of float, shape (N,)
        Interaction radii a_p, sorted.
    level : numpy.ndarray of int64, shape (N,)
        Level of every point, sorted.
    level_reach : numpy.ndarray of float, shape (L,)
        Largest radius on every level.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level.
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level.
    cell_start : numpy.ndarray of int64, shape (n_total + 1,)
        Start of every cell's points.
    pad : float
        Relative pad of the cutoff, >= 1.

    Returns
    -------
    rows : numpy.ndarray of int64, shape (M, d + 2)
        (p, q, n) of every pair.
    tests : int
        Distance tests.
    visits : int
        Cell visits.
    """
    n_points, d = x.shape
    last = d - 1
    buf = np.empty((max(64, 4 * n_points), d + 2), np.int64)
    m = 0
    tests = 0
    visits = 0
    lo = np.empty(d, np.int64)
    hi = np.empty(d, np.int64)
    c = np.empty(d, np.int64)
    image = np.empty(d, np.int64)
    row_shift = np.empty(d)
    shift = np.empty(d)
    for p in range(n_points):
        h = level[p]
        for lv in range(h + 1):
            search_range(frac[p], (reach[p] + level_reach[lv]) * pad, inv_heights, n_cells, lv, lo, hi)
            clamp_range(periodic, n_cells, lv, lo, hi)
            n_last = n_cells[lv, last]
            for k in range(d):
                c[k] = lo[k]
            while True:  # rows: the cells c_0..c_{d-2} with the whole range along the last direction
                base = cell_offset[lv]
                for k in range(last):
                    im = c[k] // n_cells[lv, k]
                    image[k] = im
                    base += (c[k] - im * n_cells[lv, k]) * strides[lv, k]
                for k in range(d):
                    acc = 0.0
                    for b in range(last):
                        acc += lattice[k, b] * image[b]
                    row_shift[k] = acc
                visits += hi[last] - lo[last] + 1
                t = lo[last]
                while t <= hi[last]:  # runs of consecutive cells with one image along the last direction
                    im = t // n_last
                    first_cell = t - im * n_last
                    end = min(hi[last], (im + 1) * n_last - 1)
                    q0 = cell_start[base + first_cell]
                    q1 = cell_start[base + end - im * n_last + 1]
                    t = end + 1
                    image[last] = im
                    for k in range(d):
                        shift[k] = row_shift[k] + lattice[k, last] * im
                    if lv == h:
                        if q1 <= p:
                            continue
                        if q0 <= p:  # p's own run: its images, then the points after it
                            first = 0
                            while first < d and image[first] == 0:
                                first += 1
                            if first == d or image[first] < 0:
                                q0 = p + 1
                            else:
                                q0 = p
                    for q in range(q0, q1):
                        tests += 1
                        r2 = 0.0
                        for k in range(d):
                            dx = x[q, k] + shift[k] - x[p, k]
                            r2 += dx * dx
                        lim = (reach[p] + reach[q]) * pad
                        if r2 <= lim * lim:
                            if m == buf.shape[0]:
                                buf = _grow(buf, m)
                            buf[m, 0] = p
                            buf[m, 1] = q
                            for k in range(d):
                                buf[m, 2 + k] = image[k]
                            m += 1
                c[last] = hi[last]  # the odometer below steps the other directions only
                if not next_cell(c, lo, hi):
                    break
    return buf[:m], tests, visits


@numba.njit(cache=True)
def _neighbour_cell(c, m, n_cells, strides, lattice, shift_vec):
    """Flat index of cell c + m (wrapped) on a single-level grid and the Cartesian image shift it
    carries."""
    d = n_cells.size
    flat = 0
    for a in range(d):
        shift_vec[a] = 0.0
    for a in range(d):
        t = c[a] + m[a]
        img = t // n_cells[a]
        flat += (t - img * n_cells[a]) * strides[a]
        for b in range(d):
            shift_vec[b] += lattice[b, a] * img
    return flat


@numba.njit(cache=True)
def _unravel(flat, n_cells, strides, out):
    for a in range(n_cells.size):
        out[a] = (flat // strides[a]) % n_cells[a]


@numba.njit(cache=True, parallel=True)
def pair_histograms(x, radii, lattice, n_cells, strides, cell_start, order, offsets,
                    cutoff, dr, n_r, dx, n_x, contact_tol, self_images):
    """Histograms of unordered pair distances r and scaled distances r / (r_i + r_j) on a single-level
    grid (``n_cells``, ``strides`` of level 0; ``offsets`` from :func:`stencil`), cell pair by cell pair.

    An offset m maps cell c to the stored cell (c + m) mod n and the lattice image floor((c + m) / n);
    this map is one to one, so visiting every offset visits each (particle, image) pair once. Bins are
    [k dr, (k + 1) dr), k < n_r (and likewise for x). Pairs with |r/(r_i+r_j) - 1| <= contact_tol are
    contacts: counted separately and left out of both histograms. Self-image pairs are included only if
    ``self_images``. Returns (hist_r, hist_x, n_contacts) as floats (self-image pairs carry weight 1/2
    per ordered visit, as (i, i, n) and (i, i, -n) are both visited).

    Parameters
    ----------
    x : numpy.ndarray of float, shape (N, d)
        Cartesian centres.
    radii : numpy.ndarray of float, shape (N,)
        Particle radii.
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    n_cells, strides : numpy.ndarray of int64, shape (d,)
        Cells per lattice direction and flat-index strides of level 0 (rows 0 of the grid's).
    cell_start : numpy.ndarray of int64, shape (n_total + 1,)
        Start of every cell's points in ``order``.
    order : numpy.ndarray of int64, shape (N,)
        Particle indices sorted by flat cell.
    offsets : numpy.ndarray of int64, shape (n_offsets, d)
        The stencil.
    cutoff : float
        Largest distance counted.
    dr : float
        Bin width of r.
    n_r : int
        Bins of r.
    dx : float
        Bin width of r / (r_i + r_j).
    n_x : int
        Bins of r / (r_i + r_j).
    contact_tol : float
        Relative tolerance of a contact.
    self_images : bool
        Count a particle's pairs with its own images.

    Returns
    -------
    hist_r : numpy.ndarray of float, shape (n_r,)
        Pairs per r bin.
    hist_x : numpy.ndarray of float, shape (n_x,)
        Pairs per r / (r_i + r_j) bin.
    n_contacts : float
        Contacts.
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
def window_counts(centres_frac, x, lattice, inv_heights, n_cells, strides, cell_offset, cell_start, order,
                  window_radii):
    """Number of points (all periodic images) within each window radius of each centre, on a
    single-level grid.

    ``window_radii`` must be sorted ascending; returns counts (M, n_radii) with counts[m, k] =
    #{images with |x - centre_m| < window_radii[k]}.

    Parameters
    ----------
    centres_frac : numpy.ndarray of float, shape (M, d)
        Window centres, fractional coordinates.
    x : numpy.ndarray of float, shape (N, d)
        Cartesian points.
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    inv_heights : numpy.ndarray of float, shape (d,)
        1 / h_k.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level (level 0 is used).
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level.
    cell_start : numpy.ndarray of int64, shape (n_total + 1,)
        Start of every cell's points in ``order``.
    order : numpy.ndarray of int64, shape (N,)
        Point indices sorted by flat cell.
    window_radii : numpy.ndarray of float, shape (n_radii,)
        Sorted window radii.

    Returns
    -------
    numpy.ndarray of int64, shape (M, n_radii)
        The counts.
    """
    m_total = centres_frac.shape[0]
    n_rad = window_radii.size
    out = np.zeros((m_total, n_rad), dtype=np.int64)
    rmax = window_radii[-1]
    for m in numba.prange(m_total):
        point = np.empty(64, dtype=np.int64)
        dist = np.empty(64)
        k = _window_members(centres_frac[m], rmax, x, lattice, inv_heights, n_cells, strides, cell_offset,
                            cell_start, order, point, dist)
        if k > point.size:
            point = np.empty(k, dtype=np.int64)
            dist = np.empty(k)
            _window_members(centres_frac[m], rmax, x, lattice, inv_heights, n_cells, strides, cell_offset,
                            cell_start, order, point, dist)
        hist = np.zeros(n_rad + 1, dtype=np.int64)
        for q in range(k):
            hist[np.searchsorted(window_radii, dist[q], side="right")] += 1
        acc = 0
        for b in range(n_rad):
            acc += hist[b]
            out[m, b] = acc
    return out


@numba.njit(cache=True)
def points_within(centres_frac, x, lattice, inv_heights, n_cells, strides, cell_offset, cell_start, order,
                  radius):
    """Every point image (all periodic images) closer than ``radius`` to each centre, on a single-level
    grid: the members of spherical windows.

    Parameters
    ----------
    centres_frac : numpy.ndarray of float, shape (M, d)
        Window centres, fractional coordinates.
    x : numpy.ndarray of float, shape (N, d)
        Cartesian points.
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    inv_heights : numpy.ndarray of float, shape (d,)
        1 / h_k.
    n_cells, strides : numpy.ndarray of int64, shape (L, d)
        Cells per lattice direction and flat-index strides of every level (level 0 is used).
    cell_offset : numpy.ndarray of int64, shape (L + 1,)
        First flat index of every level.
    cell_start : numpy.ndarray of int64, shape (n_total + 1,)
        Start of every cell's points in ``order``.
    order : numpy.ndarray of int64, shape (N,)
        Point indices sorted by flat cell.
    radius : float
        Window radius.

    Returns
    -------
    start : numpy.ndarray of int64, shape (M + 1,)
        The members of window m are ``point[start[m]:start[m + 1]]``.
    point : numpy.ndarray of int64, shape (K,)
        Point indices (an index appears once per image within the window).
    distance : numpy.ndarray of float, shape (K,)
        Distance of that image from the window's centre.
    """
    m_total = centres_frac.shape[0]
    start = np.zeros(m_total + 1, dtype=np.int64)
    none_i = np.empty(0, dtype=np.int64)
    none_f = np.empty(0)
    for m in range(m_total):  # count
        start[m + 1] = start[m] + _window_members(centres_frac[m], radius, x, lattice, inv_heights, n_cells,
                                                  strides, cell_offset, cell_start, order, none_i, none_f)
    point = np.empty(start[-1], dtype=np.int64)
    distance = np.empty(start[-1])
    for m in range(m_total):  # fill
        _window_members(centres_frac[m], radius, x, lattice, inv_heights, n_cells, strides, cell_offset,
                        cell_start, order, point[start[m]:start[m + 1]], distance[start[m]:start[m + 1]])
    return start, point, distance


@numba.njit(cache=True)
def _window_members(centre_frac, radius, x, lattice, inv_heights, n_cells, strides, cell_offset, cell_start,
                    order, point, distance):
    """The point images closer than ``radius`` to one centre (fractional ``centre_frac``) on level 0 of
    the grid: writes the first ``point.size`` of them (index, distance) into ``point`` and ``distance``
    and returns how many there are (call again with larger buffers if that is more)."""
    d = x.shape[1]
    r2max = radius * radius
    lo = np.empty(d, dtype=np.int64)
    hi = np.empty(d, dtype=np.int64)
    c = np.empty(d, dtype=np.int64)
    image = np.empty(d, dtype=np.int64)
    shift = np.empty(d)
    centre = np.zeros(d)
    for a in range(d):
        for b in range(d):
            centre[a] += lattice[a, b] * centre_frac[b]
    search_range(centre_frac, radius * (1.0 + RANGE_PAD), inv_heights, n_cells, 0, lo, hi)
    for a in range(d):
        c[a] = lo[a]
    k = 0
    while True:
        flat = image_cell(c, n_cells, strides, cell_offset, 0, image)
        for a in range(d):
            s = 0.0
            for b in range(d):
                s += lattice[a, b] * image[b]
            shift[a] = s
        for q in range(cell_start[flat], cell_start[flat + 1]):
            j = order[q]
            r2 = 0.0
            for a in range(d):
                t = x[j, a] + shift[a] - centre[a]
                r2 += t * t
            if r2 < r2max:
                if k < point.size:
                    point[k] = j
                    distance[k] = np.sqrt(r2)
                k += 1
        if not next_cell(c, lo, hi):
            break
    return k
