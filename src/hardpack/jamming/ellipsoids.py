"""Contact network, rigidity matrix and stress matrix of a packing of ellipses or ellipsoids: periodic,
between flat hard walls or in a spherical container.

Donev 2006, dissertation ch. 5 (Secs. 5.3, 5.5) with the configurational derivatives of the
Perram-Wertheim overlap potential zeta (Sec. 2.2.4; :mod:`hardpack.geometry.contact`).

Degrees of freedom. Particle i has the centre r_i (d components) and an infinitesimal rotation
omega_i (the angle in 2D, the rotation vector in 3D, acting in the lab frame: an orientation
moves as X_i^-1 -> R X_i^-1 R^T with R = exp(W), W v = omega x v), so d_f = d + d(d-1)/2 per
particle (3 for ellipses, 6 for ellipsoids). Column ``i * d_f + k`` of the full matrices is
translation k of i for k < d and rotation k - d after that.

Contacts. A pair (i, j, image n) is a contact when mu_ij - 1 <= delta, mu^2 = zeta + 1 the
Perram-Wertheim scale factor (bounding-sphere candidates first). With r_ij = x_j + L n - x_i,
zeta, the maximiser lam and the unnormalised normal n = Y^-1 r_ij from :func:`pw_contact`, the
contact point r_C (Eq. 2.13) gives the lever arms r_iC = r_C - x_i and r_jC = r_C - (x_j + L n).

Rigidity matrix (Sec. 5.3, A = grad_Q zeta column by column; we normalise each column by the
length of its translational part). The gradient is
grad_j zeta = -grad_i zeta (translations) = 2 lam (1 - lam) n and
grad_{omega_j} zeta = 2 lam (1 - lam) r_jC x n, grad_{omega_i} zeta = -2 lam (1 - lam) r_iC x n
(Sec. 2.2.4; derived again in :func:`zeta_hessian`), so with the unit normal u = n / |n| the row of
contact c in A^T is the gap rate

    u . (v_j + w_j x r_jC - v_i - w_i x r_iC) = grad zeta . Qdot / s_c,   s_c = 2 lam (1 - lam) |n|,

(2D: w x r = w (-r_y, r_x), so the rotational entry is r x u = r_x u_y - r_y u_x). For spheres this
is the sphere code's row (:mod:`hardpack.jamming.rigidity`) plus rotational entries that vanish,
since the lever arms are parallel to u.

Container walls (Donev 2006, Sec. 4.4.3 for spheres: a contact with a fixed point of the wall;
ellipsoids in a spherical container as in Ch. 7). With the container centre c and radius R, the
gap of particle i is h = R - rho, rho the distance from c of its farthest surface point p
(:mod:`hardpack.geometry.ellipsoid_container`, exact). Every strict local maximum of the
distance with h <= delta a_max is a wall contact (at most two per particle: the global one and,
for an elongated particle lying like a chord, its other tip; both tips when the centre is on
the container's plane through the particle's short axes), stored with ``wall`` = 0 (-1 for a
pair), j = i, unit normal n = (p - c) / rho (the radial direction, which is the surface normal
at a farthest point), lever arm r_iC = p - x_i, ``scale`` 1 and ``zeta`` chosen so that ``gap``
is h / a_max. By the envelope theorem (the point on the body is stationary),
grad_r h = -n and grad_omega h = -r_iC x n: the pair row with the wall as a fixed particle j,
u . (-v_i - w_i x r_iC). The Hessian of h is :func:`wall_gap_hessian`.

Flat hard walls (:class:`hardpack.geometry.boundaries.HardWalls`: planes x_k = 0 and x_k = L_k for
the walled axes k, periodic along the others; Donev 2006, Sec. 3.2.2.1 for the boundary, Sec. 4.4.3
for the wall contact as a contact with a fixed point of the wall). The wall with outward unit
normal n (n = -e_k for x_k = 0, n = +e_k for x_k = L_k) is the plane n . y = b (b = 0 and L_k).
The point of particle i farthest along n is p = x + X^-1 n / s with s = sqrt(n^T X^-1 n) (the
support function of the ellipsoid y^T X y <= 1 about its centre, Donev 2006, Sec. 2.2.5.1: the
maximiser of n . y on the surface, by a Lagrange multiplier), so the gap is
h = b - n . x - s: x_k - s for the wall x_k = 0, L_k - x_k - s for x_k = L_k. A particle has at
most one contact per wall (the farthest point of a strictly convex body is unique), and it is a
contact when h <= delta a_max, as for the container. It is stored like a container contact (j = i,
unit normal n, lever r_iC = p - x_i, ``scale`` 1, ``zeta`` with ``gap`` = h / a_max), with
separation (b - n . x) n, from the centre to the foot of the perpendicular on the wall (as for
spheres, :mod:`hardpack.jamming.contacts`), and the sphere code's wall numbers: ``wall`` = 2 k for
x_k = 0 and 2 k + 1 for x_k = L_k (``centre`` None tells them from the container's wall 0).
Derivatives: grad_r h = -n and, by the envelope theorem (p maximises n . y over the body),
grad_omega h = -(p - x) x n = -r_iC x n, the container's row. The translations enter h linearly,
so the r-r and r-omega blocks of Hess h vanish; the omega-omega block is -Hess s, derived in
:func:`plane_gap_hessian`. Translations along a periodic axis (parallel to every wall) are the
trivial motions (none in a closed box, Donev 2006, Sec. 4.4.2).

Stress matrix (Sec. 5.5.2.1, Eq. 5.16). For a self-stress F (A F = 0, F >= 0, in the units of the
rows above) the stress matrix is the force-weighted sum of the contacts' Hessians of zeta,
sum_c (F_c / s_c) Hess zeta_c. With the sign convention of Donev (zeta >= 0 for disjoint
particles), a floppy mode Qdot (A^T Qdot = 0) is blocked at second order iff
Qdot^T (sum_c F_c / s_c Hess zeta_c) Qdot < 0. We store the negative, the *stiffness*
K = -sum_c (F_c / s_c) Hess zeta_c, which is positive on blocked modes. The factor 1 / s_c converts
zeta to the gap: both vanish on the same set, zeta = gap * s + O(gap^2), so on a floppy mode
(grad gap . Qdot = 0) Qdot^T Hess zeta Qdot = s Qdot^T Hess gap Qdot; the terms that depend on the
parametrisation of the rotations (Qddot) drop out because A F = 0 (Eq. 5.15). A wall contact
enters with its gap h itself (s = 1): K gets -F_c Hess h_c in the block of its particle, in the
same parametrisation of the rotations (x -> x + v, orientation R(omega) = exp(W) times the
current one) as the pair Hessians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp
from scipy.spatial.transform import Rotation

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import contact_point, inverse_shapes, pw_contact
from hardpack.geometry.ellipsoid_container import body_offset, lab_point, local_farthest_body
from hardpack.geometry.neighbours.pairs import pairs_within, wrapped_positions
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids
from hardpack.jamming.contacts import ContactArrays

__all__ = [
    "EllipsoidContacts",
    "ellipsoid_contacts",
    "contacts_of_pairs",
    "contact_centres",
    "dof_per_particle",
    "rigidity_transpose_full",
    "stiffness_matrix_full",
    "contact_hessians",
    "zeta_hessian",
    "wall_gap_hessian",
    "plane_gap_hessian",
    "container_contacts",
    "container_tips",
    "plane_wall_contacts",
    "wall_name",
    "generators",
    "displaced",
]


def dof_per_particle(d: int) -> int:
    """d + d(d-1)/2: translations and rotations of one particle (3 in 2D, 6 in 3D).

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    int
        Degrees of freedom d_f of one rigid particle.
    """
    return d + d * (d - 1) // 2


def generators(d: int) -> np.ndarray:
    """The infinitesimal rotations E_a (E_a v = e_a x v; in 2D the rotation by +90 degrees), (k, d, d).

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    numpy.ndarray of float, shape (d(d-1)/2, d, d)
        The generators E_a (one in 2D, three in 3D).
    """
    if d == 2:
        return np.array([[[0.0, -1.0], [1.0, 0.0]]])
    e = np.zeros((3, 3, 3))
    for a in range(3):
        for b in range(3):
            e[a, :, b] = np.cross(np.eye(3)[a], np.eye(3)[b])
    return e


@dataclass(frozen=True)
class EllipsoidContacts(ContactArrays):
    """Contacts (i, j, image shift) of an ellipsoid packing; arrays have length M (module docstring).

    ``normal`` is the unit normal u from i to j; ``lever_i``/``lever_j`` are r_C - x_i and
    r_C - (x_j + L n); ``scale`` is s = 2 lam (1 - lam) |n|, the factor between grad zeta and the
    gap rows; ``zeta`` and ``lam`` come from the Perram-Wertheim function. ``shape_inv`` holds every
    particle's X^-1 (N, d, d). ``wall`` is -1 for a pair, 0 for a contact with the container
    wall (module docstring: j = i, lam NaN, scale 1, lever_j 0, separation p - c) and 2 k or
    2 k + 1 for the flat wall x_k = 0 or x_k = L_k (separation (b - n . x) n); ``centre`` and
    ``radius`` describe the container (None in a periodic cell or between flat walls), ``periodic``
    the periodic axes.

    Attributes
    ----------
    i, j : numpy.ndarray of int, shape (M,)
        The particles of each contact (j = i for a wall contact).
    shift : numpy.ndarray of int, shape (M, d)
        Lattice image n of j.
    separation : numpy.ndarray of float, shape (M, d)
        x_j + L n - x_i (for a wall contact p - c or (b - n . x) n, above).
    zeta, lam : numpy.ndarray of float, shape (M,)
        Perram-Wertheim overlap potential mu^2 - 1 and its maximiser (Donev 2006, sec. 2.2.2.1).
    normal, raw_normal : numpy.ndarray of float, shape (M, d)
        Unit contact normal u from i to j, and the unnormalised n = Y^-1 r.
    lever_i, lever_j : numpy.ndarray of float, shape (M, d)
        Lever arms from the centres to the contact point.
    scale : numpy.ndarray of float, shape (M,)
        2 lam (1 - lam) |n|.
    positions : numpy.ndarray of float, shape (N, d)
        Particle centres.
    lattice : numpy.ndarray of float, shape (d, d)
        Cell, lattice vectors as columns.
    shape_inv : numpy.ndarray of float, shape (N, d, d)
        X^-1 of every particle.
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes of every particle.
    delta : float
        Contact tolerance on mu - 1.
    wall : numpy.ndarray of int, shape (M,), or None
        -1 for a pair, 0 for a contact with the container wall, 2 k (2 k + 1) for the flat wall
        x_k = 0 (x_k = L_k); None in the constructor: pairs only.
    centre : numpy.ndarray of float, shape (d,), or None
        Container centre (None in a periodic cell or between flat walls).
    radius : float or None
        Container radius.
    periodic : numpy.ndarray of bool, shape (d,), or None
        The periodic axes (their uniform translations are trivial motions); None in the
        constructor: every axis without a container, none with one.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    separation: np.ndarray
    zeta: np.ndarray
    lam: np.ndarray
    normal: np.ndarray
    raw_normal: np.ndarray
    lever_i: np.ndarray
    lever_j: np.ndarray
    scale: np.ndarray
    positions: np.ndarray
    lattice: np.ndarray
    shape_inv: np.ndarray
    semiaxes: np.ndarray
    delta: float
    wall: np.ndarray | None = None
    centre: np.ndarray | None = None
    radius: float | None = None
    periodic: np.ndarray | None = None

    def __post_init__(self):
        super().__post_init__()
        if self.periodic is None:
            object.__setattr__(self, "periodic", np.full(self.positions.shape[1], self.centre is None))

    @property
    def is_plane_wall(self) -> np.ndarray:
        """(M,) True for the contacts with flat hard walls (wall >= 0 without a container)."""
        return self.is_wall & (self.centre is None)

    @property
    def gap(self) -> np.ndarray:
        """mu - 1, the relative scale gap of every contact (negative for overlaps)."""
        return np.sqrt(np.maximum(self.zeta + 1.0, 0.0)) - 1.0

    def subset(self, mask) -> EllipsoidContacts:
        """The network of the contacts in ``mask``, in the same order.

        Parameters
        ----------
        mask : numpy.ndarray of bool, shape (M,), or of int
            Selection (a boolean mask or indices) of the contacts.

        Returns
        -------
        EllipsoidContacts
            The selected contacts, with the particle data (positions, lattice, shapes, delta,
            container, periodic axes) unchanged.
        """
        kw = {k: getattr(self, k)[mask] for k in _PER_CONTACT}
        return EllipsoidContacts(**kw, positions=self.positions, lattice=self.lattice,
                                 shape_inv=self.shape_inv, semiaxes=self.semiaxes, delta=self.delta,
                                 centre=self.centre, radius=self.radius, periodic=self.periodic)


