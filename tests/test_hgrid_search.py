"""HGrid neighbour search (Ogarko ch. 2.1, Top-Down, Eqs. 2.1-2.5) and HGrid-accelerated RSA.

The reference is an independent exhaustive search: scipy's periodic cKDTree over all pairs within the
largest possible contact distance, filtered by the exact criterion |x_i - x_j| <= r_i + r_j + skin.
The HGrid must return exactly the same set of pairs, each once.
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from hardpack.distributions import LogNormal, uniform_size, uniform_volume
from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume
from hardpack.hgrid import search as hs
from hardpack.hgrid.rsa import random_sequential_addition


def reference_pairs(x, r, box, skin):
    """Exhaustive periodic search with cKDTree (minimum image; box >= 3 contact ranges)."""
    tree = cKDTree(hs.wrap(x, box), boxsize=box)
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


@pytest.mark.parametrize(
    "dist, d, n_levels, skin",
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
def test_same_pairs_as_exhaustive_search(dist, d, n_levels, skin):
    x, r, box = random_overlapping(dist, 8000 if d < 4 else 1500, 0.3, d, seed=7)
    res = hs.neighbour_pairs(x, r, box, skin=skin, n_levels=n_levels)
    got = list(zip(res.i.tolist(), res.j.tolist()))
    assert len(got) == len(set(got)), "a pair was reported twice"
    assert np.all(res.i < res.j)
    ref = reference_pairs(x, r, box, skin)
    assert len(ref) > 100  # the comparison is not vacuous
    assert set(got) == ref
    if n_levels is None:
        assert res.grid.n_levels > 1


def test_hgrid_does_far_less_work_than_single_level():
    """UV omega = 20 at phi = 0.3: the single-level grid tests O(m_1) ~ 1e3 pairs per particle, the HGrid
    O(10) (Eq. 2.7 and the cost model, ch. 2.2); same pairs."""
    x, r, box = random_overlapping(uniform_volume(20.0), 8000, 0.3, 3, seed=3)
    multi = hs.neighbour_pairs(x, r, box)
    single = hs.neighbour_pairs(x, r, box, n_levels=1)
    assert np.array_equal(multi.i, single.i) and np.array_equal(multi.j, single.j)
    assert multi.distance_tests < single.distance_tests / 20


def test_search_box_of_figure_2_1():
    """Fig. 2.1 (L949-961): 2-D, s_1 = 3; particle B (r = 4) at (10.3, 14.4) searches level 1 with
    beta = r_B + s_1/2 = 5.5 (Eq. 2.4): cells (1, 2)..(5, 6). The caption's start (1, 3) contradicts
    the equation (a level-1 particle at y in [8.9, 9) can touch B), as note 002 sec. 1.2 explains."""
    lo, hi, full = np.empty(2, np.int64), np.empty(2, np.int64), np.empty(2, np.bool_)
    hs._box_range(np.array([10.3, 14.4]), 4.0 + 1.5, np.array([300.0, 300.0]), np.array([[100, 100]]), 0, lo, hi, full)
    assert lo.tolist() == [1, 2] and hi.tolist() == [5, 6] and not full.any()


def test_levels_follow_insertion_rule():
    """Each particle's level has the smallest cell size >= its (skin-inflated) diameter (Eq. 2.3), and
    the actual cell lengths are never smaller than the nominal ones."""
    r = uniform_volume(20.0).sample(20000)
    box = np.full(3, (ball_volume(r, 3).sum() / 0.4) ** (1 / 3))
    grid = hs.plan(r, box, skin=0.3)
    sizes = grid.assignment.cell_sizes
    assert np.array_equal(grid.level, np.searchsorted(sizes, (2 * r + 0.3) * (1 - 1e-15)))
    assert np.all(grid.cell_length >= sizes[:, None] * (1 - 1e-12))
    assert np.allclose(grid.reach, [r[grid.level == h].max() for h in range(grid.n_levels)])


def test_forward_rows_make_a_half_stencil():
    """The forward rows (3 cells along axis 0 each) plus the next cell along axis 0: (3^d - 1)/2 offsets,
    and with their negatives every non-zero neighbour offset exactly once (L2334-2337)."""
    for d in (2, 3, 4):
        rows = hs.forward_rows(d)
        offsets = [(1,) + (0,) * (d - 1)] + [(dx,) + tuple(row) for row in rows.tolist() for dx in (-1, 0, 1)]
        assert len(offsets) == len(set(offsets)) == (3**d - 1) // 2
        both = set(offsets) | {tuple(-v for v in o) for o in offsets}
        assert len(both) == 3**d - 1


def test_refuses_bad_input():
    r = np.ones(10)
    x = np.random.default_rng(0).random((10, 3)) * 7
    with pytest.raises(InvalidInputError, match="3 top-level cells"):
        hs.neighbour_pairs(x, r, np.full(3, 5.9))
    with pytest.raises(InvalidInputError, match="orthorhombic"):
        hs.neighbour_pairs(x, r, np.array([[7.0, 1.0, 0], [0, 7.0, 0], [0, 0, 7.0]]))
    with pytest.raises(InvalidInputError, match="radii"):
        hs.neighbour_pairs(x, -r, np.full(3, 7.0))
    with pytest.raises(InvalidInputError, match="skin"):
        hs.neighbour_pairs(x, r, np.full(3, 7.0), skin=-1.0)
    grid = hs.plan(r, np.full(3, 7.0))
    with pytest.raises(InvalidInputError, match="plan"):
        hs.neighbour_pairs(x, r, np.full(3, 7.0), skin=0.1, grid=grid)


def test_rsa_places_everything_without_overlap():
    """HGrid RSA of UV omega = 20 at phi = 0.5 (largest first): no pair closer than contact, but many
    near contact (RSA is dense here)."""
    r = uniform_volume(20.0).sample(20000, np.random.default_rng(2))
    box = np.full(3, (ball_volume(r, 3).sum() / 0.5) ** (1 / 3))
    x = random_sequential_addition(r, box, seed=5)
    assert np.all((x >= 0) & (x < box))
    assert len(hs.neighbour_pairs(x, r, box)) == 0  # the search itself is checked against cKDTree above
    assert len(hs.neighbour_pairs(x, r, box, skin=0.05)) > 1000
    again = random_sequential_addition(r, box, seed=5)
    assert np.array_equal(x, again)


def test_rsa_refuses_above_saturation():
    r = np.ones(400)
    box = np.full(3, (ball_volume(r, 3).sum() / 0.45) ** (1 / 3))  # monodisperse RSA saturates at 0.384
    with pytest.raises(InvalidInputError, match="saturation"):
        random_sequential_addition(r, box, seed=1, max_trials=2000)
