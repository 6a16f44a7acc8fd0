"""The sign of the Perram-Wertheim potential against an independent overlap verdict: the algebraic
separation condition of Wang, Wang & Kim 2001 for ellipsoids and its analogue for ellipses
(Choi, Wang, Liu & Kim 2006).

For quadrics x^T M x = 0 in homogeneous coordinates (M = [[X, -X c], [-c^T X, c^T X c - 1]], the
inside negative), the characteristic polynomial det(lam M_A + M_B) has two distinct positive roots
if and only if the particles are disjoint, and a positive double root when they touch externally.
Near contact the two roots merge, so round-off decides the verdict within a band |zeta| < ZETA_BAND
of contact; outside that band the two must agree on every pair.
"""

import numba
import numpy as np
import pytest

from hardpack.geometry.contact import pw_contact, shape_inverse

N_PAIRS = 100_000
ZETA_BAND = 1e-10  # measured worst disagreement: |zeta| ~ 1.5e-12 in 2e5 pairs


def homogeneous(x, centres):
    """(n, d+1, d+1) matrices of the quadrics (r - c)^T X (r - c) - 1 = 0."""
    n, d = centres.shape
    m = np.zeros((n, d + 1, d + 1))
    xc = np.einsum("nij,nj->ni", x, centres)
    m[:, :d, :d] = x
    m[:, :d, d] = m[:, d, :d] = -xc
    m[:, d, d] = np.einsum("ni,ni->n", centres, xc) - 1
    return m


def separated_algebraic(x_a, c_a, x_b, c_b):
    """Wang, Wang & Kim 2001 verdict per pair: True iff det(lam M_A + M_B) = 0 has two distinct
    positive real roots (the roots are the eigenvalues of -M_A^-1 M_B)."""
    roots = np.linalg.eigvals(np.linalg.solve(homogeneous(x_a, c_a), -homogeneous(x_b, c_b)))
    positive = (roots.imag == 0) & (roots.real > 0)
    return positive.sum(axis=1) >= 2


@numba.njit  # no cache: a cached caller would not see changes to pw_contact
def zetas(r, a_inv, b_inv):
    out = np.empty(r.shape[0])
    for k in range(r.shape[0]):
        out[k] = pw_contact(r[k], a_inv[k], b_inv[k], 0.5)[0]
    return out


def random_inverse_shapes(rng, n, d):
    """X^-1 of n random ellipsoids: aspect ratios up to 10, sizes over two decades."""
    axes = rng.uniform(1.0, 10.0, size=(n, d)) * 10.0 ** rng.uniform(-1, 1, size=(n, 1))
    out = np.empty((n, d, d))
    for k in range(n):
        if d == 2:
            orientation = rng.uniform(-np.pi, np.pi, size=1)
        else:
            orientation = rng.normal(size=4)
            orientation /= np.linalg.norm(orientation)
        shape_inverse(axes[k], orientation, out[k])
    return out


@pytest.mark.parametrize("d", [2, 3])
def test_the_algebraic_verdict_is_right_for_spheres(d):
    x = np.broadcast_to(np.eye(d), (4, d, d))
    centres_b = np.zeros((4, d))
    centres_b[:, 0] = [3.0, 2.1, 1.9, 0.5]
    assert separated_algebraic(x, np.zeros((4, d)), x, centres_b).tolist() == [True, True, False, False]


@pytest.mark.parametrize("d", [2, 3])
def test_the_sign_of_zeta_agrees_with_the_algebraic_verdict_on_random_pairs(d):
    """1e5 random pairs per dimension at relative distances 1 + delta from contact along a random
    direction, |delta| log-uniform in [1e-15, 0.5] with either sign. Contact is found from the
    homogeneity of mu in r (mu(s r) = s mu(r)), so zeta = (1 + delta)^2 - 1 by construction, up to round-off (worst seen
    1.5e-12: aspect ratios 10 and size ratios 100 make Y ill-conditioned)."""
    rng = np.random.default_rng(2001 + d)
    a_inv, b_inv = random_inverse_shapes(rng, N_PAIRS, d), random_inverse_shapes(rng, N_PAIRS, d)
    u = rng.normal(size=(N_PAIRS, d))
    u /= np.linalg.norm(u, axis=1)[:, None]
    delta = rng.choice([-1.0, 1.0], size=N_PAIRS) * 10.0 ** rng.uniform(-15, np.log10(0.5), N_PAIRS)
    r = u / np.sqrt(zetas(u, a_inv, b_inv) + 1)[:, None] * (1 + delta)[:, None]
    zeta = zetas(r, a_inv, b_inv)
    np.testing.assert_allclose(zeta, delta * (2 + delta), rtol=0, atol=1e-11)  # measured worst 1.5e-12
    centres_a = rng.normal(size=(N_PAIRS, d)) * 3
    separated = separated_algebraic(np.linalg.inv(a_inv), centres_a, np.linalg.inv(b_inv), centres_a + r)
    outside = np.abs(zeta) >= ZETA_BAND
    disagree = (separated != (zeta > 0)) & outside
    assert outside.sum() > 0.6 * N_PAIRS and (np.abs(zeta[outside]) < 1e-4).sum() > 0.2 * N_PAIRS
    assert 0.4 < separated[outside].mean() < 0.6
    assert not disagree.any(), f"{disagree.sum()} of {outside.sum()} pairs with |zeta| >= {ZETA_BAND:g} disagree"