#: the per-contact arrays of :class:`EllipsoidContacts`
_PER_CONTACT = ("i", "j", "shift", "separation", "zeta", "lam", "normal", "raw_normal", "lever_i",
                "lever_j", "scale", "wall")


@numba.njit(cache=True)
def _pair_contacts(positions, shape_inv, bounding, ii, jj, sep):
    m, d = sep.shape
    zeta = np.empty(m)
    lam = np.empty(m)
    normal = np.empty((m, d))
    point = np.empty((m, d))
    for c in range(m):
        a, b = ii[c], jj[c]
        lam0 = bounding[a] / (bounding[a] + bounding[b])
        z, lm, n = pw_contact(sep[c], shape_inv[a], shape_inv[b], lam0)
        zeta[c], lam[c] = z, lm
        normal[c] = n
        contact_point(positions[a], shape_inv[a], lm, n, point[c])
    return zeta, lam, normal, point


def _cross(r: np.ndarray, u: np.ndarray) -> np.ndarray:
    """r x u per row: (M,) in 2D, (M, 3) in 3D."""
    if r.shape[1] == 2:
        return r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]
    return np.cross(r, u)


def ellipsoid_contacts(packing: Packing, delta: float) -> EllipsoidContacts:
    """All pairs with Perram-Wertheim scale factor mu <= 1 + delta, with every periodic image.

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids (``hardpack.geometry.shapes.Ellipsoids``) in a periodic cell,
        between flat hard walls or in a spherical container.
    delta : float
        Relative contact tolerance, 0 < delta < 1: pairs with mu - 1 <= delta are contacts (mu the
        common factor by which both particles must be scaled to be tangent); in a container, the
        local farthest points with gap h <= delta a_max are wall contacts, and between flat walls
        the farthest points along each wall's normal with h <= delta a_max (module docstring),
        after the pairs.

    Returns
    -------
    EllipsoidContacts
        The contacts with unit normals, lever arms and the PW data.

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a packing of ellipsoids (periodic, between flat walls or in a
        container), delta is not in (0, 1), a particle within delta of the container touches
        it along a continuum (a disk, sphere or oblate spheroid centred so that its longest
        semiaxes lie on the wall), or a centre lies beyond a flat wall.
    """
    check_ellipsoid_packing(packing)
    try:
        delta = float(delta)
    except (TypeError, ValueError):
        raise InvalidInputError(f"delta must be a number, got {delta!r}") from None
    if not (np.isfinite(delta) and 0.0 < delta < 1.0):
        raise InvalidInputError(
            f"delta = {delta!r} is not a valid contact tolerance: pairs with Perram-Wertheim scale "
            "factor mu <= 1 + delta count as touching; it must satisfy 0 < delta < 1"
        )
    shape = packing.shape
    semiaxes = np.ascontiguousarray(shape.semiaxes, dtype=float)
    orient = np.ascontiguousarray(np.asarray(shape.orientations, dtype=float).reshape(packing.n_particles, -1))
    inv = inverse_shapes(semiaxes, orient)
    if packing.boundary.kind == "hard_walls":
        _check_centres_between_walls(packing)
    pairs = pairs_within(packing, rel_gap=delta)
    x = np.ascontiguousarray(contact_centres(packing))
    ii, jj = pairs.i.astype(np.int64), pairs.j.astype(np.int64)
    sep = np.ascontiguousarray(pairs.separation, dtype=float)
    zeta, lam, raw, point = _pair_contacts(x, inv, np.asarray(shape.bounding_radii, float), ii, jj, sep)
    keep = np.sqrt(np.maximum(zeta + 1.0, 0.0)) - 1.0 <= delta
    ii, jj, sep, zeta, lam, raw, point = (a[keep] for a in (ii, jj, sep, zeta, lam, raw, point))
    norm = np.linalg.norm(raw, axis=1)
    u = raw / norm[:, None]
    net = EllipsoidContacts(
        i=ii, j=jj, shift=pairs.shift[keep].astype(np.int64), separation=sep, zeta=zeta, lam=lam,
        normal=u, raw_normal=raw, lever_i=point - x[ii], lever_j=point - (x[ii] + sep),
        scale=2.0 * lam * (1.0 - lam) * norm, positions=x, lattice=np.array(packing.lattice, float),
        shape_inv=inv, semiaxes=semiaxes, delta=delta, periodic=packing.boundary.periodic_axes(packing.dim),
    )
    if packing.boundary.kind == "spherical_container":
        net = _with_container(net, shape.rotations(), packing.boundary)
    elif packing.boundary.kind == "hard_walls":
        net = _with_plane_walls(net, packing.boundary)
    return net


