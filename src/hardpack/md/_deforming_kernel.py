"""Numba kernels of the deforming-cell sphere MD (:mod:`hardpack.md.deforming`).

The cell is a general (sheared) lattice H whose columns are the lattice vectors (Donev's Lambda,
Donev 2006, sec. 3.2.4 and Eq. 3.1); it stays FIXED during a window and is deformed only between
windows by the driver, so inside a window every particle moves on a straight line and the pair
contact time is the quadratic root of the fixed-cell engine (:func:`hardpack.events.roots.contact_root`,
derived in :mod:`hardpack.md._kernel`), not Donev's quartic of a cell deforming during the flight
(Donev 2006, sec. 3.2.2.2).

Same event scheme as :mod:`hardpack.md._kernel` in its simplest form: one predicted event per
particle in a 4-ary heap (:func:`hardpack.events.heap.heap_set`), lazy invalidation by collision
counters, and neighbour lists with immobile bounding spheres (Donev 2006, sec. 3.3.2). A list
entry is a neighbour j and a periodic image n with |H (s_j - s_i + n)| < R_i + R_j (s = H^-1 x,
R the bounding radii), packed as j * m + code, code the index of n in the image table ``img``
(m entries, n_k in [-M_k, M_k], lexicographic with axis 0 fastest, so the image -n has code
m - 1 - code). The candidates come from a single-level cell grid of the bounding-sphere centres
over the fractional coordinates (:mod:`hardpack.geometry.neighbours.grid`, linked lists per cell
since a centre moves at every rebuild of its list): a rebuild visits the cells within R_i + max R
of i's centre, a bounded number in a large cell, so the first build of a window costs O(N) and a
partial one O(1); the unbounded cell range visits every (centre, image) within reach once.
Along an axis where the range spans every cell (small or sheared cells, several images of one
neighbour) the stored cells are visited once and a centre's images along it are the integers of
the per-pair image box below; when it does so along every axis all particles are candidates,
taken in index order. The ellipsoid kernel (:mod:`hardpack.md._ellipsoid_deforming_kernel`)
builds its lists on the same grid. :func:`list_particle` is the exhaustive scan over all N
particles and their image boxes (|s_j,k - s_i,k + n_k| <= (R_i + R_j) / h_k, h_k the cell height
1 / |row k of H^-1|), O(N) per list, whose entries and order the grid reproduces.

A bounding-sphere exit re-wraps the particle into the cell and rebuilds its list; it also raises
the particle's collision counter, so that predictions of others against it (whose image codes
may have changed with the wrap) are invalidated and made again (the particle's trajectory is
unchanged, so the re-prediction finds the same collision).

Stress (Donev 2006, sec. 3.2.4.2, with the kinetic term added): the window accumulates the time
integral of sum_i v_i v_i^T (``kin``) and the collisional virial sum_coll r_ij J_ij^T
(``vir``; r_ij from i to j, J_ij the impulse on j, both along the contact normal, so the tensor
is symmetric); sigma = (kin + vir) / (V dt) with m = 1.
"""

from __future__ import annotations

import enum

import numpy as np
from numba import njit

from hardpack.events.heap import heap_set
from hardpack.events.roots import contact_root, exit_root
from hardpack.geometry.neighbours.grid import (
    RANGE_PAD,
    image_cell,
    link_point,
    next_cell,
    point_cell,
    search_range,
    unlink_point,
)

EXIT = -1
NONE = -2



class DeformingStatus(enum.IntEnum):
    """How the deforming-cell :func:`run_events` ended a window."""

    DONE_COLLISIONS = 0  # the window's collision budget is used up
    DONE_TIME = 1  # the next event is later than the window's end
    OVERFLOW = 2  # a neighbour list is full: enlarge the capacity and redo the window
    STUCK = 3  # no event can ever happen (nothing moves)
    SELF_IMAGE = 4  # a bounding sphere reaches its own periodic image: the cell is too small
    STALLED = 5  # a long run of events at one time without progress (an engine failure)


# integer counters
I_COLL, I_EVENTS, I_STALE, I_EXIT, I_GRAZE = 0, 1, 2, 3, 4
N_COUNTERS = 5


def image_ranges(lattice: np.ndarray, reach: float) -> np.ndarray:
    """M_k = 1 + ceil(reach / h_k): the image range that holds every pair within ``reach`` when
    both fractional coordinates lie in [0, 1).

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        The cell H, lattice vectors as columns.
    reach : float
        Largest pair distance that must be covered (length units).

    Returns
    -------
    numpy.ndarray of int64, shape (d,)
        M_k for every lattice vector k (h_k = 1 / |row k of H^-1| the cell height).
    """
    heights = 1.0 / np.linalg.norm(np.linalg.inv(lattice), axis=1)
    return (1 + np.ceil(reach / heights)).astype(np.int64)


