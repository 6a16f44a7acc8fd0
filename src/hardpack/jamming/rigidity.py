"""The rigidity matrix A of a periodic contact network, as a scipy.sparse matrix.

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
  (n_ij != 0) have strain entries.

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
    return d * (d + 1) // 2


def strain_tensor(eps_hat: np.ndarray, d: int) -> np.ndarray:
    """The symmetric d x d tensor from its independent components (order of strain_pairs)."""
    eps = np.zeros((d, d))
    for value, (p, q) in zip(eps_hat, strain_pairs(d)):
        eps[p, q] = eps[q, p] = value
    return eps


def strain_coefficients(net: ContactNetwork) -> np.ndarray:
    """(M, d(d+1)/2) derivatives of each contact length with respect to the strain components."""
    u, w = net.normal, net.image_offset
    cols = []
    for p, q in strain_pairs(net.dim):
        cols.append(u[:, p] * w[:, p] if p == q else u[:, p] * w[:, q] + u[:, q] * w[:, p])
    return np.stack(cols, axis=1)


def rigidity_transpose(net: ContactNetwork, strain: bool = False) -> sp.csr_matrix:
    """A^T as a CSR matrix of shape (M, N d [+ d(d+1)/2]): row k is the gradient of contact k's
    length with respect to (positions, strain)."""
    m, d, n = net.n_contacts, net.dim, net.n_particles
    u = net.normal
    rows = np.repeat(np.arange(m), 2 * d)
    dofs = np.arange(d)
    cols = np.concatenate(
        [net.i[:, None] * d + dofs, net.j[:, None] * d + dofs], axis=1
    ).ravel()
    vals = np.concatenate([-u, u], axis=1).ravel()
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


def anchored_transpose(net: ContactNetwork, backbone: np.ndarray,
                       contacts: np.ndarray) -> tuple[np.ndarray, sp.csr_matrix]:
    """(moving, rows ``contacts`` of A^T restricted to the positions of the ``moving`` particles):
    the ``backbone`` particles except the first one, which stays fixed (removes the d
    translations of a periodic backbone)."""
    moving = backbone.copy()
    moving[np.flatnonzero(backbone)[0]] = False
    return moving, rigidity_transpose(net)[contacts][:, np.flatnonzero(np.repeat(moving, net.dim))]


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
