"""Exact simplex volumes (Donev ch. 6 Eqs. 6.3-6.5) against independent volumes."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial import ConvexHull, HalfspaceIntersection
from scipy.special import gammaln

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.ladder import random_simplex
from hardpack.freeenergy.simplex import jamming_simplex, log_simplex_volume


def test_note_one_dimensional_example():
    # A = (1, -1)^T, b = (1, 1) -> the segment [-1, 1], V = 2 exactly
    assert np.exp(log_simplex_volume([[1.0], [-1.0]], [1.0, 1.0])) == pytest.approx(
        2.0, rel=1e-14
    )


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_against_qhull(n):
    # qhull's volume of the convex hull of the vertices is exact to round-off (~1e-12)
    rng = np.random.default_rng(n)
    for _ in range(3):
        a, b, vol = random_simplex(n, rng)
        assert np.exp(log_simplex_volume(a, b)) == pytest.approx(vol, rel=1e-9)
        hs = HalfspaceIntersection(np.hstack([a, -b[:, None]]), np.zeros(n))
        assert ConvexHull(hs.intersections).volume == pytest.approx(vol, rel=1e-9)


def test_against_monte_carlo():
    # 4D simplex, 4e5 uniform samples in the bounding box: binomial relative error ~ 0.5 %,
    # tolerance 3 %
    rng = np.random.default_rng(7)
    a, b, _ = random_simplex(4, rng)
    hs = HalfspaceIntersection(np.hstack([a, -b[:, None]]), np.zeros(4))
    lo, hi = hs.intersections.min(axis=0), hs.intersections.max(axis=0)
    pts = rng.uniform(lo, hi, size=(400_000, 4))
    inside = np.all(pts @ a.T <= b, axis=1).mean()
    assert np.exp(log_simplex_volume(a, b)) == pytest.approx(
        inside * np.prod(hi - lo), rel=0.03
    )


def ring_rigidity(n):
    """Rigidity matrix of a 1D periodic ring of n touching unit rods with rod 0 frozen.

    Contact k joins rods k and k+1 (mod n); its row entries are -1 on rod k, +1 on rod k+1.
    The gaps g_k = 1 + x_{k+1} - x_k >= 0 sum to n, so P_x is {g >= 0, sum g = n} with unit
    Jacobian: |P_x| = n^(n-1) / (n-1)! exactly, and all forces are 1/n.
    """
    rows, cols, vals = [], [], []
    for k in range(n):
        for rod, sign in ((k, -1.0), ((k + 1) % n, 1.0)):
            if rod != 0:
                rows.append(rod - 1)
                cols.append(k)
                vals.append(sign)
    return sp.csc_matrix((vals, (rows, cols)), shape=(n - 1, n))


@pytest.mark.parametrize("n", [3, 10, 1000])
def test_ring_packing_exact(n):
    res = jamming_simplex(ring_rigidity(n), n_eff=n - 1)
    exact = (n - 1) * np.log(n) - gammaln(n)
    assert res.log_volume == pytest.approx(exact, rel=1e-10)
    np.testing.assert_allclose(res.forces, 1.0 / n, rtol=1e-10)
    assert res.f_j == pytest.approx(exact / (n - 1), rel=1e-10)


def test_small_ring_against_qhull():
    # the n = 5 ring's polytope (A^T x <= e) from halfspaces, independent of the formula
    a = ring_rigidity(5).toarray()
    hs = HalfspaceIntersection(np.hstack([a.T, -np.ones((5, 1))]), np.zeros(4))
    vol = ConvexHull(hs.intersections).volume
    assert np.exp(jamming_simplex(a, n_eff=4).log_volume) == pytest.approx(
        vol, rel=1e-9
    )


def test_refuses_non_isostatic():
    a = ring_rigidity(6).toarray()
    with pytest.raises(InvalidInputError, match="not isostatic"):
        jamming_simplex(a[:, :-1], n_eff=5)
    with pytest.raises(InvalidInputError, match="not isostatic"):
        jamming_simplex(np.hstack([a, a[:, :1]]), n_eff=5)


def test_refuses_negative_force():
    # flipping one contact's orientation makes the polytope unbounded: force becomes negative
    a = ring_rigidity(6).toarray()
    a[:, 2] *= -1
    with pytest.raises(InvalidInputError, match="force"):
        jamming_simplex(a, n_eff=5)


def test_refuses_unbounded_h_representation():
    with pytest.raises(InvalidInputError, match="do not bound"):
        log_simplex_volume([[1.0], [2.0]], [1.0, 1.0])  # x <= 1 and x <= 1/2: unbounded
    with pytest.raises(InvalidInputError, match="b must be"):
        log_simplex_volume([[1.0], [-1.0]], [1.0, -1.0])
