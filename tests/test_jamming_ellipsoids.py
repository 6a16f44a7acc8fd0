"""First- and second-order jamming tests of ellipse and ellipsoid packings (Donev 2006, Secs. 5.5-5.6).

Exact cases:
- the Hessian of the Perram-Wertheim potential against finite differences of ``pw_contact``;
- Donev 2006, Fig. 5.5: an ellipse (alpha = 2) held by three fixed ellipses whose contact
  normals meet in one point I: not first-order rigid (the rotation about I), jammed at second
  order; the projected stiffness equals the osculating-circle value derived in
  :func:`osculating_stiffness`, and a configuration with I elsewhere is second-order flexible;
- disks as ellipses with equal semiaxes: the same verdict, rattlers and counts as the sphere
  verifier on the 64-disk packing of tests/data; spins are trivial;
- the affinely stretched triangular crystal (sec. (d) below).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from test_jamming_support import jammed_disks

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import pw_contact, shape_inverse
from hardpack.geometry.lattices import lattice_packing
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.jamming import verify
from hardpack.jamming.ellipsoids import (
    ellipsoid_contacts,
    generators,
    rigidity_transpose_full,
    zeta_hessian,
)
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import verify_ellipsoids


# ------------------------------------------------------------------------------- derivatives
@pytest.mark.parametrize("d", [2, 3])
def test_hessian_and_gradient_match_finite_differences(d):
    """Hess zeta and grad zeta (Donev 2006, Sec. 2.2.4) against central differences of
    pw_contact with the orientations rotated as R X^-1 R^T, R = exp(W(omega))."""
    rng = np.random.default_rng(7 + d)
    gens = generators(d)
    f = d + gens.shape[0]
    for _ in range(3):
        axes = rng.uniform(0.4, 2.0, (2, d))
        orient = ([np.array([rng.uniform(0, np.pi)]) for _ in range(2)] if d == 2
                  else [q / np.linalg.norm(q) for q in rng.standard_normal((2, 4))])
        a, b = np.empty((d, d)), np.empty((d, d))
        shape_inverse(axes[0], orient[0], a)
        shape_inverse(axes[1], orient[1], b)
        r_b = rng.standard_normal(d) * 2.0

        def zeta(x):
            ra = sla.expm(np.tensordot(x[d:f], gens, 1))
            rb = sla.expm(np.tensordot(x[f + d:], gens, 1))
            return pw_contact(r_b + x[f:f + d] - x[:d], ra @ a @ ra.T, rb @ b @ rb.T, 0.5)[0]

        _, lam, n = pw_contact(r_b, a, b, 0.5)
        hess = zeta_hessian(r_b, a, b, lam)
        h, eye = 1e-4, np.eye(2 * f)
        fd = np.array([[(zeta(h * (eye[p] + eye[q])) - zeta(h * (eye[p] - eye[q]))
                         - zeta(h * (eye[q] - eye[p])) + zeta(-h * (eye[p] + eye[q]))) / (4 * h * h)
                        for q in range(2 * f)] for p in range(2 * f)])
        assert np.abs(hess - fd).max() < 1e-6 * max(1.0, np.abs(hess).max())
        # gradient: 2 lam (1 - lam) [-n, -r_AC x n, n, r_BC x n]
        c = lam * (1 - lam)
        r_ac, r_bc = (1 - lam) * a @ n, (1 - lam) * a @ n - r_b
        cross = (lambda r: np.atleast_1d(r[0] * n[1] - r[1] * n[0])) if d == 2 else (lambda r: np.cross(r, n))
        grad = 2 * c * np.concatenate([-n, -cross(r_ac), n, cross(r_bc)])
        fd_grad = np.array([(zeta(1e-6 * eye[p]) - zeta(-1e-6 * eye[p])) / 2e-6 for p in range(2 * f)])
        assert np.abs(grad - fd_grad).max() < 1e-7


def test_2d_angle_is_the_rotation_generator():
    """The 2D rotation column is the orientation angle of Ellipsoids (counter-clockwise)."""
    a0, a1 = np.empty((2, 2)), np.empty((2, 2))
    shape_inverse(np.array([2.0, 1.0]), np.array([0.3]), a0)
    shape_inverse(np.array([2.0, 1.0]), np.array([0.31]), a1)
    rot = sla.expm(0.01 * generators(2)[0])
    assert np.abs(rot @ a0 @ rot.T - a1).max() < 1e-15


# ------------------------------------------------------------------------------- Fig. 5.5
SEMI = (2.0, 1.0)  # alpha = 2


def curvature_radius(t, a=SEMI[0], b=SEMI[1]):
    """Radius of curvature of the ellipse at (a cos t, b sin t)."""
    return (a * a * np.sin(t) ** 2 + b * b * np.cos(t) ** 2) ** 1.5 / (a * b)


def trap(params) -> Packing:
    """A mobile ellipse (semiaxes 2, 1, at the origin, angle 0) touched at the points
    (2 cos t, sin t), t in ``params``, by three equal fixed ellipses that touch with their flat side
    (their minor vertex), in a large periodic box. Particle 0 is the mobile one."""
    a, b = SEMI
    pos, ang = [np.zeros(2)], [0.0]
    for t in params:
        c = np.array([a * np.cos(t), b * np.sin(t)])
        u = np.array([b * np.cos(t), a * np.sin(t)])
        u /= np.linalg.norm(u)
        pos.append(c + b * u)
        ang.append(np.arctan2(u[0], -u[1]))  # minor axis along -u
    box = 40.0
    return Packing(np.array(pos) + box / 2, lattice=box * np.eye(2),
                   shape=Ellipsoids(np.tile(SEMI, (4, 1)), np.array(ang)), allow_overlap=True)


def osculating_stiffness(params, point, forces):
    """Stiffness of the rotation about I = ``point`` (unit speed in (v, w) coordinates), from the
    osculating circles: the mobile body rotating about I, with I at distance rho from the contact
    along the inner normal, moves its circle of curvature (radius R_m) on a circle of radius
    |rho - R_m| about I, and the gap to the fixed circle (radius R_f) changes by
    (rho + R_f)(rho - R_m) theta^2 / (2 (R_f + R_m)) (derived from the law of cosines). The
    stiffness is -sum_c F_c d^2 gap_c / d theta^2 divided by |(v, w)|^2 = 1 + |I|^2."""
    a, b = SEMI
    total = 0.0
    for t, f in zip(params, forces):
        c = np.array([a * np.cos(t), b * np.sin(t)])
        rho, r_m, r_f = np.linalg.norm(c - point), curvature_radius(t), a * a / b
        total -= f * (rho + r_f) * (rho - r_m) / (r_f + r_m)
    return total / (1.0 + point @ point)


FROZEN = np.array([False, True, True, True])


def _x_axis_trap(x_i):
    """Normals meeting at I = (x_i, 0): the left tip and the two points with cos t = a x_i / (a^2 - b^2)."""
    a, b = SEMI
    t0 = np.arccos(a * x_i / (a * a - b * b))
    return [t0, -t0, np.pi], np.array([x_i, 0.0])


def _y_axis_trap(y_i):
    """Normals meeting at I = (0, y_i): the top vertex and the two points with sin t = -b y_i / (a^2 - b^2)."""
    a, b = SEMI
    s = np.arcsin(-b * y_i / (a * a - b * b))
    return [s, np.pi - s, np.pi / 2], np.array([0.0, y_i])


def test_fig_5_5_jammed_at_second_order():
    """Donev 2006, Fig. 5.5: three contacts, three dof, the normals meet at I: one self-stress,
    one floppy mode (the rotation about I), blocked by the flat contacts' curvature."""
    params, point = _x_axis_trap(0.3)
    res = verify_ellipsoids(trap(params), frozen=FROZEN)
    c = res.collective
    assert res.network.n_contacts == 3 and np.abs(res.network.gap).max() < 1e-12
    assert (c.n_constraints, c.n_dof, c.n_stresses, c.n_floppy) == (3, 3, 1, 1)
    assert not c.first_order_rigid and c.lp_flex  # the randomised LP finds the null flex
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert res.local[0] == Verdict.JAMMED and not res.rattler.any()
    expected = osculating_stiffness(params, point, c.forces)
    assert expected > 0
    assert c.lambda_min == pytest.approx(expected, rel=1e-9)
    ds = res.to_dataset()
    assert ds.attrs["verdict"] == 1 and ds.attrs["order"] == "second"