@njit(cache=True)
def image_table(H, M):
    """Cartesian image vectors H n for n_k in [-M_k, M_k] (axis 0 fastest), shape (m, d).

    Parameters
    ----------
    H : numpy.ndarray of float64, shape (d, d)
        The cell, lattice vectors as columns.
    M : numpy.ndarray of int64, shape (d,)
        Image range along each lattice vector (:func:`image_ranges`).

    Returns
    -------
    numpy.ndarray of float64, shape (prod_k (2 M_k + 1), d)
        Row ``code`` is H n of the code's integer vector n; the image -n has code m - 1 - code.
    """
    d = H.shape[0]
    m = 1
    for k in range(d):
        m *= 2 * M[k] + 1
    img = np.zeros((m, d))
    for c in range(m):
        rem = c
        for k in range(d):
            w = 2 * M[k] + 1
            nk = rem % w - M[k]
            rem //= w
            for q in range(d):
                img[c, q] += H[q, k] * nk
    return img


@njit(cache=True)
def wrap_into_cell(X, H, Hinv):
    """Move every position into the cell (fractional coordinates in [0, 1)).

    Parameters
    ----------
    X : numpy.ndarray of float64, shape (N, d) or (N, m > d)
        Cartesian positions in columns 0 .. d - 1 (further columns, as in the ellipsoid state rows,
        are left alone), modified in place (shifted by whole lattice vectors).
    H, Hinv : numpy.ndarray of float64, shape (d, d)
        The cell (lattice vectors as columns) and its inverse.
    """
    s = np.empty(H.shape[0])
    for i in range(X.shape[0]):
        wrap_one(X, i, H, Hinv, s)


@njit(cache=True, inline="always")
def wrap_one(X, i, H, Hinv, s):
    """Move position i (columns 0 .. d - 1 of row i of X, which may hold more columns, such as the
    ellipsoid state rows) into the cell by whole lattice vectors (``s``: scratch of length d)."""
    d = H.shape[0]
    for k in range(d):
        acc = 0.0
        for q in range(d):
            acc += Hinv[k, q] * X[i, q]
        s[k] = np.floor(acc)
    for q in range(d):
        acc = 0.0
        for k in range(d):
            acc += H[q, k] * s[k]
        X[i, q] -= acc


@njit(cache=True, inline="always")
def _image_box(xi, xj, Hinv, reach, cfac, ds, lo, hi, od):
    """The lattice images n of j whose centre x_j + H n can lie within ``reach`` of x_i: the box
    lo <= n <= hi (``ds`` = H^-1 (x_j - x_i), ``cfac`` = the row norms of H^-1, ``od`` set to
    lo as the first image); returns the number of images in the box (0 when it is empty)."""
    d = xi.shape[0]
    for k in range(d):
        acc = 0.0
        for q in range(d):
            acc += Hinv[k, q] * (xj[q] - xi[q])
        ds[k] = acc
        c = reach * cfac[k]
        lo[k] = int(np.ceil(-c - acc))
        hi[k] = int(np.floor(c - acc))
    total = 1
    for k in range(d):
        if hi[k] < lo[k]:
            return 0
        total *= hi[k] - lo[k] + 1
        od[k] = lo[k]
    return total


@njit(cache=True, inline="always")
def pair_sigma(ai, aj, ki, kj, t):
    """Contact distance sigma(t) = a_i(t) + a_j(t) of a pair at window time t and its rate
    sigma' = A_i kappa_i + A_j kappa_j (radii a(t) = A (1 + kappa t), A at window time 0).

    The rate is the growth part of the approach speed in both the contact prediction (the root of
    |r + u t| = sigma(t)) and the collision law (the normal relative velocity is reflected in the
    frame of the growing surfaces), so a pair in which only one particle grows moves apart after a
    collision at the speed the LS rule gives it, with that one rate (Donev 2006, sec. 13.5 grows one
    species only). Equal rates use (A_i + A_j)(1 + kappa t) and (A_i + A_j) kappa: the arithmetic of
    uniform growth, so that path is unchanged bit for bit.

    Parameters
    ----------
    ai, aj : float
        Radii A_i, A_j at window time 0.
    ki, kj : float
        Relative growth rates kappa_i, kappa_j.
    t : float
        Window time.

    Returns
    -------
    sigma : float
        Contact distance a_i(t) + a_j(t).
    rate : float
        Its time derivative A_i kappa_i + A_j kappa_j.
    """
    if ki == kj:
        s = ai + aj
        return s * (1.0 + ki * t), s * ki
    return ai * (1.0 + ki * t) + aj * (1.0 + kj * t), ai * ki + aj * kj