def contact_centres(packing: Packing) -> np.ndarray:
    """The centres that contact separations refer to: wrapped into the cell along the periodic
    axes, as given (bit for bit, as :meth:`Packing.wrapped`) along walled ones.

    Parameters
    ----------
    packing : Packing
        The packing.

    Returns
    -------
    numpy.ndarray of float, shape (N, d)
        The centres.
    """
    x = wrapped_positions(packing)
    walled = ~packing.boundary.periodic_axes(packing.dim)
    x[:, walled] = packing.positions[:, walled]
    return x


def container_contacts(positions, semiaxes, rotations, centre, radius, delta):
    """Wall contacts of ellipsoids in a spherical container (module docstring).

    Parameters
    ----------
    positions : ndarray, shape (N, d)
    semiaxes : ndarray, shape (N, d)
    rotations : ndarray, shape (N, d, d)
        Lab to body (``Ellipsoids.rotations``).
    centre : ndarray, shape (d,)
    radius : float
    delta : float
        Local farthest points with gap h = R - rho <= delta a_max are contacts.

    Returns
    -------
    particle : ndarray of int, shape (M,)
    point : ndarray, shape (M, d)
        The local farthest surface points (lab frame).
    gap : ndarray, shape (M,)
        h = R - rho.
    continuum : ndarray of bool, shape (N,)
        Particles within delta of the wall whose farthest points form a continuum.
    """
    return _container_contacts(np.ascontiguousarray(positions, dtype=float),
                               np.ascontiguousarray(semiaxes, dtype=float),
                               np.ascontiguousarray(rotations, dtype=float),
                               np.asarray(centre, dtype=float), float(radius), float(delta))


@numba.njit(cache=True)
def _container_contacts(positions, semiaxes, rotations, centre, radius, delta):
    n, d = positions.shape
    part = np.empty(2 * n, np.int64)
    pts = np.empty((2 * n, d))
    gap = np.empty(2 * n)
    continuum = np.zeros(n, np.bool_)
    b = np.empty(d)
    loc = np.empty((2, d))
    m = 0
    for i in range(n):
        amax = semiaxes[i].max()
        body_offset(rotations, i, positions, centre, b)
        count = local_farthest_body(b, semiaxes[i], loc)
        if count < 0:
            continuum[i] = radius - np.sqrt((loc[0] * loc[0]).sum()) <= delta * amax
            continue
        for c in range(count):
            h = radius - np.sqrt((loc[c] * loc[c]).sum())
            if h <= delta * amax:
                part[m] = i
                gap[m] = h
                lab_point(rotations, i, loc[c], centre, pts, m)
                m += 1
    return part[:m], pts[:m], gap[:m], continuum


def _with_container(net: EllipsoidContacts, rotations, boundary) -> EllipsoidContacts:
    """``net`` with the wall contacts of the container appended (module docstring)."""
    centre = np.asarray(boundary.centre, dtype=float)
    part, point, h, continuum = container_contacts(net.positions, net.semiaxes, rotations, centre,
                                                   boundary.radius, net.delta)
    if continuum.any():
        bad = np.flatnonzero(continuum)
        raise InvalidInputError(
            f"particles {bad.tolist()} touch the container wall (within delta = {net.delta:g}) along a "
            "circle or sphere of farthest points (equal longest semiaxes, centred on the container's "
            "plane through them): the jamming tests need isolated contact points; move or shrink them")
    return _append_container(net, part, point, h, centre, float(boundary.radius))


