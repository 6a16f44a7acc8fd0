"""Contact network, rigidity matrix and stress matrix of a periodic packing of ellipses or ellipsoids.

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

Stress matrix (Sec. 5.5.2.1, Eq. 5.16). For a self-stress F (A F = 0, F >= 0, in the units of the
rows above) the stress matrix is the force-weighted sum of the contacts' Hessians of zeta,
sum_c (F_c / s_c) Hess zeta_c. With the sign convention of Donev (zeta >= 0 for disjoint
particles), a floppy mode Qdot (A^T Qdot = 0) is blocked at second order iff
Qdot^T (sum_c F_c / s_c Hess zeta_c) Qdot < 0. We store the negative, the *stiffness*
K = -sum_c (F_c / s_c) Hess zeta_c, which is positive on blocked modes. The factor 1 / s_c converts
zeta to the gap: both vanish on the same set, zeta = gap * s + O(gap^2), so on a floppy mode
(grad gap . Qdot = 0) Qdot^T Hess zeta Qdot = s Qdot^T Hess gap Qdot; the terms that depend on the
parametrisation of the rotations (Qddot) drop out because A F = 0 (Eq. 5.15).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

from hardpack.errors import InvalidInputError
from hardpack.geometry.contact import contact_point, inverse_shapes, pw_contact
from hardpack.geometry.neighbours.pairs import pairs_within, wrapped_positions
from hardpack.geometry.packing import Packing
from hardpack.jamming.contacts import ContactArrays

__all__ = [
    "EllipsoidContacts",
    "ellipsoid_contacts",
    "contacts_of_pairs",
    "dof_per_particle",
    "rigidity_transpose_full",
    "stiffness_matrix_full",
    "contact_hessians",
    "zeta_hessian",
    "generators",
]


def dof_per_particle(d: int) -> int:
    """d + d(d-1)/2: translations and rotations of one particle (3 in 2D, 6 in 3D)."""
    return d + d * (d - 1) // 2


def generators(d: int) -> np.ndarray:
    """The infinitesimal rotations E_a (E_a v = e_a x v; in 2D the rotation by +90 degrees), (k, d, d)."""
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
    particle's X^-1 (N, d, d).
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

    @property
    def gap(self) -> np.ndarray:
        """mu - 1, the relative scale gap of every contact (negative for overlaps)."""
        return np.sqrt(np.maximum(self.zeta + 1.0, 0.0)) - 1.0

    def subset(self, mask) -> EllipsoidContacts:
        """The network of the contacts in ``mask`` (boolean (M,) or indices)."""
        per = ("i", "j", "shift", "separation", "zeta", "lam", "normal", "raw_normal", "lever_i",
               "lever_j", "scale")
        kw = {k: getattr(self, k)[mask] for k in per}
        return EllipsoidContacts(**kw, positions=self.positions, lattice=self.lattice,
                                 shape_inv=self.shape_inv, semiaxes=self.semiaxes, delta=self.delta)

    def counts(self, active: np.ndarray | None = None) -> np.ndarray:
        """Contacts per particle among ``active`` (a self-image contact counts twice)."""
        keep = self.among(active)
        n = self.n_particles
        return np.bincount(self.i[keep], minlength=n) + np.bincount(self.j[keep], minlength=n)


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
        Ellipses or ellipsoids (``hardpack.geometry.shapes.Ellipsoids``) in a periodic cell.
    delta : float
        Relative contact tolerance, 0 < delta < 1: pairs with mu - 1 <= delta are contacts (mu the
        common factor by which both particles must be scaled to be tangent).

    Returns
    -------
    EllipsoidContacts
        The contacts with unit normals, lever arms and the PW data.

    Raises
    ------
    InvalidInputError
        If ``packing`` is not a periodic packing of ellipsoids, or delta is not in (0, 1).
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
    pairs = pairs_within(packing, rel_gap=delta)
    x = np.ascontiguousarray(wrapped_positions(packing))
    ii, jj = pairs.i.astype(np.int64), pairs.j.astype(np.int64)
    sep = np.ascontiguousarray(pairs.separation, dtype=float)
    zeta, lam, raw, point = _pair_contacts(x, inv, np.asarray(shape.bounding_radii, float), ii, jj, sep)
    keep = np.sqrt(np.maximum(zeta + 1.0, 0.0)) - 1.0 <= delta
    ii, jj, sep, zeta, lam, raw, point = (a[keep] for a in (ii, jj, sep, zeta, lam, raw, point))
    norm = np.linalg.norm(raw, axis=1)
    u = raw / norm[:, None]
    return EllipsoidContacts(
        i=ii, j=jj, shift=pairs.shift[keep].astype(np.int64), separation=sep, zeta=zeta, lam=lam,
        normal=u, raw_normal=raw, lever_i=point - x[ii], lever_j=point - (x[ii] + sep),
        scale=2.0 * lam * (1.0 - lam) * norm, positions=x, lattice=np.array(packing.lattice, float),
        shape_inv=inv, semiaxes=semiaxes, delta=delta,
    )


def contacts_of_pairs(packing: Packing, i, j, shift, positions=None) -> EllipsoidContacts:
    """The contact data of given pairs (i, j, image shift), touching or not (``delta`` = inf).

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell.
    i, j : array_like of int, shape (M,)
        The pairs.
    shift : array_like of int, shape (M, d)
        Lattice images: the separation is x_j + L shift - x_i.
    positions : ndarray, shape (N, d), optional
        The centres x the shifts refer to (default ``packing.positions`` as given, not wrapped).

    Returns
    -------
    EllipsoidContacts
    """
    check_ellipsoid_packing(packing)
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
    return EllipsoidContacts(
        i=ii, j=jj, shift=shift, separation=sep, zeta=zeta, lam=lam, normal=raw / norm[:, None],
        raw_normal=raw, lever_i=point - x[ii], lever_j=point - (x[ii] + sep),
        scale=2.0 * lam * (1.0 - lam) * norm, positions=x, lattice=lattice, shape_inv=inv,
        semiaxes=semiaxes, delta=float("inf"),
    )


def check_ellipsoid_packing(packing) -> None:
    """Refuse anything but a periodic packing of ellipses or ellipsoids."""
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
    if not np.all(packing.boundary.periodic_axes(packing.dim)):
        raise InvalidInputError(
            "the ellipsoid jamming tests need a periodic cell (fixed walls are not implemented); "
            "model fixed obstacles as frozen particles (argument `frozen`)"
        )


def rigidity_transpose_full(net: EllipsoidContacts) -> sp.csr_matrix:
    """A^T (M, N d_f): row c is the gap rate of contact c (module docstring), all particle dof."""
    m, d, n = net.n_contacts, net.dim, net.n_particles
    f = dof_per_particle(d)
    u = net.normal
    ti, tj = _cross(net.lever_i, u), _cross(net.lever_j, u)
    ti, tj = ti.reshape(m, -1), tj.reshape(m, -1)
    block_i = np.concatenate([-u, -ti], axis=1)
    block_j = np.concatenate([u, tj], axis=1)
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
    (:func:`zeta_hessian`)."""
    return _hessians(net.separation, net.shape_inv, net.i, net.j, net.lam, generators(net.dim))


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
