"""Ellipses made from a jammed disk packing (Donev 2006, Sec. 5.9.2, Eqs. 5.27-5.29, Figs. 5.16-5.17).

The 64-disk packing of tests/data (62 in the backbone, isostatic) is turned into ellipses of aspect
ratio alpha = 1 + eps: long semiaxis the disk radius O_i at angle phi_i, short O_i / alpha. The
jamming point on the disk contact network is the maximum of the common scale s subject to
zeta_c >= 0 on those contacts; :func:`kkt_newton` solves its KKT conditions
(zeta_c = 0, A_zeta F = 0 with force AND torque balance, sum F = M) by Newton's method, whose
Jacobian [[A^T, dzeta/ds, 0], [sum_c F_c Hess zeta_c, -2 A F / s, A], [0, 0, 1^T]] uses the stress
matrix of :mod:`hardpack.jamming.ellipsoids` (zeta + 1 scales as 1 / s^2). What the text says:

- at the torque-balancing orientations of Eq. 5.28 the density rises as 1 + s_phi eps, and "for
  small disk packings, we have found the perturbed ellipse packings to be second-order jammed
  sufficiently close to the sphere point" (Sec. 5.9.2.1);
- for a random assignment of orientations the expected density change is zero and torque balance
  fails (Sec. 5.9.2), so such a packing (orientations free) is not jammed;
- Fig. 5.17: at alpha = 1.025 the linear perturbation theory makes many new overlaps between
  particles that were nearly touching in the disk packing.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import scipy.sparse as sp
from test_jamming_support import jammed_disks

from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.jamming import verify
from hardpack.jamming.ellipsoids import (
    contacts_of_pairs,
    ellipsoid_contacts,
    rigidity_transpose_full,
    stiffness_matrix_full,
)
from hardpack.jamming.near_sphere import ellipse_slope, slope_at_angles
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import dof_basis, verify_ellipsoids

EPS = 1e-3


def _ellipses(x, lattice, axes, angles) -> Packing:
    return Packing(x, lattice=lattice, shape=Ellipsoids(axes, angles), allow_overlap=True)


def kkt_newton(x, lattice, base, angles, scale, pairs, forces, rotate=True, tol=1e-13, iters=30):
    """Jamming point of ellipses on a fixed contact network (module docstring): Newton's method
    on the KKT system of max s s.t. zeta_c(Q, s) >= 0, particle 0's translation anchored.
    ``rotate=False`` freezes the orientations (force balance only). Returns (x, angles, s, F, the
    residual norms) with F conjugate to zeta."""
    i, j, shift = pairs
    n, m = len(x), len(i)
    history = []
    for _ in range(iters):
        net = contacts_of_pairs(_ellipses(x, lattice, base * scale, angles), i, j, shift, positions=x)
        t, _ = dof_basis(net, np.ones(n, bool))
        keep = np.ones(t.shape[1], bool)
        keep[:2] = False
        if not rotate:
            keep &= np.tile([True, True, False], n)
        t = t[:, np.flatnonzero(keep)]
        a_t = (sp.diags(net.scale) @ rigidity_transpose_full(net) @ t).toarray()  # grad zeta rows
        hess = (t.T @ stiffness_matrix_full(net, -forces * net.scale) @ t).toarray()  # sum F Hess zeta
        balance = a_t.T @ forces
        res = np.concatenate([net.zeta, balance, [forces.sum() - m]])
        history.append(float(np.abs(res).max()))
        if history[-1] < tol:
            break
        k = a_t.shape[1]
        jac = np.zeros((m + k + 1, k + 1 + m))
        jac[:m, :k], jac[:m, k] = a_t, -2.0 * (net.zeta + 1.0) / scale
        jac[m:m + k, :k], jac[m:m + k, k], jac[m:m + k, k + 1:] = hess, -2.0 * balance / scale, a_t.T
        jac[-1, k + 1:] = 1.0
        step = np.linalg.solve(jac, -res)
        dq = (t @ step[:k]).reshape(n, 3)
        x, angles = x + dq[:, :2], angles + dq[:, 2]
        scale, forces = scale + step[k], forces + step[k + 1:]
    return x, angles, scale, forces, history


@functools.lru_cache(maxsize=1)
def disk_backbone():
    """(positions, radii, lattice, pairs, forces, slope) of the disk backbone's contacts."""
    disks = jammed_disks()
    ref = verify(disks, tests=("local", "collective"))
    backbone = ~ref.rattler
    net = ref.network
    use = net.among(backbone) & (ref.forces.forces > 0)
    index = np.full(disks.n_particles, -1)
    index[backbone] = np.arange(backbone.sum())
    pairs = (index[net.i[use]], index[net.j[use]], net.shift[use])
    radii = disks.radii[backbone]
    forces = ref.forces.forces[use]
    slope = ellipse_slope(net.separation[use], pairs[0], pairs[1], forces, radii)
    return net.positions[backbone], radii, np.array(disks.lattice), pairs, forces, slope, net.separation[use]