@njit(cache=True)
def list_particle(i, jstop, bs, H, Hinv, M, strides, nb, nn, m, mul, cfac, lmin):
    """List every bounding sphere j < jstop (j != i) that overlaps i's, in both lists (entries
    j * mul + code, the image -n of code c has code m - 1 - c for a table of m images); returns
    OVERFLOW when a list is full, SELF_IMAGE when i's bounding sphere reaches its own image
    (``lmin`` is the shortest lattice vector), else 0. ``cfac`` = 1 / h_k."""
    d = H.shape[0]
    cap = nb.shape[1]
    ds = np.empty(d)
    lo = np.empty(d, dtype=np.int64)
    hi = np.empty(d, dtype=np.int64)
    od = np.empty(d, dtype=np.int64)
    ri = bs[i, d]
    if 2.0 * ri >= lmin:  # i's bounding sphere would reach its own periodic image
        return DeformingStatus.SELF_IMAGE
    for j in range(jstop):
        if j == i:
            continue
        reach = ri + bs[j, d]
        total = _image_box(bs[i, :d], bs[j, :d], Hinv, reach, cfac, ds, lo, hi, od)
        for _ in range(total):
            code = 0
            d2 = 0.0
            for k in range(d):
                code += (od[k] + M[k]) * strides[k]
            for q in range(d):
                acc = 0.0
                for k in range(d):
                    acc += H[q, k] * (ds[k] + od[k])
                d2 += acc * acc
            for k in range(d):  # odometer step
                od[k] += 1
                if od[k] <= hi[k]:
                    break
                od[k] = lo[k]
            if d2 < reach * reach:
                if nn[i] >= cap or nn[j] >= cap:
                    return DeformingStatus.OVERFLOW
                nb[i, nn[i]] = j * mul + code
                nn[i] += 1
                nb[j, nn[j]] = i * mul + (m - 1 - code)
                nn[j] += 1
    return 0


@njit(cache=True)
def link_cells(Y, Hinv, n_cells, strides, head, nxt, cell_of, wrap, sw):
    """Sort the points Y (any position, wrapped or not) into the linked lists of a single-level
    grid of the cell (:func:`hardpack.geometry.neighbours.grid.point_cell`).

    Parameters
    ----------
    Y : numpy.ndarray of float64, shape (N, >= d)
        Cartesian points in columns 0 .. d - 1.
    Hinv : numpy.ndarray of float64, shape (d, d)
        Inverse of the cell.
    n_cells, strides : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction and their flat-index strides.
    head : numpy.ndarray of int64, shape (prod n_cells,)
        Receives the first point of every cell (-1: empty).
    nxt, cell_of : numpy.ndarray of int64, shape (N,)
        Receive the next point of every point's cell and every point's flat cell.
    wrap : numpy.ndarray of int64, shape (N, d)
        Receives floor(s) of every point's fractional coordinates s (a point found through the
        unbounded cell c is its image floor(c / n) - wrap).
    sw : numpy.ndarray of float64, shape (N, d)
        Receives s - floor(s).
    """
    head[:] = -1
    for i in range(Y.shape[0]):
        link_one(Y, i, Hinv, n_cells, strides, head, nxt, cell_of, wrap, sw, True)


@njit(cache=True, inline="always")
def link_one(Y, i, Hinv, n_cells, strides, head, nxt, cell_of, wrap, sw, first):
    """Put point i into its cell (:func:`link_cells`), taking it out of its old one unless ``first``
    (``head`` must be all -1 before the first point)."""
    d = Hinv.shape[0]
    if not first:
        unlink_point(head, nxt, i, cell_of[i])
    coff = np.zeros(2, dtype=np.int64)
    _fractional(Y, i, Hinv, sw[i])
    cell_of[i] = point_cell(sw[i], n_cells, strides, coff, 0, wrap[i])
    for k in range(d):
        sw[i, k] -= wrap[i, k]
    link_point(head, nxt, i, cell_of[i])


@njit(cache=True, inline="always")
def _cell_range(s, beta, cfac, n_cells, w, lo, hi, wide):
    """The cells to visit for the points within ``beta`` of fractional point s: the unbounded range
    of :func:`hardpack.geometry.neighbours.grid.search_range` (padded against round-off), except
    along the axes where it spans all n_k cells (``wide``), whose stored cells are visited once
    and each point's images along them are found by :func:`_image_range`; ``w`` receives the
    fractional half-widths beta / h_k. Returns True when every axis is wide: every point is a
    candidate, and the caller takes them in index order instead of from the cells."""
    search_range(s, beta * (1.0 + RANGE_PAD), cfac, n_cells, 0, lo, hi)
    every = True
    for k in range(s.shape[0]):
        w[k] = beta * (1.0 + RANGE_PAD) * cfac[k]
        wide[k] = hi[k] - lo[k] + 1 >= n_cells[0, k]
        if wide[k]:
            lo[k] = 0
            hi[k] = n_cells[0, k] - 1
        else:
            every = False
    return every


@njit(cache=True, inline="always")
def _image_range(s, w, swj, wide, image, blo, bhi, od):
    """The images n of the point at wrapped fractional coordinates ``swj``, found in a cell seen
    through ``image``, with |swj_k + n_k - s_k| <= w_k along every axis: n_k = image_k along the
    narrow axes (if within w_k), the integers within w_k along the ``wide`` ones (:func:`_cell_range`);
    returns their number (0 if none) with the box in [blo, bhi] and ``od`` set to its first image."""
    total = 1
    for k in range(s.shape[0]):
        if wide[k]:
            blo[k] = int(np.ceil(s[k] - w[k] - swj[k]))
            bhi[k] = int(np.floor(s[k] + w[k] - swj[k]))
            if bhi[k] < blo[k]:
                return 0
        else:
            t = swj[k] + image[k] - s[k]
            if t > w[k] or t < -w[k]:
                return 0
            blo[k] = image[k]
            bhi[k] = image[k]
        total *= bhi[k] - blo[k] + 1
        od[k] = blo[k]
    return total