def test_fig_5_5_variant_second_order_flexible():
    """Normals meeting at I = (0, 0.5): the two contacts near the tips are beyond their centres of
    curvature from I and carry most of the force, so the rotation about I opens the contacts at
    second order: not jammed, decided at second order, and the local test makes it a rattler."""
    params, point = _y_axis_trap(0.5)
    res = verify_ellipsoids(trap(params), frozen=FROZEN, local=False)
    c = res.collective
    assert (c.n_stresses, c.n_floppy) == (1, 1)
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "second"
    expected = osculating_stiffness(params, point, c.forces)
    assert expected < 0
    assert c.lambda_min == pytest.approx(expected, rel=1e-9)
    # the floppy mode is the rotation about I: v = w z x (0 - I)
    motion = c.motion / c.motion[2]
    assert motion[:2] == pytest.approx([point[1], -point[0]], abs=1e-12)
    full = verify_ellipsoids(trap(params), frozen=FROZEN)
    assert full.rattler[0] and full.verdict == Verdict.NOT_JAMMED and full.order == "second"


def test_three_contacts_without_common_point_are_first_order():
    """Rotating one fixed ellipse's contact point away from the common point breaks torque balance:
    no self-stress, not jammed at first order."""
    params, _ = _x_axis_trap(0.3)
    params[2] = np.pi - 0.2
    res = verify_ellipsoids(trap(params), frozen=FROZEN, local=False)
    assert res.verdict == Verdict.NOT_JAMMED and res.order == "first"
    assert res.collective.lp_flex  # a strict flex, found by the LP with B = A e
    assert res.collective.stress_margin < 0 or not np.isfinite(res.collective.stress_margin)