def jamming_point(eps, angles, rotate=True):
    x0, radii, lattice, pairs, forces, slope, sep = disk_backbone()
    s_angles = slope_at_angles(sep, pairs[0], pairs[1], forces, radii, angles)
    base = np.column_stack([radii, radii / (1.0 + eps)])
    scale = 1.0 + eps * (1.0 + s_angles) / 2.0  # first order: s_phi = 2 dmu / eps - 1
    start = contacts_of_pairs(_ellipses(x0, lattice, base * scale, angles), *pairs, positions=x0)
    f = forces / start.scale
    f *= len(f) / f.sum()
    x, ang, s, f, history = kkt_newton(x0.copy(), lattice, base, angles.copy(), scale, pairs, f, rotate)
    return _ellipses(x, lattice, base * s, ang), s, f, history, s_angles


def test_torque_balanced_ellipses_are_second_order_jammed():
    """alpha = 1.001 at the orientations of Eq. 5.28: Newton converges (quadratically), the density
    ratio (s^2 / alpha) is 1 + s_phi eps to O(eps^2), every contact carries force, no other pair
    overlaps, and the packing (Z = 3.97 < 2 d_f = 6, hypostatic) is jammed at second order."""
    slope = disk_backbone()[5]
    packing, s, f, history, _ = jamming_point(EPS, slope.angles)
    assert history[-1] < 1e-13 and len(history) <= 8
    density = s * s / (1.0 + EPS) - 1.0
    assert density / EPS == pytest.approx(slope.slope, abs=20 * EPS)
    assert f.min() > 0
    res = verify_ellipsoids(packing)
    assert res.network.n_contacts == len(f)  # no pair beyond the disk contacts closes
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.isostaticity_gap < 0 and res.collective.n_floppy > 0
    assert not res.collective.first_order_rigid and res.collective.lp_flex  # hypostatic
    assert not res.rattler.any()


def test_random_orientations_are_not_jammed():
    """Random orientations frozen at the jamming point of force balance alone: the density change
    is -O(eps) small (zero in expectation, Sec. 5.9.2) and, with the rotations free, there is no
    self-stress with torque balance: not jammed at first order."""
    x0, radii = disk_backbone()[:2]
    angles = np.random.default_rng(0).uniform(-np.pi / 2, np.pi / 2, len(radii))
    packing, s, f, history, s_angles = jamming_point(EPS, angles, rotate=False)
    assert history[-1] < 1e-13 and f.min() > 0
    density = s * s / (1.0 + EPS) - 1.0
    assert density / EPS == pytest.approx(s_angles, abs=20 * EPS)
    assert abs(s_angles) < disk_backbone()[5].slope / 10
    res = verify_ellipsoids(packing, local=False)
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "first"
    assert res.collective.stress_margin < 0 and res.collective.lp_flex


