"""Exact solution of the displacement LP (4.10) by a sparse-LU working set (column generation).

The LP of :mod:`hardpack.jamming.lp`, written with one list of constraint columns,

    max c^T x   s.t.  a_j^T x >= -h_j  for every column j,

where the columns are the contacts (a_j = column of A restricted to the variables, h_j = gap),
the volume constraint of the strict test (a = -trace, h = 0) and the box (-e_k and +e_k with
h = the bound on |x_k|). Its dual is the force LP (Donev 2006, Eq. 4.12, sec. 4.3.2.2):

    min h^T f   s.t.  sum_j f_j a_j = -c,  f >= 0.

A jammed packing supports almost any load with nearly the same N_f contacts (the isostatic
core: the true contacts plus the near contacts that block its few floppy modes); HiGHS instead
starts every LP from scratch and spends thousands of simplex iterations rebuilding that core
(~4000 iterations, ~2.5 CPU s at N = 1000 in 3D; > 5 CPU min at N = 8000). Here (our
derivation, the revised-simplex decomposition with column generation):

1. Basis S: the n columns with the smallest gaps (or the previous LP's optimal basis: warm
   start), factorised by SuperLU (:func:`_factorise`; dense rows such as the strain rows scaled
   down by :func:`_row_scale`). Numerically dependent columns (tiny pivots: floppy modes of the
   true-contact network, translations), found on a copy regularised on a matching of the
   pattern (:func:`_regulariser`), are replaced by the box column e_r of the row left without
   a pivot (LP basis repair), so A_S is regular.
2. Working set W: K more columns (the columns the repair took out, the partners of box columns
   in S, the next 20 smallest gaps or the previous LP's working set, and later every violated
   column). With y = -A_S^{-1} c and N = -A_S^{-1} A_W, every dual solution on S + W is
   f_S = y + N alpha, f_W = alpha: an LP in K variables (the K-LP, :class:`_KLP`), solved by
   HiGHS in its dual form (K rows) over only the rows of S whose force can reach zero (row
   generation), in one highspy model per basis that each round extends and re-solves. The
   columns of S may also carry tension t >= 0 at the price p_s = sum_k |a_sk| u_k: that is the
   cost of the same load carried by box columns, so it keeps the restricted LP feasible without
   changing the optimum of the full LP.
3. The motion: the multipliers mu of the K-LP rows f_S >= 0 are the reduced costs
   a_s^T x + h_s of the basis columns, hence x = A_S^{-T} (mu - h_S) (one triangular solve pair).
4. Pricing: every column with a_j^T x + h_j < -tol joins W and the K-LP is solved again (when
   W would grow beyond ``max_working``, S moves to the current optimum and is factorised
   anew); when none is violated, x is feasible for the full LP and f (with the tensions
   expanded into box columns) is a dual solution of equal value: x is optimal to the
   tolerances of HiGHS (1e-10) and of the pricing (1e-10 of the box). The optimal basis, for
   the next LP's warm start, applies the simplex pivots of the K-LP to S
   (:meth:`_KLP.optimal_basis`).

Returns None (the caller then uses HiGHS on the full LP) when the basis cannot be repaired or
the LP does not converge within ``max_rounds`` rounds -- in practice LPs far from the contact
core, such as the first LP of a strict test of a fixed-cell packing, whose optimum closes
hundreds of near contacts under a shear.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import highspy
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import maximum_bipartite_matching

from hardpack.jamming.highs import HIGHS_OPTIONS, LPFailure
from hardpack.jamming.triangular import BlockSolver

#: relative pivot size below which a basis column counts as dependent (repaired)
PIVOT_TOL = 1e-10
#: columns of the first working set of a cold start beyond those the basis needs
K0 = 20
#: rows of the K-LP that start bounding each working column of negative reduced cost (the
#: rows with its most negative entries of N; row generation adds the others that are needed)
BOUNDING_ROWS = 5
#: rows joining the K-LP for an improving ray of its unbounded restricted primal bound it this
#: many times over (their tension cost against the ray's gain), so that the next solve rarely
#: finds a ray of the same columns again
RAY_MARGIN = 2.0
#: HiGHS solves of one K-LP (row generation and ray rows) before the working set gives up (each
#: adds rows and continues from the previous optimum; MAX_NEW_ROWS per round needs many)
MAX_RESOLVES = 200
#: row generation adds, with each row found short, this many of the rows closest to it
NEAR_ROWS = 1
#: rows one round of row generation adds at most (the most negative of those found short;
#: without near rows then): a warm start at N = 1e4 in 3D found 4718 rows short after its first
#: K-LP, and adding them all (with as many near rows) grew the K-LP to 11000 dense rows, 28 s
#: per HiGHS solve; 500 at a time it stayed below 3000 rows and took 8 s in all (250: the same,
#: 1000 and 2000: 10-14 s)
MAX_NEW_ROWS = 500
#: fraction of the rows, those of the smallest basis loads y, that the K-LP starts with: the
#: rows whose force reaches zero at the optimum are mostly among them (in a strict LP at
#: N = 1e4 in 3D, 71 % were in the lowest 5 % of y and 91 % in the lowest 10 %); starting
#: with them saves rounds of row generation (8 s instead of 12-15 s for that K-LP). The rows
#: with y < 0 beyond them are left to row generation: a warm start from the previous LP of a
#: strict loading sequence (N = 1e4 in 3D) once had y < 0 on 68 % of its rows, all through the
#: trace column's negative load (a pressure turned into a tension); one working column that
#: relieves it lifts most of them, and a K-LP over all of them took 118 s instead of 25 s
LOW_LOAD_ROWS = 0.05
#: seconds after which each further round of an LP is logged (progress of long LPs: at N = 1e4
#: in 3D a strict LP far from its start can take > 1 h in rounds of 1-8 min)
PROGRESS_AFTER = 60.0

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class WorkingSetSolution:
    """Optimum of :func:`solve_working_set`.

    Attributes
    ----------
    x : numpy.ndarray of float, shape (n,)
        Optimal motion.
    forces : numpy.ndarray of float, shape (M,)
        Dual values (forces) of the contact columns.
    objective : float
        c^T x.
    basis : numpy.ndarray of int, shape (n,)
        Unified column indices of the optimal basis (warm start of the next LP).
    working : numpy.ndarray of int
        Unified indices of the other columns the LP worked with.
    rounds : int
        Rounds of the working-set loop.
    """

    x: np.ndarray  # (n,) optimal motion
    forces: np.ndarray  # (M,) forces on the (non-box) columns
    objective: float  # c^T x
    basis: np.ndarray  # (n,) unified indices of the optimal basis (warm start of the next LP)
    working: np.ndarray  # unified indices of the other columns the LP worked with
    rounds: int


@dataclass(frozen=True)
class WarmStart:
    """Basis and working set of a previous LP, by column identity (``keys`` rows of the given
    columns; box columns by their offset from M), to start the next LP of the same variables.

    Attributes
    ----------
    basis_keys : numpy.ndarray of int, shape (k, 2 + d)
        Keys (i, j, lattice image n) of the contact columns in the basis.
    basis_box : numpy.ndarray of int
        Box columns in the basis as signed variable numbers: -(k+1) for -e_k, k+1 for +e_k.
    working_keys : numpy.ndarray of int, shape (w, 2 + d)
        Keys of the contact columns in the working set.
    working_box : numpy.ndarray of int
        Box columns in the working set, signed as ``basis_box``.
    """

    basis_keys: np.ndarray
    basis_box: np.ndarray
    working_keys: np.ndarray
    working_box: np.ndarray

    @classmethod
    def of(cls, sol: WorkingSetSolution, keys: np.ndarray) -> WarmStart:
        """The warm start of an LP's optimum.

        Parameters
        ----------
        sol : WorkingSetSolution
            The optimum of :func:`solve_working_set`.
        keys : numpy.ndarray of int, shape (M, 2 + d)
            Keys (i, j, lattice image n) of that LP's M contact columns.

        Returns
        -------
        WarmStart
            Its basis and working set by column identity.
        """
        return cls.from_columns(sol.basis, sol.working, keys, sol.x.size)

    @classmethod
    def from_columns(cls, b: np.ndarray, w: np.ndarray, keys: np.ndarray, n: int) -> WarmStart:
        """From unified column indices (basis b, working set w) of an LP with n variables.

        Unified indices: 0..M-1 the contact columns, M + k the box column -e_k, M + n + k the box
        column +e_k.

        Parameters
        ----------
        b : numpy.ndarray of int
            Unified indices of the basis.
        w : numpy.ndarray of int
            Unified indices of the working set.
        keys : numpy.ndarray of int, shape (M, 2 + d)
            Keys (i, j, lattice image n) of the contact columns.
        n : int
            Number of variables.

        Returns
        -------
        WarmStart
            The columns by identity.
        """
        m = keys.shape[0]

        def box(idx):  # signed variable numbers: -(k+1) for -e_k, k+1 for +e_k
            off = idx[idx >= m] - m
            return np.where(off < n, -(off + 1), off - n + 1)

        return cls(keys[b[b < m]], box(b), keys[w[w < m]], box(w))

    def rewrapped(self, wraps: np.ndarray) -> WarmStart:
        """The same columns after the particles were wrapped back into the cell.

        The particles moved by x_i -> x_i - lattice @ w_i. A contact key (i, j, n) (``keys`` of
        :func:`hardpack.jamming.lp.solve_motion`: separation x_j + lattice @ n - x_i) becomes
        (i, j, n + w_j - w_i); keys with i < 0 (the trace column) or j < 0 (a wall contact) stay.

        Parameters
        ----------
        wraps : numpy.ndarray of int, shape (N, d)
            The integer lattice vectors w_i.

        Returns
        -------
        WarmStart
            The moved keys; the box columns unchanged.
        """

        def moved(keys):
            keys = keys.copy()
            real = (keys[:, 0] >= 0) & (keys[:, 1] >= 0)
            i, j = keys[real, 0], keys[real, 1]
            keys[real, 2:] += wraps[j] - wraps[i]
            return keys

        return WarmStart(moved(self.basis_keys), self.basis_box, moved(self.working_keys), self.working_box)

    def locate(self, keys: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(basis, working) as unified indices into the columns with these ``keys`` and n variables.

        Contact columns absent from ``keys`` and box columns of variables beyond n are dropped.

        Parameters
        ----------
        keys : numpy.ndarray of int, shape (M, 2 + d)
            Keys of the new LP's contact columns.
        n : int
            Number of variables of the new LP.

        Returns
        -------
        tuple of numpy.ndarray of int
            Unified indices (as :meth:`from_columns`) of the basis and of the working set.
        """
        m = keys.shape[0]

        def box(signed):
            k = np.abs(signed) - 1
            return (m + np.where(signed < 0, k, n + k))[k < n]

        return (np.concatenate([_match(self.basis_keys, keys), box(self.basis_box)]),
                np.concatenate([_match(self.working_keys, keys), box(self.working_box)]))


