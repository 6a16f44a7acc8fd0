"""The pair list of the neighbour layer against an independent brute-force search.

The reference loops over every pair i <= j and every lattice image n that can matter (|n_k| <=
range / h_k + 1, h_k the perpendicular widths of the cell) and keeps |x_j + L n - x_i| within range: O(N^2)
per image, no cells, no levels. Cells are random and sheared, radii polydisperse up to omega = 50 (several
hierarchical levels), and small cells put a particle next to its own images. The packing model decides what
is searched: images only along the periodic axes of the boundary (none across hard walls, none in a
spherical container), and the bounding radii of the shape (ellipsoids).
"""

import itertools

import numpy as np
import pytest

from hardpack.distributions import uniform_size, uniform_volume
from hardpack.geometry import HardWalls, Packing, SphericalContainer, pairs_within
from hardpack.geometry.balls import ball_volume
from hardpack.geometry.neighbours import build_grid
from hardpack.geometry.shapes import Ellipsoids


def brute_force(packing, rel_gap=0.0, cutoff=None):
    """{(i, j, n): distance} of every pair i < j, and i == j with n lexicographically positive; images n
    along the periodic axes only, r the bounding radii."""
    lat = packing.lattice
    x = packing.fractional() @ lat.T
    r = packing.shape.bounding_radii
    reach = cutoff if cutoff is not None else (1.0 + rel_gap) * 2.0 * r.max()
    heights = 1.0 / np.linalg.norm(np.linalg.inv(lat), axis=1)
    ks = np.where(packing.boundary.periodic_axes(packing.dim), np.ceil(reach / heights).astype(int) + 1, 0)
    upper = np.triu(np.ones((len(r), len(r)), dtype=bool))
    limit = cutoff if cutoff is not None else (1.0 + rel_gap) * (r[:, None] + r[None, :])
    found = {}
    for n in itertools.product(*[range(-k, k + 1) for k in ks]):
        sep = x[None, :, :] + lat @ np.array(n, dtype=float) - x[:, None, :]
        dist = np.sqrt(np.sum(sep**2, axis=2))
        nz = [v for v in n if v != 0]
        self_ok = bool(nz) and nz[0] > 0
        keep = upper & (dist <= limit)
        if not self_ok:
            np.fill_diagonal(keep, False)
        for i, j in zip(*np.nonzero(keep)):
            found[(int(i), int(j), tuple(n))] = dist[i, j]
    return found


def as_dict(pl):
    return {(int(i), int(j), tuple(int(v) for v in n)): dist
            for i, j, n, dist in zip(pl.i, pl.j, pl.shift, pl.distance)}


def random_cell(d, volume, shear, rng):
    """A random lattice (columns) of the given volume: the identity plus random shear and stretch."""
    while True:
        lat = np.eye(d) + shear * rng.uniform(-1.0, 1.0, (d, d))
        det = np.linalg.det(lat)
        if det > 0.2:
            return lat * (volume / det) ** (1.0 / d)


def random_packing(n, d, dist, phi, shear, seed):
    rng = np.random.default_rng(seed)
    radii = rng.permutation(dist.sample(n, rng))
    lat = random_cell(d, ball_volume(radii, d).sum() / phi, shear, rng)
    positions = (rng.random((n, d)) * 3.0 - 1.0) @ lat.T  # centres outside the cell too: wrapping tested
    return Packing(positions, radii, lat, allow_overlap=True)


def check(packing, **kwargs):
    pl = pairs_within(packing, **kwargs)
    got, ref = as_dict(pl), brute_force(packing, **kwargs)
    assert len(got) == len(pl), "a pair was reported twice"
    assert set(got) == set(ref)
    assert np.allclose([got[k] for k in ref], [ref[k] for k in ref], rtol=1e-12, atol=0)
    x = packing.fractional() @ packing.lattice.T
    np.testing.assert_allclose(pl.separation, x[pl.j] + pl.shift @ packing.lattice.T - x[pl.i], atol=1e-12)
    assert np.all(pl.i <= pl.j)
    keys = list(zip(pl.i.tolist(), pl.j.tolist(), map(tuple, pl.shift.tolist())))
    assert keys == sorted(keys)
    return pl


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("d, omega, shear", [(3, 50.0, 0.6), (2, 50.0, 0.9), (3, 10.0, 0.0), (4, 5.0, 0.4)])
def test_polydisperse_sheared_cells_against_brute_force(d, omega, shear, seed):
    """Uniform-volume radii up to omega = 50 in random (sheared) cells: the hierarchical grid has several
    levels, and any choice of levels gives the same list."""
    n = 400 if d < 4 else 150
    p = random_packing(n, d, uniform_volume(omega), 0.3, shear, seed)
    for rel_gap in (0.0, 0.3):
        pl = check(p, rel_gap=rel_gap)
        assert len(pl) > 20
        single = pairs_within(p, rel_gap=rel_gap, levels=1)
        assert np.array_equal(single.shift, pl.shift) and np.array_equal(single.j, pl.j)
    grid = build_grid(p.fractional(), p.lattice, p.radii)
    assert grid.n_levels > 1


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("d", [2, 3])
def test_fixed_cutoff_in_sheared_cells_against_brute_force(d, seed):
    p = random_packing(200, d, uniform_size(3.0), 0.2, 0.8, seed)
    check(p, cutoff=3.0 * 2 * p.radii.mean())


