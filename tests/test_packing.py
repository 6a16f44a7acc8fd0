"""Packing model: known volume fractions, periodic geometry, and every refused input."""

import math

import numpy as np
import pytest

from hardpack import InvalidInputError, Packing
from hardpack.geometry import Spheres, ball_volume, lattice_packing, pairs_within, unit_ball_volume


@pytest.mark.parametrize(
    "d, exact",
    [(1, 2.0), (2, math.pi), (3, 4 * math.pi / 3), (4, math.pi**2 / 2),
     (5, 8 * math.pi**2 / 15), (6, math.pi**3 / 6)],
)
def test_unit_ball_volumes(d, exact):
    assert unit_ball_volume(d) == pytest.approx(exact, rel=1e-14)
    assert ball_volume(2.0, d) == pytest.approx(exact * 2.0**d, rel=1e-14)


# densities of the crystals, exact expressions (Conway & Sloane, Table 1.2)
@pytest.mark.parametrize(
    "name, phi, z",
    [("square", math.pi / 4, 4), ("triangular", math.pi / math.sqrt(12), 6),
     ("honeycomb", math.pi / (3 * math.sqrt(3)), 3), ("kagome", math.pi * math.sqrt(3) / 8, 4),
     ("sc", math.pi / 6, 6), ("bcc", math.pi * math.sqrt(3) / 8, 8),
     ("fcc", math.pi / math.sqrt(18), 12), ("hcp", math.pi / math.sqrt(18), 12),
     ("diamond", math.pi * math.sqrt(3) / 16, 4), ("D4", math.pi**2 / 16, 24),
     ("D5", math.pi**2 * math.sqrt(2) / 30, 40)],
)
def test_lattice_volume_fractions_and_coordination(name, phi, z):
    for reps in (1, 2):
        p = lattice_packing(name, reps)
        assert p.phi == pytest.approx(phi, rel=1e-12)
        contacts = pairs_within(p, rel_gap=1e-9)
        # each contact counted once, so mean coordination is 2 M / N (self-images included)
        assert 2 * len(contacts) / p.n_particles == pytest.approx(z)
        assert p.overlap_report().n_overlapping == 0


def test_published_rounded_densities():
    assert round(lattice_packing("fcc").phi, 4) == 0.7405
    assert round(lattice_packing("triangular").phi, 4) == 0.9069
    assert round(lattice_packing("sc").phi, 4) == 0.5236


def test_sheared_cell_same_lattice_same_contacts():
    """FCC described by its primitive (sheared) cell: same density, 12 contacts, self-images."""
    a = math.sqrt(2.0)
    prim = 0.5 * a * np.array([[0, 1, 1], [1, 0, 1], [1, 1, 0]], float)
    p = Packing(np.zeros((1, 3)), [0.5], prim)
    assert p.phi == pytest.approx(math.pi / math.sqrt(18))
    pairs = pairs_within(p, rel_gap=1e-9)
    assert len(pairs) == 6  # 12 self-image contacts, each stored once
    assert (pairs.i == pairs.j).all()
    assert np.allclose(pairs.distance, 1.0)


def test_minimum_image_and_separation():
    p = Packing([[0.1, 0.1], [9.9, 9.8]], [0.1, 0.1], 10 * np.eye(2))
    assert np.allclose(p.separation(0, 1), [-0.2, -0.3])
    assert np.allclose(p.minimum_image(np.array([[6.0, -7.0]])), [[-4.0, 3.0]])


def test_overlap_report_names_worst_pair():
    pos = [[0, 0, 0], [0.95, 0, 0], [3, 3, 3], [3.99, 3, 3]]
    p = Packing(pos, [0.5] * 4, 8 * np.eye(3), allow_overlap=True)
    rep = p.overlap_report()
    assert rep.n_overlapping == 2
    assert (rep.worst_i, rep.worst_j) == (0, 1)
    assert rep.overlap == pytest.approx(0.05)


def test_overlap_across_the_periodic_boundary_is_found():
    with pytest.raises(InvalidInputError, match=r"particles 0 and 1 \(image \(-1, 0\)\)"):
        Packing([[0.2, 1.0], [4.9, 1.0]], [0.5, 0.5], 5 * np.eye(2))


