"""Per-particle growth in the deforming-cell MD (hardpack.md.deforming; Donev 2006, sec. 13.5
grows only the large disks of a binary packing).

- two disks, one growing at dD/dt = Gamma and one fixed, collide at the analytic time
  t* = (|r| - sigma) / (u + Gamma / 2) and leave with the LS velocities: the normal relative
  velocity is reflected in the frame of the growing surfaces (approach speed u + Gamma / 2 before
  and after), total momentum conserved, the fixed disk keeps its radius exactly;
- uniform growth through the per-particle path is bit-identical to the scalar-rate arithmetic
  (:func:`hardpack.md._deforming_kernel.pair_sigma` with equal rates);
- a run in which a third of the disks grow conserves the total momentum and leaves the others'
  radii untouched;
- bad masks are refused.
"""

from __future__ import annotations

import numpy as np
import pytest

from hardpack.distributions import monodisperse
from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.initial import random_packing
from hardpack.md import _deforming_kernel as dk
from hardpack.md.deforming import DeformingSimulation, cell_grid


def _first_collision(packing, velocities, kappa):
    """Run the kernel from t = 0 to its first collision; returns (time, status, X, V, A)."""
    n, d = packing.n_particles, packing.dim
    H = np.array(packing.lattice, dtype=float)
    Hinv = np.linalg.inv(H)
    X = np.array(packing.positions, dtype=float)
    V = np.array(velocities, dtype=float)
    A = np.array(packing.radii, dtype=float)
    lmin = float(np.linalg.norm(H, axis=0).min())
    M = dk.image_ranges(H, lmin)
    img = dk.image_table(H, M)
    z = lambda dtype=float: np.zeros(n, dtype=dtype)  # noqa: E731
    acc, iacc = np.zeros(2), np.zeros(dk.N_COUNTERS, dtype=np.int64)
    T = z()
    status = dk.run_events(X, V, T, A, H, Hinv, M, img, np.linalg.norm(Hinv, axis=1), lmin,
                           *cell_grid(H, 2 * (float(A.max()) + 0.3), n), np.asarray(kappa, dtype=float), np.full(n, 0.3), np.zeros((n, d + 1)),
                           np.zeros((n, 16), dtype=np.int64), z(np.int64), z(np.int8), z(np.int64),
                           z(np.int64), z(np.int64), z(np.int64), z(), z(), z(np.int64), z(np.int64),
                           np.zeros((d, d)), np.zeros((d, d)), acc, iacc, 1, np.inf)
    dk.synchronise(X, V, T, A, acc[0], np.asarray(kappa, dtype=float))
    return float(acc[0]), status, X, V, A, int(iacc[dk.I_COLL])


@pytest.mark.parametrize("u, gamma", [(1.0, 0.5), (0.3, 2.0), (0.0, 1.0)])
def test_one_growing_disk_collides_at_the_analytic_time(u, gamma):
    a, gap0 = 0.5, 2.0  # centre distance 3 = 2 a + gap0
    pk = Packing(np.array([[5.0, 10.0], [8.0, 10.0]]), np.array([a, a]), np.diag([20.0, 20.0]))
    v = np.array([[u, 0.0], [0.0, 0.0]])
    kappa = [gamma / (2 * a), 0.0]  # disk 0 grows at dD/dt = gamma, disk 1 keeps its size
    t, status, X, V, A, colls = _first_collision(pk, v, kappa)
    t_star = gap0 / (u + gamma / 2)
    assert status == dk.DeformingStatus.DONE_COLLISIONS and colls == 1
    assert t == pytest.approx(t_star, rel=1e-13)
    assert A[0] == pytest.approx(a + gamma / 2 * t_star, rel=1e-13)
    assert A[1] == a  # exactly
    assert X[1, 0] - X[0, 0] == pytest.approx(A[0] + A[1], rel=1e-13)  # touching
    # reflection in the frame of the growing surfaces: v0 = -gamma / 2, v1 = u + gamma / 2
    np.testing.assert_allclose(V, [[-gamma / 2, 0.0], [u + gamma / 2, 0.0]], atol=1e-14)
    np.testing.assert_allclose(V.sum(axis=0), v.sum(axis=0), atol=1e-14)


def test_pair_sigma_equal_rates_is_the_uniform_arithmetic():
    rng = np.random.default_rng(3)
    for ai, aj, k, t in rng.uniform(0.1, 2.0, size=(200, 4)):
        s = ai + aj
        assert dk.pair_sigma(ai, aj, k, k, t) == (s * (1.0 + k * t), s * k)  # bit for bit
        sig, rate = dk.pair_sigma(ai, aj, k, 0.0, t)
        assert sig == pytest.approx(ai * (1 + k * t) + aj) and rate == pytest.approx(ai * k)


def test_species_growth_conserves_momentum_and_fixed_radii():
    start = random_packing(60, 2, monodisperse(), 0.4, 4)
    growing = np.arange(60) % 3 == 0
    rng = np.random.default_rng(1)
    v = rng.normal(size=(60, 2))
    v -= v.mean(axis=0)
    sim = DeformingSimulation(start, v, 0.05, applied_pressure=None, growing=growing)
    a0 = sim.A.copy()
    for _ in range(20):
        sim.run_window(20 * 60)
    assert sim.collisions > 10_000
    np.testing.assert_allclose(sim.V.sum(axis=0), 0.0, atol=1e-11)
    np.testing.assert_array_equal(sim.A[~growing], a0[~growing])
    grown = sim.A[growing] - a0[growing]
    np.testing.assert_allclose(grown, grown[0], rtol=1e-9)  # all grew by the same Gamma t / 2
    assert grown[0] == pytest.approx(0.05 * sim.time / 2, rel=1e-9)
    assert sim.packing().overlap_report().n_overlapping == 0


@pytest.mark.parametrize("mask, match", [
    (np.zeros(20, dtype=bool), "no particle"),
    (np.ones(19, dtype=bool), "boolean mask"),
    (np.ones(20, dtype=int), "boolean mask"),
])
def test_bad_growing_masks_are_refused(mask, match):
    start = random_packing(20, 2, monodisperse(), 0.3, 0)
    with pytest.raises(InvalidInputError, match=match):
        DeformingSimulation(start, np.zeros((20, 2)), 0.02, growing=mask)
