"""Particle shapes and boundaries of the packing model (hardpack.geometry.shapes / boundaries).

- Ellipsoids: volumes and phi against the closed forms (pi a b, 4/3 pi a b c) and a Monte Carlo
  estimate of the covered fraction of a periodic cell (which also checks the rotation and shape
  matrices: a non-orthogonal Q would change the covered volume); Donev's rotation matrices
  (Donev 2006, Sec. 1.4.3) on known rotations; every refused input.
- Boundaries: spheres in hard walls and in a spherical container (containment, phi over the
  container, no images across walls, fractional coordinates, tiling); every refused lattice.
- Ellipsoid overlaps by the Perram-Wertheim contact function on exact cases (parallel ellipsoids,
  spheres as ellipsoids), hard walls by the ellipsoid's extent; a spherical container by the
  exact farthest surface point.
- The netCDF store: shapes and boundaries round trip bit for bit, files of format 1 (written by
  the code before particle shapes, tests/data) load as spheres in a periodic cell, damaged or
  newer files are refused.
- MD, jamming, SLP, structure and BCMD refuse other shapes and boundaries by name.
"""

import math

import numpy as np
import pytest
import xarray as xr

from hardpack import InvalidInputError, Packing
from hardpack.errors import StoreError
from hardpack.geometry import (
    Ellipsoids,
    HardWalls,
    Spheres,
    SphericalContainer,
    ball_volume,
    lattice_packing,
)
from hardpack.io import combine_ensemble, load_dataset, load_packing, save_packing
from hardpack.io.store import dataset_to_packing, packing_to_dataset

DATA = __import__("pathlib").Path(__file__).parent / "data"


def random_quaternions(n, rng):
    q = rng.standard_normal((n, 4))
    return q / np.linalg.norm(q, axis=1)[:, None]


def sparse_ellipsoids(d=3, n=12, seed=0, box=12.0, walls=None):
    """n ellipsoids with disjoint bounding spheres in a periodic cube of side ``box``, one
    straddling the cell face x = 0; with ``walls`` (a HardWalls) every bounding sphere is inside
    the walls instead."""
    rng = np.random.default_rng(seed)
    axes = rng.uniform(0.4, 1.2, (n, d))
    orient = random_quaternions(n, rng) if d == 3 else rng.uniform(-np.pi, np.pi, n)
    bound = axes.max(axis=1)
    walled = [] if walls is None else list(walls.axes)

    def draw(k):
        x = rng.uniform(0, box, d)
        x[walled] = rng.uniform(bound[k], box - bound[k], len(walled))
        return x

    first = draw(0)
    if walls is None:
        first[0] = 0.1  # its covered volume is split over the cell
    centres = [first]
    while len(centres) < n:
        x, k = draw(len(centres)), len(centres)
        if all(np.linalg.norm((x - c + box / 2) % box - box / 2) > bound[k] + bound[i] + 1e-9
               for i, c in enumerate(centres)):
            centres.append(x)
    return Packing(np.array(centres), lattice=box * np.eye(d), shape=Ellipsoids(axes, orient),
                   boundary="periodic" if walls is None else walls)


# ---------------------------------------------------------------- ellipsoid volumes and phi
def test_ellipsoid_volumes_are_the_closed_forms():
    e3 = Ellipsoids([[1.0, 2.0, 3.0], [0.5, 0.5, 0.5]], [[1, 0, 0, 0], [0, 1, 0, 0]])
    np.testing.assert_allclose(e3.volumes(3), [4 / 3 * math.pi * 6, 4 / 3 * math.pi * 0.125], rtol=1e-15)
    e2 = Ellipsoids([[1.0, 3.0], [0.2, 0.7]], [0.0, 1.0])
    np.testing.assert_allclose(e2.volumes(2), [3 * math.pi, 0.14 * math.pi], rtol=1e-15)
    np.testing.assert_array_equal(e3.bounding_radii, [3.0, 0.5])
    # an ellipsoid with equal semiaxes is a sphere: same volume
    assert e3.volumes(3)[1] == pytest.approx(float(ball_volume(0.5, 3)), rel=1e-15)