@njit(cache=True, inline="always")
def _fractional(Y, i, Hinv, s):
    """s = H^-1 y_i (row i of Y, columns 0 .. d - 1)."""
    d = Hinv.shape[0]
    for k in range(d):
        acc = 0.0
        for q in range(d):
            acc += Hinv[k, q] * Y[i, q]
        s[k] = acc


@njit(cache=True, inline="always")
def _fractional_difference(Y, i, j, Hinv, ds):
    """ds = H^-1 (y_j - y_i) (rows i and j of Y, columns 0 .. d - 1)."""
    d = Hinv.shape[0]
    for k in range(d):
        acc = 0.0
        for q in range(d):
            acc += Hinv[k, q] * (Y[j, q] - Y[i, q])
        ds[k] = acc


@njit(cache=True, inline="always")
def _image_vector(H, ds, n, r):
    """r = H (ds + n), the separation of an image n at fractional difference ``ds``; returns |r|^2."""
    d = H.shape[0]
    rr = 0.0
    for q in range(d):
        acc = 0.0
        for k in range(d):
            acc += H[q, k] * (ds[k] + n[k])
        r[q] = acc
        rr += acc * acc
    return rr


@njit(cache=True)
def cell_heights_inverse(Hinv):
    """1 / h_k for every lattice direction k, h_k the cell's height along it: the row norms of H^-1.

    Parameters
    ----------
    Hinv : numpy.ndarray of float64, shape (d, d)
        The inverse cell.

    Returns
    -------
    numpy.ndarray of float64, shape (d,)
        1 / h_k.
    """
    d = Hinv.shape[0]
    cfac = np.empty(d)
    for k in range(d):
        s2 = 0.0
        for q in range(d):
            s2 += Hinv[k, q] * Hinv[k, q]
        cfac[k] = np.sqrt(s2)
    return cfac


@njit(cache=True)
def linked_grid(Y, Hinv, n_cells, cstr):
    """A new single-level grid of the points Y (:func:`link_cells`).

    Parameters
    ----------
    Y, Hinv, n_cells, cstr
        The points, the inverse cell, and the grid's cell counts and strides, as in
        :func:`link_cells`.

    Returns
    -------
    head, nxt, wrap, sw : numpy.ndarray
        The grid's linked lists, the wrap of every point and its wrapped fractional coordinates
        (:func:`link_cells`).
    """
    n = Y.shape[0]
    d = Hinv.shape[0]
    head = np.empty(n_cells[0].prod(), dtype=np.int64)
    nxt = np.empty(n, dtype=np.int64)
    cell_of = np.empty(n, dtype=np.int64)
    wrap = np.empty((n, d), dtype=np.int64)
    sw = np.empty((n, d))
    link_cells(Y, Hinv, n_cells, cstr, head, nxt, cell_of, wrap, sw)
    return head, nxt, wrap, sw


@njit(cache=True, inline="always")
def walk_scratch(d):
    """Scratch of a walk over the cells of :func:`_cell_range` and the images of
    :func:`_image_range`: s, w, ds (float), lo, hi (int), wide (bool), c, image, blo, bhi, od
    (int), all of length d, and the level offsets ``coff`` of the single-level grid."""
    return (np.empty(d), np.empty(d), np.empty(d), np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64),
            np.empty(d, dtype=np.bool_), np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64),
            np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64),
            np.zeros(2, dtype=np.int64))


