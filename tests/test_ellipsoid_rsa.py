"""Random sequential addition of ellipsoids and ellipses (hardpack.initial.random_ellipsoid_packing):
the target volume fraction without overlaps (checked by the packing model and by the independent
algebraic separation condition of Wang, Wang & Kim 2001), tiny boxes where particles meet their own
images, reproducibility, isotropic orientations, and refusals."""

import math

import numpy as np
import pytest
from test_ellipsoid_overlap_verdict import separated_algebraic

from hardpack import InvalidInputError
from hardpack.geometry.contact import inverse_shapes
from hardpack.geometry.ellipsoid_stats import nematic_order
from hardpack.geometry.neighbours import pairs_within
from hardpack.initial import random_ellipsoid_packing

BINARY = {2: [[1.4, 0.7]] * 100 + [[1.0, 0.5]] * 200, 3: [[0.5, 0.5, 1.0]] * 100 + [[0.3, 0.6, 0.9]] * 200}


def assert_disjoint_by_the_algebraic_condition(packing):
    pairs = pairs_within(packing)  # bounding spheres that meet, every image
    inv = inverse_shapes(packing.shape.semiaxes, packing.shape.orientations.reshape(packing.n_particles, -1))
    x = np.linalg.inv(inv)
    zeros = np.zeros((len(pairs), packing.dim))
    assert separated_algebraic(x[pairs.i], zeros, x[pairs.j], pairs.separation).all()
    return len(pairs)


@pytest.mark.parametrize("d", [2, 3])
def test_rsa_reaches_the_target_without_overlap(d):
    packing = random_ellipsoid_packing(300, BINARY[d], 0.25, seed=1)
    assert packing.phi == pytest.approx(0.25, rel=1e-12) and packing.n_particles == 300
    assert packing.overlap_report().n_overlapping == 0
    assert assert_disjoint_by_the_algebraic_condition(packing) > 30  # many bounding spheres meet
    bound = packing.shape.bounding_radii
    assert (np.diff(bound) <= 0).all()  # largest first


@pytest.mark.parametrize("d", [2, 3])
def test_tiny_boxes_check_every_image(d):
    """A needle alone or in pairs in a box narrower than four bounding radii: every image counts."""
    needle = [0.1, 1.0] if d == 2 else [0.2, 0.2, 1.0]
    for n in (1, 2, 3):
        for seed in range(10):
            packing = random_ellipsoid_packing(n, needle, 0.15, seed=seed)
            assert packing.lattice[0, 0] < 4 * max(needle)
            assert_disjoint_by_the_algebraic_condition(packing)


def test_rsa_is_reproducible_and_seed_dependent():
    a = random_ellipsoid_packing(50, [0.4, 0.4, 1.0], 0.2, seed=3)
    b = random_ellipsoid_packing(50, [0.4, 0.4, 1.0], 0.2, seed=3)
    c = random_ellipsoid_packing(50, [0.4, 0.4, 1.0], 0.2, seed=4)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.shape.orientations, b.shape.orientations)
    assert not np.array_equal(a.positions, c.positions)


@pytest.mark.parametrize("d", [2, 3])
def test_orientations_are_isotropic(d):
    n = 2000
    packing = random_ellipsoid_packing(n, [1.0, 0.4] if d == 2 else [0.4, 0.4, 1.0], 0.05, seed=5)
    s, _ = nematic_order(packing)
    assert s * math.sqrt(n) < 4
    assert np.abs(packing.fractional().mean(axis=0) - 0.5).max() < 4 * math.sqrt(1 / 12 / n)


@pytest.mark.parametrize("kwargs,message", [
    (dict(n=0), "n must be a positive integer"),
    (dict(semiaxes=[1.0]), "semiaxes must be positive, of shape"),
    (dict(semiaxes=[[1.0, 0.5]] * 3), r"shape \(d,\) or \(10, d\)"),
    (dict(semiaxes=[1.0, -0.5]), "semiaxes must be positive"),
    (dict(phi=1.2), "phi must be in"),
    (dict(seed=-1), "seed must be a non-negative integer"),
    (dict(box_shape=[1.0]), "box_shape must be 2 positive numbers"),
    (dict(phi=0.85, max_trials=200), "could not place ellipsoid .* lower one"),
])
def test_bad_requests_are_refused(kwargs, message):
    args = dict(n=10, semiaxes=[1.0, 0.5], phi=0.2, seed=0) | kwargs
    with pytest.raises(InvalidInputError, match=message):
        random_ellipsoid_packing(**args)