@numba.njit(cache=True)
def _tracked_container_rows(positions, semiaxes, rotations, centre, radius, particle, tips):
    """The container contact of each ``particle`` at the local farthest point nearest its ``tip``
    (body frame, relative to the particle centre): (lab-frame points (W, d), gaps h = R - rho)."""
    m = particle.shape[0]
    d = positions.shape[1]
    pts = np.empty((m, d))
    gap = np.empty(m)
    b = np.empty(d)
    loc = np.empty((2, d))
    for c in range(m):
        i = particle[c]
        body_offset(rotations, i, positions, centre, b)
        count = max(local_farthest_body(b, semiaxes[i], loc), 1)  # a continuum (-1): its point loc[0]
        best, best_dist = 0, np.inf
        for t in range(count):
            dist = 0.0
            for k in range(d):
                dist += (loc[t, k] - b[k] - tips[c, k]) ** 2
            if dist < best_dist:
                best, best_dist = t, dist
        gap[c] = radius - np.sqrt((loc[best] * loc[best]).sum())
        lab_point(rotations, i, loc[best], centre, pts, c)
    return pts, gap


def container_tips(net: EllipsoidContacts, rotations: np.ndarray) -> np.ndarray:
    """The contact points of the container contacts in their particles' body frames, relative to
    the particle centres: what :func:`contacts_of_pairs` tracks a container contact by (a particle
    can touch the container at two tips, module docstring).

    Parameters
    ----------
    net : EllipsoidContacts
        Contacts of a packing in a spherical container.
    rotations : numpy.ndarray of float, shape (N, d, d)
        Lab to body rotations of the particles (``Ellipsoids.rotations``).

    Returns
    -------
    numpy.ndarray of float, shape (W, d)
        R_i (p - x_i) of every container contact, in the order of the network's wall contacts.
    """
    on_wall = net.is_wall
    return np.einsum("mkq,mq->mk", np.asarray(rotations, float)[net.i[on_wall]], net.lever_i[on_wall])


def _append_container(net: EllipsoidContacts, part, point, h, centre, radius: float) -> EllipsoidContacts:
    """``net`` with container contacts of particles ``part`` at the lab-frame points ``point``
    with gaps ``h`` appended (module docstring: j = i, scale 1, zeta with ``gap`` = h / a_max)."""
    x, d = net.positions, net.dim
    rel = point - centre
    u = rel / np.linalg.norm(rel, axis=1)[:, None]
    amax = net.semiaxes[part].max(axis=1)
    m = len(part)
    wall = EllipsoidContacts(
        i=part, j=part, shift=np.zeros((m, d), np.int64), separation=rel,
        zeta=(1.0 + h / amax) ** 2 - 1.0, lam=np.full(m, np.nan), normal=u, raw_normal=u.copy(),
        lever_i=point - x[part], lever_j=np.zeros((m, d)), scale=np.ones(m), positions=x,
        lattice=net.lattice, shape_inv=net.shape_inv, semiaxes=net.semiaxes, delta=net.delta,
        wall=np.zeros(m, np.int64))
    kw = {k: np.concatenate([getattr(net, k), getattr(wall, k)]) for k in _PER_CONTACT}
    return EllipsoidContacts(**kw, positions=x, lattice=net.lattice, shape_inv=net.shape_inv,
                             semiaxes=net.semiaxes, delta=net.delta, centre=centre, radius=radius)


def plane_wall_contacts(positions, shape_inv, semiaxes, axes, lengths, delta):
    """Contacts of ellipsoids with the flat hard walls x_k = 0 and x_k = L_k (module docstring).

    The particle's farthest point along the wall's outward normal n is p = x + X^-1 n / s,
    s = sqrt(n^T X^-1 n) = sqrt((X^-1)_kk) for n = +-e_k, and the gap is h = x_k - s (wall
    x_k = 0) or L_k - x_k - s (wall x_k = L_k); every wall with h <= delta a_max is a contact.

    Parameters
    ----------
    positions : numpy.ndarray of float, shape (N, d)
        Particle centres (along the walled axes as given, not wrapped).
    shape_inv : numpy.ndarray of float, shape (N, d, d)
        X^-1 of every particle (:func:`hardpack.geometry.contact.inverse_shapes`).
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes (a_max sets the contact tolerance).
    axes : sequence of int
        The walled axes k.
    lengths : sequence of float
        L_k of each walled axis (the diagonal entry of the lattice).
    delta : float
        Walls with h <= delta a_max are contacts.

    Returns
    -------
    particle : numpy.ndarray of int, shape (M,)
        The particle of each contact, sorted by particle, then by wall number.
    wall : numpy.ndarray of int, shape (M,)
        2 k for the wall x_k = 0, 2 k + 1 for x_k = L_k.
    normal : numpy.ndarray of float, shape (M, d)
        The wall's outward unit normal n (-e_k or +e_k).
    lever : numpy.ndarray of float, shape (M, d)
        p - x = X^-1 n / s.
    gap : numpy.ndarray of float, shape (M,)
        h (negative when the particle crosses the wall).
    distance : numpy.ndarray of float, shape (M,)
        The centre-wall distance b - n . x (x_k or L_k - x_k).
    """
    x = np.asarray(positions, dtype=float)
    inv = np.asarray(shape_inv, dtype=float)
    n, d = x.shape
    full = np.zeros(d)
    full[np.asarray(axes, np.int64)] = lengths
    walls = np.array(sorted(2 * int(k) + upper for k in axes for upper in (0, 1)), np.int64)
    particle = np.repeat(np.arange(n, dtype=np.int64), walls.size)  # sorted by particle, then wall
    found = _plane_wall_rows(x, inv, full, particle, np.tile(walls, n))
    amax = np.asarray(semiaxes, dtype=float).max(axis=1)
    keep = found[4] <= delta * amax[particle]
    return tuple(column[keep] for column in found)


def _plane_wall_rows(x, inv, lengths, particle, wall):
    """The flat-wall contact data (the arrays of :func:`plane_wall_contacts`) of the given
    (particle, wall number) pairs, touching or not, in that order; ``lengths`` holds L_k at each
    walled axis k."""
    k, upper = np.divmod(wall, 2)
    s = np.sqrt(inv[particle, k, k])
    dist = np.where(upper == 1, lengths[k] - x[particle, k], x[particle, k])
    sign = np.where(upper == 1, 1.0, -1.0)
    normal = np.zeros((len(particle), x.shape[1]))
    normal[np.arange(len(particle)), k] = sign
    lever = sign[:, None] * inv[particle, :, k] / s[:, None]
    return particle, wall, normal, lever, dist - s, dist


