"""Lattice-basis reduction (Lenstra-Lenstra-Lovasz) for periodic cells that shear.

A sheared cell keeps describing the same periodic packing when its basis is replaced by M U with U
unimodular; LLL picks short, nearly orthogonal lattice vectors, so the number of periodic images
a neighbour search must visit stays small (Torquato & Jiao 2010 do not discuss it; the SLP note,
sec. 5.3, measured a 10-40x speed-up in d = 5). Lenstra, Lenstra & Lovasz, Math. Ann. 261, 515
(1982), with the usual Lovasz parameter delta = 3/4.
"""

from __future__ import annotations

import numpy as np


def lll_reduce(lattice: np.ndarray, delta: float = 0.75) -> tuple[np.ndarray, np.ndarray]:
    """LLL-reduce the basis whose **columns** are the lattice vectors.

    Returns (reduced, U) with reduced = lattice @ U and U an integer matrix with det +-1.

    Lenstra, Lenstra & Lovasz (1982), with the Lovasz condition
    |b*_k|^2 >= (delta - mu_{k,k-1}^2) |b*_{k-1}|^2.

    Parameters
    ----------
    lattice : numpy.ndarray of float, shape (d, d)
        The basis, lattice vectors as columns.
    delta : float, optional
        Lovasz parameter in (1/4, 1].

    Returns
    -------
    reduced : numpy.ndarray of float, shape (d, d)
        The reduced basis, columns.
    U : numpy.ndarray of int64, shape (d, d)
        Unimodular matrix with reduced = lattice @ U.
    """
    b = np.array(lattice, dtype=float).T.copy()  # rows are basis vectors
    d = b.shape[0]
    u = np.eye(d, dtype=np.int64)

    def gram_schmidt(b):
        bstar = np.zeros_like(b)
        mu = np.zeros((d, d))
        for i in range(d):
            bstar[i] = b[i]
            for j in range(i):
                mu[i, j] = b[i] @ bstar[j] / (bstar[j] @ bstar[j])
                bstar[i] = bstar[i] - mu[i, j] * bstar[j]
        return bstar, mu

    bstar, mu = gram_schmidt(b)
    k = 1
    while k < d:
        for j in range(k - 1, -1, -1):
            q = int(np.rint(mu[k, j]))
            if q:
                b[k] -= q * b[j]
                u[:, k] -= q * u[:, j]
                bstar, mu = gram_schmidt(b)
        if bstar[k] @ bstar[k] >= (delta - mu[k, k - 1] ** 2) * (bstar[k - 1] @ bstar[k - 1]):
            k += 1
        else:
            b[[k, k - 1]] = b[[k - 1, k]]
            u[:, [k, k - 1]] = u[:, [k - 1, k]]
            bstar, mu = gram_schmidt(b)
            k = max(k - 1, 1)
    return b.T.copy(), u