@pytest.mark.parametrize("n, d, shear, reach", [
    (1, 3, 0.0, 2.5), (1, 3, 0.7, 1.7), (2, 2, 0.9, 3.2), (3, 3, 0.5, 1.3), (5, 2, 0.0, 2.0), (1, 1, 0.0, 3.5),
    (4, 4, 0.3, 1.2),
])
def test_small_cells_find_every_image_including_self_images(n, d, shear, reach):
    """Cells smaller than the range: a particle meets its own images and several images of each
    neighbour (cutoff ``reach`` times the largest cell vector)."""
    rng = np.random.default_rng(n + 10 * d)
    lat = random_cell(d, 1.0, shear, rng)
    p = Packing(rng.random((n, d)) @ lat.T, np.full(n, 0.01), lat)
    pl = check(p, cutoff=reach * np.linalg.norm(lat, axis=0).max())
    assert np.any(pl.i == pl.j)
    assert max(np.count_nonzero((pl.i == a) & (pl.j == b)) for a, b in zip(pl.i, pl.j)) > 1


def test_contacts_of_small_cells_with_self_images():
    """Disks of radius 1/2 in a unit square cell touch their own images: 2 self-contacts (4 neighbours)."""
    p = Packing(np.array([[0.3, 0.6]]), np.array([0.5]), np.eye(2))
    pl = check(p, rel_gap=1e-9)
    assert len(pl) == 2 and set(map(tuple, pl.shift.tolist())) == {(0, 1), (1, 0)}


def walled_packing(n, d, walls, phi, seed):
    """Random polydisperse centres between hard walls on ``walls``: the walled lattice vectors L_k e_k, the
    periodic ones sheared among themselves; some centres a little outside the walls (overlapping input)."""
    rng = np.random.default_rng(seed)
    radii = rng.permutation(uniform_volume(10.0).sample(n, rng))
    periodic = np.ones(d, dtype=bool)
    periodic[list(walls)] = False
    lat = np.eye(d) + 0.7 * rng.uniform(-1.0, 1.0, (d, d)) * np.outer(periodic, periodic)
    lat *= (ball_volume(radii, d).sum() / phi / abs(np.linalg.det(lat))) ** (1.0 / d)
    s = rng.random((n, d)) * 1.1 - 0.05
    s[:, periodic] = s[:, periodic] * 3.0 - 1.0
    return Packing(s @ lat.T, radii, lat, boundary=HardWalls(walls), allow_overlap=True)


@pytest.mark.parametrize("d, walls", [(2, (0,)), (3, (2,)), (3, (0, 1)), (3, (0, 1, 2)), (4, (1, 3))])
def test_hard_walls_have_no_images_across_them(d, walls):
    """Images only along the periodic axes: a periodic search of the same cell finds pairs across the walls
    that the walled search must not report."""
    p = walled_packing(300 if d < 4 else 150, d, walls, 0.3, seed=d + len(walls))
    pl = check(p, rel_gap=0.2)
    assert np.all(pl.shift[:, list(walls)] == 0)
    periodic = pairs_within(p.replace(boundary="periodic", positions=p.fractional().clip(0, 0.999) @ p.lattice.T),
                            rel_gap=0.2)
    assert np.any(periodic.shift[:, list(walls)] != 0)  # the comparison is not vacuous
    check(p, cutoff=2.5 * p.radii.max())


def test_spherical_container_has_no_images():
    rng = np.random.default_rng(4)
    radii = uniform_volume(5.0).sample(400, rng)
    box = np.array([10.0, 10.0, 10.0])
    p = Packing(rng.random((400, 3)) * box, radii * 0.6, np.diag(box),
                boundary=SphericalContainer((5.0, 5.0, 5.0), 5.0), allow_overlap=True)
    pl = check(p, rel_gap=0.5)
    assert len(pl) > 100 and np.all(pl.shift == 0)


def test_a_disk_between_walls_touches_only_its_periodic_images():
    """A disk of radius 1/2 in a unit cell with walls on x: one self-contact (along y), not two."""
    p = Packing(np.array([[0.5, 0.3]]), np.array([0.5]), np.eye(2), boundary=HardWalls((0,)))
    pl = check(p, rel_gap=1e-9)
    assert pl.shift.tolist() == [[0, 1]]


def test_ellipsoids_are_searched_by_their_bounding_spheres():
    """Pairs of ellipsoids are the pairs of their bounding spheres (radius = the largest semiaxis)."""
    rng = np.random.default_rng(5)
    axes = rng.uniform(0.2, 1.0, (300, 3))
    q = rng.normal(size=(300, 4))
    shape = Ellipsoids(axes, q / np.linalg.norm(q, axis=1)[:, None])
    lat = np.array([[9.0, 2.0, 0.0], [0.0, 8.0, 1.0], [0.0, 0.0, 10.0]])
    p = Packing(rng.random((300, 3)) @ lat.T, lattice=lat, shape=shape, allow_overlap=True)
    pl = check(p)
    assert len(pl) > 50
    np.testing.assert_array_equal(pl.contact, axes.max(axis=1)[pl.i] + axes.max(axis=1)[pl.j])
