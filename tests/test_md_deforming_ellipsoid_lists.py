"""Neighbour lists and pair searches of the deforming-cell ellipsoid kernel on the cell grid
(hardpack.md._ellipsoid_deforming_kernel: run_events' lists, near_pairs).

- the lists of a window's complete build are, as sets of (i, j, image n), the pairs of bounding
  spheres with |x_j + H n - x_i| < R_i + R_j and the own images with |H n| < 2 R_i (once per
  pair +-n, n with its last non-zero component positive) found by an independent brute-force
  enumeration in numpy, in a large cubic cell, a strongly sheared (not reduced) cell whose
  heights are shorter than the reach, and small cells (2D and 3D, N = 1 too) where a bounding
  sphere meets several images of one neighbour and of itself; a grid of one cell and a fine grid
  give the same lists;
- they equal, entry for entry and in order, the lists of the exhaustive scan
  (_deforming_kernel.list_particle, then list_self, particle by particle);
- after a window with many bounding-sphere exits, with and without growth (each exit re-wraps a
  centre, moves it to another grid cell and rebuilds its list with a larger bounding sphere when
  the particle grows), the lists are still exactly the brute-force pairs of the bounding spheres,
  and the window is bit-identical on a grid of one cell and on a fine grid;
- a window whose particles grow threefold in a small cell ends at its time cap with collisions
  and no overlaps (the collision finds the image in contact however far the growth took it);
- near_pairs gives the brute-force pairs and images, own images included, in its documented
  order (i, j, then the image with its last component slowest), with centres inside or outside
  the cell, on any grid.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hardpack.geometry.neighbours.grid import c_strides
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.md import _deforming_kernel as dk
from hardpack.md import _ellipsoid_deforming_kernel as edk
from hardpack.md import _ellipsoid_kernel as ek
from hardpack.md import maxwell_boltzmann
from hardpack.md._kernel import A_KE
from hardpack.md.deforming import EllipsoidDeformingSimulation, cell_grid

CELLS = {
    # name: (lattice H, columns the lattice vectors; particles; bounding radii range)
    "cubic": (6.0 * np.eye(3), 80, (0.3, 0.6)),
    "sheared": (np.array([[5.0, 3.7, 1.2], [0.0, 4.0, 2.9], [0.0, 0.0, 4.5]]), 60, (0.3, 0.7)),
    "small_sheared_2d": (2.0 * np.array([[1.0, 5.0], [0.0, 1.0]]), 5, (0.8, 1.3)),
    "small_3d": (2.5 * np.eye(3) + 0.4 * np.triu(np.ones((3, 3)), 1), 3, (1.3, 1.7)),
    "one_3d": (np.array([[2.0, 1.3, 0.4], [0.0, 1.8, 0.7], [0.0, 0.0, 2.2]]), 1, (1.2, 1.6)),
}
SEMIAXIS = 0.08  # small particles (no overlaps, few collisions) in large bounding spheres


def _images(H, reach, extra=2):
    """Every integer vector n with |n_k| <= extra + reach / h_k (all images within ``reach`` of
    two points of the cell, and more)."""
    heights = 1.0 / np.linalg.norm(np.linalg.inv(H), axis=1)
    span = (extra + np.ceil(reach / heights)).astype(int)
    return np.array(list(itertools.product(*[range(-k, k + 1) for k in span])))


def _simulation(name, seed=0):
    """Small random ellipsoids (ellipses) in the cell, velocities kT = 1, and per-particle skins
    that make the bounding radii uniform in the cell's range."""
    H, n, (rlo, rhi) = CELLS[name]
    d = H.shape[0]
    rng = np.random.default_rng(seed)
    images = _images(H, 4 * SEMIAXIS) @ H.T
    x = np.empty((0, d))
    while len(x) < n:  # centres farther apart than the particles' bounding diameter, images included
        y = rng.random(d) @ H.T
        sep = (x[:, None, :] + images[None, :, :] - y).reshape(-1, d)
        if np.all(np.linalg.norm(sep, axis=1) > 2.5 * SEMIAXIS * 1.5):
            x = np.vstack([x, y])
    axes = SEMIAXIS * np.column_stack([np.full(n, 1.5)] + [np.ones(n)] * (d - 1))
    if d == 3:
        q = rng.normal(size=(n, 4))
        orient = q / np.linalg.norm(q, axis=1)[:, None]
    else:
        orient = rng.uniform(0, 2 * np.pi, n)
    packing = Packing(x, lattice=H, shape=Ellipsoids(axes, orient))
    sim = EllipsoidDeformingSimulation(packing, maxwell_boltzmann(n, d, seed), np.zeros((n, 3 if d == 3 else 1)),
                                       0.0)
    cr = ek.columns(d)[2]
    skin = rng.uniform(rlo, rhi, n) - sim.P[:, cr]
    return sim, skin


