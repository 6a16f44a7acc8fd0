"""Hierarchical-grid neighbour search (Ogarko, dissertation, Sec. 2.1.2: Top-Down, Eqs. 2.1-2.5) and RSA
on the grid.

The reference is an independent exhaustive search: scipy's periodic cKDTree over all pairs within the
largest possible contact distance, filtered by the exact criterion |x_i - x_j| <= r_i + r_j + skin.
The grid must return exactly the same set of pairs, each once.
"""

import itertools

import numpy as np
import pytest
from scipy.spatial import cKDTree

from hardpack.distributions import LogNormal, uniform_size, uniform_volume
from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import build_grid, grid_pairs, insertion_levels, random_sequential_addition
from hardpack.geometry.neighbours.grid import points_within, search_range


def wrap(x, box):
    return x - box * np.floor(x / box)


def reference_pairs(x, r, box, skin):
    """Exhaustive periodic search with cKDTree (minimum image; box >= 3 contact ranges)."""
    tree = cKDTree(wrap(x, box), boxsize=box)
    cand = tree.query_pairs(2 * r.max() + skin + 1e-9, output_type="ndarray")
    dx = x[cand[:, 1]] - x[cand[:, 0]]
    dx -= box * np.round(dx / box)
    keep = np.sqrt(np.sum(dx**2, axis=1)) <= r[cand[:, 0]] + r[cand[:, 1]] + skin
    return set(map(tuple, np.sort(cand[keep], axis=1).tolist()))


def random_overlapping(dist, n, phi, d, seed):
    """Uniformly random centres (overlaps allowed), so contacts at skin 0 are plentiful."""
    rng = np.random.default_rng(seed)
    r = dist.sample(n, rng)
    rng.shuffle(r)
    side = (ball_volume(r, d).sum() / phi) ** (1 / d)
    box = side * np.linspace(1.0, 1.3, d)  # unequal sides
    box *= (side**d / np.prod(box)) ** (1 / d)
    return rng.random((n, d)) * box - 0.3 * box, r, box  # some centres outside [0, box): wrapping tested


def search(x, r, box, skin=0.0, levels=None):
    """The grid's pairs with |x_i - x_j| <= r_i + r_j + skin (interaction radii r + skin / 2), the exact
    criterion applied to its candidates; returns (pairs, grid, raw search result)."""
    grid = build_grid(wrap(x, box) / box, np.diag(box), r + 0.5 * skin, levels=levels)
    res = grid_pairs(grid)
    dx = grid.x[res.j] - grid.x[res.i] + res.shift * box
    keep = np.sqrt(np.sum(dx**2, axis=1)) <= r[res.i] + r[res.j] + skin
    return list(zip(res.i[keep].tolist(), res.j[keep].tolist())), grid, res


@pytest.mark.parametrize(
    "dist, d, levels, skin",
    [
        (uniform_volume(20.0), 3, None, 0.0),
        (uniform_volume(20.0), 3, 1, 0.0),
        (uniform_volume(20.0), 3, 4, 0.5),
        (uniform_size(10.0), 3, None, 0.2),
        (LogNormal(0.6), 3, None, 0.0),
        (uniform_volume(10.0), 2, None, 0.1),
        (uniform_size(5.0), 4, None, 0.0),
    ],
    ids=["UV20", "UV20-single", "UV20-L4-skin", "US10-skin", "LN0.6", "2D-UV10", "4D-US5"],
)
def test_same_pairs_as_exhaustive_search(dist, d, levels, skin):
    x, r, box = random_overlapping(dist, 8000 if d < 4 else 1500, 0.3, d, seed=7)
    got, grid, res = search(x, r, box, skin, levels)
    assert len(got) == len(set(got)), "a pair was reported twice"
    assert np.all(res.i < res.j)
    ref = reference_pairs(x, r, box, skin)
    assert len(ref) > 100  # the comparison is not vacuous
    assert set(got) == ref
    if levels is None:
        assert grid.n_levels > 1


def test_hgrid_does_far_less_work_than_single_level():
    """UV omega = 20 at phi = 0.3: the single-level grid tests O(m_1) ~ 1e3 pairs per particle, the HGrid
    O(10) (Eq. 2.7 and the cost model, ch. 2.2); same pairs."""
    x, r, box = random_overlapping(uniform_volume(20.0), 8000, 0.3, 3, seed=3)
    multi, _, multi_res = search(x, r, box)
    single, _, single_res = search(x, r, box, levels=1)
    assert multi == single
    assert multi_res.distance_tests < single_res.distance_tests / 20


def test_search_box_of_figure_2_1():
    """Fig. 2.1: 2-D, s_1 = 3; particle B (r = 4) at (10.3, 14.4) searches level 1 with
    beta = r_B + s_1/2 = 5.5 (Eq. 2.4): cells (1, 2)..(5, 6). The caption's start (1, 3) contradicts
    the equation (a level-1 particle at y in [8.9, 9) can touch B)."""
    lo, hi = np.empty(2, np.int64), np.empty(2, np.int64)
    box = np.array([300.0, 300.0])
    search_range(np.array([10.3, 14.4]) / box, 4.0 + 1.5, 1.0 / box, np.array([[100, 100]]), 0, lo, hi)
    assert lo.tolist() == [1, 2] and hi.tolist() == [5, 6]


