"""Contacts, rattlers, contact number and nematic order of ellipsoid packings
(hardpack.geometry.ellipsoid_stats): affinely stretched crystals keep their contact network exactly
(FCC Z = 12, triangular Z = 6), rattler removal is the (d+1)-core of the contact graph (against
networkx), and the nematic order on exact cases (perfect alignment S = 1, two perpendicular
families, planar isotropy S -> 1/4, isotropy with E[N S^2] = 1 in 2D)."""

import math

import networkx as nx
import numpy as np
import pytest

from hardpack import InvalidInputError, Packing
from hardpack.geometry import Ellipsoids, HardWalls, lattice_packing
from hardpack.geometry.ellipsoid_stats import ellipsoid_contacts, near_sphere_contact_law, nematic_order, symmetry_axes


def stretched_crystal(name, alpha, reps=2):
    """The sphere crystal ``name`` (radius 1/2) stretched by ``alpha`` along the last axis: parallel
    spheroids (ellipses) with the same contacts (an affine map keeps tangency)."""
    spheres = lattice_packing(name, reps)
    d, n = spheres.dim, spheres.n_particles
    stretch = np.ones(d)
    stretch[-1] = alpha
    axes = np.tile(0.5 * stretch, (n, 1))
    orient = np.tile([1.0, 0, 0, 0], (n, 1)) if d == 3 else np.zeros(n)
    return Packing(spheres.positions * stretch, lattice=stretch[:, None] * spheres.lattice,
                   shape=Ellipsoids(axes, orient))


def quaternion(angle, axis):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis]


def with_orientations(orient, axes, box=100.0, seed=0):
    """Well separated particles of the given orientations on a grid (nematic order only)."""
    orient = np.asarray(orient, dtype=float)
    n = len(orient)
    d = len(axes)
    side = math.ceil(n ** (1 / d))
    grid = np.stack(np.meshgrid(*[np.arange(side)] * d, indexing="ij"), -1).reshape(-1, d)[:n]
    spacing = 2.5 * max(axes)
    return Packing(grid * spacing, lattice=side * spacing * np.eye(d), shape=Ellipsoids(np.tile(axes, (n, 1)), orient))


# ---------------------------------------------------------------- contacts and rattlers
@pytest.mark.parametrize("name,alpha,z", [("fcc", 1.7, 12), ("fcc", 0.6, 12), ("triangular", 2.5, 6),
                                          ("triangular", 0.5, 6)])
def test_stretched_crystals_keep_their_contact_network(name, alpha, z):
    packing = stretched_crystal(name, alpha)
    stats = ellipsoid_contacts(packing)
    assert (stats.degree == z).all() and stats.n_rattlers == 0 and stats.passes == 0
    assert stats.mean_contact_number == z
    np.testing.assert_allclose(stats.contacts.mu, 1.0, atol=1e-13)
    ds = stats.to_dataset()
    assert ds.attrs["mean_contact_number"] == z and ds.sizes["contact"] == z * packing.n_particles // 2


def test_a_vacancy_cluster_leaves_rattlers_removed_in_passes():
    """Remove from a stretched triangular crystal all but a 'T' of touching ellipses: a 3-contact
    particle left only by rattlers is removed in the second pass."""
    crystal = stretched_crystal("triangular", 1.3, reps=(6, 6))
    keep = np.zeros(crystal.n_particles, dtype=bool)
    stats = ellipsoid_contacts(crystal)
    # a particle and its 6 neighbours (a hexagon) is a backbone: each rim particle has 3 contacts
    centre = 0
    ring = np.r_[stats.contacts.pairs.j[stats.contacts.pairs.i == centre],
                 stats.contacts.pairs.i[stats.contacts.pairs.j == centre]]
    keep[centre] = True
    keep[ring] = True
    hexagon = crystal.replace(positions=crystal.positions[keep], shape=crystal.shape.take(keep))
    core = ellipsoid_contacts(hexagon)
    assert core.degree.tolist().count(6) == 1 and core.degree.tolist().count(3) == 6
    assert core.n_rattlers == 0 and core.mean_contact_number == pytest.approx(24 / 7)
    # a tail of two ellipses: the end has 1 contact (pass 1), its neighbour then only the end (pass 2)
    outside = [k for k in range(crystal.n_particles) if not keep[k]]
    pairs = stats.contacts.pairs
    neighbours = {k: set(pairs.j[pairs.i == k]) | set(pairs.i[pairs.j == k]) for k in range(crystal.n_particles)}
    first = next(k for k in outside if len(neighbours[k] & set(np.flatnonzero(keep))) == 2)
    tail_keep = keep.copy()
    tail_keep[first] = True
    second = next(k for k in outside if k != first and first in neighbours[k]
                  and not neighbours[k] & set(np.flatnonzero(keep)))
    tail_keep[second] = True
    tailed = crystal.replace(positions=crystal.positions[tail_keep], shape=crystal.shape.take(tail_keep))
    result = ellipsoid_contacts(tailed)
    assert result.n_rattlers == 2 and result.passes == 2
    assert ellipsoid_contacts(tailed, min_contacts=1).n_rattlers == 0