def _window(sim, skin, n_cells=None, t_cap=0.0, kappa=0.0, cap=512):
    """One window of the kernel from the driver's arrays, as the driver sets it up, the semiaxes
    growing at the relative rate ``kappa``; t_cap = 0 stops it right after the complete build.
    Returns (nb, nn, cbits, M, iacc)."""
    n, d, H = sim.n, sim.d, sim.H
    Hinv = np.linalg.inv(H)
    cr = ek.columns(d)[2]
    rb = sim.P[:, cr] + skin
    reach = 2.0 * float(rb.max() + sim.P[:, cr].max() * kappa * t_cap) * 1.01  # the largest bounding sphere
    M = dk.image_ranges(H, reach)
    img, cbits = edk.padded_image_table(H, M)
    if n_cells is None:
        n_cells = cell_grid(H, 2.0 * float(rb.max()), n)[0]
    nb = np.zeros((n, cap), dtype=np.int64)
    acc = np.zeros(edk.N_ACC)
    acc[A_KE] = 0.5 * float(np.sum(sim.V * sim.V))
    iacc = np.zeros(edk.N_COUNTERS, dtype=np.int64)
    status = edk.run_events(
        sim.P, H, Hinv, M, img, cbits, np.linalg.norm(Hinv, axis=1), reach, n_cells, c_strides(n_cells), kappa,
        sim.eps_f, skin, sim.bs, nb, sim.nn, sim.mark, sim.cnt, sim.ep, sim.ec, sim.hkey, sim.heap, sim.hpos,
        np.empty(cap), np.empty(cap), np.empty(cap, dtype=np.int8), np.empty((cap, ek.PAIR_STATE)),
        np.zeros((d, d)), np.zeros((d, d)), acc, iacc, 10**9, t_cap)
    assert status == dk.DeformingStatus.DONE_TIME
    return nb, sim.nn.copy(), cbits, M, iacc


def _as_set(nb, nn, cbits, M):
    """{(i, j, n)} of packed lists (entries j << cbits | code, axis 0 fastest in the code)."""
    out = set()
    for i in range(nb.shape[0]):
        for e in nb[i, :nn[i]]:
            j, code = int(e) >> cbits, int(e) & ((1 << cbits) - 1)
            image = []
            for k in range(len(M)):
                image.append(code % (2 * int(M[k]) + 1) - int(M[k]))
                code //= 2 * int(M[k]) + 1
            out.add((i, j, tuple(image)))
    return out


def _positive(n):
    """The image of a pair +-n that is listed: n != 0 with its last non-zero component positive."""
    nz = np.flatnonzero(n)
    return len(nz) > 0 and n[nz[-1]] > 0


