"""Hierarchical levels by Ogarko's rules (dissertation, Sec. 2.1.2-2.1.3 and the appendix of ch. 2.1)."""

import numpy as np
import pytest

from hardpack.distributions import bidisperse, uniform_size, uniform_volume
from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import (
    assign_levels,
    assign_with_threshold,
    build_grid,
    geometric_levels,
    insertion_levels,
    optimal_levels,
)


def system(dist, n=125_001, nu=0.62, d=3):
    """Benchmark systems of Ogarko 2014, Sec. 2.1.4: N = 125001 systematic-sampled radii at nu = 0.62."""
    radii = dist.sample(n)
    volume = np.sum(4 / 3 * np.pi * radii**3) / nu
    return radii, volume


@pytest.fixture(scope="module")
def uv50():
    return system(uniform_volume(50.0))


def test_optimal_number_of_levels_uv50(uv50):
    """UV, omega = 50: ONL = 7 from L (m + K) with K = 0.3 (Ogarko 2014, Sec. 2.1.3); m_h equal within +-2 % at L = 7
    (the spread stated with dm = 1e-3 in the appendix of Ogarko 2014, ch. 2.1)."""
    best = optimal_levels(*uv50, d=3, K=0.3)
    assert best.n_levels == 7
    m_h = best.m_per_level
    assert (m_h.max() - m_h.min()) / (m_h.max() + m_h.min()) < 0.02  # +-2 % about the mid-range


def test_optimal_number_of_levels_us50():
    """US, omega = 50: the measured optimum is L = 3 (Ogarko 2014, Sec. 2.1.4); Eq. 2.7 predicts the same."""
    assert optimal_levels(*system(uniform_size(50.0)), d=3, K=0.3).n_levels == 3


def test_assignment_rules(uv50):
    radii, volume = uv50
    a = assign_levels(radii, volume, 3, 5)
    assert a.n_levels == 5
    # insertion rule h(p) = min{h : s_h >= 2 r_p} (Eq. 2.3) with s_h the largest diameter on level h
    assert np.array_equal(a.level, np.searchsorted(a.cell_sizes, 2 * radii * (1 - 1e-15)))
    assert a.cell_sizes[-1] == pytest.approx(2 * radii.max())
    # no level exceeds the threshold (Eq. 2.8) except through its first particle, and m is the smallest
    # threshold that gives 5 levels: slightly less needs more levels
    assert np.all(a.m_per_level <= a.m * (1 + 1e-12))
    assert assign_with_threshold(radii, volume, 3, a.m).n_levels == 5
    assert assign_with_threshold(radii, volume, 3, a.m * (1 - 1e-9)).n_levels > 5


def test_single_level_is_linked_cell(uv50):
    radii, volume = uv50
    a = assign_levels(radii, volume, 3, 1)
    assert a.n_levels == 1 and np.all(a.level == 0)
    assert a.m == pytest.approx(radii.size * (2 * radii.max()) ** 3 / volume)


def test_equal_radii_share_a_level():
    """A bidisperse packing has at most two levels, however small m is (cells of equal size would be
    one level by the insertion rule)."""
    radii = bidisperse(1.4, 0.5).sample(1000)
    a = assign_levels(radii, 2000.0, 3, 10)
    assert a.n_levels == 2
    assert set(a.level[radii == radii.min()]) == {0} and set(a.level[radii == radii.max()]) == {1}


def test_two_dimensional_and_order_independent():
    rng = np.random.default_rng(4)
    radii = uniform_volume(10.0).sample(5000)
    shuffled = rng.permutation(radii)
    a = assign_levels(radii, 5000.0, 2, 4)
    b = assign_levels(shuffled, 5000.0, 2, 4)
    assert np.array_equal(a.cell_sizes, b.cell_sizes)
    order = np.argsort(shuffled, kind="stable")
    assert np.array_equal(b.level[order], a.level)


