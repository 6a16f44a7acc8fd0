"""Contact network, rigidity matrix, rattlers, input validation and the result dataset."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog
from test_jamming_support import primitive_cell, triangular_with_vacancies

from hardpack.errors import InvalidInputError
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.jamming import contact_network, remove_rattlers, rigidity_matrix, verify
from hardpack.jamming.rigidity import strain_pairs


# ---------------------------------------------------------------------------- contacts
@pytest.mark.parametrize("name, m, z", [("triangular", 3, 6), ("fcc", 6, 12), ("square", 2, 4)])
def test_one_particle_cells_touch_their_own_images(name, m, z):
    """With one particle per cell every contact is with the particle's own image (Donev 2006, sec. 4.4.3);
    each is stored once (n lexicographically positive) and counts twice for the particle."""
    net = contact_network(primitive_cell(name), delta=1e-6)
    assert net.n_contacts == m
    assert np.all(net.is_self_image) and np.all(np.any(net.shift != 0, axis=1))
    assert net.counts()[0] == z
    np.testing.assert_allclose(net.gap, 0.0, atol=1e-14)


def test_contact_network_uses_delta():
    """Square lattice: 4 nearest neighbours at distance 1, diagonal ones at sqrt(2)."""
    p = lattice_packing("square", (3, 3))
    assert contact_network(p, 1e-6).counts().tolist() == [4] * 9
    assert contact_network(p, 0.5).counts().tolist() == [8] * 9


# ---------------------------------------------------------------------------- rigidity matrix
def test_rigidity_matrix_structure_and_strain_rows():
    """Particle part: -u in block i, +u in block j (zero for self-images); strain rows equal the
    derivative of each contact length under the lattice deformation Lambda -> (I + eps) Lambda
    (Eqs. 4.20-4.21), checked by central finite differences on a sheared, polydisperse cell."""
    rng = np.random.default_rng(0)
    lat = np.array([[3.1, 0.7], [0.0, 2.9]])
    x = rng.uniform(0, 1, (5, 2)) @ lat.T
    from hardpack.geometry.neighbours import pairs_within

    closest = pairs_within(Packing(x, np.full(5, 0.01), lat), cutoff=3.0).distance.min()
    radii = 0.5 * closest * rng.uniform(0.5, 0.99, 5)
    net = contact_network(Packing(x, radii, lat), delta=0.99)
    assert net.n_contacts >= 3 and np.any(net.shift != 0)
    a = rigidity_matrix(net, strain=True).toarray()
    n, d = net.n_particles, net.dim
    assert a.shape == (n * d + 3, net.n_contacts)
    np.testing.assert_allclose(a[: n * d].reshape(n, d, -1).sum(axis=0), 0.0, atol=1e-14)
    for s, (pq, qp) in enumerate(strain_pairs(d)):
        e = np.zeros((d, d))
        e[pq, qp] = e[qp, pq] = 1.0
        h = 1e-6
        plus = np.linalg.norm(net.separation + net.image_offset @ (h * e).T, axis=1)
        minus = np.linalg.norm(net.separation - net.image_offset @ (h * e).T, axis=1)
        np.testing.assert_allclose(a[n * d + s], (plus - minus) / (2 * h), atol=1e-8)


# ---------------------------------------------------------------------------- rattlers
def _positively_spanning(normals: np.ndarray) -> bool:
    """0 strictly inside the convex hull of the normals <=> they positively span R^d."""
    k, d = normals.shape
    # max t s.t. sum l_k u_k = 0, sum l_k = 1, l_k >= t
    res = linprog(
        np.r_[np.zeros(k), -1.0],
        A_ub=np.c_[-np.eye(k), np.ones(k)], b_ub=np.zeros(k),
        A_eq=np.vstack([np.c_[normals.T, np.zeros(d)], np.r_[np.ones(k), 0.0]]),
        b_eq=np.r_[np.zeros(d), 1.0], bounds=[(0, None)] * k + [(None, None)], method="highs",
    )
    return res.status == 0 and -res.fun > 1e-9 and np.linalg.matrix_rank(normals) == d


def test_rattler_removal_cascades_through_a_honeycomb():
    """Honeycomb disks have exactly d + 1 = 3 contacts. One vacancy leaves its 3 neighbours with
    2 contacts; removing them frees their neighbours, and so on (Donev 2006, sec. 4.4.3.1): iterative removal
    must strip the whole packing, a single pass would remove only 3 disks."""
    p = lattice_packing("honeycomb", (4, 4))
    p = p.replace(positions=p.positions[1:], radii=p.radii[1:])
    net = contact_network(p, 1e-6)
    assert (net.counts() < 3).sum() == 3
    r = verify(p, delta=1e-6)
    assert not r.local and r.rattler.all() and r.category == "not jammed"


def test_lp_rattler_that_passes_the_contact_count():
    """Triangular lattice with a divacancy: the two disks touching both vacancies keep 4 >= d + 1
    contacts, all in one closed half-plane, so only the LP (4.15) finds that they can escape.
    The LP escape of every disk agrees with an independent convex-hull test of its normals.
    (On the torus the hole then grows disk by disk until nothing is left: iterative removal.)"""
    from hardpack.jamming.rattlers import local_displacements

    p = triangular_with_vacancies(6, [(2, 2), (3, 2)])
    net = contact_network(p, 1e-6)
    everyone = np.ones(p.n_particles, dtype=bool)
    by_count, _ = remove_rattlers(net, everyone, dr_large=1e-6, box=1.0,
                                  rng=np.random.default_rng(0), use_lp=False)
    assert by_count.all()
    escape = local_displacements(net, everyone, everyone, np.random.default_rng(1).normal(size=(34, 2)), 1.0)
    loose = escape > 1e-6
    assert loose.sum() == 2 and escape[loose].min() > 0.5 and escape[~loose].max() < 1e-12
    for k in range(p.n_particles):
        normals = np.concatenate([net.normal[net.i == k], -net.normal[net.j == k]])
        assert _positively_spanning(normals) == (not loose[k])
    active, _ = remove_rattlers(net, everyone, dr_large=1e-6, box=1.0, rng=np.random.default_rng(0))
    assert not active.any()


def test_small_disk_in_a_hole_is_a_rattler():
    """A disk of radius 0.05 in a triangular hole (free radius 1/sqrt(3) - 1/2 = 0.077) has no
    contact: a rattler; the rest stays strictly jammed."""
    p = lattice_packing("triangular", (3, 3))
    hole = (p.positions[0] + p.positions[1] + p.positions[3]) / 3
    q = Packing(np.vstack([p.positions, hole]), np.r_[p.radii, 0.05], p.lattice)
    r = verify(q, delta=1e-6)
    assert r.rattler.tolist() == [False] * 9 + [True]
    assert r.strict and r.z_mean == 6.0


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("delta", [-1e-3, 0.0, 1.0, 2.5, float("nan"), float("inf"), "abc", [0.1]])
def test_nonsense_delta_refused(delta):
    with pytest.raises(InvalidInputError, match="delta"):
        verify(lattice_packing("square", 2), delta=delta)


def test_sequential_test_that_cannot_fail_is_refused():
    """Each LP of Algorithm 14 moves a particle by at most delta r_min (neighbour list), so with
    delta = 1e-6 three LPs reach 1.5e-6 D, far below the 1e-3 threshold: refused, with the fix."""
    with pytest.raises(InvalidInputError, match="could never report"):
        verify(lattice_packing("square", 2), delta=1e-6, method="sequential")


def test_overlapping_packing_refused():
    p = Packing([[0, 0], [0.9, 0]], [0.5, 0.5], 4 * np.eye(2), allow_overlap=True)
    with pytest.raises(InvalidInputError, match="overlap"):
        verify(p)


@pytest.mark.parametrize("kwargs, match", [
    ({"tests": ("local", "rigid")}, "unknown jamming test"),
    ({"method": "exact"}, "method"),
    ({"seed": -1}, "seed"),
    ({"seed": 1.5}, "seed"),
    ({"dr_large": -1.0}, "dr_large"),
    ({"dr_large": 2.0, "box": 1.0}, "dr_large"),
    ({"n_loads": 0}, "n_loads"),
])
def test_bad_options_refused(kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        verify(lattice_packing("square", 2), **kwargs)


def test_non_packing_refused():
    with pytest.raises(InvalidInputError, match="Packing"):
        verify(np.zeros((3, 2)))


# ---------------------------------------------------------------------------- result
def test_result_dataset_roundtrip_and_determinism(tmp_path):
    from hardpack.io import load_dataset, write_dataset

    p = lattice_packing("kagome", (2, 1))
    a, b = verify(p, seed=11), verify(p, seed=11)
    np.testing.assert_array_equal(a.collective_test.motion, b.collective_test.motion)
    ds = a.to_dataset()
    assert set(ds.dims) >= {"particle", "contact", "dim"}
    assert ds.sizes["particle"] == p.n_particles and ds.sizes["contact"] == a.network.n_contacts
    write_dataset(ds, tmp_path / "v.nc")
    back = load_dataset(tmp_path / "v.nc", kind="jamming")
    assert back.attrs["verdict"] == "locally jammed"
    assert back.attrs["collective"] == 0 and back.attrs["local"] == 1
    np.testing.assert_array_equal(back["contact_shift"].values, a.network.shift)
    np.testing.assert_allclose(back["force"].values, a.forces.forces)