def _brute_force(H, bs):
    """{(i, j, n)}: j != i with |x_j + H n - x_i| < R_i + R_j (in both lists), and i's own images
    with |H n| < 2 R_i, n positive (:func:`_positive`)."""
    d = H.shape[0]
    x, r = bs[:, :d], bs[:, d]
    images = _images(H, 2 * r.max())
    shifts = images @ H.T
    out = set()
    for i in range(len(x)):
        dist = np.linalg.norm(x[None, :, :] + shifts[:, None, :] - x[i], axis=-1)  # (images, j)
        hit = dist < r[i] + r[None, :]
        for a, j in zip(*np.nonzero(hit)):
            if j != i or _positive(images[a]):
                out.add((i, int(j), tuple(int(v) for v in images[a])))
    return out


@pytest.mark.parametrize("name", sorted(CELLS))
def test_complete_build_is_the_brute_force_pairs(name):
    sim, skin = _simulation(name)
    p0 = sim.P.copy()
    nb, nn, cbits, M, _ = _window(sim, skin)
    truth = _brute_force(sim.H, sim.bs)
    assert _as_set(nb, nn, cbits, M) == truth
    assert sum(nn) == len(truth)  # no entry twice
    if name.startswith(("small", "one")):  # several images of one neighbour, own images
        assert len({(i, j) for i, j, _ in truth}) < len(truth)
        assert any(i == j for i, j, _ in truth)
    d = sim.d
    one = np.ones((1, d), dtype=np.int64)  # one cell (the grid prunes nothing) and fine cells
    for cells in (one, cell_grid(sim.H, 0.3 * float(sim.bs[:, d].max()), 10**6)[0]):
        sim.P[:] = p0
        nb1, nn1, _, _, _ = _window(sim, skin, cells)
        assert np.array_equal(nn1, nn) and np.array_equal(nb1, nb)


@pytest.mark.parametrize("name", sorted(CELLS))
def test_complete_build_equals_the_scan_in_order(name):
    sim, skin = _simulation(name, seed=1)
    nb, nn, cbits, M, _ = _window(sim, skin)
    # the exhaustive scan over all N bounding spheres and their image boxes, then the own images,
    # particle by particle (partners j < i): the lists the grid must reproduce entry for entry
    n, d, H = sim.n, sim.d, sim.H
    Hinv = np.linalg.inv(H)
    strides = np.cumprod(np.concatenate([[1], 2 * M[:-1] + 1])).astype(np.int64)
    m0 = int(np.prod(2 * M + 1))
    img, _ = edk.padded_image_table(H, M)
    reach = 2.0 * float(sim.bs[:, d].max()) * 1.01
    ref, rn = np.zeros_like(nb), np.zeros(n, dtype=np.int64)
    for i in range(n):
        assert dk.list_particle(i, i, sim.bs, H, Hinv, M, strides, ref, rn, m0, 1 << cbits,
                                np.linalg.norm(Hinv, axis=1), reach) == 0
        assert edk.list_self(i, sim.bs, img, m0, cbits, ref, rn) == 0
    assert np.array_equal(rn, nn) and np.array_equal(ref, nb)


@pytest.mark.parametrize("name", sorted(CELLS))
@pytest.mark.parametrize("grow", [False, True])
def test_lists_after_exits_are_the_brute_force_pairs(name, grow):
    # growing: the semiaxes end 5 (large cells) or 2 (small cells, where faster growth jams the
    # particles) times larger, so a rebuilt bounding sphere is larger than the complete build's
    kappa = (0.25 if name.startswith(("small", "one")) else 1.0) if grow else 0.0
    sim, skin = _simulation(name, seed=2)
    skin *= 0.5  # more exits
    p0 = sim.P.copy()
    nb, nn, cbits, M, iacc = _window(sim, skin, t_cap=4.0, kappa=kappa)
    assert iacc[dk.I_EXIT] >= 5 * sim.n  # every particle re-listed several times
    truth = _brute_force(sim.H, sim.bs)
    assert _as_set(nb, nn, cbits, M) == truth
    assert sum(nn) == len(truth)
    frac = sim.bs[:, :sim.d] @ np.linalg.inv(sim.H).T  # exits re-wrapped the centres
    assert np.all((frac > -1e-12) & (frac < 1 + 1e-12))
    p1 = sim.P.copy()
    one = np.ones((1, sim.d), dtype=np.int64)  # one cell and fine cells (the search range counts)
    for cells in (one, cell_grid(sim.H, 0.2 * float(sim.bs[:, sim.d].min()), 10**6)[0]):
        sim.P[:] = p0
        nb1, nn1, _, _, iacc1 = _window(sim, skin, cells, t_cap=4.0, kappa=kappa)
        assert np.array_equal(sim.P, p1) and np.array_equal(iacc1, iacc)
        assert np.array_equal(nn1, nn) and np.array_equal(nb1, nb)


