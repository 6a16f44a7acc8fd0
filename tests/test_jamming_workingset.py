"""Pieces of the working-set LP solver (hardpack.jamming.workingset) against exact answers.

The solver as a whole is checked against HiGHS in test_jamming_hypostatic.py; here its basis
repair (which columns of a singular basis are dependent) and the row generation of its K-LP.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import linprog
from scipy.sparse.csgraph import maximum_bipartite_matching, structural_rank

from hardpack.geometry.lattices import lattice_packing
from hardpack.jamming import contact_network, workingset
from hardpack.jamming.rigidity import anchored_transpose


def _regular_sparse(n: int, seed: int) -> sp.csc_matrix:
    """A sparse regular matrix with 3 entries per column, none on the diagonal (like a rigidity
    matrix, whose rows and columns are unrelated)."""
    rng = np.random.default_rng(seed)
    rows = np.concatenate([(np.arange(n) + s) % n for s in (1, 2, 5)])
    cols = np.tile(np.arange(n), 3)
    a = sp.csc_matrix((rng.uniform(1, 2, 3 * n) * rng.choice([-1, 1], 3 * n), (rows, cols)), shape=(n, n))
    assert abs(np.linalg.det(a.toarray())) > 1e-8
    return a


def test_regulariser_stays_in_the_pattern_and_fills_structural_holes():
    a = _regular_sparse(60, 0).tolil()
    a[:, 7] = 0.0  # an empty column: structurally singular
    a = sp.csc_matrix(a)
    a.eliminate_zeros()
    reg = workingset._regulariser(a, 1e-13)
    assert reg.nnz == a.shape[0]
    full = sp.csc_matrix(a + reg)
    assert np.all(maximum_bipartite_matching(full.tocsr(), perm_type="row") >= 0)
    outside = (abs(reg) > 0).astype(int) - (abs(reg) > 0).multiply(abs(a) > 0).astype(int)
    assert outside.nnz == 0 or outside.sum() == 1  # only the empty column's entry is new


def test_factorise_finds_exactly_the_dependent_columns():
    """Two columns made linear combinations of others: the repair reports two columns, and
    replacing them by unit columns of the reported rows gives a regular matrix."""
    a = _regular_sparse(80, 1).tolil()
    a[:, 30] = a[:, 3] * 2.0 - a[:, 4]
    a[:, 50] = a[:, 12] * 0.5
    a = sp.csc_matrix(a)
    lu, cols, rows = workingset._factorise(a)
    assert lu is None
    assert cols.size == 2
    fixed = a.tolil()
    for c, r in zip(cols, rows):
        fixed[:, c] = 0.0
        fixed[r, c] = 1.0
    assert abs(np.linalg.det(fixed.toarray())) > 1e-8
    lu, cols, _ = workingset._factorise(sp.csc_matrix(fixed))
    assert lu is not None and cols is None


@pytest.mark.parametrize("bounding_rows", [1, 5, 1000])
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("loads", ["mixed", "positive"])
@pytest.mark.parametrize("max_new_rows", [1, 500])
def test_k_lp_row_generation_matches_the_full_lp(monkeypatch, bounding_rows, seed, loads, max_new_rows):
    """The K-LP over generated rows has the optimum of the LP over all rows (HiGHS, 1e-9), for
    few or many starting rows. With positive basis loads y the rows start from the bounding
    rows alone: 1 per column leaves the first restricted primal unbounded for some seeds
    (HiGHS's ray then brings the rows that bound it); the mixed loads (y < 0 on ~30 % of the
    rows, of which the K-LP starts with the lowest 5 %) take several rounds of row generation,
    one row per round with max_new_rows = 1."""
    monkeypatch.setattr(workingset, "BOUNDING_ROWS", bounding_rows)
    monkeypatch.setattr(workingset, "MAX_NEW_ROWS", max_new_rows)
    if loads == "positive":  # no low-load rows either: R starts from the bounding rows alone
        monkeypatch.setattr(workingset, "LOW_LOAD_ROWS", 0.0)
    rng = np.random.default_rng(seed)
    n, k = 60, 12
    y = rng.normal(size=n) + 0.5 if loads == "mixed" else rng.uniform(0.1, 1.0, n)
    null = rng.normal(size=(n, k))
    h_s, h_w = rng.uniform(0, 1, n), rng.uniform(-0.5, 1, k)
    upper = rng.uniform(1, 2, n)
    mu, alpha, t = workingset._KLP(y, h_s, upper).solve(null, h_w)
    q = h_s @ null + h_w
    full = linprog(y, A_ub=null.T, b_ub=q, bounds=np.column_stack([np.zeros(n), upper]), method="highs")
    assert full.status == 0
    assert mu is not None
    assert y @ mu == pytest.approx(full.fun, abs=1e-9 * max(1.0, abs(full.fun)))
    assert np.all(null.T @ mu <= q + 1e-9) and np.all(mu >= -1e-12) and np.all(mu <= upper + 1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_k_lp_grown_column_by_column_matches_the_full_lp(seed):
    """The K-LP object kept across rounds, as the working set grows (2, 5, 9, then 14 columns),
    has after each round the optimum of the LP over all rows and the columns so far (HiGHS,
    1e-9): the additions to its HiGHS model and the restarts from the previous basis change
    nothing but the time."""
    rng = np.random.default_rng(100 + seed)
    n, k = 60, 14
    y, null = rng.normal(size=n) + 0.5, rng.normal(size=(n, k))
    h_s, h_w, upper = rng.uniform(0, 1, n), rng.uniform(-0.5, 1, k), rng.uniform(1, 2, n)
    k_lp = workingset._KLP(y, h_s, upper)
    for size in (2, 5, 9, 14):
        mu, alpha, t = k_lp.solve(null[:, :size], h_w[:size])
        q = h_s @ null[:, :size] + h_w[:size]
        full = linprog(y, A_ub=null[:, :size].T, b_ub=q, bounds=np.column_stack([np.zeros(n), upper]),
                       method="highs")
        assert full.status == 0 and mu is not None
        assert y @ mu == pytest.approx(full.fun, abs=1e-9 * max(1.0, abs(full.fun)))
        assert np.all(null[:, :size].T @ mu <= q + 1e-9) and np.all((mu >= -1e-12) & (mu <= upper + 1e-12))
        # the primal: f = y + N alpha + t >= 0 with alpha, t >= 0 and the same objective
        assert np.all(alpha >= -1e-12) and np.all(t >= -1e-12)
        assert np.all(y + null[:, :size] @ alpha + t >= -1e-9)
        assert q @ alpha + upper @ t == pytest.approx(-full.fun, abs=1e-8 * max(1.0, abs(full.fun)))


def _with_dense_row(n: int, seed: int) -> sp.csc_matrix:
    """A regular sparse matrix whose last row has an entry in every column, most of them tiny
    (the strain row of a sheared cell): the path of workingset._row_scale."""
    rng = np.random.default_rng(seed)
    a = _regular_sparse(n, seed).tolil()
    row = rng.uniform(-1e-6, 1e-6, n)
    row[::7] = rng.uniform(1, 2, row[::7].size)
    a[n - 1, :] = row
    return sp.csc_matrix(a)


@pytest.mark.parametrize("seed", range(3))
def test_scaled_lu_solves_with_dense_rows(seed):
    """The dense row is scaled down for the LU (its largest entry 1e-3 of the others'); the
    solves are those of the matrix itself (1e-9: these matrices have condition ~1e3)."""
    a = _with_dense_row(400, seed)
    scale = workingset._row_scale(a)
    assert np.all(scale[:-1] == 1.0)
    assert np.abs(a[-1].toarray()).max() * scale[-1] == pytest.approx(1e-3 * np.abs(a[:-1].toarray()).max())
    lu, cols, _ = workingset._factorise(a)
    assert cols is None
    rng = np.random.default_rng(seed)
    b, m = rng.normal(size=400), rng.normal(size=(400, 3))
    dense = a.toarray()
    np.testing.assert_allclose(dense @ lu.solve(b), b, atol=1e-9)
    np.testing.assert_allclose(dense.T @ lu.solve(b, trans="T"), b, atol=1e-9)
    np.testing.assert_allclose(dense @ lu.solve(m), m, atol=1e-9)


def test_factorise_with_dense_rows_finds_the_dependent_column():
    a = _with_dense_row(400, 4).tolil()
    a[:, 100] = a[:, 10] - a[:, 20]
    lu, cols, rows = workingset._factorise(sp.csc_matrix(a))
    assert lu is None and cols.size == 1
    fixed = a.copy()
    fixed[:, cols[0]] = 0.0
    fixed[rows[0], cols[0]] = 1.0
    assert workingset._factorise(sp.csc_matrix(fixed))[1] is None


@pytest.mark.parametrize("dense_rows", [False, True])
def test_block_solves_match_a_dense_solve(dense_rows):
    """The blocked triangular solves (hardpack.jamming.triangular) give A^{-1} B for a block
    wider than two passes (70 = 2 x 32 + 6 columns), with and without a scaled dense row (as in
    a strict LP). Tolerance 1e-10: the condition number of these matrices is ~1e2-1e3, so
    round-off stays near 1e-13."""
    a = _regular_sparse(120, 3).tolil()
    if dense_rows:
        a[0, :] = np.linspace(0.5, 1.5, 120)  # a dense row: scaled for the LU
    a = sp.csc_matrix(a)
    assert np.any(workingset._row_scale(a) != 1.0) == dense_rows
    lu = workingset._ScaledLU(a)
    b = np.random.default_rng(4).standard_normal((120, 70))
    exact = np.linalg.solve(a.toarray(), b)
    assert np.abs(lu.solve_block(b) - exact).max() <= 1e-10 * np.abs(exact).max()


def test_factorise_a_crystal_basis_with_equal_entries():
    """A basis of the BCC 3 x 2 x 1 cell's collective LP: its first 33 contact columns (all of
    gap 0, as a cold start takes them), rank 27 and structural rank 29. SuperLU refused the
    regularised copy with equal regularising entries ('Factor is exactly singular', the crash
    of verify(lattice_packing('bcc', (3, 2, 1)))); now the 6 dependent columns are found, and
    the repair cycles of _repaired_lu (dependent columns replaced by the unit columns of their
    rows) end with a regular basis."""
    p = lattice_packing("bcc", (3, 2, 1))
    net = contact_network(p, 1e-6)
    backbone = np.ones(p.n_particles, bool)
    _, at = anchored_transpose(net, backbone, net.among(backbone))
    basis = at.T.tocsc()[:, :33].tocsc()
    assert np.linalg.matrix_rank(basis.toarray()) == 27 and structural_rank(basis) == 29
    lu, cols, _ = workingset._factorise(basis)
    assert lu is None and cols.size == 6
    columns = workingset._Columns(basis, np.zeros(33), np.ones(33))
    lu, repaired, replaced = workingset._repaired_lu(columns, np.arange(33))
    assert lu is not None and replaced.size >= 6
    regular = columns.matrix(repaired).toarray()
    assert np.linalg.matrix_rank(regular) == 33
    x = np.arange(33.0)
    np.testing.assert_allclose(regular @ lu.solve(x), x, atol=1e-9)


def test_structurally_singular_basis_never_reaches_superlu(monkeypatch):
    """SuperLU on a structurally singular matrix calls BLAS with negative sizes (OpenBLAS:
    'On entry to DGEMV parameter number 2 had an illegal value'): _factorise probes such a
    matrix on its regularised copy only."""
    seen = []
    real = workingset._ScaledLU

    class Spy(real):
        def __init__(self, a):
            seen.append(workingset.structurally_regular(a))
            super().__init__(a)

    monkeypatch.setattr(workingset, "_ScaledLU", Spy)
    a = sp_random_structurally_singular()
    lu, cols, _ = workingset._factorise(a)
    assert lu is None and cols.size >= 1
    assert seen and all(seen)


def sp_random_structurally_singular():
    """40 x 40, two columns supported on the same single row: structural rank 39."""
    rng = np.random.default_rng(3)
    n = 40
    rows = np.concatenate([(np.arange(n) + s) % n for s in (1, 2, 5)])
    cols = np.tile(np.arange(n), 3)
    a = sp.csc_matrix((rng.uniform(1, 2, 3 * n), (rows, cols)), shape=(n, n)).tolil()
    a[:, 10] = 0.0
    a[:, 11] = 0.0
    a[4, 10] = 1.0
    a[4, 11] = 2.0
    a = sp.csc_matrix(a)
    a.eliminate_zeros()
    assert not workingset.structurally_regular(a)
    return a
