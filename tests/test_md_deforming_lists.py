"""Neighbour lists and pair searches of the deforming-cell sphere kernel on the cell grid
(hardpack.md._deforming_kernel, list_particle_grid and strain_limit).

- the lists built from the grid are, as sets of (i, j, image n), the pairs of bounding spheres
  with |x_j + H n - x_i| < R_i + R_j found by an independent brute-force enumeration in numpy
  over a box of images, in a large cubic cell, a strongly sheared (not reduced) cell whose
  heights are shorter than the reach, and small cells where a sphere meets several images of
  one neighbour; a grid of one cell gives the same lists;
- they equal the exhaustive scan's (list_particle) entry for entry, order included (the first
  build of a window and the rebuild of one list);
- strain_limit's smallest relative gap and largest strain fraction equal a brute-force numpy
  evaluation over all pairs and images (own images included), with positions inside or (after a
  synchronisation) slightly outside the cell.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hardpack.geometry.neighbours.grid import c_strides
from hardpack.md import _deforming_kernel as dk
from hardpack.md.deforming import cell_grid, shortest_vector

CELLS = {
    # name: (lattice H, columns the lattice vectors; particles; bounding radii range)
    "cubic": (6.0 * np.eye(3), 80, (0.3, 0.6)),
    "sheared": (np.array([[5.0, 3.7, 1.2], [0.0, 4.0, 2.9], [0.0, 0.0, 4.5]]), 60, (0.3, 0.7)),
    "small_sheared_2d": (2.0 * np.array([[1.0, 5.0], [0.0, 1.0]]), 5, (0.4, 0.9)),
    "small_4d": (2.5 * np.eye(4) + 0.4 * np.triu(np.ones((4, 4)), 1), 6, (0.4, 0.95)),
}


def _spheres(name, seed=0):
    H, n, (rlo, rhi) = CELLS[name]
    rng = np.random.default_rng(seed)
    d = H.shape[0]
    frac = rng.random((n, d))
    frac[0, 0] = 0.0  # on a cell face
    frac[1, -1] = np.nextafter(1.0, 0.0)
    bs = np.empty((n, d + 1))
    bs[:, :d] = frac @ H.T
    bs[:, d] = rng.uniform(rlo, rhi, n)
    assert 2 * bs[:, d].max() < shortest_vector(H)  # no bounding sphere reaches its own image
    return H, bs


def _setup(H):
    d = H.shape[0]
    Hinv = np.linalg.inv(H)
    lmin = shortest_vector(H)
    M = dk.image_ranges(H, lmin)
    strides = np.cumprod(np.concatenate([[1], 2 * M[:-1] + 1])).astype(np.int64)
    m = int(np.prod(2 * M + 1))
    return d, Hinv, lmin, M, strides, m, np.linalg.norm(Hinv, axis=1)


def _grid_lists(H, bs, n_cells, jstop_all=False, cap=512):
    """Lists of every particle from list_particle_grid: the first build (partners j < i), or with
    ``jstop_all`` each particle's own rebuild from empty lists (all partners)."""
    n = bs.shape[0]
    d, Hinv, lmin, M, strides, m, cfac = _setup(H)
    cstr = c_strides(n_cells)
    head = np.empty(int(np.prod(n_cells)), dtype=np.int64)
    nxt, cell_of = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    wrap, sw = np.empty((n, d), dtype=np.int64), np.empty((n, d))
    dk.link_cells(bs, Hinv, n_cells, cstr, head, nxt, cell_of, wrap, sw)
    nb, nn, ent = np.zeros((n, cap), dtype=np.int64), np.zeros(n, dtype=np.int64), np.empty(cap, dtype=np.int64)
    rmax = float(bs[:, d].max())
    out = []
    for i in range(n):
        if jstop_all:
            nn[:] = 0
        st = dk.list_particle_grid(i, n if jstop_all else i, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin,
                                   rmax, n_cells, cstr, head, nxt, wrap, sw, ent)
        assert st == 0
        if jstop_all:
            out.append(nb[i, :nn[i]].copy())
    return out if jstop_all else (nb, nn)


def _scan_lists(H, bs, jstop_all=False, cap=512):
    """The same from the exhaustive scan list_particle."""
    n = bs.shape[0]
    d, Hinv, lmin, M, strides, m, cfac = _setup(H)
    nb, nn = np.zeros((n, cap), dtype=np.int64), np.zeros(n, dtype=np.int64)
    out = []
    for i in range(n):
        if jstop_all:
            nn[:] = 0
        assert dk.list_particle(i, n if jstop_all else i, bs, H, Hinv, M, strides, nb, nn, m, m, cfac, lmin) == 0
        if jstop_all:
            out.append(nb[i, :nn[i]].copy())
    return out if jstop_all else (nb, nn)