def _match(old: np.ndarray, new: np.ndarray) -> np.ndarray:
    """Indices into the rows of ``new`` of the rows of ``old`` that ``new`` also has."""
    if old.shape[0] == 0 or new.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    void = np.dtype((np.void, new.dtype.itemsize * new.shape[1]))
    new_ids = np.ascontiguousarray(new).view(void).ravel()
    old_ids = np.ascontiguousarray(old.astype(new.dtype)).view(void).ravel()
    order = np.argsort(new_ids)
    pos = np.minimum(np.searchsorted(new_ids[order], old_ids), new_ids.size - 1)
    found = new_ids[order][pos] == old_ids
    return order[pos[found]].astype(np.int64)


def _unit_columns(rows: np.ndarray, signs: np.ndarray, n: int) -> sp.csc_matrix:
    return sp.csc_matrix((signs.astype(float), (rows, np.arange(rows.size))), shape=(n, rows.size))


class _Columns:
    """The unified column list: 0..M-1 the given columns, M + k the box column -e_k
    (x_k <= u_k), M + n + k the box column +e_k (x_k >= -u_k); all with their 'gap'."""

    def __init__(self, g: sp.csc_matrix, h: np.ndarray, upper: np.ndarray):
        self.g, self.h, self.upper = g, h, upper
        self.n, self.m = g.shape

    def gap(self, idx: np.ndarray) -> np.ndarray:
        out = np.empty(idx.size)
        box = idx >= self.m
        out[~box] = self.h[idx[~box]]
        out[box] = self.upper[(idx[box] - self.m) % self.n]
        return out

    def matrix(self, idx: np.ndarray) -> sp.csc_matrix:
        box = idx >= self.m
        if not box.any():
            return self.g[:, idx]
        k = (idx - self.m) % self.n
        sign = np.where(idx - self.m < self.n, -1.0, 1.0)
        unit = _unit_columns(k[box], sign[box], self.n)
        out = sp.hstack([self.g[:, idx[~box]], unit], format="csc")
        order = np.empty(idx.size, dtype=np.int64)
        order[np.flatnonzero(~box)] = np.arange(int((~box).sum()))
        order[np.flatnonzero(box)] = int((~box).sum()) + np.arange(int(box.sum()))
        return out[:, order]

    def slacks(self, x: np.ndarray) -> np.ndarray:
        """a_j^T x + h_j for every column (the box columns last)."""
        return np.concatenate([self.h + self.g.T @ x, self.upper - x, self.upper + x])

    def partner(self, idx: np.ndarray) -> np.ndarray:
        """The opposite box column of each box column."""
        off = idx - self.m
        return self.m + np.where(off < self.n, off + self.n, off - self.n)