# ------------------------------------------------------------------------------- disks
def _as_ellipses(p: Packing, stretch=1.0, angles=None) -> Packing:
    n = p.n_particles
    axes = np.column_stack([p.radii, p.radii / stretch])
    angles = np.zeros(n) if angles is None else angles
    return Packing(p.positions, lattice=p.lattice, shape=Ellipsoids(axes, angles), allow_overlap=True)


def test_disks_as_ellipses_match_the_sphere_verifier():
    """Equal semiaxes: the spin columns are removed (trivial), and the verdict, rattlers, contacts
    and isostatic count are the sphere verifier's (Donev 2006, Sec. 5.5.2.2: a sphere packing is
    jammed iff first-order jammed)."""
    disks = jammed_disks()
    spheres = verify(disks, tests=("local", "collective"))
    res = verify_ellipsoids(_as_ellipses(disks))
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert np.array_equal(res.rattler, spheres.rattler)
    assert res.collective.n_constraints == spheres.statics.n_contacts
    assert res.z_mean == pytest.approx(spheres.z_mean, rel=1e-12)
    assert set(res.dof[res.backbone]) == {2}
    assert res.collective.n_dof == 2 * (spheres.statics.n_backbone - 1)
    assert res.collective.n_floppy == 0 and res.collective.n_stresses == 1
    assert res.collective.lp_flex is False
    # the self-stress is the sphere one (unique up to normalisation)
    used = res.network.subset(res.contacts_used)
    key = {(i, j, tuple(s)): f for i, j, s, f in zip(used.i, used.j, used.shift, res.collective.forces)}
    net = spheres.network
    ref = {(i, j, tuple(s)): f for i, j, s, f in zip(net.i, net.j, net.shift, spheres.forces.forces) if f > 0}
    assert set(key) == set(ref)
    ratio = np.array([key[k] / ref[k] for k in ref])
    assert ratio == pytest.approx(ratio.mean(), rel=1e-6)


def test_disks_missing_a_contact_are_not_jammed():
    """Removing one backbone disk's contact partner (shrinking it) unjams the packing in both codes."""
    disks = jammed_disks()
    spheres = verify(disks, tests=("local", "collective"))
    pick = int(np.flatnonzero(~spheres.rattler)[0])
    radii = disks.radii.copy()
    radii[pick] *= 0.999
    smaller = Packing(disks.positions, radii, disks.lattice)
    ref = verify(smaller, tests=("local", "collective"))
    res = verify_ellipsoids(_as_ellipses(smaller))
    assert (res.verdict == Verdict.JAMMED) == bool(ref.collective)
    assert np.array_equal(res.rattler, ref.rattler)


# ------------------------------------------------------------------------------- (d) crystal
def stretched_triangular(reps, alpha, psi) -> Packing:
    """The triangular disk crystal (diameter 1) stretched by alpha along the direction psi, with
    ellipses of semiaxes (alpha / 2, 1 / 2) at angle psi: an affine image, so every contact stays."""
    p = lattice_packing("triangular", reps)
    c, s = np.cos(psi), np.sin(psi)
    rot = np.array([[c, -s], [s, c]])
    stretch = rot @ np.diag([alpha, 1.0]) @ rot.T
    n = p.n_particles
    return Packing(p.positions @ stretch.T, lattice=stretch @ p.lattice,
                   shape=Ellipsoids(np.tile([0.5 * alpha, 0.5], (n, 1)), np.full(n, psi)),
                   allow_overlap=True)