def test_overlap_within_tolerance_is_accepted():
    # relative overlap 1e-12 < default tolerance 1e-9 (round-off after a collision)
    p = Packing([[0, 0], [1 - 1e-12, 0]], [0.5, 0.5], 5 * np.eye(2))
    assert p.overlap_report().n_overlapping == 0
    assert p.overlap_report(tol=1e-13).n_overlapping == 1


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(positions=[[0, np.nan]], radii=[1], lattice=5 * np.eye(2)), "positions contains a non-finite value.*index \\[0, 1\\]"),
        (dict(positions=[[0, 0]], radii=[np.inf], lattice=5 * np.eye(2)), "radii contains a non-finite"),
        (dict(positions=[[0, 0]], radii=[1], lattice=[[5, 0], [0, np.nan]]), "lattice contains a non-finite"),
        (dict(positions=[0, 0], radii=[1], lattice=5 * np.eye(2)), r"shape \(N, d\)"),
        (dict(positions=[[0, 0]], radii=[1, 2], lattice=5 * np.eye(2)), r"radii must have shape \(1,\)"),
        (dict(positions=[[0, 0]], radii=[-1], lattice=5 * np.eye(2)), "particle 0 has radius -1"),
        (dict(positions=[[0, 0]], radii=[0.0], lattice=5 * np.eye(2)), "radii must be positive"),
        (dict(positions=[[0, 0]], radii=[1], lattice=np.eye(3)), r"lattice must be a \(2, 2\)"),
        (dict(positions=[[0, 0]], radii=[1], lattice=[[1, 2], [2, 4]]), "lattice is singular"),
        (dict(positions=np.zeros((1, 13)), radii=[1], lattice=np.eye(13)), "dimension d = 13"),
        (dict(positions=np.zeros((0, 2)), radii=[], lattice=np.eye(2)), "at least one particle"),
        (dict(positions=[["a", 0]], radii=[1], lattice=np.eye(2)), "positions must be numeric"),
        (dict(positions=[[0, 0]], radii=[1], lattice=5 * np.eye(2), boundary="box"), "boundary 'box'"),
        (dict(positions=[[0, 0]], radii=[1], lattice=5 * np.eye(2), species=[0.5]), "species must be an integer"),
        (dict(positions=[[0, 0]], radii=[1], lattice=5 * np.eye(2), shape=Spheres([1])), "either radii .* or shape"),
        (dict(positions=[[0, 0]], lattice=5 * np.eye(2)), "needs radii .* or shape"),
        (dict(positions=[[0, 0]], radii=[1]), "needs a lattice"),
    ],
)
def test_bad_input_is_refused_with_a_message(kwargs, message):
    with pytest.raises(InvalidInputError, match=message):
        Packing(**kwargs)


def test_arrays_are_read_only_and_replace_validates():
    p = lattice_packing("sc", 2)
    with pytest.raises(ValueError):
        p.positions[0, 0] = 1.0
    with pytest.raises(InvalidInputError, match="overlap"):
        p.replace(radii=np.full(p.n_particles, 0.6))
    assert p.replace(radii=np.full(p.n_particles, 0.4)).phi == pytest.approx(math.pi / 6 * 0.8**3)


def test_pairs_within_brute_force_small_triclinic_cell():
    """Exhaustive check of the image search against a brute-force loop over images."""
    rng = np.random.default_rng(3)
    lat = np.array([[3.0, 1.2, 0.3], [0.0, 2.5, 0.7], [0.0, 0.0, 2.8]])
    pos = rng.random((6, 3)) @ lat.T
    p = Packing(pos, np.full(6, 0.05), lat)
    cutoff = 4.0
    found = pairs_within(p, cutoff=cutoff)
    s = p.fractional()
    x = s @ lat.T
    brute = set()
    rng_n = range(-4, 5)
    for i in range(6):
        for j in range(i, 6):
            for n in np.array(np.meshgrid(rng_n, rng_n, rng_n)).reshape(3, -1).T:
                if i == j and not (n[np.flatnonzero(n)[0]] > 0 if n.any() else False):
                    continue
                if np.linalg.norm(x[j] + lat @ n - x[i]) <= cutoff:
                    brute.add((i, j, tuple(n)))
    got = {(int(a), int(b), tuple(int(v) for v in n)) for a, b, n in zip(found.i, found.j, found.shift)}
    assert got == brute


def test_tiled_packing_keeps_phi_and_contact_number():
    from hardpack.geometry.lattices import lattice_packing
    from hardpack.geometry.neighbours import pairs_within

    p = lattice_packing("fcc", 1)
    big = p.tiled((2, 3, 1))
    assert big.n_particles == 6 * p.n_particles
    assert big.phi == pytest.approx(p.phi, rel=1e-12)
    assert len(pairs_within(big, rel_gap=1e-9).i) == 6 * len(pairs_within(p, rel_gap=1e-9).i)
    with pytest.raises(InvalidInputError, match="positive integers"):
        p.tiled(0)


@pytest.mark.parametrize("reps", [1.5, (2.9, 1, 1), 0, -1, (1, 1, 0), True, "2", float("nan"), (2, 2), (1, 1, 1, 1), [[1, 2, 3]]])
def test_lattice_repetitions_must_be_positive_whole_numbers_one_per_vector(reps):
    """Non-integer repetitions were truncated (1.5 -> 1, 2.9 -> 2), a wrong count crashed."""
    with pytest.raises(InvalidInputError, match="reps must be"):
        lattice_packing("fcc", reps)


def test_lattice_repetitions_accept_whole_floats_and_numpy_integers():
    assert lattice_packing("fcc", 2.0).n_particles == 32
    assert lattice_packing("fcc", np.array([3, 2, 1])).n_particles == 24
    assert lattice_packing("triangular", (np.int64(3), 2)).n_particles == 6