@pytest.mark.parametrize("d", [2, 3])
def test_rattler_removal_is_the_k_core_of_the_contact_graph(d):
    rng = np.random.default_rng(11)
    n = 300
    axes = rng.uniform(0.2, 0.6, (n, d))
    orient = rng.uniform(-np.pi, np.pi, n) if d == 2 else rng.normal(size=(n, 4))
    if d == 3:
        orient /= np.linalg.norm(orient, axis=1)[:, None]
    box = (n * np.prod(axes, axis=1).mean() * (math.pi if d == 2 else 4.2) / 0.3) ** (1 / d)
    packing = Packing(rng.uniform(0, box, (n, d)), lattice=box * np.eye(d), shape=Ellipsoids(axes, orient),
                      allow_overlap=True)
    stats = ellipsoid_contacts(packing, tol=0.35)
    pairs = stats.contacts.pairs
    graph = nx.Graph()
    graph.add_nodes_from(range(n))
    graph.add_edges_from(zip(pairs.i.tolist(), pairs.j.tolist()))
    assert graph.number_of_edges() == len(pairs) and not any(pairs.i == pairs.j)  # a simple graph
    core = nx.k_core(graph, d + 1)
    assert set(np.flatnonzero(~stats.rattler)) == set(core.nodes)
    assert all(stats.backbone_degree[k] == core.degree[k] for k in core.nodes)
    assert 0 < stats.n_rattlers < n - 20 and stats.passes >= 2


def test_bad_input_is_refused():
    crystal = stretched_crystal("triangular", 1.5)
    with pytest.raises(InvalidInputError, match="tolerance must be a finite number >= 0"):
        ellipsoid_contacts(crystal, tol=-1e-9)
    with pytest.raises(InvalidInputError, match="min_contacts must be a positive integer"):
        ellipsoid_contacts(crystal, min_contacts=0)
    with pytest.raises(InvalidInputError, match="ellipsoids and ellipses, got hard spheres"):
        ellipsoid_contacts(lattice_packing("triangular", 2))
    walled = stretched_crystal("fcc", 1.5).replace(boundary=HardWalls(0), allow_overlap=True)
    with pytest.raises(InvalidInputError, match="periodic cells only"):
        ellipsoid_contacts(walled)
    with pytest.raises(InvalidInputError, match="ellipsoids and ellipses, got hard spheres"):
        nematic_order(lattice_packing("fcc", 1))


# ---------------------------------------------------------------- nematic order
def test_symmetry_axes_of_spheroids_ellipsoids_and_ellipses():
    unit = [[1.0, 0, 0, 0]] * 4
    shape = Ellipsoids([[1, 1, 3], [3, 3, 1], [1, 3, 3], [1, 2, 4]], unit)
    np.testing.assert_array_equal(symmetry_axes(shape), np.eye(3)[[2, 2, 0, 2]])
    np.testing.assert_allclose(symmetry_axes(Ellipsoids([[1, 2], [2, 1]], [0.0, math.pi / 2])),
                               [[0, 1], [0, 1]], atol=1e-15)


@pytest.mark.parametrize("d", [2, 3])
def test_perfect_alignment_gives_one(d):
    rng = np.random.default_rng(3)
    n = 50
    if d == 3:
        base = quaternion(0.8, [1, 2, 3])
        # a half turn about a body axis perpendicular to the prolate's axis u turns u into -u (Donev's
        # composition, Eq. 1.9, applies the left factor in the body frame); q and -q are one rotation
        flips = [quaternion(math.pi, [1, 0, 0] if k % 2 else [0, 1, 0]) for k in range(n)]
        orient = np.array([(-1) ** k * (_compose(flips[k], base) if k % 3 == 0 else base) for k in range(n)])
        axes = [0.4, 0.4, 1.0]
        rows = Ellipsoids(np.tile(axes, (n, 1)), orient).rotations()[:, 2, :]
        assert np.allclose(rows @ rows[1], np.where(np.arange(n) % 3 == 0, -1.0, 1.0))
    else:
        orient = 0.3 + math.pi * rng.integers(-2, 3, n)
        axes = [1.0, 0.4]
    s, director = nematic_order(with_orientations(orient, axes))
    assert s == pytest.approx(1.0, abs=1e-14)