@pytest.mark.parametrize("alpha, psi", [(1.5, 0.0), (1.5, np.pi / 2), (1.5, 0.3), (1.1, 1.0), (3.0, 0.7)])
def test_stretched_triangular_cell_is_first_order_rigid(alpha, psi):
    """One particle per cell: three self-image contacts (lattice directions theta_k = 0, 60, 120
    degrees), no translation entries, one rotation column with entries (lever difference) x u
    = -(S e_k) x u_k with u_k ~ S^-1 e_k (e_k the unit disk-crystal vectors), i.e.
    -sin 2(theta_k - psi) (alpha - 1/alpha) / (2 |S^-1 e_k|) (derived: in the stretch frame
    e = (c, s), S e x S^-1 e = c s (alpha - 1/alpha)).
    The three sin 2(theta_k - psi) sum to zero, so they have both signs for alpha != 1: a strict
    self-stress balances the torque and the rotation is blocked at first order."""
    p = stretched_triangular(1, alpha, psi)
    net = ellipsoid_contacts(p, 1e-9)
    assert net.n_contacts == 3 and np.abs(net.gap).max() < 1e-12
    at = rigidity_transpose_full(net).toarray()
    assert np.abs(at[:, :2]).max() < 1e-15
    c, s = np.cos(psi), np.sin(psi)
    rot = np.array([[c, -s], [s, c]])
    e = net.separation @ rot @ np.diag([1 / alpha, 1.0])  # unit disk-crystal directions, stretch frame
    assert np.linalg.norm(e, axis=1) == pytest.approx(1.0, abs=1e-14)
    phi = np.arctan2(e[:, 1], e[:, 0])
    inv_len = np.hypot(np.cos(phi) / alpha, np.sin(phi))
    expected = -np.sin(2 * phi) * (alpha - 1 / alpha) / (2 * inv_len)
    assert at[:, 2] == pytest.approx(expected, abs=1e-14)
    res = verify_ellipsoids(p)
    assert res.verdict == Verdict.JAMMED and res.order == "first" and res.collective.first_order_rigid
    assert res.collective.lp_flex is False
    assert abs(res.collective.forces @ at[:, 2]) < 1e-12 and res.collective.forces.min() > 0


@pytest.mark.parametrize("reps, psi", [(2, 0.0), (2, np.pi / 2), (3, 0.3), ((3, 4), np.pi / 2)])
def test_stretched_triangular_supercells_are_jammed(reps, psi):
    """Supercells: M = 3N contacts, N_f = 3N - 2 dof (translations trivial), so
    N_stresses - N_floppy = M - N_f = 2 (Maxwell). The crystal's line stresses give more self-
    stresses than that, hence floppy modes (rotations with translations), which the stress
    matrix of the best self-stress blocks: jammed at second order (pre-stress stable)."""
    p = stretched_triangular(reps, 1.5, psi)
    res = verify_ellipsoids(p)
    c = res.collective
    n = p.n_particles
    assert c.n_constraints == 3 * n and c.n_dof == 3 * n - 2
    assert c.n_stresses - c.n_floppy == 2
    assert c.n_floppy > 0 and c.lp_flex
    assert res.verdict == Verdict.JAMMED and res.order == "second"
    assert c.lambda_min > 0


def test_triangular_disks_as_ellipses_are_first_order_rigid():
    """alpha = 1: the triangular disk crystal is collectively jammed (Donev 2006, Table 4.1)."""
    res = verify_ellipsoids(stretched_triangular(3, 1.0, 0.0))
    assert res.verdict == Verdict.JAMMED and res.order == "first"
    assert set(res.dof) == {2}


# ------------------------------------------------------------------------------- input checks
def test_refuses_spheres_and_bad_arguments():
    with pytest.raises(InvalidInputError, match="ellipses and ellipsoids"):
        verify_ellipsoids(jammed_disks())
    p = stretched_triangular(1, 1.5, 0.0)
    with pytest.raises(InvalidInputError, match="frozen"):
        verify_ellipsoids(p, frozen=[1])
    with pytest.raises(InvalidInputError, match="method"):
        verify_ellipsoids(p, method="fast")
    with pytest.raises(InvalidInputError, match="delta"):
        verify_ellipsoids(p, delta=2.0)


def test_refuses_overlapping_ellipses():
    """Overlaps are found with the Perram-Wertheim function, not the bounding spheres."""
    p = stretched_triangular(1, 1.5, 0.0)
    fat = Packing(p.positions, lattice=p.lattice, allow_overlap=True,
                  shape=Ellipsoids(p.shape.semiaxes * 1.01, p.shape.orientations))
    with pytest.raises(InvalidInputError, match="overlap"):
        verify_ellipsoids(fat)


