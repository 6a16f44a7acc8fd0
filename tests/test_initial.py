"""Random sequential addition start configurations."""

import numpy as np
import pytest

from hardpack import InvalidInputError
from hardpack.distributions import bidisperse, monodisperse, uniform_volume
from hardpack.initial import random_packing


@pytest.mark.parametrize("d, phi", [(2, 0.4), (3, 0.25), (4, 0.15), (5, 0.08), (6, 0.04)])
def test_rsa_reaches_target_without_overlap(d, phi):
    p = random_packing(400, d, monodisperse(), phi, seed=1)
    assert p.phi == pytest.approx(phi, rel=1e-12)
    assert p.dim == d and p.n_particles == 400
    # construction already refuses overlaps; check the strict version too (no contact at all)
    assert p.overlap_report(tol=0.0).n_overlapping == 0


def test_rsa_is_reproducible_and_seed_dependent():
    a = random_packing(200, 3, uniform_volume(5), 0.2, seed=3)
    b = random_packing(200, 3, uniform_volume(5), 0.2, seed=3)
    c = random_packing(200, 3, uniform_volume(5), 0.2, seed=4)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.radii, b.radii)
    assert not np.array_equal(a.positions, c.positions)


def test_rsa_positions_are_uniform():
    """Mean fractional coordinate 1/2 with standard error 1/sqrt(12 N): a 5-sigma bound."""
    p = random_packing(5000, 3, monodisperse(), 0.1, seed=2)
    s = p.fractional()
    assert np.all(np.abs(s.mean(axis=0) - 0.5) < 5 / np.sqrt(12 * 5000))


def test_species_labels_for_mixtures():
    p = random_packing(100, 2, bidisperse(1.4, 0.5), 0.3, seed=1)
    assert set(p.species) == {0, 1}
    assert np.all(p.radii[p.species == 1] > p.radii[p.species == 0])


def test_rsa_refuses_impossible_targets():
    with pytest.raises(InvalidInputError, match="RSA saturates.*near 0.384"):
        random_packing(300, 3, monodisperse(), 0.45, seed=1, max_trials=2000)
    with pytest.raises(InvalidInputError, match="phi must be in"):
        random_packing(10, 3, monodisperse(), 1.2, seed=1)
    with pytest.raises(InvalidInputError, match="smaller than two largest diameters"):
        random_packing(2, 3, monodisperse(), 0.3, seed=1)
    with pytest.raises(InvalidInputError, match="d must be an integer"):
        random_packing(10, 0, monodisperse(), 0.1, seed=1)