def _check_centres_between_walls(packing: Packing) -> None:
    """Refuse centres beyond a flat wall (x_k < 0 or x_k > L_k on a walled axis k). Inside,
    h = (x_k or L_k - x_k) - s >= -s >= -a_max, so the stored gap h / a_max >= -1 is encoded
    faithfully by ``zeta`` (module docstring) and an overlap is reported with its size."""
    axes = list(packing.boundary.axes)
    x = packing.positions[:, axes]
    length = np.diag(packing.lattice)[axes]
    out = (x < 0) | (x > length)
    if out.any():
        i, q = (int(v[0]) for v in np.nonzero(out))
        k = axes[q]
        raise InvalidInputError(
            f"the centre of particle {i} lies beyond the wall x_{k} = {0.0 if x[i, q] < 0 else length[q]:.6g} "
            f"(x_{k} = {x[i, q]:.6g}; the walls are at 0 and {length[q]:.6g}); particles between hard "
            "walls must lie inside them: move it in or shrink the particles")


def _with_plane_walls(net: EllipsoidContacts, boundary) -> EllipsoidContacts:
    """``net`` with the contacts of the flat hard walls appended (module docstring)."""
    axes = list(boundary.axes)
    found = plane_wall_contacts(net.positions, net.shape_inv, net.semiaxes, axes, np.diag(net.lattice)[axes],
                                net.delta)
    return _append_plane_walls(net, *found)


def _append_plane_walls(net: EllipsoidContacts, part, wall, u, lever, h, dist) -> EllipsoidContacts:
    """``net`` with flat-wall contacts appended (module docstring: j = i, scale 1, zeta with
    ``gap`` = h / a_max)."""
    x, d = net.positions, net.dim
    amax = net.semiaxes[part].max(axis=1)
    m = len(part)
    walls = dict(
        i=part, j=part, shift=np.zeros((m, d), np.int64), separation=dist[:, None] * u,
        zeta=(1.0 + h / amax) ** 2 - 1.0, lam=np.full(m, np.nan), normal=u, raw_normal=u.copy(),
        lever_i=lever, lever_j=np.zeros((m, d)), scale=np.ones(m), wall=wall)
    kw = {k: np.concatenate([getattr(net, k), walls[k]]) for k in _PER_CONTACT}
    return EllipsoidContacts(**kw, positions=x, lattice=net.lattice, shape_inv=net.shape_inv,
                             semiaxes=net.semiaxes, delta=net.delta, periodic=net.periodic)


def wall_name(net: EllipsoidContacts, c: int) -> str:
    """The wall of wall contact ``c`` in words: "the container wall" or "the wall x_k = 0" /
    "the wall x_k = L_k" (with the value of L_k).

    Parameters
    ----------
    net : EllipsoidContacts
        The contact network.
    c : int
        Index of a wall contact (``net.wall[c] >= 0``).

    Returns
    -------
    str
        The name.
    """
    if net.centre is not None:
        return "the container wall"
    k, upper = divmod(int(net.wall[c]), 2)
    return f"the wall x_{k} = {net.lattice[k, k]:.6g}" if upper else f"the wall x_{k} = 0"