def test_fig_5_17_linear_perturbation_overlaps_near_contacts():
    """Fig. 5.17: extrapolate the jamming point linearly from alpha = 1.001 to 1.025 (the linear
    perturbation theory: Q(eps) = Q0 + eps dQ/deps): pairs that are not contacts of the disk
    packing overlap, more at 1.025 than at 1.005, and all of them were nearly touching disks: gaps
    below 0.1 of the diameter (the first coordination shell, Donev 2006, Sec. 4.6.2.1)."""
    x0, radii, lattice = disk_backbone()[:3]
    slope = disk_backbone()[5]
    packing, s, *_ = jamming_point(EPS, slope.angles)
    counts = []
    for eps in (0.005, 0.025):
        k = eps / EPS
        disp = (packing.positions - x0) * k
        angles = slope.angles + (packing.shape.orientations - slope.angles) * k
        axes = np.column_stack([radii, radii / (1.0 + eps)]) * (1.0 + (s - 1.0) * k)
        net = ellipsoid_contacts(_ellipses(x0 + disp, lattice, axes, angles), 0.5)
        disk_sep = net.separation - disp[net.j] + disp[net.i]  # the same image in the disk packing
        disk_gap = np.linalg.norm(disk_sep, axis=1) / (radii[net.i] + radii[net.j]) - 1.0
        assert np.abs(disk_gap).min() < 1e-12  # the disk contacts are there (zero disk gap)
        new = (net.zeta < 0) & (disk_gap > 1e-9)  # overlaps of pairs that were not disk contacts
        assert np.all(disk_gap[new] < 0.1)
        old = disk_gap < 1e-9  # "the original contacts ... are maintained relatively well"
        assert np.median(np.abs(net.gap[old])) < 0.2 * eps
        counts.append(int(new.sum()))
    assert 0 < counts[0] < counts[1]


def test_sparse_shifted_form_agrees_with_the_dense_test():
    """Donev 2006, Sec. 5.6: the smallest eigenvalue of k A A^T + k P_T + K (eigsh, shift-invert)
    is positive exactly when the projected stiffness is positive definite; for large k it tends
    to lambda_min(K_V) (relative difference O(1/k))."""
    packing, *_ = jamming_point(EPS, disk_backbone()[5].angles)
    dense = verify_ellipsoids(packing, method="dense", local=False)
    sparse = verify_ellipsoids(packing, method="sparse", local=False)
    assert dense.verdict == sparse.verdict == Verdict.JAMMED
    assert sparse.order == dense.order == "second"
    assert sparse.collective.lambda_min == pytest.approx(dense.collective.lambda_min, rel=1e-2)
    assert sparse.fallbacks["sparse_eigsh_dense"] == 0
    # the counts from the inertia of LDL^T factorisations
    assert (sparse.collective.n_stresses, sparse.collective.n_floppy) == (dense.collective.n_stresses,
                                                                         dense.collective.n_floppy)


@pytest.mark.slow
def test_sparse_shifted_form_finds_a_negative_mode():
    """The 2 x 2 supercell of that packing (N = 248): its floppy modes of the supercell's wave
    vectors are not all blocked (dense: second-order flexible with a unique self-stress); the
    sparse path sees the negative eigenvalue (the shift put below it by bisection on the inertia
    of LDL^T factorisations, which also count the self-stresses and floppy modes)."""
    packing, *_ = jamming_point(EPS, disk_backbone()[5].angles)
    big = packing.tiled(2)
    dense = verify_ellipsoids(big, method="dense", local=False)
    sparse = verify_ellipsoids(big, method="sparse", local=False)
    assert dense.verdict == Verdict.NOT_JAMMED and dense.order == "second"
    assert dense.collective.n_stresses == 1
    assert sparse.verdict == Verdict.NOT_JAMMED and sparse.order == "second"
    assert (sparse.collective.n_stresses, sparse.collective.n_floppy) == (1, dense.collective.n_floppy)
    assert sparse.collective.lambda_min < 0
    assert sparse.collective.lambda_min == pytest.approx(dense.collective.lambda_min, rel=0.2)
