"""Equal-particles-per-cell level assignment (Ogarko ch. 2.1, Eqs. 2.6-2.8, Appendix L1492-1532)."""

import numpy as np
import pytest

from hardpack.distributions import bidisperse, uniform_size, uniform_volume
from hardpack.errors import InvalidInputError
from hardpack.hgrid.levels import assign_levels, assign_with_threshold, optimal_levels


def system(dist, n=125_001, nu=0.62, d=3):
    """ch. 2.1 benchmark systems (L1214-1240): N = 125001 systematic-sampled radii at nu = 0.62."""
    radii = dist.sample(n)
    volume = np.sum(4 / 3 * np.pi * radii**3) / nu
    return radii, volume


@pytest.fixture(scope="module")
def uv50():
    return system(uniform_volume(50.0))


def test_optimal_number_of_levels_uv50(uv50):
    """UV, omega = 50: ONL = 7 from L (m + K) with K = 0.3 (L1199-1204); m_h equal within +-2 % at L = 7
    (the text's spread with dm = 1e-3, L1529-1532)."""
    best = optimal_levels(*uv50, d=3, K=0.3)
    assert best.n_levels == 7
    m_h = best.m_per_level
    assert (m_h.max() - m_h.min()) / (m_h.max() + m_h.min()) < 0.02  # +-2 % about the mid-range


def test_optimal_number_of_levels_us50():
    """US, omega = 50: the measured optimum is L = 3 (L1360-1363); Eq. 2.7 predicts the same."""
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