def _as_set(H, nb, nn):
    """{(i, j, n)} of packed lists."""
    _, _, _, M, strides, m, _ = _setup(H)
    out = set()
    for i in range(nb.shape[0]):
        for e in nb[i, :nn[i]]:
            j, code = divmod(int(e), m)
            image = tuple(int((code // strides[k]) % (2 * M[k] + 1) - M[k]) for k in range(len(M)))
            out.add((i, j, image))
    return out


def _brute_force(H, bs):
    """{(i, j, n)}: j != i, |x_j + H n - x_i| < R_i + R_j, over every n in a box that holds all
    (|n_k| <= 1 + reach / h_k for fractional coordinates in [0, 1))."""
    d = H.shape[0]
    x, r = bs[:, :d], bs[:, d]
    heights = 1.0 / np.linalg.norm(np.linalg.inv(H), axis=1)
    span = (2 + np.ceil(2 * r.max() / heights)).astype(int)
    images = np.array(list(itertools.product(*[range(-k, k + 1) for k in span])))
    out = set()
    for i in range(len(x)):
        sep = x[None, None, :, :] + (images @ H.T)[None, :, None, :] - x[i]
        dist = np.linalg.norm(sep, axis=-1)[0]  # (images, j)
        hit = dist < r[i] + r[None, :]
        hit[:, i] = False
        for a, j in zip(*np.nonzero(hit)):
            out.add((i, int(j), tuple(int(v) for v in images[a])))
    return out


@pytest.mark.parametrize("name", sorted(CELLS))
def test_grid_lists_are_the_brute_force_pairs(name):
    H, bs = _spheres(name)
    n, d = bs.shape[0], H.shape[0]
    n_cells, _ = cell_grid(H, 2 * float(bs[:, d].max()), n)
    nb, nn = _grid_lists(H, bs, n_cells)
    truth = _brute_force(H, bs)
    pairs = _as_set(H, nb, nn)
    assert pairs == truth
    assert sum(nn) == len(truth)  # no entry twice
    if name.startswith("small"):  # several images of one neighbour in one list
        assert len({(i, j) for i, j, _ in truth}) < len(truth)
    one = np.ones((1, d), dtype=np.int64)  # one cell (the grid prunes nothing) and fine cells
    for cells in (one, cell_grid(H, 0.3 * float(bs[:, d].max()), 10**6)[0]):
        nb1, nn1 = _grid_lists(H, bs, cells)
        assert np.array_equal(nn1, nn) and np.array_equal(nb1, nb)


@pytest.mark.parametrize("name", sorted(CELLS))
@pytest.mark.parametrize("rebuild", [False, True])
def test_grid_lists_equal_the_scan_in_order(name, rebuild):
    H, bs = _spheres(name, seed=1)
    n, d = bs.shape[0], H.shape[0]
    n_cells, _ = cell_grid(H, 2 * float(bs[:, d].max()), n)
    grid = _grid_lists(H, bs, n_cells, jstop_all=rebuild)
    scan = _scan_lists(H, bs, jstop_all=rebuild)
    if rebuild:
        assert all(np.array_equal(a, b) for a, b in zip(grid, scan))
        nb = np.zeros((n, max(len(a) for a in grid)), dtype=np.int64)
        for i, a in enumerate(grid):
            nb[i, :len(a)] = a
        assert _as_set(H, nb, np.array([len(a) for a in grid])) == _brute_force(H, bs)
    else:
        assert np.array_equal(grid[1], scan[1]) and np.array_equal(grid[0], scan[0])


def _brute_strain_limit(X, A, H, strain, reach, self_sigma):
    heights = 1.0 / np.linalg.norm(np.linalg.inv(H), axis=1)
    span = (3 + np.ceil(reach / heights)).astype(int)
    images = np.array(list(itertools.product(*[range(-k, k + 1) for k in span]))) @ H.T
    smax, gmin = 1.0, np.inf
    for i in range(len(X)):
        for j in range(i, len(X)):
            r = X[j] + images - X[i]
            rr = np.sum(r * r, axis=1)
            keep = rr < reach**2
            if i == j:
                keep &= np.any(images != 0, axis=1)
            r, rr = r[keep], rr[keep]
            if not len(r):
                continue
            sigma = self_sigma if i == j else A[i] + A[j]
            gap = np.sqrt(rr) - sigma
            gmin = min(gmin, float((gap / sigma).min()))
            u = r @ strain.T
            if np.any((gap <= 0) & (np.sum(r * u, axis=1) < 0)):  # overlapping and pushed closer
                smax = 0.0
            r, rr, u, gap = r[gap > 0], rr[gap > 0], u[gap > 0], gap[gap > 0]
            # |r + s u| = sigma + gap / 2: uu s^2 + 2 ru s + rr - c^2 = 0, smallest root in [0, 1]
            c2 = (sigma + 0.5 * gap) ** 2
            a, b, cc = np.sum(u * u, axis=1), np.sum(r * u, axis=1), rr - c2
            disc = b * b - a * cc
            ok = (disc >= 0) & (a > 0)
            root = np.where(ok, (-b - np.sqrt(np.where(ok, disc, 0.0))) / np.where(ok, a, 1.0), np.inf)
            root = root[(root >= 0) & (root <= 1)]
            if len(root):
                smax = min(smax, float(root.min()))
    return smax, gmin


@pytest.mark.parametrize("name", sorted(CELLS))
def test_strain_limit_is_the_brute_force_one(name):
    H, bs = _spheres(name, seed=2)
    d = H.shape[0]
    X = np.ascontiguousarray(bs[:, :d])
    rng = np.random.default_rng(3)
    e = rng.normal(size=(d, d))
    strain = 2.0 * (e + e.T) / np.linalg.norm(e + e.T)  # large: some pairs limit the step
    Hinv = np.linalg.inv(H)
    A = 0.5 * bs[:, d]
    reach = 4.4 * float(A.max())
    A *= 0.97 * (1.0 + _brute_strain_limit(X, A, H, strain, reach, 2.2 * float(A.max()))[1])  # no overlaps
    self_sigma = 1.1 * 2 * float(A.max())
    reach = 2.0 * max(self_sigma, 2.0 * float(A.max()))
    smax, gmin = dk.strain_limit(X, A, H, Hinv, strain, reach, self_sigma, *cell_grid(H, reach, len(X)))
    bsmax, bgmin = _brute_strain_limit(X, A, H, strain, reach, self_sigma)
    assert gmin == pytest.approx(bgmin, rel=1e-12, abs=1e-12)
    assert smax == pytest.approx(bsmax, rel=1e-9, abs=1e-12)
    assert 0.0 < smax < 1.0 and gmin > 0.0  # pairs limit the step
    # one cell (no pruning) and positions moved slightly out of the cell (as after a window's
    # synchronisation): the same answer
    one = np.ones((1, d), dtype=np.int64)
    assert dk.strain_limit(X, A, H, Hinv, strain, reach, self_sigma, one, c_strides(one)) == (smax, gmin)
    moved = X + 1e-3 * rng.normal(size=X.shape)
    ref = _brute_strain_limit(moved, A, H, strain, reach, self_sigma)
    got = dk.strain_limit(moved, A, H, Hinv, strain, reach, self_sigma, *cell_grid(H, reach, len(X)))
    assert got == pytest.approx(ref, rel=1e-9)


@pytest.mark.parametrize("name", ["cubic", "sheared"])
def test_strain_limit_finds_a_pair_near_the_reach(name):
    # two particles only, 0.95 reach apart: the one pair (and the far own images) decide both
    # outputs; on grids of cells narrower than the reach the pair is several cells away
    H = CELLS[name][0]
    d = H.shape[0]
    reach, a = 2.0, 0.25
    direction = np.ones(d) / np.sqrt(d)
    X = np.array([np.full(d, 0.1) @ H.T, np.full(d, 0.1) @ H.T + 0.95 * reach * direction])
    A = np.full(2, a)
    strain = -np.outer(direction, direction)  # squeezes the pair
    ref = _brute_strain_limit(X, A, H, strain, reach, 4 * a)
    assert ref[1] == pytest.approx((0.95 * reach - 2 * a) / (2 * a), rel=1e-12)
    for width in (reach, reach / 3, reach / 7):
        got = dk.strain_limit(X, A, H, np.linalg.inv(H), strain, reach, 4 * a, *cell_grid(H, width, 10**6))
        assert got == pytest.approx(ref, rel=1e-12)