def test_cli_dispatches_ellipses(tmp_path, capsys):
    """``hardpack verify`` sends an ellipse packing to verify_ellipsoids and stores its dataset."""
    from hardpack.cli import main
    from hardpack.io import load_dataset, save_packing

    path = tmp_path / "trap.nc"
    save_packing(stretched_triangular(2, 1.5, np.pi / 2), path)
    out = tmp_path / "verdict.nc"
    assert main(["verify", str(path), "--out", str(out)]) == 0
    ds = load_dataset(out)
    assert ds.attrs["hardpack_kind"] == "ellipsoid_jamming"
    assert ds.attrs["verdict"] == int(Verdict.JAMMED) and ds.attrs["order"] == "second"
    assert "second-order jammed" in capsys.readouterr().out


# ------------------------------------------------------------------------------- 3D
def _quaternion(rot):
    """The orientation quaternion (s, p) of hardpack.geometry.shapes whose Q is rot^T (body axes =
    the columns of rot): scipy's quaternion of rot, scalar first."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(rot).as_quat()
    return np.array([w, x, y, z])


def stretched_fcc(reps, semiaxes, rot) -> Packing:
    """The FCC sphere crystal (diameter 1) stretched by diag(semiaxes) / 0.5 in the frame rot, with
    aligned ellipsoids of those semiaxes: an affine image, every contact stays."""
    p = lattice_packing("fcc", reps)
    stretch = rot @ np.diag(np.asarray(semiaxes) / 0.5) @ rot.T
    n = p.n_particles
    return Packing(p.positions @ stretch.T, lattice=stretch @ p.lattice, allow_overlap=True,
                   shape=Ellipsoids(np.tile(semiaxes, (n, 1)), np.tile(_quaternion(rot), (n, 1))))


ROT = sla.expm(np.tensordot([0.3, -0.5, 0.7], generators(3), 1))


def test_quaternion_helper_matches_the_shape_convention():
    out = np.empty((3, 3))
    shape_inverse(np.array([1.0, 2.0, 3.0]), _quaternion(ROT), out)
    assert np.abs(out - ROT @ np.diag([1.0, 4.0, 9.0]) @ ROT.T).max() < 1e-14


def test_spheroid_spin_is_trivial_and_removed():
    """A spheroid's rotation about its symmetry axis leaves X unchanged: that combination of the
    rotation columns of A^T vanishes to round-off, and the reduced dof are 5 per spheroid, 6 per
    general ellipsoid, 3 per sphere (translations only)."""
    spheroids = stretched_fcc(1, (0.5, 0.5, 0.75), ROT)
    at = rigidity_transpose_full(ellipsoid_contacts(spheroids, 1e-9)).toarray().reshape(-1, 4, 6)
    axis = ROT[:, 2]
    assert np.abs(at[:, :, 3:] @ axis).max() < 1e-14
    assert np.abs(at[:, :, 3:] @ ROT[:, 0]).max() > 1e-2
    for axes, dof in (((0.5, 0.5, 0.75), 5), ((0.5, 0.6, 0.75), 6), ((0.5, 0.5, 0.5), 3)):
        res = verify_ellipsoids(stretched_fcc(1, axes, ROT))
        assert set(res.dof) == {dof}
        assert res.collective.n_dof == 4 * dof - 3


def test_fcc_spheres_as_ellipsoids_match_the_sphere_verifier():
    """Equal semiaxes: the FCC crystal is collectively jammed (Donev 2006, Table 4.1), first order."""
    spheres = verify(lattice_packing("fcc", 2), tests=("local", "collective"))
    res = verify_ellipsoids(stretched_fcc(2, (0.5, 0.5, 0.5), np.eye(3)))
    assert spheres.collective and res.verdict == Verdict.JAMMED and res.order == "first"
    assert res.collective.n_constraints == spheres.statics.n_contacts == 192


@pytest.mark.parametrize("semiaxes, order", [((0.5, 0.5, 0.75), "first"), ((0.5, 0.6, 0.75), "second")])
def test_stretched_fcc_is_jammed(semiaxes, order):
    """Aligned spheroids / ellipsoids on the affinely stretched FCC lattice (Z = 12 > 2 d_f):
    translations are rigid as for spheres (the gap rows are the sphere rows in the coordinates
    v' = S v), so only rotations can be floppy; N_stresses - N_floppy = M - N_f (Maxwell).
    The orders are what this code finds (not derived independently): the spheroids are
    first-order rigid, the general ellipsoids have floppy rotation modes that the stress matrix
    blocks."""
    res = verify_ellipsoids(stretched_fcc(2, semiaxes, ROT))
    c = res.collective
    assert res.verdict == Verdict.JAMMED and res.order == order
    assert c.n_stresses - c.n_floppy == c.n_constraints - c.n_dof
