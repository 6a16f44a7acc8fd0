"""Solves with a sparse LU factorisation for a block of right-hand sides (numba kernels).

SuperLU (scipy's ``splu``) solves one right-hand side at a time outside its supernodes, so
each column reads all of L and U from memory: at N = 1e4 in 3D (a strict-LP basis of 30000
columns, 2.3e7 entries in L + U) that is 16-19 ms per column, and the working set of an LP
needs ~800 of them (:mod:`hardpack.jamming.workingset`). Here the same factors are applied
to ``BLOCK`` columns at once: each entry of L and U is read once per block and updates a
contiguous row of the block (the column-oriented forward and back substitutions of
Golub & Van Loan, Matrix Computations, sec. 3.1, with rows of right-hand sides in place of
scalars).

With Pr A Pc = L U (SuperLU's ``perm_r``, ``perm_c``; L unit lower triangular):
A x = b  <=>  L U (Pc^T x) = Pr b, i.e. z[perm_r] = b, solve L w = z, U v = w, x = v[perm_c].
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp

#: right-hand sides per pass over the factors: 32 rows of 8 bytes (256 B) per row of the
#: block keep it cache-resident at n = 30000; 8 columns took twice as long per column, and 64
#: no less (measured on a 3D periodic grid LU of 1e8 entries: 24 ms per column against 50-63
#: ms for SuperLU's own multi-column solve)
BLOCK = 32


@numba.njit(cache=True)
def _forward(indptr, indices, data, x):
    """x <- L^{-1} x for unit lower triangular L (CSC; diagonal entries, if stored, ignored)."""
    n, k = x.shape
    for j in range(n):
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            if i > j:
                v = data[p]
                for c in range(k):
                    x[i, c] -= v * x[j, c]


@numba.njit(cache=True)
def _backward(indptr, indices, data, diagonal, x):
    """x <- U^{-1} x for upper triangular U (CSC) with the given diagonal."""
    n, k = x.shape
    for j in range(n - 1, -1, -1):
        inv = 1.0 / diagonal[j]
        for c in range(k):
            x[j, c] *= inv
        for p in range(indptr[j], indptr[j + 1]):
            i = indices[p]
            if i < j:
                v = data[p]
                for c in range(k):
                    x[i, c] -= v * x[j, c]


class BlockSolver:
    """A^{-1} B for dense blocks B, from a SuperLU factorisation ``lu`` of A (scipy's
    ``splu`` object: its L, U, perm_r and perm_c).

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU
        Factorisation of the square matrix A.
    """

    def __init__(self, lu):
        lower, upper = sp.csc_matrix(lu.L), sp.csc_matrix(lu.U)
        self.lower = (lower.indptr, lower.indices, lower.data)
        self.upper = (upper.indptr, upper.indices, upper.data, upper.diagonal())
        self.perm_r, self.perm_c = lu.perm_r, lu.perm_c

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x with A x = b, by forward and backward substitution with the factors, BLOCK columns at a time.

        Parameters
        ----------
        b : numpy.ndarray of float, shape (n, k)
            Right-hand sides as columns.

        Returns
        -------
        numpy.ndarray of float, shape (n, k)
            The solutions.
        """
        n, k = b.shape
        out = np.empty((n, k))
        for start in range(0, k, BLOCK):
            z = np.empty((n, min(BLOCK, k - start)))
            z[self.perm_r] = b[:, start:start + BLOCK]
            _forward(*self.lower, z)
            _backward(*self.upper, z)
            out[:, start:start + BLOCK] = z[self.perm_c]
        return out


__all__ = ["BLOCK", "BlockSolver"]