def test_levels_follow_insertion_rule():
    """Each particle's level has the smallest cell size >= its (skin-inflated) diameter (Eq. 2.3), and
    the actual cell widths are never smaller than the nominal ones."""
    r = uniform_volume(20.0).sample(20000)
    box = np.full(3, (ball_volume(r, 3).sum() / 0.4) ** (1 / 3))
    grid = build_grid(np.zeros((r.size, 3)), np.diag(box), r + 0.15)
    sizes = grid.levels.cell_sizes
    assert grid.n_levels > 1
    assert np.array_equal(grid.level, insertion_levels(r + 0.15, sizes))
    assert np.array_equal(grid.level, np.searchsorted(sizes, (2 * r + 0.3) * (1 - 1e-15)))
    assert np.all(box[None, :] / grid.n_cells >= sizes[:, None] * (1 - 1e-12))
    assert np.allclose(grid.level_reach, [r[grid.level == h].max() + 0.15 for h in range(grid.n_levels)])


def test_refuses_bad_input():
    r = np.ones(10)
    s = np.random.default_rng(0).random((10, 3))
    with pytest.raises(InvalidInputError, match="interaction radii"):
        build_grid(s, np.eye(3) * 7, -r)
    levels = build_grid(s, np.eye(3) * 7, r).levels
    with pytest.raises(InvalidInputError, match="assign the levels again"):
        build_grid(s[:5], np.eye(3) * 7, r[:5], levels=levels)
    with pytest.raises(InvalidInputError, match="in \\[0, 1\\) along the periodic axes"):
        build_grid(s + 1.0, np.eye(3) * 7, r)
    with pytest.raises(InvalidInputError, match="periodic must be 3 booleans"):
        build_grid(s, np.eye(3) * 7, r, periodic=[True, False])
    build_grid(s + [0.0, 0.0, 1.0], np.eye(3) * 7, r, periodic=np.array([True, True, False]))  # not wrapped


def test_rsa_places_everything_without_overlap():
    """RSA of UV omega = 20 at phi = 0.5 (largest first), checked by cKDTree: no pair closer than contact,
    but many near contact (RSA is dense here); the same seed gives the same packing, another seed another."""
    r = uniform_volume(20.0).sample(20000, np.random.default_rng(2))
    box = np.full(3, (ball_volume(r, 3).sum() / 0.5) ** (1 / 3))
    x = random_sequential_addition(r, box, seed=5)
    assert np.all((x >= 0) & (x < box))
    assert len(reference_pairs(x, r * (1 - 1e-12), box, 0.0)) == 0
    assert len(reference_pairs(x, r, box, 0.05)) > 1000
    assert np.array_equal(x, random_sequential_addition(r, box, seed=5))
    assert not np.array_equal(x, random_sequential_addition(r, box, seed=6))


def test_rsa_refuses_above_saturation():
    r = np.ones(400)
    box = np.full(3, (ball_volume(r, 3).sum() / 0.45) ** (1 / 3))  # monodisperse RSA saturates at 0.384
    with pytest.raises(InvalidInputError, match="saturation"):
        random_sequential_addition(r, box, seed=1, max_trials=2000)


@pytest.mark.parametrize("d", [2, 3])
def test_points_within_windows_match_an_exhaustive_search_over_images(d):
    """Window members of a sheared periodic cell, radius beyond half the cell (several images of a
    point in one window): the grid finds exactly the (point, image) pairs an exhaustive search over
    lattice images finds, with their distances."""
    rng = np.random.default_rng(3)
    lattice = np.eye(d) * 4.0
    lattice[0, 1] = 1.5
    frac = rng.random((60, d))
    x = frac @ lattice.T
    centres = rng.random((25, d))
    radius = 2.6
    grid = build_grid(frac, lattice, np.full(len(frac), radius / 2), per_cell=2)
    start, point, dist = points_within(centres, grid.x, grid.lattice, 1.0 / grid.heights, grid.n_cells,
                                       grid.strides, grid.cell_offset, grid.cell_start, grid.order, radius)
    images = np.array(list(itertools.product(range(-3, 4), repeat=d))) @ lattice.T
    for m, c in enumerate(centres @ lattice.T):
        r = np.linalg.norm(x[:, None, :] + images[None] - c, axis=2)
        want = sorted((j, round(v, 12)) for j, v in zip(*np.nonzero(r < radius)[:1], r[r < radius]))
        got = sorted((j, round(v, 12)) for j, v in zip(point[start[m]:start[m + 1]], dist[start[m]:start[m + 1]]))
        assert got == want
    assert start[-1] > len(centres) * len(frac) * 0.3  # a real test: windows hold many points