@pytest.mark.parametrize("d", [2, 3])
def test_ellipsoid_phi_matches_closed_form_and_a_monte_carlo_estimate(d):
    p = sparse_ellipsoids(d=d, n=10 if d == 3 else 14, box=8.0 if d == 3 else 9.0)
    exact = (math.pi if d == 2 else 4 / 3 * math.pi) * np.prod(p.shape.semiaxes, axis=1).sum() / p.volume
    assert p.phi == pytest.approx(exact, rel=1e-14)
    # Monte Carlo: uniform points in the cell, inside a particle if (r - r0)^T X (r - r0) <= 1
    # for the nearest image (bounding spheres are far below half the cell)
    rng = np.random.default_rng(1)
    m = 400_000
    pts = rng.uniform(0, p.lattice[0, 0], (m, d))
    x_mat = p.shape.shape_matrices()
    inside = np.zeros(m, dtype=bool)
    box = p.lattice[0, 0]
    for centre, x in zip(p.positions, x_mat):
        dr = (pts - centre + box / 2) % box - box / 2
        inside |= np.einsum("mi,ij,mj->m", dr, x, dr) <= 1.0
    f = inside.mean()
    err = math.sqrt(f * (1 - f) / m)
    assert abs(f - p.phi) < 4 * err, (f, p.phi, err)