def contacts_of_pairs(packing: Packing, i, j, shift, positions=None, walls=None) -> EllipsoidContacts:
    """The contact data of given pairs (i, j, image shift), touching or not (``delta`` = inf), and
    of given wall contacts after them.

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell, between flat hard walls or in a spherical container.
    i, j : array_like of int, shape (M,)
        The pairs.
    shift : array_like of int, shape (M, d)
        Lattice images: the separation is x_j + L shift - x_i.
    positions : ndarray, shape (N, d), optional
        The centres x the shifts refer to (default ``packing.positions`` as given, not wrapped).
    walls : tuple of array_like, optional
        Wall contacts, appended after the pairs in this order: (particle, wall number) of flat
        walls (2 k for x_k = 0, 2 k + 1 for x_k = L_k), or (particle, wall number 0, tip) in a
        spherical container, where tip (W, d) is a point near the contact in the particle's body
        frame relative to its centre (:func:`container_tips`): the contact is the local farthest
        point nearest it (a particle can touch the container at two tips, module docstring).

    Returns
    -------
    EllipsoidContacts

    Raises
    ------
    InvalidInputError
        If ``walls`` is given for a periodic packing, names a wall the boundary does not have, or
        lacks the tips in a container.
    """
    check_ellipsoid_packing(packing)
    boundary = packing.boundary
    if walls is not None and len(walls[0]):
        if boundary.kind == "periodic":
            raise InvalidInputError(f"wall contacts need a packing with walls, not {boundary}")
        if boundary.kind == "hard_walls":
            axes = set(int(k) for k in boundary.axes)
            if not set(int(k) for k in np.asarray(walls[1]) // 2) <= axes:
                raise InvalidInputError(
                    f"a wall contact names a wall on an axis without walls (walled axes {sorted(axes)})")
        elif len(walls) != 3 or np.any(np.asarray(walls[1]) != 0):
            raise InvalidInputError("container contacts are given as (particle, 0, tip), the tip a body-frame "
                                    "point near the contact (container_tips)")
    shape = packing.shape
    n = packing.n_particles
    semiaxes = np.ascontiguousarray(shape.semiaxes, dtype=float)
    orient = np.ascontiguousarray(np.asarray(shape.orientations, dtype=float).reshape(n, -1))
    inv = inverse_shapes(semiaxes, orient)
    x = np.ascontiguousarray(packing.positions if positions is None else positions, dtype=float)
    ii, jj = np.asarray(i, np.int64), np.asarray(j, np.int64)
    shift = np.asarray(shift, np.int64).reshape(len(ii), packing.dim)
    lattice = np.array(packing.lattice, float)
    sep = np.ascontiguousarray(x[jj] + shift @ lattice.T - x[ii])
    zeta, lam, raw, point = _pair_contacts(x, inv, np.asarray(shape.bounding_radii, float), ii, jj, sep)
    norm = np.linalg.norm(raw, axis=1)
    container = boundary.kind == "spherical_container"
    net = EllipsoidContacts(
        i=ii, j=jj, shift=shift, separation=sep, zeta=zeta, lam=lam, normal=raw / norm[:, None],
        raw_normal=raw, lever_i=point - x[ii], lever_j=point - (x[ii] + sep),
        scale=2.0 * lam * (1.0 - lam) * norm, positions=x, lattice=lattice, shape_inv=inv,
        semiaxes=semiaxes, delta=float("inf"), periodic=boundary.periodic_axes(packing.dim),
        centre=np.asarray(boundary.centre, dtype=float) if container else None,
        radius=float(boundary.radius) if container else None,
    )
    if walls is None or not len(walls[0]):
        return net
    part = np.asarray(walls[0], np.int64)
    if container:
        tips = np.ascontiguousarray(np.asarray(walls[2], dtype=float).reshape(len(part), packing.dim))
        point, h = _tracked_container_rows(x, semiaxes, np.ascontiguousarray(shape.rotations(), dtype=float),
                                           net.centre, net.radius, part, tips)
        return _append_container(net, part, point, h, net.centre, net.radius)
    found = _plane_wall_rows(x, inv, np.diag(lattice), part, np.asarray(walls[1], np.int64))
    return _append_plane_walls(net, *found)


def check_ellipsoid_packing(packing) -> None:
    """Refuse anything but a packing of ellipses or ellipsoids (periodic, between flat hard walls or
    in a spherical container).

    Parameters
    ----------
    packing : Packing
        The packing to test.

    Raises
    ------
    InvalidInputError
        If it is not a packing of ellipses or ellipsoids.
    """
    if not isinstance(packing, Packing):
        raise InvalidInputError(
            f"expected a hardpack Packing, got {type(packing).__name__}; build one with "
            "hardpack.Packing(positions, lattice=..., shape=Ellipsoids(semiaxes, orientations))"
        )
    if packing.shape.kind != "ellipsoid":
        raise InvalidInputError(
            f"this test is for ellipses and ellipsoids, the packing holds {packing.shape.name}; "
            "use hardpack.jamming.verify for spheres"
        )
    if packing.boundary.kind not in ("periodic", "hard_walls", "spherical_container"):
        raise InvalidInputError(
            f"the ellipsoid jamming tests need a periodic cell, flat hard walls or a spherical "
            f"container, got the boundary {packing.boundary}"
        )


def rigidity_transpose_full(net: EllipsoidContacts) -> sp.csr_matrix:
    """A^T (M, N d_f): row c is the gap rate of contact c (module docstring), all particle dof; a
    wall contact has its particle's block only.

    Parameters
    ----------
    net : EllipsoidContacts
        The contact network.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (M, N d_f)
        A^T; the dof of particle i are (x_i, omega_i), d_f = :func:`dof_per_particle`.
    """
    m, d, n = net.n_contacts, net.dim, net.n_particles
    f = dof_per_particle(d)
    u = net.normal
    ti, tj = _cross(net.lever_i, u), _cross(net.lever_j, u)
    ti, tj = ti.reshape(m, f - d), tj.reshape(m, f - d)
    block_i = np.concatenate([-u, -ti], axis=1)
    block_j = np.concatenate([u, tj], axis=1) * (net.wall < 0)[:, None]  # the wall is fixed
    dofs = np.arange(f)
    rows = np.repeat(np.arange(m), 2 * f)
    cols = np.concatenate([net.i[:, None] * f + dofs, net.j[:, None] * f + dofs], axis=1).ravel()
    vals = np.concatenate([block_i, block_j], axis=1).ravel()
    at = sp.csr_matrix((vals, (rows, cols)), shape=(m, n * f))  # sums the blocks of i == j
    at.eliminate_zeros()
    return at


@numba.njit(cache=True)
def _hessian_one(r, a_inv, b_inv, lam, gens):
    """Hessian of zeta in (r_A, omega_A, r_B, omega_B); see :func:`zeta_hessian`."""
    d = r.shape[0]
    k = gens.shape[0]
    f = d + k
    c = lam * (1.0 - lam)
    y = lam * b_inv + (1.0 - lam) * a_inv
    p = np.linalg.inv(y)
    n = p @ r
    dmat = b_inv - a_inv
    # first derivatives of Y and D with respect to the rotations of A (0) and B (1)
    dy = np.empty((2, k, d, d))
    dd = np.empty((2, k, d, d))
    for a in range(k):
        e = gens[a]
        ga = e @ a_inv - a_inv @ e
        gb = e @ b_inv - b_inv @ e
        dy[0, a] = (1.0 - lam) * ga
        dy[1, a] = lam * gb
        dd[0, a] = -ga
        dd[1, a] = gb
    # F_xx at fixed lambda
    h = np.zeros((2 * f, 2 * f))
    for s in range(d):
        for t in range(d):
            h[s, t] = h[f + s, f + t] = 2.0 * c * p[s, t]
            h[s, f + t] = h[f + s, t] = -2.0 * c * p[s, t]
    for x in range(2):
        for a in range(k):
            col = x * f + d + a
            v = p @ (dy[x, a] @ n)
            for s in range(d):
                h[s, col] = h[col, s] = 2.0 * c * v[s]  # r_A
                h[f + s, col] = h[col, f + s] = -2.0 * c * v[s]  # r_B
    for x in range(2):
        m = a_inv if x == 0 else b_inv
        coef = (1.0 - lam) if x == 0 else lam
        for a in range(k):
            for yy in range(2):
                for b in range(k):
                    val = 2.0 * c * (n @ (dy[x, a] @ (p @ (dy[yy, b] @ n))))
                    if x == yy:
                        ea, eb = gens[a], gens[b]
                        sym = 0.5 * (ea @ eb + eb @ ea)
                        gab = sym @ m + m @ sym - (ea @ m @ eb + eb @ m @ ea)
                        val -= c * coef * (n @ (gab @ n))
                    h[x * f + d + a, yy * f + d + b] = val
    # mixed derivatives with lambda and the envelope correction
    g = np.zeros(2 * f)
    dn = dmat @ n
    flr = 2.0 * (1.0 - 2.0 * lam) * n - 2.0 * c * (p @ dn)
    for s in range(d):
        g[s] = -flr[s]
        g[f + s] = flr[s]
    for x in range(2):
        for a in range(k):
            dyn = dy[x, a] @ n
            g[x * f + d + a] = (-(1.0 - 2.0 * lam) * (n @ dyn) + 2.0 * c * (dn @ (p @ dyn))
                                - c * (n @ (dd[x, a] @ n)))
    fll = -2.0 * (r @ n) - 2.0 * (1.0 - 2.0 * lam) * (n @ dn) + 2.0 * c * (dn @ (p @ dn))
    for s in range(2 * f):
        for t in range(2 * f):
            h[s, t] -= g[s] * g[t] / fll
    return h


@numba.njit(cache=True)
def _hessians(sep, shape_inv, ii, jj, lam, gens):
    m, d = sep.shape
    f = d + gens.shape[0]
    out = np.empty((m, 2 * f, 2 * f))
    for c in range(m):
        out[c] = _hessian_one(sep[c], shape_inv[ii[c]], shape_inv[jj[c]], lam[c], gens)
    return out


def zeta_hessian(r_ab, a_inv, b_inv, lam) -> np.ndarray:
    """Hessian of the Perram-Wertheim potential zeta with respect to (r_A, omega_A, r_B, omega_B).

    zeta(Q) = max_lam F(lam, Q) with F = lam (1 - lam) r^T Y^-1 r - 1, r = r_B - r_A,
    Y = lam B + (1 - lam) A and A = R_A A0 R_A^T, R = exp(W(omega)) (module docstring). By the
    envelope theorem Hess zeta = F_QQ - F_Qlam F_lamQ / F_lamlam (derived here; Donev 2006,
    Sec. 2.2.4 gives the same structure). With c = lam (1 - lam), P = Y^-1, n = P r, D = B - A,
    the generators G_a(M) = E_a M - M E_a and
    G_ab(M) = (E_a E_b + E_b E_a) M / 2 + M (E_a E_b + E_b E_a) / 2 - E_a M E_b - E_b M E_a
    (the first and second derivatives of R M R^T), Delta_{A,a} = (1 - lam) G_a(A),
    Delta_{B,a} = lam G_a(B):

    - F_rr = 2 c P (with the signs of r = r_B - r_A), F_{r_B omega} = -2 c P Delta n,
    - F_{omega_X,a omega_Y,b} = 2 c n^T Delta_{X,a} P Delta_{Y,b} n - [X = Y] c w_X n^T G_ab(X) n,
      w_A = 1 - lam, w_B = lam,
    - F_{lam r_B} = 2 (1 - 2 lam) n - 2 c P D n,
      F_{lam omega} = -(1 - 2 lam) n^T Delta n + 2 c n^T D P Delta n - c n^T (dD) n with
      dD = -G_a(A) for omega_A and +G_a(B) for omega_B,
    - F_lamlam = -2 r.n - 2 (1 - 2 lam) n^T D n + 2 c (D n)^T P (D n).

    Parameters
    ----------
    r_ab : ndarray, shape (d,)
        r_B - r_A.
    a_inv, b_inv : ndarray, shape (d, d)
        X_A^-1 and X_B^-1.
    lam : float
        The maximiser from :func:`hardpack.geometry.contact.pw_contact`.

    Returns
    -------
    ndarray, shape (2 d_f, 2 d_f)
        The Hessian in the order (r_A, omega_A, r_B, omega_B), d_f = 3 (2D) or 6 (3D).
    """
    r = np.asarray(r_ab, float)
    return _hessian_one(r, np.asarray(a_inv, float), np.asarray(b_inv, float), float(lam),
                        generators(r.shape[0]))


def contact_hessians(net: EllipsoidContacts) -> np.ndarray:
    """Hess zeta of every contact, (M, 2 d_f, 2 d_f) in the order (r_i, omega_i, r_j, omega_j)
    (:func:`zeta_hessian`); for a wall contact the Hessian of its gap h (:func:`wall_gap_hessian`
    for the container, :func:`plane_gap_hessian` for a flat wall) in the (r_i, omega_i) block and
    zeros elsewhere.

    Parameters
    ----------
    net : EllipsoidContacts
        The contact network.

    Returns
    -------
    numpy.ndarray of float, shape (M, 2 d_f, 2 d_f)
        The Hessian of every contact.
    """
    gens = generators(net.dim)
    pair = np.flatnonzero(net.wall < 0)
    if pair.size == net.n_contacts:
        return _hessians(net.separation, net.shape_inv, net.i, net.j, net.lam, gens)
    f = dof_per_particle(net.dim)
    out = np.zeros((net.n_contacts, 2 * f, 2 * f))
    out[pair] = _hessians(net.separation[pair], net.shape_inv, net.i[pair], net.j[pair], net.lam[pair], gens)
    wall = np.flatnonzero(net.wall >= 0)
    p = net.i[wall]
    if net.centre is None:
        out[wall, :f, :f] = _plane_hessians(np.ascontiguousarray(net.normal[wall]), net.shape_inv[p], gens)
    else:
        out[wall, :f, :f] = _wall_hessians(np.ascontiguousarray(net.positions[p] - net.centre),
                                           np.ascontiguousarray(net.lever_i[wall]), net.shape_inv[p], gens)
    return out


@numba.njit(cache=True)
def _plane_hessian_one(normal, x_inv, gens):
    """Hessian of h = b - n . x - s; see :func:`plane_gap_hessian`."""
    d = normal.shape[0]
    k = gens.shape[0]
    f = d + k
    mn = x_inv @ normal
    s = np.sqrt(normal @ mn)
    en = np.empty((k, d))
    g = np.empty(k)
    for a in range(k):
        en[a] = gens[a] @ normal
        g[a] = -2.0 * (mn @ en[a])
    out = np.zeros((f, f))
    for a in range(k):
        for b in range(k):
            sym = gens[a] @ gens[b] + gens[b] @ gens[a]
            gab = 2.0 * (en[a] @ (x_inv @ en[b])) + mn @ (sym @ normal)
            out[d + a, d + b] = -(gab / (2.0 * s) - g[a] * g[b] / (4.0 * s * s * s))
    return out


@numba.njit(cache=True)
def _plane_hessians(normal, shape_inv, gens):
    m, d = normal.shape
    f = d + gens.shape[0]
    out = np.empty((m, f, f))
    for c in range(m):
        out[c] = _plane_hessian_one(normal[c], shape_inv[c], gens)
    return out


def plane_gap_hessian(normal, x_inv) -> np.ndarray:
    """Hessian of the gap h = b - n . x - s of a particle and a flat wall n . y = b with respect to
    (r, omega) (translation, then rotation as in :func:`zeta_hessian`; derived here).

    h is linear in the centre x, so the r-r and r-omega blocks vanish. With X^-1 = M now and the
    orientation R(omega) = exp(W) times the current one (W = sum_a omega_a E_a), X^-1 becomes
    R M R^T and s(omega) = sqrt(g), g = n^T R M R^T n = v^T M v with v = R^T n. To second order
    R^T = I - W + W^2 / 2, so v = n - W n + W^2 n / 2 and

        g = n^T M n - 2 n^T M W n + (W n)^T M (W n) + n^T M W^2 n + O(omega^3),

    g_a = -2 (M n) . (E_a n),  g_ab = 2 (E_a n)^T M (E_b n) + (M n)^T (E_a E_b + E_b E_a) n.

    Then s_ab = g_ab / (2 s) - g_a g_b / (4 s^3) and Hess_omega h = -Hess s. (The first derivative
    s_a = g_a / (2 s) = -(M n / s) . (E_a n) = (r_C x n)_a with r_C = M n / s = p - x, the row
    of A^T.) Example: an ellipse with semiaxes (a, b) along (x, y) and the wall y = b (n = e_y):
    g = b^2 cos^2 theta + a^2 sin^2 theta, so s = b + (a^2 - b^2) theta^2 / (2 b) + O(theta^4)
    and h_theta,theta = -(a^2 - b^2) / b.

    Parameters
    ----------
    normal : numpy.ndarray of float, shape (d,)
        The wall's outward unit normal n.
    x_inv : numpy.ndarray of float, shape (d, d)
        X^-1 of the particle.

    Returns
    -------
    numpy.ndarray of float, shape (d_f, d_f)
        Hess h in the order (r, omega); only the (omega, omega) block is nonzero.
    """
    n = np.asarray(normal, float)
    return _plane_hessian_one(n, np.asarray(x_inv, float), generators(n.shape[0]))


@numba.njit(cache=True)
def _wall_hessian_one(rel, y, x_inv, gens):
    """Hessian of h = R - rho; see :func:`wall_gap_hessian`."""
    d = rel.shape[0]
    k = gens.shape[0]
    f = d + k
    shape = np.linalg.inv(x_inv)
    p = rel + y
    rho = np.sqrt(p @ p)
    xy = shape @ y
    mu = np.sqrt((p @ p) / (xy @ xy))
    ey = np.empty((k, d))
    for a in range(k):
        ey[a] = gens[a] @ y
    lqq = np.zeros((f, f))
    lqy = np.zeros((f, d))
    for s in range(d):
        lqq[s, s] = 2.0
        lqy[s, s] = 2.0
    for a in range(k):
        er = gens[a] @ rel
        for s in range(d):
            lqq[s, d + a] = lqq[d + a, s] = 2.0 * ey[a, s]
            lqy[d + a, s] = -2.0 * er[s]
        for b in range(k):
            sym = gens[a] @ gens[b] + gens[b] @ gens[a]
            lqq[d + a, d + b] = 2.0 * (ey[a] @ ey[b]) + p @ (sym @ y)
    kkt = np.zeros((d + 1, d + 1))
    rhs = np.zeros((d + 1, f))
    for s in range(d):
        for t in range(d):
            kkt[s, t] = -2.0 * mu * shape[s, t]
        kkt[s, s] += 2.0
        kkt[s, d] = kkt[d, s] = -2.0 * xy[s]
        for q in range(f):
            rhs[s, q] = -lqy[q, s]
    sol = np.linalg.solve(kkt, rhs)
    hv = lqq + lqy @ np.ascontiguousarray(sol[:d])
    grad = np.empty(f)
    for s in range(d):
        grad[s] = p[s] / rho
    for a in range(k):
        grad[d + a] = (p @ ey[a]) / rho
    out = np.empty((f, f))
    for s in range(f):
        for t in range(f):
            out[s, t] = -(0.5 * (hv[s, t] + hv[t, s]) - 2.0 * grad[s] * grad[t]) / (2.0 * rho)
    return out


@numba.njit(cache=True)
def _wall_hessians(rel, lever, shape_inv, gens):
    m, d = rel.shape
    f = d + gens.shape[0]
    out = np.empty((m, f, f))
    for c in range(m):
        out[c] = _wall_hessian_one(rel[c], lever[c], shape_inv[c], gens)
    return out


def wall_gap_hessian(rel, lever, x_inv) -> np.ndarray:
    """Hessian of the wall gap h = R - rho of a particle in a spherical container with respect to
    (r, omega) (translation, then rotation as in :func:`zeta_hessian`), at a strict local farthest
    point p (derived here).

    With rel = x - c, the lever y = p - x in the lab frame, X the shape matrix (X^-1 = ``x_inv``)
    and R(omega) = exp(W), the point is x + R(omega) y' with y' on the current body surface
    y'^T X y' = 1, so rho^2 = V(q) = max_y' F(q, y'), F = |rel + R(omega) y'|^2. With the
    Lagrangian L = F - mu (y'^T X y' - 1) (stationary: p - c = mu X y, mu > 0), the value
    function has Hess V = L_qq + L_qy y_q, where (y_q, mu_q) solve the KKT system
    [[L_yy, -c_y], [-c_y^T, 0]] [y_q; mu_q] = [-L_yq; 0], c_y = 2 X y (the constraint does not
    depend on q). At omega = 0: L_yy = 2 I - 2 mu X, L_rr = 2 I, L_ry = 2 I,
    L_{r omega_a} = 2 E_a y, L_{omega_a omega_b} = 2 (E_a y).(E_b y) + (p - c).(E_a E_b + E_b E_a) y
    (R = I + W + W^2 / 2), L_{omega_a y} = -2 E_a rel (grad_y of 2 (rel + y)^T E_a y, E_a^T = -E_a).
    Then Hess rho = (Hess V - 2 grad rho grad rho^T) / (2 rho) with grad rho = (n, y x n) and
    Hess h = -Hess rho. At a strict local maximum L_yy is negative definite on the tangent plane,
    so the KKT matrix is regular; unlike the secular form of
    :mod:`hardpack.geometry.ellipsoid_container` this holds in the hard case too (a tip).

    Parameters
    ----------
    rel : ndarray, shape (d,)
        Particle centre minus container centre.
    lever : ndarray, shape (d,)
        The local farthest point minus the particle centre.
    x_inv : ndarray, shape (d, d)
        X^-1 of the particle.

    Returns
    -------
    ndarray, shape (d_f, d_f)
    """
    rel = np.asarray(rel, float)
    return _wall_hessian_one(rel, np.asarray(lever, float), np.asarray(x_inv, float), generators(rel.shape[0]))


def stiffness_matrix_full(net: EllipsoidContacts, forces: np.ndarray,
                          hessians: np.ndarray | None = None) -> sp.csr_matrix:
    """K = -sum_c (F_c / s_c) Hess zeta_c over all particle dof (N d_f square; module docstring).

    Parameters
    ----------
    net : EllipsoidContacts
        The contacts.
    forces : ndarray, shape (M,)
        A self-stress in the units of the gap rows (:func:`rigidity_transpose_full`).
    hessians : ndarray, shape (M, 2 d_f, 2 d_f), optional
        :func:`contact_hessians` of ``net`` when already computed.

    Returns
    -------
    scipy.sparse.csr_matrix
        The stiffness (negative stress matrix), symmetric.
    """
    d, n = net.dim, net.n_particles
    f = dof_per_particle(d)
    hs = contact_hessians(net) if hessians is None else hessians
    w = -np.asarray(forces, float) / net.scale
    idx = np.concatenate([net.i[:, None] * f + np.arange(f), net.j[:, None] * f + np.arange(f)], axis=1)
    rows = np.repeat(idx, 2 * f, axis=1).ravel()
    cols = np.tile(idx, (1, 2 * f)).ravel()
    vals = (hs * w[:, None, None]).ravel()
    k = sp.csr_matrix((vals, (rows, cols)), shape=(n * f, n * f))
    return ((k + k.T) * 0.5).tocsr()


def displaced(packing: Packing, positions: np.ndarray, rotation: np.ndarray, factor: float,
              lattice: np.ndarray | None = None) -> Packing:
    """The packing of ellipses or ellipsoids moved and grown (overlaps allowed).

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids.
    positions : numpy.ndarray of float, shape (N, d)
        The new centres.
    rotation : numpy.ndarray of float, shape (N, 1) in 2D or (N, 3) in 3D
        Lab-frame rotation vectors (an angle in 2D) that turn each orientation.
    factor : float
        Factor of every semiaxis.
    lattice : numpy.ndarray of float, shape (d, d), optional
        A new cell (lattice vectors as columns); default the packing's.

    Returns
    -------
    Packing
        The same species, boundary and overlap tolerance (and cell, without ``lattice``).
    """
    shape = packing.shape
    if packing.dim == 2:
        orient = np.asarray(shape.orientations, float).reshape(-1) + rotation[:, 0]
    else:
        # orientations are (w, x, y, z) of the rotation R = Q^T (Q lab to body): R -> exp(W) R
        current = Rotation.from_quat(np.roll(np.asarray(shape.orientations, float), -1, axis=1))
        orient = np.roll((Rotation.from_rotvec(rotation) * current).as_quat(), 1, axis=1)
    return Packing(positions, lattice=packing.lattice if lattice is None else lattice, species=packing.species,
                   shape=Ellipsoids(shape.semiaxes * factor, orient), boundary=packing.boundary,
                   overlap_tol=packing.overlap_tol, allow_overlap=True)
