"""Ellipses and ellipsoids between flat hard walls: wall contacts in the first- and second-order
jamming tests (Donev 2006, Sec. 3.2.2.1 for the walls, Sec. 4.4.3 for the fixed wall point,
Secs. 5.5.1-5.5.3 for the tests).

A particle touches the wall with outward normal n (n = -e_k for x_k = 0, +e_k for x_k = L_k) at
its farthest point along n, p = x + X^-1 n / s, s = sqrt(n^T X^-1 n); the gap is
h = x_k - s or L_k - x_k - s, the row of A^T is (-n, -(p - x) x n) and the second-order term is
Hess h, whose only nonzero block is the rotational one, -Hess s
(:func:`hardpack.jamming.ellipsoids.plane_gap_hessian`). Exact cases, derived in the tests'
docstrings:

- an ellipse (a > b) filling the box [0, 2a] x [0, 2b]: floppy at first order (its rotation),
  jammed at second order with lambda_min = 2 (a^2 - b^2)(1 / b - 1 / a); the box 1% taller: a
  rattler; tilted by theta in its bounding box: jammed at first order, F proportional to the
  extents; the same for ellipsoids and spheroids in 3D (a tilted general ellipsoid turns along a
  curve of rotations that keep all three extents: the second order is zero, undetermined);
- an ellipse between the two walls of a slit slides along it: a rattler, not jammed;
- disks and spheres given as ellipses and ellipsoids with equal semiaxes: the sphere verifier's
  verdicts, counts and forces (Fig. 4.4's honeycomb in a box, and compressed packings).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation
from test_jamming_walls import honeycomb_in_box

from hardpack.errors import InvalidInputError
from hardpack.geometry.boundaries import HardWalls
from hardpack.geometry.contact import inverse_shapes
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.io import load_packing
from hardpack.jamming import verify
from hardpack.jamming.ellipsoids import (
    contact_hessians,
    displaced,
    ellipsoid_contacts,
    generators,
    plane_gap_hessian,
    rigidity_transpose_full,
    stiffness_matrix_full,
)
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import verify_ellipsoids

DISKS_IN_BOX = Path(__file__).parent / "data" / "disks_walls_n12.nc"
SPHERES_IN_CHANNEL = Path(__file__).parent / "data" / "spheres_walls_n10.nc"


def orientation(d: int, seed: int):
    """A random orientation: an angle in 2D, a quaternion (w, x, y, z) in 3D."""
    if d == 2:
        return float(np.random.default_rng(seed).uniform(0, np.pi))
    return np.roll(Rotation.random(random_state=seed).as_quat(), 1)


def extents(semiaxes, orient) -> np.ndarray:
    """sqrt(e_k^T X^-1 e_k): half the width of the particle along each axis."""
    semiaxes = np.asarray(semiaxes, float)
    inv = inverse_shapes(semiaxes[None, :], np.asarray(orient, float).reshape(1, -1))[0]
    return np.sqrt(np.diag(inv))


def one(semiaxes, orient, lengths, axes=None, centre=None) -> Packing:
    """One particle between hard walls on ``axes`` (default all) of the box ``lengths``, centred."""
    lengths = np.asarray(lengths, float)
    d = lengths.size
    centre = lengths / 2 if centre is None else np.asarray(centre, float)
    return Packing(centre[None, :], lattice=np.diag(lengths), allow_overlap=True,
                   shape=Ellipsoids([semiaxes], [orient]), boundary=HardWalls(list(range(d)) if axes is None else axes))


def as_ellipsoids(p: Packing) -> Packing:
    """The spheres of ``p`` as ellipsoids with equal semiaxes, between the same walls."""
    n, d = p.n_particles, p.dim
    orient = np.zeros(n) if d == 2 else np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Packing(p.positions, lattice=p.lattice, boundary=p.boundary, allow_overlap=True,
                   shape=Ellipsoids(np.repeat(p.radii[:, None], d, axis=1), orient))


def keyed(net, values) -> dict:
    """Per-contact values keyed by (i, j) for a pair, (i, -1 - wall number) for a wall contact."""
    return {(int(i), int(j) if w < 0 else -1 - int(w)): v for i, j, w, v in zip(net.i, net.j, net.wall, values)}


# ------------------------------------------------------------------------------------ (1)
@pytest.mark.parametrize("d, semiaxes, seed", [
    (2, [1.3, 0.6], 1), (2, [0.5, 2.0], 2),
    (3, [1.2, 0.5, 0.8], 3), (3, [0.4, 0.4, 1.5], 4), (3, [2.0, 0.3, 0.9], 5),
])
def test_plane_gap_gradient_and_hessian_match_finite_differences(d, semiaxes, seed):
    """One randomly oriented particle in a closed box, 0.004 and 0.006 of its largest semiaxis from
    the walls x_k = 0 and x_k = L_k. The exact gap h = (x_k or L_k - x_k) - sqrt((X^-1)_kk) of
    every wall, from the contacts of the packing moved by q (centre by q[:d], orientation turned
    by exp(W(q[d:])) with :func:`displaced`, the parametrisation of the pair Hessians), against
    central differences (step 1e-4): its gradient is the row of A^T, its Hessian that of
    :func:`contact_hessians` and :func:`plane_gap_hessian`, with exactly zero translation blocks."""
    orient = orientation(d, seed)
    semiaxes = np.asarray(semiaxes, float)
    amax = semiaxes.max()
    w = extents(semiaxes, orient)
    x0 = w + 0.004 * amax
    p0 = one(semiaxes, orient, 2 * w + 0.01 * amax, centre=x0)
    net = ellipsoid_contacts(p0, 0.5)
    assert net.n_contacts == net.n_wall_contacts == 2 * d
    assert net.wall.tolist() == list(range(2 * d))  # 2 k: x_k = 0, 2 k + 1: x_k = L_k
    np.testing.assert_allclose(net.gap * amax, np.tile([0.004, 0.006], d) * amax, rtol=1e-9)
    f = d + generators(d).shape[0]
    at = rigidity_transpose_full(net).toarray()
    hess = contact_hessians(net)
    x_inv = net.shape_inv[0]

    def gaps(q):
        moved = ellipsoid_contacts(displaced(p0, x0[None, :] + q[:d], q[None, d:], 1.0), 0.5)
        return dict(zip(moved.wall.tolist(), moved.gap * amax))

    e, eye = 1e-4, np.eye(f)
    for c, wall in enumerate(net.wall.tolist()):
        def h(q, wall=wall):
            return gaps(q)[wall]

        grad = np.array([(h(e * eye[s]) - h(-e * eye[s])) / (2 * e) for s in range(f)])
        np.testing.assert_allclose(at[c], grad, atol=1e-7)
        fd = np.array([[(h(e * (eye[s] + eye[t])) - h(e * (eye[s] - eye[t])) - h(e * (eye[t] - eye[s]))
                         + h(-e * (eye[s] + eye[t]))) / (4 * e * e) for t in range(f)] for s in range(f)])
        np.testing.assert_allclose(hess[c, :f, :f], fd, atol=1e-6)
        assert np.abs(fd).max() > 0.1  # the rotational block is not trivially small
        np.testing.assert_array_equal(plane_gap_hessian(net.normal[c], x_inv), hess[c, :f, :f])
        assert not hess[c, :d].any() and not hess[c, :, :d].any() and not hess[c, f:].any()


def test_plane_gap_hessian_of_aligned_particles_in_closed_form():
    """Aligned with the axes, X^-1 = diag(a_k^2). 2D, wall y = b (n = e_y): s(theta)^2 =
    b^2 cos^2 theta + a^2 sin^2 theta, so s = b + (a^2 - b^2) theta^2 / (2 b) + O(theta^4) and
    h_theta,theta = -(a^2 - b^2) / b. 3D, wall normal e_k: a rotation about e_q (q != k) turns
    e_k towards the third axis m, s^2 = a_k^2 cos^2 + a_m^2 sin^2, so h_qq = -(a_m^2 - a_k^2) / a_k;
    the rotation about e_k itself leaves s alone, and there are no cross terms."""
    a, b = 2.0, 0.7
    np.testing.assert_allclose(plane_gap_hessian([0.0, 1.0], np.diag([a * a, b * b]))[2:, 2:],
                               [[-(a * a - b * b) / b]], rtol=1e-14)
    np.testing.assert_allclose(plane_gap_hessian([-1.0, 0.0], np.diag([a * a, b * b]))[2:, 2:],
                               [[-(b * b - a * a) / a]], rtol=1e-14)
    ax = np.array([1.5, 1.0, 0.6])
    for k in range(3):
        expected = np.zeros(3)
        for q in range(3):
            if q != k:
                m = 3 - q - k
                expected[q] = -(ax[m] ** 2 - ax[k] ** 2) / ax[k]
        for sign in (1.0, -1.0):
            got = plane_gap_hessian(sign * np.eye(3)[k], np.diag(ax**2))
            np.testing.assert_allclose(got[3:, 3:], np.diag(expected), rtol=1e-14, atol=1e-15)


# ------------------------------------------------------------------------------------ (2)
def test_disks_as_ellipses_in_a_box_match_the_sphere_verifier():
    """12 equal disks compressed in a closed box (``hardpack init --boundary hard_walls`` and
    ``hardpack compress``, seed 1, reduced pressure 1e12): the sphere verifier finds one rattler
    and the other 11 collectively jammed and isostatic, M_b = 23 = N_f + 1 with N_f = 2 N_b = 22
    (no trivial motion in a closed box), 10 of them wall contacts. As ellipses with equal semiaxes
    (spins removed): jammed at first order, the same rattler, contacts (walls with the same numbers
    2 k, 2 k + 1) and counts, one self-stress, so the same forces (both of mean 1 over the M_b)
    and total wall reaction."""
    disks = load_packing(DISKS_IN_BOX)
    assert disks.boundary == HardWalls([0, 1])
    spheres = verify(disks, tests=("local", "collective"))
    res = verify_ellipsoids(as_ellipsoids(disks))
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert np.flatnonzero(res.rattler).tolist() == np.flatnonzero(spheres.rattler).tolist() == [0]
    c = res.collective
    assert c.n_constraints == spheres.statics.n_contacts == 23
    assert c.n_dof == spheres.statics.n_dof_collective == 22
    assert c.n_stresses == 1 and c.n_floppy == 0 and c.lp_flex is False and c.first_order_rigid
    assert res.network.n_wall_contacts == spheres.network.n_wall_contacts == 10
    assert res.n_backbone_wall_contacts == spheres.statics.n_wall_contacts == 10
    assert res.z_mean == pytest.approx(spheres.statics.z_mean, rel=1e-15)
    mine, ref = keyed(res.network, res.contact_forces), keyed(spheres.network, spheres.forces.forces)
    assert set(mine) == set(ref)
    np.testing.assert_allclose([mine[k] for k in ref], [ref[k] for k in ref], rtol=1e-9, atol=1e-12)
    assert res.wall_force == pytest.approx(spheres.statics.wall_force, rel=1e-9)
    ds = res.to_dataset()
    assert ds.attrs["n_wall_contacts"] == 10 and "hard walls" in ds.attrs["boundary"]
    np.testing.assert_array_equal(np.sort(ds["contact_wall"].values[ds["contact_wall"].values >= 0]),
                                  np.sort(spheres.network.wall[spheres.network.is_wall]))


def test_spheres_as_ellipsoids_in_a_channel_match_the_sphere_verifier():
    """10 spheres compressed between walls on x and z, periodic along y (seed 3, reduced pressure
    1e12): collectively jammed with M_b = 36 (16 wall contacts) and N_f = 3 N - 1 = 29: the
    translation along y, the one periodic axis, is the only trivial motion; 7 self-stresses. As
    ellipsoids with three equal semiaxes: jammed at first order with the same counts; the sphere
    forces are a self-stress of the ellipsoid rigidity matrix (force balance of every particle,
    walls included), and both LPs pick the same self-stress (measured: the same total wall
    reaction)."""
    packing = load_packing(SPHERES_IN_CHANNEL)
    assert packing.boundary == HardWalls([0, 2])
    spheres = verify(packing, tests=("local", "collective"))
    res = verify_ellipsoids(as_ellipsoids(packing))
    c = res.collective
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert c.n_constraints == spheres.statics.n_contacts == 36 and c.n_dof == spheres.statics.n_dof_collective == 29
    assert c.n_stresses == 7 and c.n_floppy == 0 and not res.rattler.any()
    assert res.n_backbone_wall_contacts == spheres.statics.n_wall_contacts == 16
    net = res.network
    index = keyed(net, range(net.n_contacts))
    f = np.zeros(net.n_contacts)
    for key, v in keyed(spheres.network, spheres.forces.forces).items():
        f[index[key]] = v
    assert np.abs(rigidity_transpose_full(net).T @ f).max() < 1e-12 * f.max()
    assert res.wall_force == pytest.approx(spheres.statics.wall_force, rel=1e-9)


def test_fig_4_4_honeycomb_as_ellipses_is_locally_but_not_collectively_jammed():
    """Donev 2006, Fig. 4.4: the honeycomb Nc = (3, 2) of 24 disks in a hard-wall box is locally
    but not collectively jammed (sphere verifier: 29 disk contacts and 14 wall contacts, M = 43
    < N_f = 48, hypostatic). As ellipses with equal semiaxes: every disk locally jammed at first
    order (no rattler), the same 43 contacts (walls 3, 3, 4, 4 on the four walls) and N_f = 48;
    a unique self-stress (the sphere one: the same total wall reaction) and 6 floppy modes, one
    of negative stiffness: not jammed, at second order. (The stiffness of a disk contact is
    never positive: -F Hess |r_ij| <= 0 and a flat wall's Hess h of a disk is zero.) The floppy
    mode is a first-order flex that keeps every contact."""
    p = honeycomb_in_box()
    spheres = verify(p, tests=("local", "collective"))
    res = verify_ellipsoids(as_ellipsoids(p))
    assert spheres.local is True and spheres.collective is False
    net, c = res.network, res.collective
    assert net.n_contacts == spheres.network.n_contacts == 43 and net.n_wall_contacts == 14
    assert sorted(np.bincount(net.wall[net.is_wall])) == [3, 3, 4, 4]
    assert not res.rattler.any() and (res.local == Verdict.JAMMED).all() and (res.local_order == 1).all()
    assert c.n_dof == spheres.statics.n_dof_collective == 48 and c.n_constraints == 43
    assert c.n_stresses == 1 and c.n_floppy == 6
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "second" and c.lambda_min < 0
    assert res.wall_force == pytest.approx(spheres.statics.wall_force, rel=1e-9)
    motion = res.unjamming_motion()
    rate = rigidity_transpose_full(net) @ motion.ravel()
    assert np.abs(rate).max() < 1e-12 and np.abs(motion).max() > 0.1


# ------------------------------------------------------------------------------------ (3)
@pytest.mark.parametrize("a, b", [(2.0, 1.0), (1.0, 0.6)])
def test_ellipse_filling_a_box_is_floppy_at_first_order_and_jammed_at_second(a, b):
    """An ellipse (a > b) aligned with the axes at the centre of the box [0, 2a] x [0, 2b] touches
    the four walls at its tips p = x +- a e_x, x +- b e_y, where the lever is along the normal:
    r_C x n = 0, so the rows of A^T are (-n, 0). A F = 0 gives F_left = F_right and F_bottom =
    F_top: two self-stresses, both strict in the sum, and LP 5.9 (mean 1, max min F) picks all 1.
    Rank 2 < 3 dof: the rotation is a first-order floppy mode (d(width)/dtheta = 0 at theta = 0),
    so the first-order test alone does not jam it. Second order: the half-height is
    sqrt(b^2 cos^2 + a^2 sin^2) = b + (a^2 - b^2) theta^2 / (2 b) and the half-width
    a - (a^2 - b^2) theta^2 / (2 a), so h'' = -(a^2 - b^2) / b at the top and bottom walls and
    +(a^2 - b^2) / a at the sides; with F = 1 the stiffness is -sum F h'' =
    2 (a^2 - b^2)(1 / b - 1 / a) > 0: jammed at second order (a self-stress with F_x / a >
    F_y / b would not block it: the choice of the self-stress matters)."""
    res = verify_ellipsoids(one([a, b], 0.0, [2 * a, 2 * b]))
    net, c = res.network, res.collective
    assert net.n_contacts == net.n_wall_contacts == 4 and net.wall.tolist() == [0, 1, 2, 3]
    at = rigidity_transpose_full(net).toarray()
    np.testing.assert_allclose(at, [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]], atol=1e-15)
    np.testing.assert_allclose(net.lever_i, [[-a, 0], [a, 0], [0, -b], [0, b]], atol=1e-15)
    assert c.n_dof == 3 and c.n_stresses == 2 and c.n_floppy == 1
    assert not c.first_order_rigid and c.lp_flex is True  # the first-order test alone: a flex
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.local[0] == Verdict.JAMMED and res.local_order[0] == 2
    np.testing.assert_allclose(c.forces, 1.0, rtol=1e-12)
    assert c.lambda_min == pytest.approx(2 * (a * a - b * b) * (1 / b - 1 / a), rel=1e-12)
    assert res.wall_force == pytest.approx(4.0)


def test_ellipse_in_a_box_one_percent_taller_is_a_rattler():
    """The box [0, 2a] x [0, 2.02 b]: only the side walls touch, with normals -+e_x that do not
    span the plane; the ellipse slides along y keeping both gaps exactly: not locally jammed, at
    first order, a rattler, and nothing is jammed. Without the local test the collective one finds
    the unique self-stress F = (1, 1) and the floppy space {v_y, theta}, where the stiffness is
    0 for v_y and -2 (a^2 - b^2) / a for the rotation (the half-width shrinks): not jammed, at
    second order, lambda_min = -2 (a^2 - b^2) / a."""
    a, b = 2.0, 1.0
    p = one([a, b], 0.0, [2 * a, 2.02 * b])
    res = verify_ellipsoids(p)
    assert res.network.n_wall_contacts == 2 and res.network.wall.tolist() == [0, 1]
    assert res.rattler.all() and res.verdict == Verdict.NOT_JAMMED and res.order == "first"
    assert res.local[0] == Verdict.NOT_JAMMED and res.local_order[0] == 1
    whole = verify_ellipsoids(p, local=False)
    c = whole.collective
    assert c.n_stresses == 1 and c.n_floppy == 2
    assert whole.verdict == Verdict.NOT_JAMMED and whole.order == "second"
    assert c.lambda_min == pytest.approx(-2 * (a * a - b * b) / a, rel=1e-12)


@pytest.mark.parametrize("theta", [0.5, 2.0])
def test_tilted_ellipse_in_its_bounding_box_is_jammed_at_first_order(theta):
    """An ellipse turned by theta (not a multiple of pi / 2) in its bounding box [0, 2 w_x] x
    [0, 2 w_y], w_k = sqrt((X^-1)_kk) = sqrt(e_k^T X^-1 e_k), touching all four walls. The half-widths
    change at first order, w_x' = (b^2 - a^2) sin theta cos theta / w_x = -w_y' w_y / w_x (from
    w_x^2 + w_y^2 = a^2 + b^2): either sense of rotation widens the ellipse along one axis, so no
    first-order flex. The rows (-n, -(p - x) x n), p - x = X^-1 n / w: both side walls have the
    rotational entry X^-1_xy / w_x, top and bottom -X^-1_xy / w_y, so torque balance gives
    F_x / w_x = F_y / w_y: the unique self-stress F proportional to (w_x, w_x, w_y, w_y), strict;
    rank 3 = dof, no floppy mode: jammed at first order."""
    a, b = 2.0, 1.0
    w = extents([a, b], theta)
    res = verify_ellipsoids(one([a, b], theta, 2 * w))
    c = res.collective
    assert res.network.n_wall_contacts == 4 and c.n_stresses == 1 and c.n_floppy == 0
    assert res.verdict == Verdict.JAMMED and res.order == "first" and c.lp_flex is False
    np.testing.assert_allclose(c.forces, np.repeat(w, 2) * 4 / (2 * w.sum()), rtol=1e-12)
    inv = res.network.shape_inv[0]
    np.testing.assert_allclose(rigidity_transpose_full(res.network).toarray()[:, 2],
                               [inv[0, 1] / w[0]] * 2 + [-inv[0, 1] / w[1]] * 2, rtol=1e-12)


@pytest.mark.parametrize("semiaxes", [[1.5, 1.0, 0.6], [0.6, 1.5, 1.0], [0.5, 0.5, 1.5], [1.0, 1.0, 0.4]])
def test_ellipsoid_filling_a_box_is_jammed_at_second_order(semiaxes):
    """An ellipsoid with semiaxes a_k along e_k centred in the box [0, 2 a_1] x [0, 2 a_2] x
    [0, 2 a_3] touches the six walls at its tips (torques zero): F_k equal on the two walls of
    each axis, three self-stresses, LP 5.9 picks all 1. The rotations are floppy at first order
    (a spheroid's spin about its axis is removed: 5 dof, 2 floppy). Second order
    (:func:`test_plane_gap_hessian_of_aligned_particles_in_closed_form`): the rotation about e_q
    turns the two other axes k, m into each other, h_qq = -(a_m^2 - a_k^2) / a_k on the walls of
    k and the same with k, m swapped, so with F = 1 the stiffness is diagonal with
    K_qq = 2 (a_k^2 - a_m^2)(1 / a_m - 1 / a_k) = 2 (a_k - a_m)^2 (a_k + a_m) / (a_k a_m) >= 0,
    zero only for the spin of a spheroid: jammed at second order with lambda_min the smallest
    K_qq over the nontrivial rotations. A box 1% larger along one axis: a rattler."""
    ax = np.asarray(semiaxes, float)
    res = verify_ellipsoids(one(ax, [1.0, 0.0, 0.0, 0.0], 2 * ax))
    net, c = res.network, res.collective
    spheroid = len(set(ax.tolist())) == 2
    assert net.n_wall_contacts == 6 and c.n_stresses == 3
    assert c.n_dof == (5 if spheroid else 6) and c.n_floppy == (2 if spheroid else 3)
    assert not c.first_order_rigid and res.verdict == Verdict.JAMMED and res.order == "second"
    np.testing.assert_allclose(c.forces, 1.0, rtol=1e-12)
    stiff = np.zeros(3)
    for q in range(3):
        k, m = [r for r in range(3) if r != q]
        stiff[q] = 2 * (ax[k] - ax[m]) ** 2 * (ax[k] + ax[m]) / (ax[k] * ax[m])
    k_full = stiffness_matrix_full(net, np.ones(6)).toarray()
    np.testing.assert_allclose(k_full[3:, 3:], np.diag(stiff), atol=1e-12)
    assert not k_full[:3].any()
    assert c.lambda_min == pytest.approx(stiff[stiff > 1e-12].min(), rel=1e-12)
    taller = verify_ellipsoids(one(ax, [1.0, 0.0, 0.0, 0.0], 2 * ax * [1, 1, 1.01]))
    assert taller.network.n_wall_contacts == 4 and taller.rattler.all()
    assert taller.verdict == Verdict.NOT_JAMMED and taller.local_order[0] == 1


@pytest.mark.parametrize("semiaxes, seed", [([0.5, 0.5, 1.5], 2), ([1.0, 1.0, 0.4], 3), ([1.5, 1.0, 0.6], 1)])
def test_tilted_ellipsoid_in_its_bounding_box(semiaxes, seed):
    """A randomly oriented ellipsoid in its bounding box (half-widths w_k = sqrt((X^-1)_kk)). As in
    2D, F proportional to (w_1, w_1, w_2, w_2, w_3, w_3) is a strict self-stress: the two walls of
    axis k have the rotational entry (X^-1 e_k x e_k) / w_k, and sum_k X^-1 e_k x e_k =
    sum_jk X^-1_jk e_j x e_k = 0 for a symmetric X^-1. It is the only one here (measured).

    The rotations keep the trace sum_k w_k^2 = sum a_k^2, so the three half-widths are two
    constraints on the rotation. A spheroid (two rotational dof) is held at first order: jammed.
    A general ellipsoid (three) keeps one floppy mode, and the rotations with the same three
    half-widths form a curve through the start (Schur-Horn: the matrices with the spectrum a_k^2
    and a given diagonal, inside the permutohedron, form a one-parameter family here), along
    which every contact stays closed: the stiffness on that mode is zero (lambda_min = 0 to
    round-off) and the verdict is undetermined, "higher orders would decide" -- here they are all
    zero, the particle is not jammed. The curve is found below: a rotation by 0.05 rad with the
    same half-widths to 1e-12."""
    ax = np.asarray(semiaxes, float)
    q0 = orientation(3, seed)
    w = extents(ax, q0)
    res = verify_ellipsoids(one(ax, q0, 2 * w))
    c, net = res.collective, res.network
    assert net.n_wall_contacts == 6 and c.n_stresses == 1
    np.testing.assert_allclose(c.forces, np.repeat(w, 2) * 6 / (2 * w.sum()), rtol=1e-9)
    if len(set(ax.tolist())) == 2:
        assert c.n_dof == 5 and c.n_floppy == 0
        assert res.verdict == Verdict.JAMMED and res.order == "first"
        return
    assert c.n_dof == 6 and c.n_floppy == 1
    assert res.verdict == Verdict.UNDETERMINED and abs(c.lambda_min) < 1e-12 * c.stiffness_scale
    mode = res.unjamming_motion()[0, 3:]
    mode /= np.linalg.norm(mode)
    r0 = Rotation.from_quat(np.roll(q0, -1))
    start = 0.05 * mode

    def residual(omega):
        turned = np.roll((Rotation.from_rotvec(omega) * r0).as_quat(), 1)
        return np.r_[extents(ax, turned) - w, (omega - start) @ mode]

    omega = least_squares(residual, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    assert np.abs(residual(omega)).max() < 1e-12 and np.linalg.norm(omega) > 0.049


# ------------------------------------------------------------------------------------ (4)
@pytest.mark.parametrize("walls", [[1], [0, 1]])
def test_ellipse_between_two_parallel_walls_slides_along_them(walls):
    """An ellipse (a = 2, b = 1) along x at the centre of a slit of height 2 b (walls on y only, x
    periodic with period 10 > 2 a, or walls on both axes with the side walls 3 away) touches the
    walls y = 0 and y = 2 b. Each gap h = (y or 2 b - y) - s does not depend on x: translating along
    x keeps both gaps exactly, so the ellipse is not locally jammed (decided at first order, as a
    disk with these two contacts: d vectors cannot positively span R^d, Donev 2006,
    Sec. 4.4.3.1): a rattler, and hardpack's verdict is *not jammed* (order "first"). The same for
    the disk a = b. Without the local test (slit): the slide along x is then the trivial
    translation of the one-particle backbone along the periodic axis and is projected out; what
    is left is the rotation, blocked at second order by the two walls (h'' = -(a^2 - b^2) / b each,
    F = 1): jammed at second order with lambda_min = 2 (a^2 - b^2) / b -- jammed only up to the
    slide, which is why the local test, which has no trivial motion, decides."""
    for a, b in ((2.0, 1.0), (1.0, 1.0)):
        p = one([a, b], 0.0, [10.0, 2 * b], axes=walls)
        res = verify_ellipsoids(p)
        assert res.network.n_wall_contacts == 2 and res.network.n_contacts == 2
        assert res.network.wall.tolist() == [2, 3]
        assert res.verdict == Verdict.NOT_JAMMED and res.order == "first" and res.rattler.all()
        assert res.local[0] == Verdict.NOT_JAMMED and res.local_order[0] == 1
        sphere = verify(Packing(p.positions, [b], p.lattice, boundary=p.boundary))
        assert sphere.local is False and sphere.local_rattler.all() and sphere.collective is False
    whole = verify_ellipsoids(one([2.0, 1.0], 0.0, [10.0, 2.0], axes=[1]), local=False)
    c = whole.collective
    assert c.n_dof == 2 and c.n_stresses == 1 and c.n_floppy == 1
    assert whole.verdict == Verdict.JAMMED and whole.order == "second"
    assert c.lambda_min == pytest.approx(2 * (4.0 - 1.0) / 1.0, rel=1e-12)


def test_tilted_ellipse_in_a_slit_turns_free_at_first_order():
    """The ellipse turned by 0.5 in a slit of its height 2 w_y (x periodic): the two rows
    (0, -+1, -X^-1_xy / w_y) sum to a pure torque, so A F = 0 has no solution F >= 0 but 0
    (no self-stress): turning towards the slit's axis opens both contacts, a strict first-order
    flex; not jammed at first order, even without the local test."""
    a, b, theta = 2.0, 1.0, 0.5
    w = extents([a, b], theta)
    for local in (True, False):
        res = verify_ellipsoids(one([a, b], theta, [10.0, 2 * w[1]], axes=[1]), local=local)
        assert res.network.n_wall_contacts == 2
        assert res.verdict == Verdict.NOT_JAMMED and res.order == "first"
    assert res.collective.n_stresses == 0 and res.collective.lp_flex is True


# ------------------------------------------------------------------------------------ (5)
def mirrored_pair(theta=0.5, a=2.0, b=1.0) -> Packing:
    """Two ellipses turned by +theta and -theta, mirror images in the line x = W / 2 of the box
    [0, W] x [0, 2 w_y], W = 4 w_x: each touches the floor, the ceiling, its side wall and the other
    at its farthest point along e_x, which lies on the mirror line (so the pair touches there with
    the normal e_x)."""
    w = extents([a, b], theta)
    return Packing([w, [3 * w[0], w[1]]], lattice=np.diag([4 * w[0], 2 * w[1]]),
                   shape=Ellipsoids([[a, b], [a, b]], [theta, -theta]), boundary=HardWalls([0, 1]))


@pytest.mark.parametrize("case", ["tilted", "mirrored", "disks", "tilted3d"])
def test_forces_and_torques_balance_on_every_particle(case):
    """Sum of the contact forces and of their torques about each particle's centre, from the contact
    geometry alone (force -F u at the contact point on i, +F u on j; a wall contact acts on its
    particle only): zero to round-off for the self-stress the verifier reports, with every wall
    reaction positive and the torques of single contacts not small."""
    if case == "tilted":
        w = extents([2.0, 1.0], 0.5)
        p = one([2.0, 1.0], 0.5, 2 * w)
    elif case == "mirrored":
        p = mirrored_pair()
    elif case == "disks":
        p = as_ellipsoids(load_packing(DISKS_IN_BOX))
    else:
        q = orientation(3, 2)
        p = one([0.5, 0.5, 1.5], q, 2 * extents([0.5, 0.5, 1.5], q))
    res = verify_ellipsoids(p)
    assert res.verdict == Verdict.JAMMED
    net, f = res.network, res.contact_forces
    assert (f[net.is_wall] > 0).all()
    n, d = net.n_particles, net.dim
    pair = ~net.is_wall

    def cross(r, u):
        return r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0] if d == 2 else np.cross(r, u)

    k = 1 if d == 2 else 3
    force, torque = np.zeros((n, d)), np.zeros((n, k))
    np.add.at(force, net.i, -f[:, None] * net.normal)
    np.add.at(force, net.j[pair], f[pair, None] * net.normal[pair])
    np.add.at(torque, net.i, cross(net.lever_i, -f[:, None] * net.normal).reshape(-1, k))
    np.add.at(torque, net.j[pair], cross(net.lever_j[pair], f[pair, None] * net.normal[pair]).reshape(-1, k))
    scale = f.max() * np.abs(net.lever_i).max()
    assert np.abs(force).max() < 1e-12 * f.max() and np.abs(torque).max() < 1e-12 * scale
    if case != "disks":
        single = np.abs(cross(net.lever_i, f[:, None] * net.normal)).max()
        assert single > 0.1 * scale
    if case == "mirrored":
        assert net.n_contacts == 7 and net.n_wall_contacts == 6 and res.order == "first"
        np.testing.assert_allclose(net.normal[pair], [[1.0, 0.0]], atol=1e-12)


# ------------------------------------------------------------------------------------ (6)
def test_refuses_particles_crossing_a_flat_wall_and_other_bad_input():
    """An ellipse crossing the floor or the ceiling (named, with h / a_max), a centre beyond a wall,
    and disks given as spheres are refused with a message that says what is wrong."""
    crossing = one([2.0, 1.0], 0.0, [4.0, 2.0], centre=[2.0, 0.9])
    with pytest.raises(InvalidInputError, match=r"particle 0 and the wall x_1 = 0, h / a_max = -0.05"):
        verify_ellipsoids(crossing)
    with pytest.raises(InvalidInputError, match=r"the wall x_1 = 2, h / a_max = -0.05"):
        verify_ellipsoids(one([2.0, 1.0], 0.0, [4.0, 2.0], centre=[2.0, 1.1]))
    with pytest.raises(InvalidInputError, match=r"centre of particle 0 lies beyond the wall x_1 = 2"):
        verify_ellipsoids(one([2.0, 1.0], 0.0, [10.0, 2.0], axes=[1], centre=[5.0, 5.0]))
    with pytest.raises(InvalidInputError, match=r"beyond the wall x_0 = 0"):
        ellipsoid_contacts(one([2.0, 1.0], 0.0, [10.0, 2.0], centre=[-0.5, 1.0]), 1e-9)
    with pytest.raises(InvalidInputError, match="this test is for ellipses and ellipsoids"):
        verify_ellipsoids(load_packing(DISKS_IN_BOX))


def test_cli_verify_stores_the_flat_wall_contacts_of_an_ellipse_packing(tmp_path):
    """``hardpack verify`` of the ellipse filling its box (a = 2, b = 1) writes the four wall
    contacts (numbers 0-3), their reactions (F = 1) and the second-order verdict."""
    from hardpack.cli import main
    from hardpack.io import load_dataset, save_packing

    save_packing(one([2.0, 1.0], 0.0, [4.0, 2.0]), tmp_path / "ellipse.nc")
    assert main(["verify", str(tmp_path / "ellipse.nc"), "--out", str(tmp_path / "v.nc")]) == 0
    ds = load_dataset(tmp_path / "v.nc")
    assert ds.attrs["jammed"] == 1 and ds.attrs["order"] == "second"
    assert ds.attrs["n_wall_contacts"] == 4 and ds.attrs["wall_force"] == pytest.approx(4.0)
    assert ds.attrs["boundary"] == "hard walls on axes [0, 1]"
    assert ds["contact_wall"].values.tolist() == [0, 1, 2, 3]
    np.testing.assert_allclose(ds["force"].values, 1.0, rtol=1e-12)
    assert ds.attrs["lambda_min"] == pytest.approx(3.0, rel=1e-12)