def test_rotation_matrices_follow_donev():
    """Q maps lab to body frame (X = Q^T O^-2 Q, Donev 2006 Eq. 2.8): a rotation by phi about z
    turns the first semiaxis towards (cos phi, sin phi, 0), in 3D (quaternion) and 2D (angle)."""
    phi = 0.7
    e3 = Ellipsoids([[3.0, 1.0, 0.5]], [[math.cos(phi / 2), 0, 0, math.sin(phi / 2)]])
    e2 = Ellipsoids([[3.0, 1.0]], [phi])
    c, s = math.cos(phi), math.sin(phi)
    np.testing.assert_allclose(e3.rotations()[0], [[c, s, 0], [-s, c, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(e2.rotations()[0], [[c, s], [-s, c]], atol=1e-15)
    for e, tip in ((e3, [3 * c, 3 * s, 0.0]), (e2, [3 * c, 3 * s])):
        tip = np.array(tip)
        assert tip @ e.shape_matrices()[0] @ tip == pytest.approx(1.0, rel=1e-14)
    q = Ellipsoids(np.ones((50, 3)), random_quaternions(50, np.random.default_rng(2))).rotations()
    np.testing.assert_allclose(q @ q.transpose(0, 2, 1), np.broadcast_to(np.eye(3), q.shape), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(q), 1.0, atol=1e-14)


def test_quaternions_within_round_off_are_normalised_and_unit_ones_kept_bit_for_bit():
    unit = random_quaternions(20, np.random.default_rng(3))
    kept = Ellipsoids(np.ones((20, 3)), unit).orientations
    assert np.array_equal(kept, unit)
    nudged = unit * (1 + 1e-12)
    fixed = Ellipsoids(np.ones((20, 3)), nudged).orientations
    assert np.abs(np.linalg.norm(fixed, axis=1) - 1).max() < 1e-15
    assert np.array_equal(Ellipsoids(np.ones((20, 3)), fixed).orientations, fixed)  # idempotent


@pytest.mark.parametrize(
    "semiaxes, orientations, message",
    [
        ([[1, 1, 0]], [[1, 0, 0, 0]], "particle 0 has semiaxis 2 = 0.0"),
        ([[1, -2, 1]], [[1, 0, 0, 0]], "semiaxes must be positive"),
        ([[1, np.nan, 1]], [[1, 0, 0, 0]], "semiaxes contains a non-finite"),
        ([[1, 1, 1, 1]], [[1, 0, 0, 0]], r"d in \(2, 3\)"),
        ([1, 1, 1], [[1, 0, 0, 0]], r"shape \(N, d\)"),
        ([[1, 1, 1]], [[1.1, 0, 0, 0]], "unit quaternions; particle 0 has .* of norm 1.1"),
        ([[1, 1, 1]], [[0, 0, 0, 0]], "of norm 0"),
        ([[1, 1, 1]], [[1, 0, 0, 1e-4]], "of norm 1.000000005.* within 1e-10"),
        ([[1, 1, 1]], [[np.nan, 0, 0, 1]], "orientations contains a non-finite"),
        ([[1, 1, 1]], [[1, 0, 0]], r"shape \(1, 4\)"),
        ([[1, 1, 1]], [0.3], r"shape \(1, 4\)"),
        ([[1, 1]], [[1, 0, 0, 0]], r"1 angles .* shape \(1,\)"),
        ([[1, 1]], [np.inf], "orientations contains a non-finite"),
    ],
)
def test_bad_ellipsoids_are_refused(semiaxes, orientations, message):
    with pytest.raises(InvalidInputError, match=message):
        Ellipsoids(semiaxes, orientations)


def test_shapes_must_fit_the_positions():
    e = Ellipsoids([[1, 1, 1]], [[1, 0, 0, 0]])
    with pytest.raises(InvalidInputError, match="3-dimensional .* positions are 2-dimensional"):
        Packing([[0, 0]], lattice=9 * np.eye(2), shape=e)
    with pytest.raises(InvalidInputError, match=r"semiaxes and orientations must have shape \(2,\)"):
        Packing([[0, 0, 0], [5, 5, 5]], lattice=9 * np.eye(3), shape=e)
    with pytest.raises(InvalidInputError, match="shape must be one of"):
        Packing([[0, 0, 0]], lattice=9 * np.eye(3), shape=[1.0])


def test_radii_of_ellipsoids_are_refused_and_replace_keeps_the_shape():
    p = sparse_ellipsoids()
    with pytest.raises(InvalidInputError, match="hard ellipsoids, which have no radii"):
        p.radii
    moved = p.replace(positions=p.positions + 0.01)
    assert moved.shape is p.shape
    with pytest.raises(InvalidInputError, match="replace.radii=.... would make them spheres"):
        p.replace(radii=np.ones(p.n_particles))
    with pytest.raises(InvalidInputError, match="either radii .* or shape"):
        p.replace(radii=np.ones(p.n_particles), shape=p.shape)
    assert p.replace(shape=Spheres(np.full(p.n_particles, 0.4))).shape.kind == "sphere"
    big = p.tiled(2)
    assert big.n_particles == 8 * p.n_particles and big.phi == pytest.approx(p.phi, rel=1e-12)
    assert np.array_equal(big.shape.orientations[p.n_particles:2 * p.n_particles], p.shape.orientations)


# ---------------------------------------------------------------- ellipsoid overlaps: Perram-Wertheim
def needles(distance, direction, d=3, box=10.0, **kwargs):
    """Two parallel ellipsoids with semiaxes (1, 0.5, 0.5) at ``distance`` along ``direction``: they
    touch at distance 2 along x and 1 along y, and mu = distance / contact distance exactly."""
    axes = [[1.0, 0.5, 0.5][:d]] * 2
    orient = [[1, 0, 0, 0]] * 2 if d == 3 else [0.0, 0.0]
    x0 = np.full(d, 3.0)
    return Packing([x0, x0 + distance * np.asarray(direction, dtype=float)], lattice=box * np.eye(d),
                   shape=Ellipsoids(axes, orient), **kwargs)


@pytest.mark.parametrize("d", [2, 3])
def test_ellipsoid_overlaps_are_decided_by_the_contact_function(d):
    x, y = np.eye(d)[0], np.eye(d)[1]
    # side by side: the bounding spheres (radius 1) overlap, the ellipsoids do not
    side = needles(1.2, y, d)
    assert side.overlap_report().n_overlapping == 0
    assert side.overlap_report().overlap == pytest.approx(1 - 1.2, rel=1e-13)
    assert needles(2 * (1 + 1e-6), x, d).overlap_report().worst_i == -1  # bounding spheres disjoint
    assert needles(2 * (1 - 1e-10), x, d).overlap_report().overlap == pytest.approx(1e-10, rel=1e-4)
    with pytest.raises(InvalidInputError, match=r"1 overlapping pair\(s\); worst: particles 0 and 1 .* by 1\.000e-06"):
        needles(2 * (1 - 1e-6), x, d)
    with pytest.raises(InvalidInputError, match=r"particles 0 and 1 .* by 1\.000e-01"):
        needles(0.9, y, d)
    # within the tolerance: accepted
    assert needles(1 - 1e-10, y, d).overlap_report().overlap == pytest.approx(1e-10, rel=1e-4)
    # a pair that meets only through a periodic image is found and named with its image
    across = needles(1.2, y, d, allow_overlap=True)
    positions = across.positions.copy()
    positions[:, 1] = [0.3, 9.4]
    with pytest.raises(InvalidInputError, match=r"particles 0 and 1 \(image \(0, -1.* by 1\.000e-01"):
        across.replace(positions=positions, allow_overlap=False)


@pytest.mark.parametrize("d", [2, 3])
def test_the_ellipsoid_overlap_of_spheres_is_the_sphere_overlap(d):
    """Ellipsoids with equal semiaxes give the sphere check's worst pair and relative overlap."""
    rng = np.random.default_rng(7)
    n = 40
    radii = rng.uniform(0.3, 0.6, n)
    x = rng.uniform(0, 5.0, (n, d))
    orient = random_quaternions(n, rng) if d == 3 else rng.uniform(-np.pi, np.pi, n)
    spheres = Packing(x, radii, 5.0 * np.eye(d), allow_overlap=True)
    balls = Packing(x, lattice=5.0 * np.eye(d), shape=Ellipsoids(np.repeat(radii[:, None], d, 1), orient),
                    allow_overlap=True)
    a, b = spheres.overlap_report(), balls.overlap_report()
    assert (a.n_overlapping, a.worst_i, a.worst_j, a.shift) == (b.n_overlapping, b.worst_i, b.worst_j, b.shift)
    assert a.n_overlapping > 5 and b.overlap == pytest.approx(a.overlap, rel=1e-13)


def test_ellipsoids_between_hard_walls_are_checked_by_their_extent_along_the_wall_normal():
    """An ellipsoid reaches sqrt(e_k^T X^-1 e_k) along axis k (Donev 2006, Sec. 2.2.5.1)."""
    walls = HardWalls((0, 1, 2))
    along_x = Ellipsoids([[1.0, 0.5, 0.5], [1.0, 0.5, 0.5]], [[1, 0, 0, 0]] * 2)
    quarter = math.sqrt(0.5)
    along_y = Ellipsoids([[1.0, 0.5, 0.5], [1.0, 0.5, 0.5]], [[quarter, 0, 0, quarter]] * 2)
    with pytest.raises(InvalidInputError, match="particle 0 crosses the wall x_0 = 0 by 4.000e-01"):
        Packing([[0.6, 2, 2], [5, 5, 5]], lattice=8 * np.eye(3), shape=along_x, boundary=walls)
    turned = Packing([[0.6, 2, 2], [5, 5, 5]], lattice=8 * np.eye(3), shape=along_y, boundary=walls)
    assert turned.containment_report().overlap == pytest.approx(1 - 0.6 / 0.5, rel=1e-12)
    with pytest.raises(InvalidInputError, match="particle 1 crosses the wall x_1 = 8 by 1.000e-01"):
        turned.replace(positions=[[0.6, 2, 2], [5, 7.1, 5]])
    # 2D, turned by 45 degrees: extent sqrt((a^2 + b^2) / 2) along both axes
    tilted = Ellipsoids([[2.0, 1.0]], [math.pi / 4])
    reach = math.sqrt(2.5)
    ok = Packing([[reach * (1 + 1e-12), 4.0]], lattice=8 * np.eye(2), shape=tilted, boundary=HardWalls(0))
    assert ok.containment_report().overlap == pytest.approx(0, abs=1e-11)
    with pytest.raises(InvalidInputError, match="crosses the wall x_0 = 0"):
        ok.replace(positions=[[reach * (1 - 1e-6), 4.0]])


def test_ellipsoids_in_a_spherical_container_are_decided_by_their_farthest_point():
    shape = Ellipsoids([[1.0, 0.5, 0.5], [1.0, 0.5, 0.5]], [[1, 0, 0, 0]] * 2)
    inside = Packing([[4, 4, 4], [4, 4, 6]], lattice=8 * np.eye(3), shape=shape,
                     boundary=SphericalContainer((4, 4, 4), 3.2))
    assert inside.containment_report().n_outside == 0
    # the second one's bounding sphere (radius 1) crosses the wall, the ellipsoid (extent 0.5
    # along z, farthest point at distance 2.7 + 0.5 = 3.2 on the z axis) touches it
    touching = inside.replace(positions=[[4, 4, 4], [4, 4, 6.7]])
    assert touching.containment_report().overlap == pytest.approx(0.0, abs=1e-14)
    with pytest.raises(InvalidInputError, match="particle 1 crosses the container wall by 1.000e-01"):
        inside.replace(positions=[[4, 4, 4], [4, 4, 6.8]])


# ---------------------------------------------------------------- hard walls
def test_spheres_between_hard_walls():
    walls = HardWalls((0,))
    p = Packing([[0.5, 0.2], [4.5, 4.9]], [0.5, 0.5], 5 * np.eye(2), boundary=walls)  # touching both walls
    assert p.containment_report().n_outside == 0 and p.containment_report().overlap == pytest.approx(0, abs=1e-15)
    assert p.phi == pytest.approx(2 * math.pi * 0.25 / 25)
    with pytest.raises(InvalidInputError, match="cross the boundary .* particle 1 crosses the wall x_0 = 5 by 2.000e-01"):
        p.replace(positions=[[0.5, 0.2], [4.6, 2.0]])
    # periodic along y: the spheres (y = 0.2 and y = 4.9) overlap through the image along y
    with pytest.raises(InvalidInputError, match=r"particles 0 and 1 \(image \(0, -1\)\)"):
        p.replace(positions=[[2.0, 0.2], [2.5, 4.9]])


def test_no_images_across_walls():
    """Spheres on both sides of a walled axis do not meet through the (absent) image."""
    x = [[0.1, 2.0], [4.9, 2.0]]
    periodic = Packing(x, [0.5, 0.5], 5 * np.eye(2), allow_overlap=True)
    walled = Packing(x, [0.5, 0.5], 5 * np.eye(2), boundary=HardWalls([0]), allow_overlap=True)
    assert periodic.overlap_report().n_overlapping == 1
    assert walled.overlap_report().n_overlapping == 0
    assert walled.containment_report().n_outside == 2
    # a centre outside the box (allowed for diagnosis) is not wrapped along a walled axis
    out = Packing([[-0.3, 2.0], [0.4, 2.0]], [0.5, 0.5], 5 * np.eye(2), boundary=HardWalls([0]), allow_overlap=True)
    rep = out.overlap_report()
    assert rep.n_overlapping == 1 and rep.overlap == pytest.approx(0.3)
    np.testing.assert_allclose(out.fractional(), [[-0.06, 0.4], [0.08, 0.4]])
    np.testing.assert_allclose(out.minimum_image(np.array([[4.0, 4.0]])), [[4.0, -1.0]])


def test_walls_with_a_sheared_periodic_plane_and_tiling():
    lat = np.array([[3.0, 1.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]])  # walls along z, xy sheared
    p = Packing([[1.0, 1.0, 1.0]], [0.5], lat, boundary=HardWalls((2,)))
    big = p.tiled((2, 3, 1))
    assert big.n_particles == 6 and big.boundary == p.boundary and big.phi == pytest.approx(p.phi)
    with pytest.raises(InvalidInputError, match="reps must be 1 along the axes without periodic images"):
        p.tiled(2)


@pytest.mark.parametrize(
    "axes, lattice, message",
    [
        ((), np.eye(3), "at least one walled axis"),
        ((0, 0), np.eye(3), "distinct non-negative"),
        ((-1,), np.eye(3), "distinct non-negative"),
        ((True,), np.eye(3), "distinct non-negative"),
        ((0.5,), np.eye(3), "distinct non-negative"),
        (("x",), np.eye(3), "distinct non-negative"),
        ((3,), np.eye(3), "axis 3 does not exist in 3 dimensions"),
        ((2,), [[3, 0, 1], [0, 3, 0], [0, 0, 3]], r"orthorhombic along it.*got column \[1.0, 0.0, 3.0\]"),
        ((0,), [[3, 1, 0], [0, 3, 0], [0, 0, 3]], "orthorhombic along it"),
        ((1,), [[3, 0, 0], [0, -3, 0], [0, 0, 3]], "orthorhombic along it"),
    ],
)
def test_bad_walls_are_refused(axes, lattice, message):
    with pytest.raises(InvalidInputError, match=message):
        Packing([[0.5, 0.5, 0.5]], [0.1], lattice, boundary=HardWalls(axes))


# ---------------------------------------------------------------- spherical container
def test_spheres_in_a_spherical_container():
    box = 10 * np.eye(3)
    container = SphericalContainer([5, 5, 5], 5.0)
    p = Packing([[5, 5, 5], [5, 5, 9.5], [5, 9.0, 5]], [0.5, 0.5, 1.0], box, boundary=container)
    assert p.volume == pytest.approx(4 / 3 * math.pi * 125)
    assert p.phi == pytest.approx((2 * 0.125 + 1) / 125, rel=1e-14)
    report = p.containment_report()
    assert report.n_outside == 0 and report.worst in (1, 2) and report.overlap == pytest.approx(0, abs=1e-15)
    with pytest.raises(InvalidInputError, match="particle 1 crosses the container wall by 4.000e-01"):
        p.replace(positions=[[5, 5, 5], [5, 5, 9.7], [5, 9.0, 5]])
    # no periodic images: spheres at opposite ends of the box do not meet
    q = Packing([[5, 5, 0.2], [5, 5, 9.8]], [0.5, 0.5], box, boundary=container, allow_overlap=True)
    assert q.overlap_report().n_overlapping == 0
    np.testing.assert_allclose(q.fractional()[:, 2], [0.02, 0.98])
    with pytest.raises(InvalidInputError, match="reps must be 1"):
        p.tiled((1, 1, 2))


@pytest.mark.parametrize(
    "centre, radius, lattice, message",
    [
        ([5, 5, 5], 5.1, 10 * np.eye(3), r"must lie inside the box \[0, L_k\]"),
        ([5, 5, 5], 5.0, [[10, 1, 0], [0, 10, 0], [0, 0, 10]], "orthorhombic box"),
        ([5, 5], 4.0, 10 * np.eye(3), "centre has 2 coordinates; the packing is 3-dimensional"),
        ([5, 5, 5], 0.0, 10 * np.eye(3), "radius must be positive"),
        ([5, 5, np.nan], 4.0, 10 * np.eye(3), "container centre contains a non-finite"),
        ([5, 5, 5], [1.0, 2.0], 10 * np.eye(3), "one radius"),
    ],
)
def test_bad_containers_are_refused(centre, radius, lattice, message):
    with pytest.raises(InvalidInputError, match=message):
        Packing([[5, 5, 5]], [0.5], lattice, boundary=SphericalContainer(centre, radius))


def test_unknown_boundary_is_refused():
    with pytest.raises(InvalidInputError, match="boundary 'walls' is not supported"):
        Packing([[0.5]], [0.1], [[2.0]], boundary="walls")


# ---------------------------------------------------------------- store
def _same(p, q):
    assert type(p.shape) is type(q.shape) and p.boundary == q.boundary
    for a, b in ((p.positions, q.positions), (p.lattice, q.lattice)):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    if p.shape.kind == "sphere":
        assert np.array_equal(p.radii, q.radii)
    else:
        assert np.array_equal(p.shape.semiaxes, q.shape.semiaxes)
        assert np.array_equal(p.shape.orientations, q.shape.orientations)
    assert p.phi == q.phi


@pytest.mark.parametrize("d", [2, 3])
def test_ellipsoids_walls_and_containers_round_trip(tmp_path, d):
    cases = [sparse_ellipsoids(d=d)]
    cases.append(sparse_ellipsoids(d=d, walls=HardWalls([0])))
    cases.append(needles(1.2, np.eye(d)[1], d))  # bounding spheres overlap: decided on loading too
    box = 10 * np.eye(d)
    cases.append(Packing(np.full((1, d), 5.0), [0.5], box, boundary=SphericalContainer(np.full(d, 5.0), 5.0)))
    cases.append(Packing(np.full((1, d), 5.0), [0.5], box, boundary=HardWalls(range(d)), species=[3]))
    for k, p in enumerate(cases):
        path = save_packing(p, tmp_path / f"{k}.nc")
        _same(p, load_packing(path))
        attrs = load_dataset(path).attrs
        assert attrs["hardpack_format"] == 2 and attrs["shape_kind"] == p.shape.kind
        assert attrs["boundary"] == p.boundary.kind


@pytest.mark.parametrize("name", ["jammed_disks_n64.nc", "slp_barlow_n64.nc"])
def test_files_of_format_1_load_as_spheres_in_a_periodic_cell(name):
    """Files written before particle shapes and boundaries (format 1, tests/data) load unchanged."""
    raw = xr.open_dataset(DATA / name).load()
    assert raw.attrs["hardpack_format"] == 1 and "shape_kind" not in raw.attrs
    p = load_packing(DATA / name)
    assert p.shape.kind == "sphere" and p.boundary.kind == "periodic"
    assert np.array_equal(p.positions, raw["position"].values) and np.array_equal(p.radii, raw["radius"].values)
    assert p.phi == pytest.approx(raw.attrs["phi"], rel=1e-14)


def test_an_old_style_dataset_without_format_attributes_loads():
    p = lattice_packing("fcc", 2)
    ds = xr.Dataset({"position": (("particle", "dim"), p.positions), "radius": (("particle",), p.radii),
                     "lattice": (("dim", "vector"), p.lattice)}, attrs={"hardpack_kind": "packing"})
    _same(p, dataset_to_packing(ds))


def test_damaged_or_newer_files_are_refused():
    e = packing_to_dataset(sparse_ellipsoids())
    w = packing_to_dataset(Packing([[1, 1]], [0.5], 5 * np.eye(2), boundary=HardWalls([1])))
    cases = [
        (e.drop_vars("quaternion"), r"variable\(s\) \['quaternion'\] of 3-dimensional ellipsoids missing"),
        (e.drop_vars("semiaxis"), "semiaxis.* missing"),
        (e.assign(radius=("particle", np.ones(e.sizes["particle"]))), "do not belong to ellipsoids"),
        (e.assign_attrs(shape_kind="superellipsoid"), "shape_kind 'superellipsoid'.*update hardpack"),
        (e.assign_attrs(hardpack_format=3), "format 3; this hardpack reads formats up to 2"),
        (w.drop_vars("wall"), r"\['wall'\] of hard walls missing"),
        (w.assign_attrs(boundary="periodic"), "do not belong to a periodic cell"),
        (w.assign_attrs(boundary="moat"), "boundary 'moat'"),
        (w.assign(wall=("dim", np.array([0, 0], np.int8))), "at least one walled axis"),
    ]
    for ds, message in cases:
        with pytest.raises(StoreError, match=message):
            dataset_to_packing(ds)


def test_ensembles_of_different_shapes_or_boundaries_are_refused_unless_indexed():
    spheres = packing_to_dataset(lattice_packing("sc", 2), attrs={"seed": 1})
    ellipsoids = packing_to_dataset(sparse_ellipsoids(), attrs={"seed": 2})
    walled = packing_to_dataset(Packing([[1, 1, 1]], [0.5], 4 * np.eye(3), boundary=HardWalls([2])), attrs={"seed": 3})
    with pytest.raises(InvalidInputError, match="different particle shapes .* shape_kind = ellipsoid: dataset 1"):
        combine_ensemble([spheres, ellipsoids])
    with pytest.raises(InvalidInputError, match="different boundaries .* boundary = hard_walls: dataset 1"):
        combine_ensemble([spheres, walled])
    both = combine_ensemble([spheres, ellipsoids], index=("seed", "shape_kind"))
    assert list(both["shape_kind"].values) == ["sphere", "ellipsoid"]


def test_info_shows_shape_and_boundary(tmp_path, capsys):
    from hardpack.cli import main

    save_packing(sparse_ellipsoids(), tmp_path / "e.nc")
    save_packing(Packing([[5, 5, 5]], [0.5], 10 * np.eye(3), boundary=SphericalContainer([5, 5, 5], 5.0)),
                 tmp_path / "c.nc")
    assert main(["info", str(tmp_path / "e.nc")]) == 0
    out = capsys.readouterr().out
    assert "hard ellipsoids: semiaxes min" in out and "boundary: periodic" in out
    assert main(["info", str(tmp_path / "c.nc")]) == 0
    out = capsys.readouterr().out
    assert "radii: min 0.5" in out and "boundary: spherical container (centre [5.0, 5.0, 5.0], radius 5)" in out
    assert "container volume 523.599" in out and "walls: no particle crosses a wall" in out


# ---------------------------------------------------------------- refusals by the simulation and analysis modules
def _refusals():
    from hardpack.freeenergy import run_bcmd, simplex_reference, simplex_test
    from hardpack.freeenergy.bcmd import cell_neighbours
    from hardpack.jamming import contact_network, verify
    from hardpack.md import compress, equilibrate
    from hardpack.md.compress import jamming_backbone
    from hardpack.md.simulation import Simulation
    from hardpack.slp import Bounds, run_slp, solve_step
    from hardpack.slp.diluted import run_diluted
    from hardpack.structure import (
        analyse,
        cumulative_coordination,
        number_variance,
        pair_correlation,
        regular_neighbours,
        steinhardt,
        structure_factor,
        translational_order,
    )

    bounds = Bounds(0.01, 0.01, 0.05)
    return {
        "the MD engine": [lambda p: compress(p, 0.01, seed=1), lambda p: equilibrate(p, 1, 100),
                          lambda p: Simulation(p, np.zeros((p.n_particles, p.dim)), 0.0)],
        "the jamming backbone of an LS compression": [jamming_backbone],
        "the jamming tests": [lambda p: verify(p), lambda p: contact_network(p, 1e-6)],
        "SLP": [lambda p: run_slp(p, 3.5, bounds), lambda p: solve_step(p, 3.5, bounds)],
        "the diluted-MRJ protocol": [lambda p: run_diluted(p, 0.1, 1, 0, 3.5, bounds)],
        "the structure analysis": [analyse, pair_correlation, cumulative_coordination, steinhardt,
                                   lambda p: structure_factor(p, 5.0), lambda p: number_variance(p, [1.0]),
                                   translational_order, regular_neighbours],
        "BCMD": [lambda p: run_bcmd(p, dmu_max=0.1), lambda p: cell_neighbours(p, 0.1)],
        "the exact simplex free energy": [lambda p: simplex_test(p, np.zeros(p.n_particles, bool)),
                                          lambda p: simplex_reference(p, 1e-8, 1e-9)],
    }


#: modules that run spheres with hard walls and in containers (tested in tests/test_walls.py)
WALLED_SPHERES_SUPPORTED = ("the MD engine", "the jamming backbone of an LS compression", "the jamming tests")


@pytest.mark.parametrize("user", list(_refusals()))
def test_modules_refuse_other_shapes_and_boundaries_by_name(user):
    ellipsoids = sparse_ellipsoids()
    sc = lattice_packing("sc", 3).replace(radii=np.full(27, 0.45))
    walled = sc.replace(positions=sc.positions + 0.5, boundary=HardWalls([0, 2]))
    box = sc.lattice[0, 0]
    contained = sc.replace(positions=sc.positions[:1] + box / 2 - 0.5, shape=Spheres([0.45]),
                           boundary=SphericalContainer(np.full(3, box / 2), box / 2))
    for call in _refusals()[user]:
        with pytest.raises(InvalidInputError, match=f"hard ellipsoids are not supported by {user}"):
            call(ellipsoids)
        if user in WALLED_SPHERES_SUPPORTED:
            continue
        with pytest.raises(InvalidInputError, match=f"hard walls are not supported by {user} yet; it handles "
                                                    "periodic cells only"):
            call(walled)
        with pytest.raises(InvalidInputError, match=f"spherical containers are not supported by {user}"):
            call(contained)