@njit(cache=True)
def list_particle_grid(i, jstop, bs, H, Hinv, M, strides, nb, nn, m, mul, cfac, lmin, rmax, n_cells, cstr,
                       head, nxt, wrap, sw, ent):
    """The lists of :func:`list_particle` (the same entries in the same order) from the bounding
    spheres in the cells within R_i + ``rmax`` of i's centre instead of all N: every bounding
    sphere j < jstop (j != i) that overlaps i's, with each periodic image n for which
    |H (s_j - s_i + n)| < R_i + R_j (s = H^-1 x, the arithmetic of the scan), in both lists.

    The cells are a single-level grid of the bounding-sphere centres over the fractional
    coordinates (:mod:`hardpack.geometry.neighbours.grid`; :func:`link_cells`); the unbounded cell
    range of :func:`hardpack.geometry.neighbours.grid.search_range` visits every (sphere, image)
    within reach once; along an axis where it spans all cells (small or sheared cells) the stored
    cells are visited once and a sphere's images along it are those of the scan's image box
    (:func:`_cell_range`, :func:`_image_range`; all particles in index order when every axis is
    such). The entries
    found are sorted by value j * mul + code before they are appended, which is the scan's order
    (j ascending, images in code order).

    Parameters
    ----------
    i, jstop : int
        The particle and the partner bound (i for the first build, N for a rebuild).
    bs : numpy.ndarray of float64, shape (N, d + 1)
        Bounding spheres, centre then radius.
    H, Hinv : numpy.ndarray of float64, shape (d, d)
        The cell and its inverse.
    M, strides : numpy.ndarray of int64, shape (d,)
        Image ranges and the strides of the image code.
    nb, nn : numpy.ndarray of int64
        Neighbour lists (N, cap) and their lengths (N,), appended to.
    m, mul : int
        Entries of the image table (the image -n of code c has code m - 1 - c) and the multiplier
        of j in an entry (>= m).
    cfac : numpy.ndarray of float64, shape (d,)
        1 / h_k, the row norms of H^-1.
    lmin : float
        Shortest lattice vector.
    rmax : float
        Upper bound of every bounding radius in the grid.
    n_cells, cstr : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction and flat-index strides of the grid.
    head, nxt, wrap, sw
        The grid's linked lists, the wrap of every centre and its wrapped fractional coordinates
        (:func:`link_cells`).
    ent : numpy.ndarray of int64, shape (cap,)
        Scratch of the entries found.

    Returns
    -------
    int
        OVERFLOW when a list is full, SELF_IMAGE when i's bounding sphere reaches its own image,
        else 0.
    """
    d = H.shape[0]
    cap = nb.shape[1]
    ri = bs[i, d]
    if 2.0 * ri >= lmin:  # i's bounding sphere would reach its own periodic image
        return DeformingStatus.SELF_IMAGE
    s, w, ds, lo, hi, wide, c, image, blo, bhi, od, coff = walk_scratch(d)
    _fractional(bs, i, Hinv, s)
    every = _cell_range(s, ri + rmax, cfac, n_cells, w, lo, hi, wide)
    j = 0  # every: the candidates are 0 .. jstop - 1
    more = not every  # else those of the cells of the range, in turn (the walk is written out in
    if more:  # each kernel: a numba helper called per candidate costs ~5x the walk, measured)
        for k in range(d):
            c[k] = lo[k]
        j = -1
    found = 0
    while True:
        if every:
            if j >= jstop:
                break
        else:
            while j < 0 and more:
                flat = image_cell(c, n_cells, cstr, coff, 0, image)
                more = next_cell(c, lo, hi)
                j = head[flat]
            if j < 0:
                break
        total = 0
        if j < jstop and j != i:
            total = _image_range(s, w, sw[j], wide, image, blo, bhi, od)
        if total > 0:
            reach = ri + bs[j, d]
            _fractional_difference(bs, i, j, Hinv, ds)
        for _ in range(total):
            d2 = 0.0
            for q in range(d):
                acc = 0.0
                for k in range(d):
                    acc += H[q, k] * (ds[k] + (od[k] - wrap[j, k]))
                d2 += acc * acc
            if d2 < reach * reach:
                if found == cap:
                    return DeformingStatus.OVERFLOW
                code = 0
                for k in range(d):
                    code += (od[k] - wrap[j, k] + M[k]) * strides[k]
                ent[found] = j * mul + code
                found += 1
            next_cell(od, blo, bhi)
        j = j + 1 if every else nxt[j]
    for a in range(1, found):  # insertion sort: the scan's order
        e = ent[a]
        b = a - 1
        while b >= 0 and ent[b] > e:
            ent[b + 1] = ent[b]
            b -= 1
        ent[b + 1] = e
    for a in range(found):
        j = ent[a] // mul
        if nn[i] >= cap or nn[j] >= cap:
            return DeformingStatus.OVERFLOW
        nb[i, nn[i]] = ent[a]
        nn[i] += 1
        nb[j, nn[j]] = i * mul + (m - 1 - (ent[a] - j * mul))
        nn[j] += 1
    return 0