class _ScaledLU:
    """SuperLU (COLAMD order) of R a, with R = :func:`_row_scale` (a), solving with a."""

    def __init__(self, a: sp.csc_matrix):
        self.scale = _row_scale(a)
        self._block = None
        self.lu = spla.splu(sp.csc_matrix(sp.diags(self.scale) @ a), permc_spec="COLAMD")

    def solve(self, b: np.ndarray, trans: str = "N") -> np.ndarray:
        """x with a x = b (``trans`` "N", x = (R a)^{-1} R b) or a^T x = b ("T", x = R (R a)^{-T} b)."""
        if trans == "N":
            return self.lu.solve(_rows_times(self.scale, b))
        return _rows_times(self.scale, self.lu.solve(b, trans="T"))

    def solve_block(self, b: np.ndarray) -> np.ndarray:
        """a^{-1} b for a block of columns b (n x k), by :mod:`hardpack.jamming.triangular`
        (3-4 times faster per column than SuperLU's own solve at N = 1e4 in 3D)."""
        if self._block is None:
            self._block = BlockSolver(self.lu)
        return self._block.solve(_rows_times(self.scale, b))

    def pivots(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(|U_kk|, column of a, row of a) of each pivot k."""
        return np.abs(self.lu.U.diagonal()), np.argsort(self.lu.perm_c), np.argsort(self.lu.perm_r)


def _rows_times(scale: np.ndarray, b: np.ndarray) -> np.ndarray:
    """diag(scale) b for a vector or a block of columns b."""
    return scale * b if b.ndim == 1 else scale[:, None] * b


def _row_scale(a: sp.csc_matrix) -> np.ndarray:
    """Row scale factors R for the LU of ``a``: 1, except on dense rows, scaled so that their
    largest entry is 1e-3 of the largest entry of the other rows.

    Dense rows: more than 10 sqrt(n) entries, the rows COLAMD leaves out of its ordering. Such
    rows (the strain rows of a strict LP: one entry per boundary-crossing basis contact, ~2000
    at N = 1e4 in 3D once the cell is sheared; the growth row of
    :func:`hardpack.jamming.forces.jamming_point_forces`: an entry -D_c for every contact) hold
    entries as large as the rigidity entries or larger, so SuperLU's partial pivoting would take
    them as pivots early and their fill would spread over the factors. Scaled down, they pivot
    last and fill only their own rows of L. Row scaling changes neither the solution nor which
    columns are dependent. Measured at N = 1e4 in 3D: the growth LP 14 s instead of 134 s; the
    strict LPs as fast as with the earlier remedy, a COLAMD order computed on a factorisation of
    a copy without the dense rows' small entries (which cost a second factorisation)."""
    n = a.shape[0]
    rows = sp.csr_matrix(a)
    dense = np.flatnonzero(np.diff(rows.indptr) > 10 * np.sqrt(n))
    scale = np.ones(n)
    if dense.size:
        row_max = abs(rows).max(axis=1).toarray().ravel()
        other = np.delete(row_max, dense).max(initial=0.0)
        big = row_max[dense] > 0
        scale[dense[big]] = 1e-3 * (other if other > 0 else 1.0) / row_max[dense[big]]
    return scale


def structurally_regular(a: sp.spmatrix) -> bool:
    """True when the pattern of the square matrix ``a`` has a perfect matching of its rows and
    columns (structural rank n), the condition under which SuperLU may be given it.

    Parameters
    ----------
    a : scipy.sparse matrix, shape (n, n)
        The matrix.

    Returns
    -------
    bool
        Whether the structural rank is n.
    """
    return bool(np.all(_matching(a) >= 0))


def _matching(a: sp.spmatrix) -> np.ndarray:
    """The row matched to each column by a maximum matching of the pattern of ``a`` (-1: none)."""
    return maximum_bipartite_matching(sp.csr_matrix(a), perm_type="row")


def _factorise(a: sp.csc_matrix):
    """LU of a square matrix (:class:`_ScaledLU`), or (None, positions of dependent columns,
    their pivot rows).

    SuperLU is given the matrix itself only when its pattern is structurally regular (a perfect
    matching of rows and columns exists; 2 ms at n = 3e4). A structurally singular matrix -- a
    basis whose columns leave some rows empty or too few, common among the many equivalent
    contacts of a crystal -- makes SuperLU's partial pivoting go on past the missing pivot with
    inconsistent supernode sizes, which calls BLAS with negative dimensions (OpenBLAS prints
    "On entry to DGEMV parameter number 2 had an illegal value", or DTRSV parameter 6) before
    it reports "Factor is exactly singular". Such a matrix, and a numerically singular one
    (exact cancellations, again in crystals), is probed on a regularised copy
    (:func:`_regulariser`), whose tiny pivots locate the dependent columns."""
    row_of = _matching(a)
    lu = None
    if np.all(row_of >= 0):
        try:
            lu = _ScaledLU(a)
        except RuntimeError:  # numerically singular: exact zero pivot
            lu = None
    probe = lu
    if lu is None:
        scale = float(abs(a).max()) if a.nnz else 1.0
        try:
            probe = _ScaledLU(a + _regulariser(a, 1e-13 * scale, row_of))
        except RuntimeError:
            raise LPFailure("the basis and its regularised copy are both exactly singular") from None
    pivots, pivot_cols, pivot_rows = probe.pivots()
    tiny = np.flatnonzero(pivots <= PIVOT_TOL * pivots.max(initial=0.0))
    if lu is not None and tiny.size == 0:
        return lu, None, None
    if tiny.size == 0:  # singular by SuperLU, yet no small pivot on the regularised copy
        raise LPFailure("basis factorisation failed")
    return None, pivot_cols[tiny], pivot_rows[tiny]


def _regulariser(a: sp.csc_matrix, eps: float, row_of: np.ndarray | None = None) -> sp.csc_matrix:
    """Entries of size eps on n positions that make the pattern of ``a`` structurally regular:
    the entries of a maximum matching of its rows and columns (``row_of``, :func:`_matching`;
    inside the pattern, so the fill of the LU stays that of ``a``), plus entries pairing the
    rows and columns the matching leaves out. eps * I would do the same on paper, but the
    diagonal of a rigidity matrix pairs unrelated particles and contacts: at N = 1e4 in 3D its
    fill made SuperLU run > 16 min instead of 6 s.

    The magnitudes are drawn from [1, 2) eps with random signs (a fixed seed: reproducible).
    With a rank deficiency k the copy then has k singular values of order eps, one tiny pivot
    each; equal entries, as a crystal's rigidity matrix has, can cancel the order-eps^k term of
    the determinant, leaving singular values ~eps^2 (measured on FCC and BCC supercell bases:
    5 of 81 such copies were still exactly singular with equal entries, none with random ones)."""
    n = a.shape[0]
    row_of = _matching(a) if row_of is None else row_of
    cols = np.flatnonzero(row_of >= 0)
    free_cols = np.flatnonzero(row_of < 0)
    free_rows = np.setdiff1d(np.arange(n), row_of[cols])
    rows = np.concatenate([row_of[cols], free_rows])
    rng = np.random.default_rng(0)
    values = eps * rng.uniform(1.0, 2.0, n) * rng.choice([-1.0, 1.0], n)
    return sp.csc_matrix((values, (rows, np.concatenate([cols, free_cols]))), shape=(n, n))


def _repaired_lu(cols: _Columns, basis: np.ndarray):
    """SuperLU of the basis columns, dependent columns replaced by box columns (module
    docstring, step 1). Returns (lu, basis, the replaced columns); lu is None on failure."""
    n, m = cols.n, cols.m
    replaced = []
    for _ in range(4):
        try:
            lu, bad_cols, bad_rows = _factorise(cols.matrix(basis))
        except LPFailure:
            break
        if lu is not None:
            return lu, basis, np.array(replaced, dtype=np.int64)
        basis = basis.copy()
        replaced.extend(basis[bad_cols])
        basis[bad_cols] = m + n + bad_rows  # +e_r: x_r >= -u_r
    return None, basis, np.array(replaced, dtype=np.int64)


def solve_working_set(
    g: sp.csc_matrix,
    h: np.ndarray,
    c: np.ndarray,
    upper: np.ndarray,
    *,
    start: tuple[np.ndarray, np.ndarray] | None = None,
    boxed: np.ndarray | None = None,
    max_working: int | None = None,
    max_rounds: int = 12,
    tol: float | None = None,
) -> WorkingSetSolution | None:
    """Solve ``max c^T x s.t. g^T x >= -h, |x| <= upper`` (module docstring); None if it gives up.

    ``start``: (basis, working set) of unified column indices from a similar LP (e.g.
    :meth:`WarmStart.locate`); the basis is completed with the smallest gaps and repaired.
    ``boxed``: variables whose two box columns are always in the working set (e.g. the
    strain, which the contacts of a fixed-cell packing do not bound).
    When the working set would exceed ``max_working`` columns (default 100 + n / 20), the
    basis moves to the current optimum instead (new LU) and the working set restarts from the
    columns closest to entering plus the violated ones.

    Parameters
    ----------
    g : scipy.sparse.csc_matrix, shape (n, M)
        Constraint columns.
    h : numpy.ndarray of float, shape (M,)
        Gaps (right-hand sides).
    c : numpy.ndarray of float, shape (n,)
        Objective.
    upper : numpy.ndarray of float, shape (n,)
        Box bound of each variable.
    start : tuple of two int arrays, optional
        (basis, working set) to start from.
    boxed : numpy.ndarray of int, optional
        Variables whose box columns are always worked with.
    max_working : int, optional
        Working-set size that triggers a restart.
    max_rounds : int, optional
        Rounds before giving up.
    tol : float, optional
        Feasibility tolerance (default 1e-10 max(upper)).

    Returns
    -------
    WorkingSetSolution or None
        The optimum, or None if the method gives up.
    """
    t0 = time.perf_counter()
    g = sp.csc_matrix(g)
    n, m = g.shape
    cols = _Columns(g, np.asarray(h, float), np.asarray(upper, float))
    c = np.asarray(c, float)
    tol = 1e-10 * float(np.max(upper)) if tol is None else tol
    max_working = 100 + n // 20 if max_working is None else max_working
    if n == 0:
        return WorkingSetSolution(np.zeros(0), np.zeros(m), 0.0, np.zeros(0, int), np.zeros(0, int), 0)

    # 1. basis: the start basis, completed with the smallest gaps
    norms = np.sqrt(np.asarray(g.multiply(g).sum(axis=0)).ravel())
    candidates = np.flatnonzero(norms > 0)
    candidates = candidates[np.argsort(cols.h[candidates], kind="stable")]
    basis, extra = (np.zeros(0, dtype=np.int64),) * 2 if start is None else map(np.unique, start)
    keep = basis >= m
    keep[~keep] = norms[basis[~keep]] > 0
    basis = _completed(basis[keep][:n], candidates, n, m)
    # 2. working set: the start's, the next K0 smallest gaps, partners of box columns in S
    pending = np.concatenate([extra, candidates]).astype(np.int64)
    boxed = np.zeros(0, dtype=np.int64) if boxed is None else np.asarray(boxed, dtype=np.int64)
    always = np.concatenate([m + boxed, m + n + boxed])
    factorise = True
    for rounds in range(1, max_rounds + 1):
        if factorise:
            lu, basis, replaced = _repaired_lu(cols, basis)
            if lu is None:
                return None
            in_set = np.zeros(m + 2 * n, dtype=bool)
            in_set[basis] = True
            partners = np.concatenate([cols.partner(basis[basis >= m]), replaced, always])
            fresh = pending[~in_set[pending]]
            _, first = np.unique(fresh, return_index=True)
            fresh = fresh[np.sort(first)]
            if rounds == 1:  # cold: the next k0 smallest gaps; warm: the start's working set
                fresh = fresh[:K0] if start is None else fresh[np.isin(fresh, extra)]
            else:
                fresh = fresh[: max_working // 2]
            working = np.unique(np.concatenate([fresh, partners[~in_set[partners]]]))
            y = -lu.solve(c)
            h_s = cols.gap(basis)
            penalty = np.asarray(abs(cols.matrix(basis)).T @ cols.upper).ravel()  # tension as box loads
            null = np.zeros((n, 0))
            k_lp = _KLP(y, h_s, h_s + penalty)
            factorise = False
        new = working[null.shape[1]:]
        in_set[new] = True
        if new.size:
            null = np.hstack([null, -lu.solve_block(cols.matrix(new).toarray())])
        k = working.size
        h_w = cols.gap(working)
        # 3. the K-LP (module docstring), in its dual form
        mu, alpha, t = k_lp.solve(null, h_w)
        if mu is None:
            return None
        x = lu.solve(mu - h_s, trans="T")
        f_s = y + null @ alpha + t
        # 4. pricing
        slack = cols.slacks(x)
        violated = np.flatnonzero((slack < -tol) & ~in_set)
        elapsed = time.perf_counter() - t0
        if elapsed > PROGRESS_AFTER:
            log.info("working set, round %d: %d working columns, %d of %d basis loads in the K-LP, "
                     "%d columns violated, %.0f s", rounds, k, int(k_lp.rows.sum()), n, violated.size, elapsed)
        if violated.size == 0:
            forces = np.zeros(m)
            forces[basis[basis < m]] = f_s[basis < m]
            forces[working[working < m]] = alpha[working < m]
            optimal = k_lp.optimal_basis(basis, working)
            rest = np.setdiff1d(np.concatenate([basis, working]), optimal)
            return WorkingSetSolution(x, forces, float(c @ x), optimal, rest, rounds)
        worst = violated[np.argsort(slack[violated])[: max(50, k)]]
        if k + worst.size <= max_working:
            working = np.concatenate([working, worst])
            continue
        # rebase: the basis moves to the current optimum, the working set restarts
        new_basis = _completed(k_lp.optimal_basis(basis, working), candidates, n, m)
        old = np.setdiff1d(np.concatenate([basis, working]), new_basis)
        pending = np.concatenate([worst[: max_working // 4], old[np.argsort(slack[old])]])
        basis, factorise = new_basis, True
    return None


class _KLP:
    """The K-LP of one basis S,

        min (h_S^T N + h_W^T) alpha + u^T t  s.t.  N alpha + t >= -y,  alpha, t >= 0,

    solved as its dual with K rows,

        min y^T mu  s.t.  N^T mu <= q = h_S^T N + h_W^T,  0 <= mu <= u,

    and only over the rows R of the basis columns that may lose their force (row generation:
    mu = 0 off R, i.e. the rows off R are dropped from the primal). R starts with the
    LOW_LOAD_ROWS fraction of rows of smallest y (the rows with y < tol in a basis too small
    for that fraction to hold a row), and the BOUNDING_ROWS most negative entries
    of N of each column with q < 0 (without them such a column would make the restricted
    primal unbounded). While the restricted primal is unbounded all the same, HiGHS's Farkas
    certificate of its dual form gives an improving ray d >= 0 of alpha; the rows off R that
    the ray drives negative (N d < 0) join R, those of largest tension cost u_r |(N d)_r|
    first, until their cost outweighs the ray's gain RAY_MARGIN times (:meth:`_add_ray_rows`).
    Each round adds the rows with y + N alpha < -tol (at most MAX_NEW_ROWS, the most negative)
    and, if these were all, as many of the rows next closest to it. When none is short, alpha
    is feasible for the full primal and optimal for a relaxation of it, hence optimal.
    Restricting R matters at large N: with every row that has a negative entry (the columns of
    N are dense) the K-LP of a strict test at N = 1e4 in 3D took 20-45 s per HiGHS solve.

    One HiGHS instance (highspy) holds the restricted LP for the whole life of the basis: y, h_S
    and u are those of S, so each round (rows of S joining R: new variables; working columns
    joining W: new constraints) only adds to the model, and HiGHS continues from its previous
    optimal basis instead of starting over (scipy's linprog cannot warm-start)."""

    def __init__(self, y: np.ndarray, h_s: np.ndarray, upper: np.ndarray, tol: float = 1e-9):
        self.y, self.h_s, self.upper, self.n = y, h_s, upper, y.size
        self.limit = tol * max(float(np.abs(y).max(initial=0.0)), 1e-300)
        low = int(LOW_LOAD_ROWS * self.n)
        if low:
            self.rows = np.zeros(self.n, dtype=bool)
            self.rows[np.argpartition(y, low - 1)[:low]] = True
        else:
            self.rows = y < self.limit
        self.var_rows = np.zeros(0, dtype=np.int64)  # row of S of each variable of the model
        self.k = 0  # working columns that are constraints of the model
        self.highs = highspy.Highs()
        for name, value in {"output_flag": False, "presolve": "off", **HIGHS_OPTIONS}.items():
            self.highs.setOptionValue(name, value)

    def solve(self, null: np.ndarray, h_w: np.ndarray):
        """Optimum with the working columns ``null`` (n x K: those of earlier calls first, then
        the new ones) of gaps ``h_w``. Returns (mu, alpha, t) for all n rows, or (None,) * 3 if
        the restricted LP is unbounded or HiGHS fails."""
        n, k = null.shape
        q = self.h_s @ null + h_w  # reduced costs of the working columns
        fresh = np.zeros(k, dtype=bool)
        fresh[self.k:] = q[self.k:] < 0
        if np.any(np.all(null[:, fresh] >= 0, axis=0)):  # a column lowering the cost unboundedly
            return None, None, None
        self._add_bounding_rows(null[:, fresh])
        for _ in range(MAX_RESOLVES):
            if not self.rows.any():  # y >= 0 and no working column can lower the cost: alpha = 0
                return np.zeros(n), np.zeros(k), np.zeros(n)
            if not self._extend(null, q):  # HiGHS refuses entries beyond 1e15 (near-singular S)
                return None, None, None
            self.highs.run()
            status = self.highs.getModelStatus()
            if status == highspy.HighsModelStatus.kInfeasible:  # restricted primal unbounded
                if not self._add_ray_rows(null, q):
                    return None, None, None
                continue
            if status != highspy.HighsModelStatus.kOptimal:
                return None, None, None
            sol = self.highs.getSolution()
            alpha = -np.asarray(sol.row_dual)
            f = self.y + null @ alpha
            short = ~self.rows & (f < -self.limit)
            if not short.any():
                mu, t = np.zeros(n), np.zeros(n)
                mu[self.var_rows] = sol.col_value
                t[self.var_rows] = np.maximum(-np.asarray(sol.col_dual), 0.0)  # duals of mu <= u
                return mu, alpha, t
            short = np.flatnonzero(short)
            if short.size > MAX_NEW_ROWS:
                self.rows[short[np.argpartition(f[short], MAX_NEW_ROWS - 1)[:MAX_NEW_ROWS]]] = True
                continue
            # the rows next closest to losing their force tend to be short in the next round
            self.rows[short] = True
            rest = np.flatnonzero(~self.rows)
            near = min(short.size * NEAR_ROWS, rest.size)
            if near:
                self.rows[rest[np.argpartition(f[rest], near - 1)[:near]]] = True
        return None, None, None

    def optimal_basis(self, basis: np.ndarray, working: np.ndarray) -> np.ndarray:
        """The basis of the full LP at the last optimum, read off HiGHS's basis of the K-LP:
        the columns of S whose mu is basic or at its upper bound (their force reached zero, or
        turned into a tension that box columns carry) leave, the working columns whose
        constraint is active (alpha basic) enter. These are the simplex pivots, so the basis is
        regular, where the n columns of largest load can be dependent at a degenerate optimum
        (ties at zero load): at N = 1e4 in 3D such a basis cost a repair cycle of three extra
        factorisations. With tensions fewer columns enter than leave; the next LP's start
        completes the basis (solve_working_set)."""
        if self.var_rows.size == 0:  # no K-LP solved: alpha = 0, the basis stays
            return basis
        status = self.highs.getBasis()
        moved = (highspy.HighsBasisStatus.kBasic, highspy.HighsBasisStatus.kUpper)
        leave = np.fromiter((st in moved for st in status.col_status), dtype=bool, count=self.var_rows.size)
        enter = np.fromiter((st != highspy.HighsBasisStatus.kBasic for st in status.row_status),
                            dtype=bool, count=self.k)
        keep = np.ones(basis.size, dtype=bool)
        keep[self.var_rows[leave]] = False
        return np.concatenate([basis[keep], working[: self.k][enter]])

    def _add_ray_rows(self, null: np.ndarray, q: np.ndarray) -> bool:
        """Rows that bound the improving ray of the unbounded restricted primal (class
        docstring) join R; False if HiGHS gives no ray or no row off R can bound it (the full
        primal is unbounded: the caller gives up).

        HiGHS's dual ray of the dual form (rows N^T mu <= q) is a Farkas certificate -d, d >= 0:
        every mu in [0, u] over R has (N d)^T mu >= sum_r u_r min(0, (N d)_r) > q^T d. Along
        alpha = s d the primal cost changes by s (q^T d + sum_R u_r max(0, -(N d)_r)) < 0;
        a row r off R with (N d)_r < 0 adds u_r |(N d)_r| to that slope."""
        _, has_ray, ray = self.highs.getDualRay()
        if not has_ray:
            return False
        d = np.maximum(-np.asarray(ray), 0.0)
        push = null @ d
        cost = self.upper * np.maximum(-push, 0.0)
        gain = -(q @ d) - cost[self.rows].sum()
        candidates = np.flatnonzero(~self.rows & (push < 0))
        if candidates.size == 0:
            return False
        order = candidates[np.argsort(-cost[candidates])]
        enough = int(np.searchsorted(np.cumsum(cost[order]), RAY_MARGIN * max(gain, 0.0))) + 1
        self.rows[order[: max(enough, BOUNDING_ROWS)]] = True
        return True

    def _add_bounding_rows(self, lowering: np.ndarray) -> None:
        """The BOUNDING_ROWS most negative entries of each column of ``lowering`` join R."""
        if lowering.size:
            count = min(BOUNDING_ROWS, self.n)
            best = np.argpartition(lowering, count - 1, axis=0)[:count]
            self.rows[best[np.take_along_axis(lowering, best, axis=0) < 0]] = True

    def _extend(self, null: np.ndarray, q: np.ndarray) -> bool:
        """Add the rows of R that are not yet variables, then the new working columns; False if
        HiGHS refuses them (it drops entries below 1e-9 with a warning, as linprog does)."""
        error = highspy.HighsStatus.kError
        new_rows = np.flatnonzero(self.rows)
        new_rows = new_rows[~np.isin(new_rows, self.var_rows)]
        if new_rows.size:
            block = sp.csc_matrix(null[new_rows, : self.k].T)  # column r: entries over the K rows
            if self.highs.addCols(new_rows.size, self.y[new_rows], np.zeros(new_rows.size),
                                  self.upper[new_rows], *_compressed(block)) == error:
                return False
            self.var_rows = np.concatenate([self.var_rows, new_rows])
        k = null.shape[1]
        if k > self.k:
            block = sp.csr_matrix(null[self.var_rows, self.k:].T)  # row j: entries over R
            if self.highs.addRows(k - self.k, np.full(k - self.k, -highspy.kHighsInf), q[self.k:],
                                  *_compressed(block)) == error:
                return False
            self.k = k
        return True


def _completed(basis: np.ndarray, candidates: np.ndarray, n: int, m: int) -> np.ndarray:
    """``basis`` completed to n columns with the ``candidates`` (smallest gaps first) it lacks,
    then box columns (the repair of the factorisation fixes any dependent ones)."""
    fill = candidates[~np.isin(candidates, basis)]
    basis = np.concatenate([basis, fill[: n - basis.size]]).astype(np.int64)
    if basis.size < n:
        spare = np.setdiff1d(m + n + np.arange(n), basis)
        basis = np.concatenate([basis, spare[: n - basis.size]])
    return basis


def _compressed(block: sp.csr_matrix | sp.csc_matrix) -> tuple:
    """(nnz, starts, indices, values) of a compressed sparse matrix, as highspy takes them."""
    return block.nnz, block.indptr.astype(np.int32), block.indices.astype(np.int32), block.data


__all__ = ["WarmStart", "WorkingSetSolution", "solve_working_set", "structurally_regular"]
