"""Exact volume of a simplex and the jamming-simplex constant f_J of an isostatic packing.

Donev 2006, dissertation sec. 6.2.2:

- H-representation (Eq. 6.5, sec. 6.2.2.2): for the simplex {x in R^n : A x <= b}, A of shape
  (n+1, n), set the square matrix At = [A b] and a = At^{-T} e_{n+1} (the last row of At^{-1}).
  Then V^{-1} = n! |det At| prod_i a_i. Derivation (checked here): y = b - A x >= 0 satisfies
  [x; -1] = -At^{-1} y, whose last component gives a^T y = 1, so the simplex is bounded exactly
  when every a_i > 0; the function refuses anything else.
- Jamming simplex (Eqs. 6.3-6.4, sec. 6.2.2): P_x = {x : A^T x <= e} with A the N_f x M
  rigidity matrix (journal sign convention; the chapter's A^T x >= -e is its mirror image and has
  the same volume). With M = N_f + 1 the augmented matrix is At = [A; e^T] and the contact forces
  f~ = At^{-1} e_{M} (force balance A f~ = 0, unit sum) are the a_i above, so
  |P_x|^{-1} = N_f! |det At| prod f~. The per-particle constant is f_J = ln|P_x| / N_eff.

Log-determinants come from one sparse LU (scipy.sparse.linalg.splu), so N ~ 10^3 is cheap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from scipy.special import gammaln

from hardpack.errors import InvalidInputError


def _log_det_and_last_solve(mat: sp.spmatrix) -> tuple[float, np.ndarray]:
    """ln|det mat| and mat^{-1} e_last for a square sparse matrix, from one sparse LU."""
    n = mat.shape[0]
    try:
        lu = splu(sp.csc_matrix(mat, dtype=float))
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise InvalidInputError(
            f"the augmented matrix is singular ({exc}): the constraints do not bound a simplex "
            "(check for duplicated or dependent constraints)"
        ) from None
    diag = lu.U.diagonal()
    if np.any(diag == 0) or not np.all(np.isfinite(diag)):
        raise InvalidInputError(
            "the augmented matrix is singular: the constraints do not bound a simplex"
        )
    rhs = np.zeros(n)
    rhs[-1] = 1.0
    return float(np.sum(np.log(np.abs(diag)))), lu.solve(rhs)


def log_simplex_volume(a, b) -> float:
    """ln V of the simplex {x in R^n : a @ x <= b}, a of shape (n+1, n), b > 0 (Eq. 6.5).

    Donev 2006, sec. 6.2.2.2: V^{-1} = n! |det [A b]| prod_i a_i with a the last row of
    [A b]^{-1}; the log-determinant comes from one sparse LU.

    Parameters
    ----------
    a : array_like or scipy.sparse matrix, shape (n+1, n)
        The constraint normals A, one row per facet.
    b : array_like, shape (n+1,)
        The right-hand sides; all > 0, i.e. the origin is interior.

    Returns
    -------
    float
        ln V, the natural logarithm of the simplex volume.

    Raises
    ------
    InvalidInputError
        If ``a`` is not of shape (n+1, n) or ``b`` not of length n+1; if ``b`` is not finite or
        some b_i <= 0 (the origin must be interior); if the constraints do not bound a simplex
        (a singular [A b] or some weight a_i <= 0).
    """
    a_mat = (
        sp.csc_matrix(a, dtype=float) if sp.issparse(a) else np.asarray(a, dtype=float)
    )
    b = np.asarray(b, dtype=float).ravel()
    if (
        a_mat.ndim != 2
        or a_mat.shape[0] != a_mat.shape[1] + 1
        or b.shape != (a_mat.shape[0],)
    ):
        raise InvalidInputError(
            f"a simplex in R^n needs A of shape (n+1, n) and b of length n+1; got A {a_mat.shape} "
            f"and b {b.shape}"
        )
    if not np.all(np.isfinite(b)) or np.any(b <= 0):
        raise InvalidInputError(
            "b must be finite and > 0 (shift the simplex so the origin is interior)"
        )
    n = a_mat.shape[1]
    at = sp.hstack([sp.csc_matrix(a_mat), sp.csc_matrix(b[:, None])]).tocsc()
    # a = last row of At^{-1} = At^{-T} e_last: solve with the transpose.
    log_det, last = _log_det_and_last_solve(at.T)
    if np.any(last <= 0):
        raise InvalidInputError(
            f"the constraints A x <= b do not bound a simplex ({np.sum(last <= 0)} of the "
            "weights a_i = (At^-T e)_i are <= 0)"
        )
    return float(-(gammaln(n + 1) + log_det + np.sum(np.log(last))))


@dataclass(frozen=True)
class JammingSimplex:
    """Result of :func:`jamming_simplex` (Donev 2006, sec. 6.2.2).

    Attributes
    ----------
    log_volume : float
        ln|P_x|, the log-volume of the jamming simplex.
    forces : numpy.ndarray, shape (M,)
        The contact forces f~ = [A; e^T]^{-1} e_M, normalised to unit sum.
    n_dof : int
        N_f, the number of degrees of freedom (rows of the rigidity matrix).
    n_eff : int
        The number of moving particles used in f_J.
    f_j : float
        f_J = ln|P_x| / n_eff.
    f_j_minus_fcj : float
        f_J - f_c^J with f_c^J = ln V_p, the quantity BCMD measures (Eq. 6.18).
    """

    log_volume: float
    forces: np.ndarray
    n_dof: int
    n_eff: int
    f_j: float
    f_j_minus_fcj: float


def jamming_simplex(
    rigidity, n_eff: int, log_vp: float = 0.0, force_tol: float = 0.0
) -> JammingSimplex:
    """Volume of the jamming polytope P_x = {x : A^T x <= e} of an isostatic packing (Eq. 6.3).

    Donev 2006, sec. 6.2.2 (Eqs. 6.3-6.5): with At = [A; e^T], |P_x|^{-1} = N_f! |det At|
    prod f~ where f~ = At^{-1} e_M are the contact forces.

    Parameters
    ----------
    rigidity : array_like or scipy.sparse matrix, shape (N_f, M)
        The rigidity matrix A, rows of frozen particles already removed. For spheres of unit
        diameter shrunk by (1 - delta) the gaps are delta e, so x = dR / delta.
    n_eff : int
        The number of moving particles (N - 1 with one frozen particle) used in
        f_J = ln|P_x| / n_eff; >= 1.
    log_vp : float, default 0.0
        ln V_p of the particle (ln(pi/6) for unit-diameter spheres, ln(pi/4) for unit disks);
        it only shifts ``f_j_minus_fcj``.
    force_tol : float, default 0.0
        Every contact force f~ must exceed this value.

    Returns
    -------
    JammingSimplex
        ln|P_x|, the forces f~, N_f, n_eff, f_J and f_J - ln V_p.

    Raises
    ------
    InvalidInputError
        If the packing is not isostatic (M != N_f + 1), if ``n_eff`` < 1, if the augmented
        matrix is singular, or if some contact force f~ <= ``force_tol`` (then P_x is not a
        bounded simplex).
    """
    a = sp.csc_matrix(rigidity, dtype=float)
    n_f, m = a.shape
    if m != n_f + 1:
        raise InvalidInputError(
            f"the packing is not isostatic: M = {m} contacts but N_f + 1 = {n_f + 1}; the "
            "jamming polytope is a simplex only when M = N_f + 1 (remove rattlers, freeze one "
            "particle, and use a gap tolerance that finds exactly the true contacts)"
        )
    if int(n_eff) < 1:
        raise InvalidInputError(f"n_eff must be a positive particle count, got {n_eff}")
    at = sp.vstack([a, sp.csr_matrix(np.ones((1, m)))]).tocsc()
    log_det, forces = _log_det_and_last_solve(at)
    if np.any(forces <= force_tol):
        bad = int(np.sum(forces <= force_tol))
        raise InvalidInputError(
            f"{bad} contact force(s) f~ = [A; e^T]^-1 e are <= {force_tol} (min {forces.min():.3g}): "
            "the packing is not rigid with strictly positive forces, so P_x is not a bounded simplex"
        )
    log_volume = float(-(gammaln(n_f + 1) + log_det + np.sum(np.log(forces))))
    f_j = log_volume / int(n_eff)
    return JammingSimplex(log_volume, forces, n_f, int(n_eff), f_j, f_j - float(log_vp))
