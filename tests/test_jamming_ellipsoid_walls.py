"""Ellipses and ellipsoids in a spherical container: wall contacts in the first- and second-order
jamming tests (Donev 2006, Sec. 4.4.3 for the fixed wall point, Secs. 5.5.1-5.5.3 for the tests).

A wall contact of a particle is a strict local farthest point p of its surface from the
container centre c within the contact tolerance; its gap is h = R - |p - c|, its row in A^T is
(-n, -r_C x n) (n the radial unit vector at p, r_C = p - x) and its second-order term is
Hess h (:func:`hardpack.jamming.ellipsoids.wall_gap_hessian`). Exact cases:

- disks given as ellipses with equal semiaxes (spins removed) in a circular container: the sphere
  verifier's verdict, counts, unique self-stress and total wall reaction (a compressed packing of
  12 disks, isostatic: M_b = N_f + 1 = 24 with N_f = 2 N - 1, the container's rotation trivial);
- an ellipse (semiaxes a > b) centred in a circle of radius a touches it at both tips; derived in
  :func:`test_centred_ellipse_touching_at_both_tips`;
- the same for a prolate spheroid in a sphere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from hardpack.errors import InvalidInputError
from hardpack.geometry.boundaries import SphericalContainer
from hardpack.geometry.contact import pw_contact, shape_inverse
from hardpack.geometry.ellipsoid_container import local_farthest_body
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.io import load_packing
from hardpack.jamming import verify
from hardpack.jamming.ellipsoids import (
    ellipsoid_contacts,
    generators,
    rigidity_transpose_full,
    wall_gap_hessian,
)
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import verify_ellipsoids

DISKS_IN_CONTAINER = Path(__file__).parent / "data" / "disks_container_n12.nc"
SPHERES_IN_CONTAINER = Path(__file__).parent / "data" / "spheres_container_n10.nc"


def as_ellipses(p: Packing) -> Packing:
    """The disks of ``p`` as ellipses with equal semiaxes, in the same container."""
    n = p.n_particles
    return Packing(p.positions, lattice=p.lattice, boundary=p.boundary, allow_overlap=True,
                   shape=Ellipsoids(np.column_stack([p.radii, p.radii]), np.zeros(n)))


def centred(semiaxes, angle_or_quaternion, radius=None) -> Packing:
    """One ellipse or ellipsoid centred in a container of radius ``radius`` (default a_max)."""
    semiaxes = np.asarray(semiaxes, float)
    d = semiaxes.size
    radius = semiaxes.max() if radius is None else radius
    box = 2.0 * radius + 1.0
    centre = np.full(d, box / 2)
    orientation = np.asarray(angle_or_quaternion, float).reshape(1, -1) if d == 3 else [angle_or_quaternion]
    return Packing(centre[None, :], lattice=box * np.eye(d), allow_overlap=True,
                   shape=Ellipsoids(semiaxes[None, :], orientation),
                   boundary=SphericalContainer(tuple(centre), radius))


# ------------------------------------------------------------------------------------ (1)
def test_disks_as_ellipses_in_a_container_match_the_sphere_verifier():
    """12 disks compressed in a circular container (``hardpack compress``, reduced pressure 1e12,
    gaps below 5e-11): the sphere verifier finds them collectively jammed and isostatic
    (M_b = 24 = N_f + 1, N_f = 2 N - 1: the rotation about the centre is trivial) with 9 wall
    contacts. As ellipses with equal semiaxes (no spin dof): the same verdict at first order, the
    same contacts, one self-stress, which is the sphere one up to normalisation (both have mean
    1 over the M_b contacts), hence the same total wall reaction."""
    disks = load_packing(DISKS_IN_CONTAINER)
    spheres = verify(disks, tests=("local", "collective"))
    res = verify_ellipsoids(as_ellipses(disks))
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert np.array_equal(res.rattler, spheres.rattler)
    c = res.collective
    assert c.n_constraints == spheres.statics.n_contacts == 24
    assert c.n_dof == spheres.statics.n_dof_collective == 23
    assert c.n_stresses == 1 and c.n_floppy == 0 and c.lp_flex is False
    assert res.network.n_wall_contacts == spheres.network.n_wall_contacts == 9
    assert res.n_backbone_wall_contacts == spheres.statics.n_wall_contacts == 9
    assert res.wall_force == pytest.approx(spheres.statics.wall_force, rel=1e-9)
    # a wall contact is a contact of one particle: Z = (2 x 15 pairs + 9 walls) / 12 = 3.25 for both
    assert spheres.statics.z_mean == res.z_mean == pytest.approx(39 / 12, rel=1e-15)
    # contact by contact (walls keyed by particle)
    net, f = res.network, res.contact_forces
    mine = {(int(i), int(j) if w < 0 else -1): v for i, j, w, v in zip(net.i, net.j, net.wall, f)}
    sn = spheres.network
    ref = {(int(i), int(j) if w < 0 else -1): v for i, j, w, v in zip(sn.i, sn.j, sn.wall, spheres.forces.forces)}
    assert set(mine) == set(ref)
    np.testing.assert_allclose([mine[k] for k in ref], [ref[k] for k in ref], rtol=1e-9)
    ds = res.to_dataset()
    assert ds.attrs["n_wall_contacts"] == 9 and ds.attrs["wall_force"] == pytest.approx(res.wall_force)
    assert int((ds["contact_wall"].values == 0).sum()) == 9
    assert "spherical container" in ds.attrs["boundary"]


def test_spheres_as_ellipsoids_in_a_container_match_the_sphere_verifier():
    """10 spheres compressed in a spherical container (``hardpack compress``, reduced pressure
    1e12): collectively jammed, M_b = 29 with 10 wall contacts, N_f = 3 N - 3 = 27 (the three
    rotations about the centre are trivial), two self-stresses. As ellipsoids with three equal
    semiaxes (no rotation dof): jammed at first order with the same counts; the sphere verifier's
    forces are a self-stress of the ellipsoid rigidity matrix (force balance of every particle,
    walls included), and on this packing both LPs pick the same self-stress (measured: the same
    total wall reaction)."""
    spheres_packing = load_packing(SPHERES_IN_CONTAINER)
    spheres = verify(spheres_packing, tests=("local", "collective"))
    n = spheres_packing.n_particles
    as_ellipsoids = Packing(spheres_packing.positions, lattice=spheres_packing.lattice, allow_overlap=True,
                            boundary=spheres_packing.boundary,
                            shape=Ellipsoids(np.repeat(spheres_packing.radii[:, None], 3, 1), np.tile([1.0, 0, 0, 0], (n, 1))))
    res = verify_ellipsoids(as_ellipsoids)
    c = res.collective
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert c.n_constraints == spheres.statics.n_contacts == 29 and c.n_dof == spheres.statics.n_dof_collective == 27
    assert c.n_stresses == 2 and c.n_floppy == 0
    assert res.n_backbone_wall_contacts == spheres.statics.n_wall_contacts == 10
    net, sn = res.network, spheres.network
    index = {(int(i), int(j) if w < 0 else -1): k for k, (i, j, w) in enumerate(zip(net.i, net.j, net.wall))}
    f = np.zeros(net.n_contacts)
    for i, j, w, v in zip(sn.i, sn.j, sn.wall, spheres.forces.forces):
        f[index[(int(i), int(j) if w < 0 else -1)]] = v
    assert np.abs(rigidity_transpose_full(net).T @ f).max() < 1e-12 * f.max()
    assert res.wall_force == pytest.approx(spheres.statics.wall_force, rel=1e-9)


def test_the_disks_are_jammed_only_because_of_the_container():
    """The same 12 disks as ellipses in a periodic box large enough that no disk touches an image:
    the disks that touched the wall lose those contacts, and the packing is not jammed (every
    particle is a rattler, as for the sphere verifier)."""
    disks = load_packing(DISKS_IN_CONTAINER)
    free = Packing(disks.positions, lattice=disks.lattice + 2 * np.eye(2), allow_overlap=True,
                   shape=Ellipsoids(np.column_stack([disks.radii, disks.radii]), np.zeros(disks.n_particles)))
    res = verify_ellipsoids(free)
    assert res.network.n_wall_contacts == 0
    assert res.verdict == Verdict.NOT_JAMMED and res.rattler.all()
    assert verify(Packing(free.positions, disks.radii, free.lattice), tests=("local",)).local is False


# ------------------------------------------------------------------------------------ (2)
@pytest.mark.parametrize("a, b", [(2.0, 1.0), (1.0, 0.6)])
def test_centred_ellipse_touching_at_both_tips(a, b):
    """An ellipse of semiaxes a > b centred in a circle of radius R = a touches it at the two
    tips p = +-a e (e its long axis): two wall contacts, n = +-e, levers +-a e, so r_C x n = 0 and
    the rows of A^T are (-e, 0) and (+e, 0): the translation along e is blocked at first order;
    the rotation about the centre keeps the tips on the circle (the farthest distance stays a)
    and is the container's trivial rotation; the translation t across the axis is first-order
    floppy. A F = 0 gives F_+ = F_-, so with mean 1: F = (1, 1), a strict self-stress, unique.
    Second order (derived): with the centre at t e_perp, rho^2 = max_s a^2 (1 - s^2) + (t + b s)^2
    (s the sine of the eccentric angle) is attained at s = t b / (a^2 - b^2), rho^2 = a^2 +
    t^2 a^2 / (a^2 - b^2), so each tip's gap has h'' = -a / (a^2 - b^2) and the stiffness on the
    floppy mode is -sum F h'' = 2 a / (a^2 - b^2) > 0: jammed at second order, only because of the
    wall (without it the ellipse is free)."""
    for angle in (0.0, 0.7):
        res = verify_ellipsoids(centred([a, b], angle))
        net = res.network
        assert net.n_wall_contacts == 2 == net.n_contacts
        e = np.array([np.cos(angle), np.sin(angle)])
        np.testing.assert_allclose(np.sort(net.normal @ e), [-1.0, 1.0], atol=1e-12)
        at = rigidity_transpose_full(net).toarray()
        np.testing.assert_allclose(np.abs(at[:, :2] @ e), 1.0, atol=1e-12)
        np.testing.assert_allclose(at[:, 2], 0.0, atol=1e-12)
        c = res.collective
        assert c.n_dof == 2 and c.n_stresses == 1 and c.n_floppy == 1 and not c.first_order_rigid
        np.testing.assert_allclose(c.forces, 1.0, rtol=1e-12)
        assert res.verdict == Verdict.JAMMED and res.order == "second"
        assert c.lambda_min == pytest.approx(2 * a / (a * a - b * b), rel=1e-9)
        assert res.wall_force == pytest.approx(2.0)


def test_centred_ellipse_smaller_than_the_container_is_a_rattler():
    """The same ellipse in a container 1% wider has no contact: a rattler, not jammed."""
    res = verify_ellipsoids(centred([2.0, 1.0], 0.3, radius=2.02))
    assert res.network.n_contacts == 0 and res.rattler.all() and res.verdict == Verdict.NOT_JAMMED


def test_centred_prolate_spheroid_touching_at_both_tips():
    """A prolate spheroid (b, b, a) centred in a sphere of radius a: as for the ellipse, the two
    tip contacts block the translation along the axis; the spin about the axis is removed and the
    two other rotations are the container's trivial rotations (t = 2 in the reduced dof), so
    N_f = 5 - 2 = 3 with two floppy translations across the axis, each blocked at second order with
    stiffness 2 a / (a^2 - b^2) (the ellipse's calculation in the plane of the axis and the
    translation): jammed at second order, lambda_min = 2 a / (a^2 - b^2)."""
    a, b = 1.5, 0.5
    q = np.array([np.cos(0.4), np.sin(0.4) * 0.6, np.sin(0.4) * 0.8, 0.0])
    res = verify_ellipsoids(centred([b, b, a], q))
    c = res.collective
    assert res.network.n_wall_contacts == 2
    assert c.n_dof == 3 and c.n_floppy == 2 and c.n_stresses == 1
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert c.lambda_min == pytest.approx(2 * a / (a * a - b * b), rel=1e-9)


def test_ellipse_off_centre_touching_at_two_points_slides_towards_the_centre():
    """An ellipse (a, b) with its long axis along x and its centre at (0, s) from the container
    centre. Its farthest points (derived as in :func:`test_centred_ellipse_touching_at_both_tips`
    with t = s): sin(theta) = s b / (a^2 - b^2), p = (+-a cos theta, s + b sin theta), at
    rho^2 = a^2 + s^2 a^2 / (a^2 - b^2); with R = rho both touch (the mirror pair of the hard
    case). Rows: -(n, r_C x n) with n = p / R, r_C = p - (0, s). A F = 0 needs
    (F_+ + F_-) p_y / R = 0 with p_y > 0, so no self-stress: a strict first-order flex (moving
    towards the centre opens both contacts), not jammed -- a rattler."""
    a, b, s = 2.0, 1.0, 0.5
    sin = s * b / (a * a - b * b)
    radius = np.sqrt(a * a + s * s * a * a / (a * a - b * b))
    box = 2 * radius + 1
    c0 = np.full(2, box / 2)
    p = Packing((c0 + [0.0, s])[None, :], lattice=box * np.eye(2), shape=Ellipsoids([[a, b]], [0.0]),
                boundary=SphericalContainer(tuple(c0), radius), allow_overlap=True)
    net = ellipsoid_contacts(p, 1e-9)
    assert net.n_wall_contacts == 2
    rows = []
    for sign in (1.0, -1.0):
        point = np.array([sign * a * np.sqrt(1 - sin * sin), s + b * sin])
        n, lever = point / radius, point - [0.0, s]
        rows.append(-np.array([n[0], n[1], lever[0] * n[1] - lever[1] * n[0]]))
    at = rigidity_transpose_full(net).toarray()
    order = np.argsort(-at[:, 0])  # the + tip has the negative x entry: put it last
    np.testing.assert_allclose(at[order], np.array(rows)[np.argsort(-np.array(rows)[:, 0])], atol=1e-12)
    res = verify_ellipsoids(p)
    assert res.verdict == Verdict.NOT_JAMMED and res.rattler.all()
    assert res.local[0] == Verdict.NOT_JAMMED and res.local_order[0] == 1  # decided at first order


# ------------------------------------------------------------------------------------ (3)
def ellipse_flower(k=7, a=0.6, b=0.3):
    """A disk at the centre of a circular container and k ellipses (semiaxes a radial, b) around
    it at equal angles, centres at distance s, each touching its two neighbours (s by bisection on
    the Perram-Wertheim function), the disk (radius s - a) with its inner tip and the container
    (radius s + a) with its outer tip. The verifier finds a strict self-stress (its verdict is not
    derived here and not asserted)."""
    angles = np.pi / 2 + 2 * np.pi / k * np.arange(k)
    dirs = np.column_stack([np.cos(angles), np.sin(angles)])
    inv = np.empty((2, 2, 2))
    shape_inverse(np.array([a, b]), np.array([angles[0]]), inv[0])
    shape_inverse(np.array([a, b]), np.array([angles[1]]), inv[1])
    lo, hi = a, 20.0 * a
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if pw_contact(mid * (dirs[1] - dirs[0]), inv[0], inv[1], 0.5)[0] < 0 else (lo, mid)
    s = hi
    radius = s + a
    box = 2 * radius + 1
    c0 = np.full(2, box / 2)
    axes = np.vstack([[s - a, s - a], np.tile([a, b], (k, 1))])
    return Packing(np.vstack([c0, c0 + s * dirs]), lattice=box * np.eye(2), allow_overlap=True,
                   shape=Ellipsoids(axes, np.r_[0.0, angles]), boundary=SphericalContainer(tuple(c0), radius))


@pytest.mark.parametrize("packing", ["flower", "disks"])
def test_forces_and_torques_balance_on_every_particle(packing):
    """Sum of the contact forces (wall reactions included) and of their torques about the centre
    of each particle, from the contact geometry alone (force -F u on i at its contact point,
    +F u on j; a wall contact acts on its particle only): zero to round-off."""
    p = ellipse_flower() if packing == "flower" else as_ellipses(load_packing(DISKS_IN_CONTAINER))
    res = verify_ellipsoids(p)
    net, f = res.network, res.contact_forces
    assert (f[net.is_wall] > 0).all() and net.n_wall_contacts >= 3
    n, d = net.n_particles, net.dim
    force = np.zeros((n, d))
    torque = np.zeros(n)
    pair = ~net.is_wall
    np.add.at(force, net.i, -f[:, None] * net.normal)
    np.add.at(force, net.j[pair], f[pair, None] * net.normal[pair])
    cross = lambda r, u: r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]  # noqa: E731
    np.add.at(torque, net.i, cross(net.lever_i, -f[:, None] * net.normal))
    np.add.at(torque, net.j[pair], cross(net.lever_j[pair], f[pair, None] * net.normal[pair]))
    assert np.abs(force).max() < 1e-12 * f.max() and np.abs(torque).max() < 1e-12 * f.max()
    if packing == "flower":
        assert net.n_wall_contacts == 7 and net.n_contacts == 21 and res.collective.stress_margin > 0
        assert np.abs(torque).max() < 1e-12 * f.max() < np.abs(f[pair] * cross(net.lever_i[pair], net.normal[pair])).max()


# ------------------------------------------------------------------------------------ (4)
def _branches(x, rot, semiaxes, radius):
    """Gaps and lab points of every local farthest point (centre at the origin)."""
    pts = np.zeros((2, x.size))
    count = local_farthest_body(rot @ x, semiaxes, pts)
    lab = pts[:count] @ rot
    return radius - np.linalg.norm(lab, axis=1), lab


def _gap_along(q, x0, rot0, semiaxes, radius, ref):
    """The gap of the branch at ``ref`` after moving the centre by q[:d] and turning by q[d:]."""
    d = x0.size
    turn = sla.expm(np.einsum("a,aij->ij", q[d:], generators(d)))
    h, lab = _branches(x0 + q[:d], rot0 @ turn.T, semiaxes, radius)
    return h[np.argmin(np.linalg.norm(lab - (ref + q[:d]), axis=1))]


@pytest.mark.parametrize("d, semiaxes, centre", [
    (2, [1.2, 0.5], [0.3, -0.4]),
    (2, [2.0, 0.4], [0.1, 0.9]),  # long: a second local maximum (the other tip)
    (3, [0.4, 0.7, 1.1], [0.2, -0.3, 0.5]),
    (3, [0.3, 0.5, 2.0], [0.1, 0.8, 0.05]),  # long: a second local maximum
])
def test_wall_gap_gradient_and_hessian_match_finite_differences(d, semiaxes, centre):
    """Row of A^T and Hess h of every local farthest point against central differences of the
    exact gap (:func:`hardpack.geometry.ellipsoid_container.local_farthest_body`), moving the
    centre and turning the particle by R = exp(W) (the parametrisation of the pair Hessians)."""
    rng = np.random.default_rng(d)
    rot0 = np.linalg.qr(rng.normal(size=(d, d)))[0]
    semiaxes, x0 = np.asarray(semiaxes, float), np.asarray(centre, float)
    radius = 3.0
    h, lab = _branches(x0, rot0, semiaxes, radius)
    if semiaxes.max() > 1.9:
        assert len(h) == 2
    f = d + generators(d).shape[0]
    x_inv = rot0.T @ np.diag(semiaxes**2) @ rot0
    eye, e = np.eye(f), 1e-4
    for ref in lab:
        def gap(q, ref=ref):
            return _gap_along(q, x0, rot0, semiaxes, radius, ref)

        n, lever = ref / np.linalg.norm(ref), ref - x0
        torque = np.cross(lever, n) if d == 3 else [lever[0] * n[1] - lever[1] * n[0]]
        grad = np.array([(gap(e * eye[s]) - gap(-e * eye[s])) / (2 * e) for s in range(f)])
        np.testing.assert_allclose(grad, -np.concatenate([n, torque]), atol=1e-7)
        hess = np.array([[(gap(e * (eye[s] + eye[t])) - gap(e * (eye[s] - eye[t]))
                           - gap(e * (eye[t] - eye[s])) + gap(-e * (eye[s] + eye[t]))) / (4 * e * e)
                          for t in range(f)] for s in range(f)])
        np.testing.assert_allclose(wall_gap_hessian(x0, lever, x_inv), hess, atol=2e-6)


def test_local_farthest_points_of_an_ellipse_by_brute_force():
    """The local maxima of the distance from the centre over an ellipse's boundary (sampled at
    2e5 points) are the points local_farthest_body returns: one or two, to 1e-8."""
    rng = np.random.default_rng(0)
    t = np.linspace(0, 2 * np.pi, 200001)[:-1]
    twos = 0
    for _ in range(100):
        a = rng.uniform(0.2, 2.0, 2)
        b = rng.normal(size=2) * rng.uniform(0, 2)
        r = np.linalg.norm(b + np.column_stack([a[0] * np.cos(t), a[1] * np.sin(t)]), axis=1)
        peaks = np.sort(r[(r > np.roll(r, 1)) & (r > np.roll(r, -1))])
        pts = np.zeros((2, 2))
        count = local_farthest_body(b, a, pts)
        np.testing.assert_allclose(np.sort(np.linalg.norm(pts[:count], axis=1)), peaks, atol=1e-8)
        twos += count == 2
    assert twos > 10


def test_cli_verify_stores_the_wall_contacts_of_an_ellipse_packing(tmp_path):
    """``hardpack verify`` of the centred ellipse (a = 2, b = 1) in its container writes the wall
    contacts and reactions (F = 1 on both tips) into the result dataset."""
    from hardpack.cli import main
    from hardpack.io import load_dataset, save_packing

    save_packing(centred([2.0, 1.0], 0.3), tmp_path / "ellipse.nc")
    assert main(["verify", str(tmp_path / "ellipse.nc"), "--out", str(tmp_path / "v.nc")]) == 0
    ds = load_dataset(tmp_path / "v.nc")
    assert ds.attrs["jammed"] == 1 and ds.attrs["order"] == "second"
    assert ds.attrs["n_wall_contacts"] == 2 and ds.attrs["wall_force"] == pytest.approx(2.0)
    np.testing.assert_allclose(ds["force"].values[ds["contact_wall"].values == 0], 1.0, rtol=1e-12)


# ------------------------------------------------------------------------------------ input
def test_refuses_a_continuum_of_wall_contacts_and_overlaps():
    """A disk (as an ellipse) centred in a container of its own radius touches it everywhere: no
    isolated contacts, refused; a particle crossing the wall is refused. (Flat hard walls:
    tests/test_jamming_ellipsoid_flat_walls.py.)"""
    with pytest.raises(InvalidInputError, match="circle or sphere of farthest points"):
        verify_ellipsoids(centred([1.0, 1.0], 0.0))
    with pytest.raises(InvalidInputError, match="container wall"):
        verify_ellipsoids(centred([2.0, 1.0], 0.0, radius=1.99))