@njit(cache=True)
def run_events(X, V, T, A, H, Hinv, M, img, cfac, lmin, n_cells, cstr, kappa, skin, bs, nb, nn, mark, cnt, ep,
               ei, ec, tv, hkey, heap, hpos, kin, vir, acc, iacc, coll_target, t_cap):
    """One window in a fixed cell H from a synchronisation point (all T = 0): build all lists,
    predict, process events until ``coll_target`` collisions or ``t_cap``.

    X, V : (N, d) positions and velocities at the particles' own times T (N,); A : (N,) radii at
    window time 0, a_i(t) = A_i (1 + kappa_i t) (``kappa`` (N,): relative growth rates, equal for
    uniform LS growth, zero for particles that keep their size); skin: bounding-sphere skin (N,) (R_i = a_i(t) +
    skin_i at the list's time); kin, vir : (d, d) accumulators (zeroed here); acc: (0) end time,
    (1) time integral of the kinetic energy; iacc: counters. Returns a status.

    Parameters
    ----------
    X, V : numpy.ndarray of float64, shape (N, d)
        Positions (wrapped into the cell by the caller) and velocities at the particles' own times;
        modified in place.
    T : numpy.ndarray of float64, shape (N,)
        Each particle's own update time (all 0 at entry); modified in place.
    A : numpy.ndarray of float64, shape (N,), read-only
        Radii at window time 0.
    H, Hinv : numpy.ndarray of float64, shape (d, d), read-only
        The cell (lattice vectors as columns) and its inverse.
    M : numpy.ndarray of int64, shape (d,), read-only
        Image range of the table ``img`` (:func:`image_ranges`).
    img : numpy.ndarray of float64, shape (m, d), read-only
        Image vectors H n (:func:`image_table`).
    cfac : numpy.ndarray of float64, shape (d,), read-only
        Row norms of H^-1, 1 / h_k.
    lmin : float
        Length of the shortest lattice vector (:func:`hardpack.md.deforming.shortest_vector`).
    n_cells, cstr : numpy.ndarray of int64, shape (1, d), read-only
        Cells per lattice direction of the grid of bounding-sphere centres that the lists are
        built from (:func:`list_particle_grid`; any counts >= 1 give the same lists, cells about
        as wide as the largest bounding diameter the fewest tests) and their flat-index strides.
    kappa : numpy.ndarray of float64, shape (N,), read-only
        Relative growth rate of every radius.
    skin : numpy.ndarray of float64, shape (N,), read-only
        Bounding-sphere skin of every particle.
    bs : numpy.ndarray of float64, shape (N, d + 1)
        Bounding spheres, centre then radius.
    nb : numpy.ndarray of int64, shape (N, cap)
        Neighbour lists, entries j * m + image code.
    nn : numpy.ndarray of int64, shape (N,)
        List lengths (reset here).
    mark : numpy.ndarray of int8, shape (N,)
        Scratch of the list updates (reset here).
    cnt, ep, ei, ec : numpy.ndarray of int64, shape (N,)
        Collision counters, the partner, image code and partner's counter of each predicted event.
    tv : numpy.ndarray of float64, shape (N,)
        Time up to which each particle's kinetic-tensor integral is closed (reset here).
    hkey, heap, hpos : numpy.ndarray, shape (N,)
        Event heap: keys (float64), particles in heap order and heap slot of each particle (int64).
    kin, vir : numpy.ndarray of float64, shape (d, d)
        Outputs (zeroed here): time integral of sum_i v_i v_i^T and the collisional virial
        sum r_ij J_ij^T.
    acc : numpy.ndarray of float64, shape (2,)
        Outputs: (0) the window's end time, (1) the time integral of the kinetic energy.
    iacc : numpy.ndarray of int64, shape (N_COUNTERS,)
        Outputs: counters I_COLL, I_EVENTS, I_STALE, I_EXIT, I_GRAZE (added to).
    coll_target : int
        Stop after this many collisions.
    t_cap : float
        Stop before the first event later than this window time.

    Returns
    -------
    int
        A :class:`DeformingStatus`.
    """
    n, d = X.shape
    m = img.shape[0]
    strides = np.ones(d, dtype=np.int64)
    for k in range(1, d):
        strides[k] = strides[k - 1] * (2 * M[k - 1] + 1)
    kin[:, :] = 0.0
    vir[:, :] = 0.0
    nn[:] = 0
    mark[:] = 0
    hpos[:] = -1
    cnt[:] = 0
    tv[:] = 0.0
    rv = np.empty(d)
    xi = np.empty(d)
    wrap = np.empty(d)  # scratch of wrap_one
    upd = np.empty(2, dtype=np.int64)
    head = np.empty(n_cells[0].prod(), dtype=np.int64)
    nxt = np.empty(n, dtype=np.int64)
    cell_of = np.empty(n, dtype=np.int64)
    gwrap = np.empty((n, d), dtype=np.int64)
    gsw = np.empty((n, d))
    ent = np.empty(nb.shape[1], dtype=np.int64)
    rmax = 0.0  # largest bounding radius in the grid
    for i in range(n):  # complete rebuild at t = 0 (positions wrapped by the caller)
        for k in range(d):
            bs[i, k] = X[i, k]
        bs[i, d] = A[i] + skin[i]
        rmax = max(rmax, bs[i, d])
    link_cells(bs, Hinv, n_cells, cstr, head, nxt, cell_of, gwrap, gsw)
    for i in range(n):
        st = list_particle_grid(i, i, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin, rmax, n_cells, cstr,
                                head, nxt, gwrap, gsw, ent)
        if st != 0:
            return st
    hsize = 0
    t = 0.0
    stage = 0
    while True:
        npred = 0
        if stage < n:  # initial predictions (schedule reset)
            upd[0] = stage
            npred = 1
            stage += 1
        else:
            if hsize == 0 or hkey[0] == np.inf:
                if t_cap < np.inf:
                    t = t_cap
                    break
                acc[0] = t
                return DeformingStatus.STUCK
            i = heap[0]
            tn = hkey[0]
            if tn > t_cap:
                t = t_cap
                break
            t = tn
            iacc[I_EVENTS] += 1
            p = ep[i]
            if p == EXIT:
                iacc[I_EXIT] += 1
                dt = t - T[i]
                for k in range(d):
                    X[i, k] += V[i, k] * dt
                T[i] = t
                wrap_one(X, i, H, Hinv, wrap)  # wrap i into the cell
                for e in range(nn[i]):  # drop i from its old neighbours' lists (each list once)
                    j = nb[i, e] // m
                    if mark[j]:
                        continue
                    mark[j] = 1
                    q2 = 0
                    while q2 < nn[j]:
                        if nb[j, q2] // m == i:
                            nn[j] -= 1
                            nb[j, q2] = nb[j, nn[j]]
                        else:
                            q2 += 1
                for e in range(nn[i]):
                    mark[nb[i, e] // m] = 0
                nn[i] = 0
                for k in range(d):
                    bs[i, k] = X[i, k]
                bs[i, d] = A[i] * (1.0 + kappa[i] * t) + skin[i]
                rmax = max(rmax, bs[i, d])
                link_one(bs, i, Hinv, n_cells, cstr, head, nxt, cell_of, gwrap, gsw, False)
                st = list_particle_grid(i, n, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin, rmax, n_cells,
                                        cstr, head, nxt, gwrap, gsw, ent)
                if st != 0:
                    acc[0] = t
                    return st
                cnt[i] += 1
                upd[0] = i
                npred = 1
            elif p == NONE or ec[i] != cnt[p]:
                iacc[I_STALE] += 1
                upd[0] = i
                npred = 1
            else:
                j = p
                dti = t - T[i]
                dtj = t - T[j]
                dist2 = 0.0
                code = ei[i]
                for k in range(d):
                    X[i, k] += V[i, k] * dti
                    X[j, k] += V[j, k] * dtj
                    dx = X[j, k] + img[code, k] - X[i, k]
                    rv[k] = dx
                    dist2 += dx * dx
                T[i] = t
                T[j] = t
                dist = np.sqrt(dist2)
                _, g = pair_sigma(A[i], A[j], kappa[i], kappa[j], t)
                vn = 0.0
                for k in range(d):
                    rv[k] /= dist
                    vn += rv[k] * (V[j, k] - V[i, k])
                vn -= g
                if vn < 0.0:
                    for q in (i, j):  # close the kinetic-tensor integral of both before the kick
                        w = t - tv[q]
                        for a1 in range(d):
                            for b1 in range(d):
                                kin[a1, b1] += V[q, a1] * V[q, b1] * w
                        tv[q] = t
                    for k in range(d):
                        dv = vn * rv[k]
                        V[i, k] += dv
                        V[j, k] -= dv
                    for a1 in range(d):
                        for b1 in range(d):
                            vir[a1, b1] -= vn * dist * rv[a1] * rv[b1]
                    cnt[i] += 1
                    cnt[j] += 1
                    iacc[I_COLL] += 1
                else:
                    iacc[I_GRAZE] += 1
                upd[0] = i
                upd[1] = j
                npred = 2
        for q in range(npred):
            i = upd[q]
            dt = t - T[i]
            grow = 1.0 + kappa[i] * t
            ai = A[i]
            adot = ai * kappa[i]
            dd = 0.0
            dv = 0.0
            vv = 0.0
            for k in range(d):
                xi[k] = X[i, k] + V[i, k] * dt
                dx = xi[k] - bs[i, k]
                dd += dx * dx
                dv += dx * V[i, k]
                vv += V[i, k] * V[i, k]
            best = exit_root(dd, dv, vv, bs[i, d] - ai * grow, adot)
            partner = EXIT if best < np.inf else NONE
            pcode = 0
            for e in range(nn[i]):
                j = nb[i, e] // m
                code = nb[i, e] - j * m
                dtj = t - T[j]
                rr = 0.0
                ru = 0.0
                uu = 0.0
                for k in range(d):
                    r = X[j, k] + V[j, k] * dtj + img[code, k] - xi[k]
                    u = V[j, k] - V[i, k]
                    rr += r * r
                    ru += r * u
                    uu += u * u
                sig, sdot = pair_sigma(ai, A[j], kappa[i], kappa[j], t)
                tc = contact_root(rr, ru, uu, sig, sdot, best)
                if tc < best:
                    best = tc
                    partner = j
                    pcode = code
            ep[i] = partner
            ei[i] = pcode
            if partner >= 0:
                ec[i] = cnt[partner]
            hsize = heap_set(hkey, heap, hpos, hsize, i, t + best)
        if stage >= n and npred == 2 and iacc[I_COLL] >= coll_target:
            break
    acc[0] = t
    for i in range(n):  # close the kinetic-tensor integrals at the window end
        w = t - tv[i]
        for a1 in range(d):
            for b1 in range(d):
                kin[a1, b1] += V[i, a1] * V[i, b1] * w
    acc[1] = 0.5 * np.trace(kin)
    if stage >= n and t == t_cap:
        return DeformingStatus.DONE_TIME
    return DeformingStatus.DONE_COLLISIONS


@njit(cache=True)
def synchronise(X, V, T, A, t, kappa):
    """Advance all particles to window time t, radii to A_i (1 + kappa_i t), time origin to t.

    Parameters
    ----------
    X, V : numpy.ndarray of float64, shape (N, d)
        Positions (advanced in place) and velocities.
    T : numpy.ndarray of float64, shape (N,)
        Own update times, set to 0.
    A : numpy.ndarray of float64, shape (N,)
        Radii at window time 0, set to their values at t.
    t : float
        Window time of the synchronisation.
    kappa : numpy.ndarray of float64, shape (N,)
        Relative growth rate of every radius.
    """
    n, d = X.shape
    for i in range(n):
        dt = t - T[i]
        for k in range(d):
            X[i, k] += V[i, k] * dt
        T[i] = 0.0
        A[i] *= 1.0 + kappa[i] * t


@njit(cache=True)
def strain_limit(X, A, H, Hinv, strain, reach, self_sigma, n_cells, cstr):
    """Largest s in [0, 1] such that mapping positions and cell by (I + s strain) leaves every
    pair within ``reach`` at least half its gap (|r| - sigma), and the smallest relative gap
    (|r| - sigma) / sigma before the map. A particle's own images count as pairs with contact
    distance ``self_sigma``. The pairs (i <= j, image n; n != 0 for i = j) with
    |r| = |H (s_j - s_i + n)| < reach come from a single-level grid of the centres over the
    fractional coordinates (:func:`link_cells`; every (particle, image) in the unbounded cell range
    within ``reach`` of i is visited once, also in cells narrower than ``reach``).

    Along the path r(s) = r + s strain r the first s with |r(s)| = sigma + gap / 2 is the
    contact root of a pair with relative velocity strain r (:func:`hardpack.events.roots.contact_root`).

    Parameters
    ----------
    X : numpy.ndarray of float64, shape (N, d)
        Positions, wrapped into the cell.
    A : numpy.ndarray of float64, shape (N,)
        Radii.
    H, Hinv : numpy.ndarray of float64, shape (d, d)
        The cell (lattice vectors as columns) and its inverse.
    strain : numpy.ndarray of float64, shape (d, d)
        The proposed deformation; the map is x -> (I + s strain) x.
    reach : float
        Pairs farther apart than this are ignored.
    self_sigma : float
        Contact distance of a particle with its own images.
    n_cells, cstr : numpy.ndarray of int64, shape (1, d)
        Cells per lattice direction of the grid (any counts >= 1 give the same result; cells about
        ``reach`` wide the fewest tests) and their flat-index strides.

    Returns
    -------
    smax : float
        Largest admissible s in [0, 1].
    gmin : float
        Smallest relative gap (|r| - sigma) / sigma among the pairs within reach (inf if none).
    """
    n, d = X.shape
    cfac = cell_heights_inverse(Hinv)
    head, nxt, wrap, sw = linked_grid(X, Hinv, n_cells, cstr)
    s, w, ds, lo, hi, wide, c, image, blo, bhi, od, coff = walk_scratch(d)
    r = np.empty(d)
    nv = np.empty(d, dtype=np.int64)
    smax = 1.0
    gmin = np.inf
    for i in range(n):
        _fractional(X, i, Hinv, s)
        every = _cell_range(s, reach, cfac, n_cells, w, lo, hi, wide)
        j = i  # every: the candidates are i .. n - 1
        more = not every  # else those of the cells of the range, in turn
        if more:
            for k in range(d):
                c[k] = lo[k]
            j = -1
        while True:
            if every:
                if j >= n:
                    break
            else:
                while j < 0 and more:
                    flat = image_cell(c, n_cells, cstr, coff, 0, image)
                    more = next_cell(c, lo, hi)
                    j = head[flat]
                if j < 0:
                    break
            jj = j
            j = j + 1 if every else nxt[j]
            if jj < i:
                continue
            total = _image_range(s, w, sw[jj], wide, image, blo, bhi, od)
            if total > 0:
                _fractional_difference(X, i, jj, Hinv, ds)
            for _ in range(total):
                skip = i == jj
                for k in range(d):
                    nv[k] = od[k] - wrap[jj, k]
                    if nv[k] != 0:
                        skip = False
                next_cell(od, blo, bhi)
                if skip:
                    continue
                rr = _image_vector(H, ds, nv, r)
                if rr >= reach * reach:
                    continue
                sigma = self_sigma if i == jj else A[i] + A[jj]
                gap = np.sqrt(rr) - sigma
                gmin = min(gmin, gap / sigma)
                ru = 0.0
                uu = 0.0
                for q in range(d):
                    u = 0.0
                    for k in range(d):
                        u += strain[q, k] * r[k]
                    ru += r[q] * u
                    uu += u * u
                if gap <= 0.0:  # touching (round-off): the strain must not push the pair closer
                    if ru < 0.0:
                        smax = 0.0
                else:
                    smax = min(smax, contact_root(rr, ru, uu, sigma + 0.5 * gap, 0.0, smax))
    return smax, gmin
