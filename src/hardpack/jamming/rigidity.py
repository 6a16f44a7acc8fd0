"""The rigidity matrix A of a contact network (periodic, hard walls, container), as scipy.sparse.

Donev 2006, dissertation sec. 4.4.3 (the rigidity matrix of sec. 4.3.1, periodic boundaries in
sec. 4.4.3, the strain in secs. 4.4.5.1-4.4.5.2). A has one column per contact and one row per
degree of freedom:

- particle rows (d per particle, row ``i*d + k``): column {i, j} holds ``-u_ij`` in block i and
  ``+u_ij`` in block j, with u_ij the unit vector from i to (the image of) j. The text writes
  the same matrix with u pointing from j to i (+u in block i); only the orientation label of u
  differs. A self-image contact (i == j) has a zero particle part.
- strain rows (``strain=True``): the d(d+1)/2 independent components of the symmetric
  macroscopic strain eps = (Delta Lambda) Lambda^-1 (Eq. 4.18), ordered by :func:`strain_pairs`
  (diagonal first). The entry is the derivative of the contact length |r_ij + eps Lambda n_ij|
  with respect to the tensor component: ``u_p w_p`` on the diagonal and ``u_p w_q + u_q w_p``
  off the diagonal, with w = Lambda n_ij (Eqs. 4.20-4.21; the text's factor 1/2 goes with the
  engineering strain 2 eps_pq, which we do not use). Only boundary-crossing contacts
  (n_ij != 0) have strain entries; wall contacts have none (the walls stay fixed).

With ``dQ = (dR, eps)``, the linearised impenetrability constraint is ``A^T dQ >= -h``
(Eq. 4.7) and equilibrium under a load B is ``A f = -B`` with f >= 0 (Eq. 4.12). The trace
(volume) constraint Tr eps <= 0 (Eqs. 4.17/4.19) is added by the LP, not stored in A.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from hardpack.jamming.contacts import ContactNetwork


def strain_pairs(d: int) -> list[tuple[int, int]]:
    """Index pairs (p, q) of the independent strain components: diagonal, then p < q.

    Parameters
    ----------
    d : int
        The dimension.

    Returns
    -------
    list of tuple of int
        The d(d+1)/2 pairs (0, 0), ..., (d-1, d-1), then (p, q) with p < q in row order: the
        order of the strain rows of :func:`rigidity_matrix`.
    """
    return [(p, p) for p in range(d)] + [(p, q) for p in range(d) for q in range(p + 1, d)]


def n_strain(d: int) -> int:
    """Number of independent strain components.

    Parameters
    ----------
    d : int
        Dimension.

    Returns
    -------
    int
        d (d + 1) / 2.
    """
    return d * (d + 1) // 2


def strain_tensor(eps_hat: np.ndarray, d: int) -> np.ndarray:
    """The symmetric d x d tensor from its independent components (order of strain_pairs).

    Parameters
    ----------
    eps_hat : array_like of float, shape (d(d+1)/2,)
        Independent components.
    d : int
        Dimension.

    Returns
    -------
    numpy.ndarray of float, shape (d, d)
        The symmetric strain tensor.
    """
    eps = np.zeros((d, d))
    for value, (p, q) in zip(eps_hat, strain_pairs(d)):
        eps[p, q] = eps[q, p] = value
    return eps


def strain_coefficients(net: ContactNetwork) -> np.ndarray:
    """(M, d(d+1)/2) derivatives of each contact length with respect to the strain components.

    Parameters
    ----------
    net : ContactNetwork
        The contact network (M contacts).

    Returns
    -------
    numpy.ndarray of float, shape (M, d(d+1)/2)
        Zero for contacts that do not cross the boundary.
    """
    u, w = net.normal, net.image_offset
    cols = []
    for p, q in strain_pairs(net.dim):
        cols.append(u[:, p] * w[:, p] if p == q else u[:, p] * w[:, q] + u[:, q] * w[:, p])
    return np.stack(cols, axis=1)


def rigidity_transpose(net: ContactNetwork, strain: bool = False) -> sp.csr_matrix:
    """A^T as a CSR matrix of shape (M, N d [+ d(d+1)/2]): row k is the gradient of contact k's
    length with respect to (positions, strain).

    Parameters
    ----------
    net : ContactNetwork
        The contact network (M contacts).
    strain : bool, optional
        Append the strain columns (:func:`strain_coefficients`).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (M, N d) or (M, N d + d(d+1)/2)
        A^T.
    """
    m, d, n = net.n_contacts, net.dim, net.n_particles
    u = net.normal
    rows = np.repeat(np.arange(m), 2 * d)
    dofs = np.arange(d)
    cols = np.concatenate(
        [net.i[:, None] * d + dofs, net.j[:, None] * d + dofs], axis=1
    ).ravel()
    vals = np.concatenate([-u, u * (net.wall < 0)[:, None]], axis=1).ravel()
    ncols = n * d
    if strain:
        s = n_strain(d)
        coef = strain_coefficients(net)
        rows = np.concatenate([rows, np.repeat(np.arange(m), s)])
        cols = np.concatenate([cols, np.tile(np.arange(ncols, ncols + s), m)])
        vals = np.concatenate([vals, coef.ravel()])
        ncols += s
    at = sp.csr_matrix((vals, (rows, cols)), shape=(m, ncols))  # sums the i == j blocks to 0
    at.eliminate_zeros()
    return at


def gauge_dofs(net: ContactNetwork, moving: np.ndarray) -> np.ndarray:
    """The degrees of freedom of the ``moving`` particles held fixed to remove the trivial
    motions (:mod:`hardpack.jamming.contacts`), as a boolean (N d,) mask.

    Periodic cell: the d coordinates of the first moving particle (Donev 2006, sec. 4.4.2: "the
    trivial translations can be most easily eliminated by fixing (freezing) the position of one
    of the particles"). Hard walls: its coordinates along the periodic axes only. Spherical
    container: d(d-1)/2 coordinates on which the rotations about the centre act regularly,
    chosen by a pivoted QR of the rotation velocities; every motion is one of these coordinates
    left at zero plus a rotation, so fixing them removes exactly the rotations.

    Parameters
    ----------
    net : ContactNetwork
        The contact network (boundary and positions).
    moving : numpy.ndarray of bool, shape (N,)
        Particles with displacement variables.

    Returns
    -------
    numpy.ndarray of bool, shape (N d,)
        The coordinates held fixed.
    """
    d, n = net.dim, net.n_particles
    fixed = np.zeros(n * d, dtype=bool)
    idx = np.flatnonzero(moving)
    if idx.size == 0:
        return fixed
    if net.centre is None:
        fixed[idx[0] * d + np.flatnonzero(net.periodic)] = True
        return fixed
    import scipy.linalg

    t = rotation_velocities(net.positions[idx] - net.centre)
    _, r, piv = scipy.linalg.qr(t, pivoting=True, mode="economic")
    diag = np.abs(np.diag(r))
    rank = int(np.count_nonzero(diag > 1e-12 * max(diag.max(initial=0.0), 1e-300)))
    dofs = (idx[:, None] * d + np.arange(d)).ravel()
    fixed[dofs[piv[:rank]]] = True
    return fixed


def rotation_velocities(rel: np.ndarray) -> np.ndarray:
    """(d(d-1)/2, K d) velocities of K points at ``rel`` (K, d) from the centre under the unit
    rotations in the planes (p, q), p < q: x_p e_q - x_q e_p.

    Parameters
    ----------
    rel : numpy.ndarray of float, shape (K, d)
        Points relative to the centre of rotation.

    Returns
    -------
    numpy.ndarray of float, shape (d(d-1)/2, K d)
        One row per rotation plane.
    """
    d = rel.shape[1]
    gens = []
    for p in range(d):
        for q in range(p + 1, d):
            v = np.zeros_like(rel)
            v[:, q], v[:, p] = rel[:, p], -rel[:, q]
            gens.append(v.ravel())
    return np.array(gens).reshape(-1, rel.size)


def anchored_transpose(net: ContactNetwork, backbone: np.ndarray,
                       contacts: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
    """(free, rows ``contacts`` of A^T restricted to the ``free`` degrees of freedom): the (N d,)
    mask of the coordinates of the ``backbone`` particles less those :func:`gauge_dofs` holds
    fixed (the first particle in a periodic cell).

    Parameters
    ----------
    net : ContactNetwork
        The contact network (M contacts).
    backbone : numpy.ndarray of bool, shape (N,)
        Backbone particles.
    contacts : numpy.ndarray of bool, shape (M,)
        The contact rows kept.

    Returns
    -------
    free : numpy.ndarray of bool, shape (N d,)
        The free coordinates.
    at : scipy.sparse.csr_matrix, shape (M_c, N_free)
        Rows ``contacts`` of A^T, columns ``free``.
    """
    free = np.repeat(backbone, net.dim) & ~gauge_dofs(net, backbone)
    return free, rigidity_transpose(net)[contacts][:, np.flatnonzero(free)]


def rigidity_matrix(net: ContactNetwork, strain: bool = False) -> sp.csc_matrix:
    """The rigidity matrix A, shape (N d [+ d(d+1)/2], M); see the module docstring.

    Donev 2006, sec. 4.4.3 (Eqs. 4.18-4.21 for the strain rows).

    Parameters
    ----------
    net : ContactNetwork
        The contacts of a periodic packing.
    strain : bool, default False
        Add the d(d+1)/2 rows of the symmetric strain components (order of
        :func:`strain_pairs`).

    Returns
    -------
    scipy.sparse.csc_matrix, shape (N d [+ d(d+1)/2], M)
        One column per contact: -u_ij in the rows of particle i, +u_ij in those of j (zero for
        a self-image contact), and the strain derivatives of the contact length when ``strain``.
    """
    return rigidity_transpose(net, strain).T.tocsc()
