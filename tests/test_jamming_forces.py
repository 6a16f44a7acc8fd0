"""Contact forces, isostaticity and pressure (hardpack.jamming.forces).

Exact references: uniform forces in the crystals (symmetry), the Tonks gas in 1D (exact
equation of state p = L / (L - N D)), the jamming gap of a uniformly shrunk jammed packing
(exactly the shrink), the isostatic count M = d(N_b - 1) + 1 of generic disordered packings
(Eq. 4.8), and the boundary form (4.23) of the stress, which equals the virial only when every
particle is in force balance.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.jamming import rigidity_matrix, verify


def _boundary_stress(r):
    """sigma = (1/V) sum_c f_c Symm(u_c (Lambda n_c)^T) (Eq. 4.23): only boundary-crossing
    contacts enter."""
    net, f = r.network, r.forces.forces
    u, w = net.normal, net.image_offset
    s = np.einsum("k,kp,kq->pq", f, u, w)
    return 0.5 * (s + s.T) / r.volume


@pytest.mark.parametrize("name, reps", [("triangular", (3, 4)), ("fcc", (2, 2, 2)), ("hcp", (2, 2, 2))])
def test_crystal_forces_uniform_and_balanced(name, reps):
    r = verify(lattice_packing(name, reps), delta=1e-6)
    f = r.forces.forces
    np.testing.assert_allclose(f, 1.0, atol=1e-9)
    assert r.forces.min_force == pytest.approx(1.0, abs=1e-9)
    assert np.abs(r.forces.imbalance).max() < 1e-13
    # virial p V = (1/d) sum f |r| with |r| = 1: M / d
    assert r.statics.pressure_virial * r.volume == pytest.approx(r.network.n_contacts / r.network.dim)
    np.testing.assert_allclose(_boundary_stress(r), r.statics.stress, atol=1e-12)


def test_disordered_forces_positive_balanced_isostatic(jammed_disks):
    """Exactly jammed binary disks: unique strictly positive self-stress, balanced to round-off
    on every backbone disk, isostatic backbone (Eq. 4.8: M = 2 N_b - 1) and the boundary stress
    (4.23) equal to the virial stress (4.24)."""
    r = verify(jammed_disks, delta=1e-6)
    assert r.collective
    s, f = r.statics, r.forces
    assert s.isostaticity_gap == 0 and s.n_contacts == 2 * (s.n_backbone - 1) + 1
    assert s.z_mean == pytest.approx(2 * s.n_contacts / s.n_backbone)
    loaded = f.forces[r.network.among(~r.rattler)]
    assert loaded.min() > 0 and loaded.mean() == pytest.approx(1.0)
    assert np.abs(f.imbalance).max() < 1e-12 * loaded.max()
    assert np.all(f.imbalance[r.rattler] == 0)
    np.testing.assert_allclose(_boundary_stress(r), s.stress, atol=1e-10 * np.abs(s.stress).max())
    # the force network is a self-stress of the rigidity matrix: A f = 0 on backbone rows
    af = (rigidity_matrix(r.network) @ f.forces).reshape(-1, 2)
    assert np.abs(af[~r.rattler]).max() < 1e-12


def test_jamming_gap_of_uniformly_shrunk_packing(jammed_disks):
    """Shrinking every radius by (1 - s) opens every contact by s D: the jamming gap mu* (the
    relative growth that closes them again) is s / (1 - s) exactly."""
    s = 1e-9
    disks = jammed_disks
    shrunk = disks.replace(radii=disks.radii * (1 - s))
    # the cage extends to ~ M s D / f_min (elongated corners, Donev 2006, sec. 4.3.2): dr_large = 1e-3 D
    r = verify(shrunk, delta=1e-6, dr_large=1e-3)
    assert r.collective
    assert r.statics.jamming_gap == pytest.approx(s / (1 - s), rel=1e-6)


def test_free_volume_pressure_equals_tonks_gas():
    """1D ring of N rods with random gaps summing to G: exact reduced pressure L / G (Tonks);
    the free-volume pressure from forces, (N - 1) / (N mu*), must agree to O(1/N + G/L)."""
    rng = np.random.default_rng(4)
    n, g_total = 50, 1e-6
    gaps = rng.dirichlet(np.ones(n)) * g_total
    x = np.cumsum(np.r_[0.0, 1.0 + gaps[:-1]])
    p = Packing(x[:, None], np.full(n, 0.5), [[n + g_total]])
    r = verify(p, delta=1e-3, dr_large=1e-2)
    assert r.collective and r.statics.isostaticity_gap == 0
    exact = (n + g_total) / g_total
    assert r.statics.pressure_free_volume == pytest.approx(exact, rel=1.5 / n)