def _brute_near_pairs(P, H, scale):
    """near_pairs by numpy over a box of images, in its order: (i, j, n_{d-1}, ..., n_0)."""
    d = H.shape[0]
    cr = ek.columns(d)[2]
    x, r = P[:, :d], P[:, cr]
    frac = x @ np.linalg.inv(H).T
    images = _images(H, 2 * scale * r.max(), extra=2 + int(np.ceil(np.ptp(frac, axis=0).max())))
    shifts = images @ H.T
    rows = []
    for i in range(len(x)):
        for j in range(i, len(x)):
            dist = np.linalg.norm(x[j] + shifts - x[i], axis=1)
            for a in np.flatnonzero(dist < scale * (r[i] + r[j])):
                if j != i or _positive(images[a]):
                    rows.append((i, j, *images[a][::-1]))
    rows.sort()
    rows = np.array(rows, dtype=np.int64).reshape(-1, 2 + d)
    return rows[:, 0], rows[:, 1], np.ascontiguousarray(rows[:, :1:-1])


@pytest.mark.parametrize("name", sorted(CELLS))
@pytest.mark.parametrize("unwrapped", [False, True])
def test_near_pairs_is_the_brute_force_enumeration(name, unwrapped):
    sim, _ = _simulation(name, seed=3)
    H, d, n = sim.H, sim.d, sim.n
    P = sim.P.copy()
    cr = ek.columns(d)[2]
    rng = np.random.default_rng(4)
    P[:, cr] = rng.uniform(*CELLS[name][2], n)  # bounding radii of the cell's range (the particles are small)
    if unwrapped:  # centres a few cells out and slightly off (as after a synchronisation)
        P[:, :d] += rng.integers(-2, 3, (n, d)) @ H.T + 1e-3 * rng.normal(size=(n, d))
    Hinv = np.linalg.inv(H)
    for scale in (1.0, 1.7):
        ref = _brute_near_pairs(P, H, scale)
        assert len(ref[0]) > 0
        if name.startswith(("small", "one")):
            assert np.any(ref[0] == ref[1])  # own images
        width = 2.0 * scale * float(P[:, cr].max())
        for n_cells in (cell_grid(H, width, n)[0], np.ones((1, d), dtype=np.int64),
                        cell_grid(H, 0.3 * width, 10**6)[0]):
            got = edk.near_pairs(P, H, Hinv, scale, n_cells, c_strides(n_cells))
            for a, b in zip(got, ref):
                assert np.array_equal(a, b)


@pytest.mark.parametrize("seed", [0, 2])
def test_fast_growth_in_a_small_cell_collides_with_the_far_image(seed):
    # the semiaxes grow 3x (kappa = 0.5 to t = 4): the pair in contact is then farther apart than
    # twice the bounding diameters of the window's start, and the collision must still find its
    # image (a filter on the start radii skipped it, the collision law saw a separating image, took
    # the event for a graze and the same collision was predicted again at one time: STALLED)
    sim, skin = _simulation("small_3d", seed=seed)
    skin *= 0.5
    kappa, t_cap = 0.5, 4.0
    _, _, _, _, iacc = _window(sim, skin, t_cap=t_cap, kappa=kappa)  # asserts DONE_TIME
    assert iacc[dk.I_COLL] > 0
    ek.synchronise(sim.P, t_cap, kappa)
    assert sim.packing().overlap_report().n_overlapping == 0