def test_refusals():
    with pytest.raises(InvalidInputError):
        assign_levels([1.0, -1.0], 10.0, 3, 2)
    with pytest.raises(InvalidInputError):
        assign_levels([1.0, 2.0], 0.0, 3, 2)
    with pytest.raises(InvalidInputError):
        assign_levels([1.0, 2.0], 10.0, 3, 0)
    with pytest.raises(InvalidInputError):
        optimal_levels([1.0, 2.0], 10.0, 3, K=-1)
    with pytest.raises(InvalidInputError):
        assign_with_threshold([1.0, 2.0], 10.0, 3, np.nan)


def test_every_rule_assigns_by_the_insertion_rule(uv50):
    """Whatever the cell sizes, a particle lives on the lowest level whose cell size is at least its
    diameter (Eq. 2.3), and each level's cell size is the largest diameter on it."""
    radii, volume = uv50
    for a in (optimal_levels(radii, volume, 3), assign_levels(radii, volume, 3, 4),
              geometric_levels(radii, volume, 3, 2.0), geometric_levels(radii, volume, 3, 3.7)):
        assert np.array_equal(a.level, insertion_levels(radii, a.cell_sizes))
        assert np.array_equal(a.cell_sizes, [2 * radii[a.level == h].max() for h in range(a.n_levels)])


def test_geometric_cell_sizes():
    """Cell sizes s_{h+1} = q s_h (Eq. 2.43) from the smallest diameter: level h holds the radii in
    [r_min q^h, r_min q^(h+1)), the levels nobody occupies dropped (here [4, 8))."""
    radii = np.array([1.0, 1.5, np.nextafter(2.0, 0.0), 2.0, 3.9, 8.0, 15.9, 16.0])
    a = geometric_levels(radii, 1e4, 3, 2.0)
    assert a.level.tolist() == [0, 0, 0, 1, 1, 2, 2, 3]
    assert a.cell_sizes.tolist() == [2 * np.nextafter(2.0, 0.0), 7.8, 31.8, 32.0]
    r = uniform_volume(50.0).sample(20000)
    classes = np.floor(np.log(r / r.min()) / np.log(2.0))
    assert np.array_equal(geometric_levels(r, 1e6, 3, 2.0).level, np.unique(classes, return_inverse=True)[1])
    assert geometric_levels(np.full(10, 0.5), 10.0, 3, 2.0).n_levels == 1
    with pytest.raises(InvalidInputError, match="ratio"):
        geometric_levels(r, 1e6, 3, 1.0)


def test_grid_uses_the_optimal_number_of_levels(uv50):
    """The static grid of the pair search takes Ogarko's ONL (Eq. 2.7) for its interaction radii, and
    a single level for equal ones."""
    radii, volume = uv50
    side = volume ** (1 / 3)
    frac = np.random.default_rng(1).random((radii.size, 3))
    grid = build_grid(frac, np.eye(3) * side, radii)
    assert grid.n_levels == 7
    assert np.array_equal(grid.level, optimal_levels(radii, volume, 3).level)
    assert build_grid(frac, np.eye(3) * side, np.full(radii.size, 2.0)).n_levels == 1


def test_md_engine_levels_are_geometric():
    """The MD engine's bounding-sphere grid: geometric cell sizes of ratio 2 over the bounding radii
    (Eq. 2.43), each level capped at its largest bounding radius (plus head room)."""
    from hardpack.md.engine import GRID_HEADROOM, LEVEL_RATIO, Engine

    rng = np.random.default_rng(3)
    radii = uniform_volume(10.0).sample(600, rng)
    box = np.full(3, (np.sum(4 / 3 * np.pi * radii**3) / 0.2) ** (1 / 3))
    eng = Engine(rng.random((600, 3)) * box, rng.normal(size=(600, 3)), radii, box)
    eng._new_bounds(0.2)
    bound = radii + 0.2 * eng.sfac
    expected = geometric_levels(bound, float(np.prod(box)), 3, LEVEL_RATIO)
    assert eng.ncl.shape[0] == expected.n_levels > 1
    assert np.array_equal(eng.lvl, expected.level)
    np.testing.assert_array_equal(eng.rcap, np.minimum(0.5 * expected.cell_sizes * GRID_HEADROOM, box[0] / 4))