def _compose(a, b):
    """Quaternion product a b (Donev 2006, Eq. 1.9)."""
    s1, p1, s2, p2 = a[0], np.asarray(a[1:]), b[0], np.asarray(b[1:])
    return np.r_[s1 * s2 - p1 @ p2, s1 * p2 + s2 * p1 - np.cross(p1, p2)]


def test_two_perpendicular_families():
    """Half along x, half along y: Q = diag(1/4, 1/4, -1/2) in 3D (S = 1/4), Q = 0 in 2D."""
    orient3 = [quaternion(math.pi / 2, [0, 1, 0])] * 20 + [quaternion(math.pi / 2, [1, 0, 0])] * 20
    s3, _ = nematic_order(with_orientations(orient3, [0.3, 0.3, 1.0]))
    assert s3 == pytest.approx(0.25, abs=1e-14)
    s2, _ = nematic_order(with_orientations([0.0] * 20 + [math.pi / 2] * 20, [1.0, 0.3]))
    assert s2 == pytest.approx(0.0, abs=1e-14)


def test_planar_isotropic_axes_give_a_quarter():
    rng = np.random.default_rng(4)
    angles = rng.uniform(0, 2 * math.pi, 4000)
    orient = [quaternion(a, [0, 0, 1]) for a in angles]  # prolate axes along x rotated in the xy plane
    s, director = nematic_order(with_orientations(orient, [1.0, 0.3, 0.3]))
    assert s == pytest.approx(0.25, abs=4 / math.sqrt(4000)) and abs(director[2]) < 0.1


def test_isotropic_ellipses_have_n_s_squared_one_on_average():
    """For isotropic angles S = |<exp(2 i theta)>| and E[N S^2] = 1 exactly; 400 samples of N = 200
    (N S^2 has standard deviation ~1: the mean is within 5/sqrt(400) of 1)."""
    rng = np.random.default_rng(5)
    n = 200
    values = [n * nematic_order(with_orientations(rng.uniform(-math.pi, math.pi, n), [1.0, 0.5]))[0] ** 2
              for _ in range(400)]
    assert np.mean(values) == pytest.approx(1.0, abs=5 / math.sqrt(400))


def test_isotropic_ellipsoids_have_s_of_order_one_over_root_n():
    rng = np.random.default_rng(6)
    for n in (100, 1600):
        q = rng.normal(size=(n, 4))
        s, _ = nematic_order(with_orientations(q / np.linalg.norm(q, axis=1)[:, None], [1.0, 0.5, 0.5]))
        assert 0.2 < s * math.sqrt(n) < 4


# ----------------------------------------------------------------------------- Eq. 5.30
def test_near_sphere_law_recovers_a_square_root_law_and_tells_it_from_a_line():
    alpha = np.array([1.0, 1.01, 1.02, 1.05, 1.1, 1.2, 1.5, 2.0])
    z = 6 + 8.0 * np.sqrt(alpha - 1)
    law = near_sphere_contact_law(alpha, z, dim=3, alpha_max=1.3)
    assert law.n == 5 and law.z_alpha == pytest.approx(8.0, rel=1e-12) and law.z_alpha_err < 1e-10
    assert law.rms_sqrt < 1e-12 < 0.1 < law.rms_linear
    linear = near_sphere_contact_law(alpha, 4 + 20 * (alpha - 1), dim=2)
    assert linear.rms_linear < 1e-12 < linear.rms_sqrt
    assert near_sphere_contact_law([1.0, 2.0], [6.0, 9.0], dim=3).n == 0
    assert np.isnan(near_sphere_contact_law([1.0, 2.0], [6.0, 9.0], dim=3).z_alpha)
    assert np.isnan(near_sphere_contact_law([1.1], [7.0], dim=3).z_alpha_err)


@pytest.mark.parametrize("alpha, z, dim, message", [
    ([1.1, 1.2], [7.0], 3, "one length"),
    ([1.1, 1.2], [7.0, np.nan], 3, "finite"),
    ([1.1], [7.0], 4, "dim"),
])
def test_near_sphere_law_refuses_bad_input(alpha, z, dim, message):
    with pytest.raises(InvalidInputError, match=message):
        near_sphere_contact_law(alpha, z, dim)
