"""Near pairs of ellipsoid packings (hardpack.geometry.ellipsoid_pairs): every pair with
mu <= 1 + rel_gap is found, against a brute-force search over all pairs and images."""

import itertools

import numpy as np
import pytest

from hardpack import InvalidInputError, Packing
from hardpack.geometry import Ellipsoids
from hardpack.geometry.contact import inverse_shapes, pw_contact
from hardpack.geometry.ellipsoid_pairs import potential_pairs


def random_ellipsoids(d, n=40, box=4.0, seed=0):
    rng = np.random.default_rng(seed)
    axes = rng.uniform(0.1, 0.8, (n, d))
    if d == 3:
        orient = rng.normal(size=(n, 4))
        orient /= np.linalg.norm(orient, axis=1)[:, None]
    else:
        orient = rng.uniform(-np.pi, np.pi, n)
    lattice = box * np.eye(d)
    lattice[0, 1] = 0.7  # a sheared cell
    return Packing(rng.uniform(0, box, (n, d)), lattice=lattice, shape=Ellipsoids(axes, orient),
                   allow_overlap=True)


def brute_force(packing, rel_gap):
    """{(i, j, image): mu} over every pair and the images -2..2 with mu <= 1 + rel_gap."""
    x = packing.positions
    inv = inverse_shapes(packing.shape.semiaxes, packing.shape.orientations.reshape(packing.n_particles, -1))
    found = {}
    for shift in itertools.product(range(-2, 3), repeat=packing.dim):
        for i in range(packing.n_particles):
            for j in range(i, packing.n_particles):
                if i == j and shift <= (0,) * packing.dim:
                    continue
                r = x[j] + packing.lattice @ np.array(shift) - x[i]
                zeta = pw_contact(r, inv[i], inv[j], 0.5)[0]
                if np.sqrt(zeta + 1) <= 1 + rel_gap:
                    found[(i, j)] = found.get((i, j), 0) + 1
    return found


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("rel_gap", [0.0, 0.3])
def test_every_pair_within_the_gap_is_found(d, rel_gap):
    packing = random_ellipsoids(d).wrapped()
    near = potential_pairs(packing, rel_gap)
    close = near.subset(near.mu <= 1 + rel_gap)
    counted = {}
    for i, j in zip(close.pairs.i, close.pairs.j):
        counted[(int(i), int(j))] = counted.get((int(i), int(j)), 0) + 1
    expected = brute_force(packing, rel_gap)
    assert len(expected) > 10 and counted == expected


def test_spheres_are_refused():
    with pytest.raises(InvalidInputError, match="needs a packing of ellipsoids"):
        potential_pairs(Packing([[0.0, 0.0]], [0.5], np.eye(2) * 3))
