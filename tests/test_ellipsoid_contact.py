"""The Perram-Wertheim contact function of ellipsoids and ellipses (Donev 2006, Sec. 2.2.2-2.2.3):
exact results for spheres and parallel identical ellipsoids, invariances, the maximiser against a
30-digit mpmath root of f'(lambda), and the rate d zeta/dt against finite differences."""

import mpmath as mp
import numpy as np
import pytest

from hardpack.geometry.contact import _pw_maximise, contact_point, pw_contact, pw_rate, shape_inverse
from hardpack.geometry.shapes import Ellipsoids


def random_rotation(rng, d):
    """A random proper rotation matrix (d, d)."""
    q, r = np.linalg.qr(rng.normal(size=(d, d)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


def random_orientation(rng, d):
    if d == 2:
        return rng.uniform(-np.pi, np.pi, size=1)
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def inverse_shape(axes, orientation):
    out = np.empty((len(axes), len(axes)))
    shape_inverse(np.asarray(axes, dtype=float), np.asarray(orientation, dtype=float), out)
    return out


def random_inverse_shape(rng, d, aspect=4.0):
    return inverse_shape(rng.uniform(1.0, aspect, size=d), random_orientation(rng, d))


# ---------------------------------------------------------------- shape matrices
@pytest.mark.parametrize("d", [2, 3])
def test_shape_inverse_inverts_the_shape_matrix_of_the_packing_model(d):
    rng = np.random.default_rng(0)
    for _ in range(20):
        axes = rng.uniform(0.1, 3.0, size=d)
        orient = random_orientation(rng, d)
        x = Ellipsoids(axes[None], orient[None] if d == 3 else orient).shape_matrices()[0]
        np.testing.assert_allclose(inverse_shape(axes, orient) @ x, np.eye(d), atol=1e-13)


def test_shape_inverse_of_the_reference_orientation_is_diagonal():
    np.testing.assert_allclose(inverse_shape([1.0, 2.0, 3.0], [1.0, 0, 0, 0]), np.diag([1.0, 4.0, 9.0]))
    # a quarter turn about z puts the first semiaxis along y
    half = np.sqrt(0.5)
    np.testing.assert_allclose(inverse_shape([1.0, 2.0, 3.0], [half, 0, 0, half]), np.diag([4.0, 1.0, 9.0]),
                               atol=1e-15)
    np.testing.assert_allclose(inverse_shape([1.0, 2.0], [np.pi / 2]), np.diag([4.0, 1.0]), atol=1e-15)


# ---------------------------------------------------------------- exact cases
@pytest.mark.parametrize("d", [2, 3])
def test_spheres_are_exact(d):
    """Donev 2006, Eq. 2.3: zeta = |r|^2 / (a + b)^2 - 1, with maximiser a / (a + b) and n = r / (a b)."""
    rng = np.random.default_rng(1)
    for _ in range(200):
        a, b = 10.0 ** rng.uniform(-3, 1, size=2)
        r = rng.normal(size=d) * (a + b) * rng.uniform(0.01, 3.0)
        zeta, lam, n = pw_contact(r, np.eye(d) * a * a, np.eye(d) * b * b, rng.uniform(0, 1))
        assert zeta == pytest.approx(r @ r / (a + b) ** 2 - 1, rel=1e-13, abs=1e-14)
        assert lam == pytest.approx(a / (a + b), rel=1e-14)
        np.testing.assert_allclose(n, r / (a * b), rtol=1e-12)  # Y = a b I at the maximiser


@pytest.mark.parametrize("d", [2, 3])
def test_identical_parallel_ellipsoids_touch_at_two_over_the_root_of_u_x_u(d):
    """Two copies of X touch at distance 2 / sqrt(u^T X u) along the unit vector u; at s times that
    distance mu = s exactly (lambda = 1/2, f = r^T X r / 4)."""
    rng = np.random.default_rng(2)
    for _ in range(100):
        axes, orient = rng.uniform(0.1, 1.0, size=d), random_orientation(rng, d)
        a_inv = inverse_shape(axes, orient)
        x = np.linalg.inv(a_inv)
        u = rng.normal(size=d)
        u /= np.linalg.norm(u)
        for s in (1.0, 1 - 1e-9, 1 + 1e-9, 0.3, 2.5):
            zeta, lam, _ = pw_contact(s * 2 / np.sqrt(u @ x @ u) * u, a_inv, a_inv.copy(), 0.2)
            assert zeta == pytest.approx(s * s - 1, rel=1e-12, abs=1e-13)
            assert lam == pytest.approx(0.5, abs=1e-14)


@pytest.mark.parametrize("d", [2, 3])
def test_rotation_invariance_and_exchange_symmetry(d):
    rng = np.random.default_rng(3)
    for _ in range(200):
        a_inv, b_inv = random_inverse_shape(rng, d), random_inverse_shape(rng, d)
        r = rng.normal(size=d) * 4
        zeta, lam, n = pw_contact(r, a_inv, b_inv, 0.5)
        rot = random_rotation(rng, d)
        zeta_r, lam_r, n_r = pw_contact(rot @ r, rot @ a_inv @ rot.T, rot @ b_inv @ rot.T, 0.5)
        assert zeta_r == pytest.approx(zeta, rel=1e-12, abs=1e-13)
        assert lam_r == pytest.approx(lam, rel=1e-12)
        np.testing.assert_allclose(n_r, rot @ n, rtol=1e-10, atol=1e-12 * np.abs(n).max())
        zeta_s, lam_s, n_s = pw_contact(-r, b_inv, a_inv, 0.5)
        assert zeta_s == pytest.approx(zeta, rel=1e-12, abs=1e-13)
        assert lam_s == pytest.approx(1 - lam, rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(n_s, -n, rtol=1e-10, atol=1e-12 * np.abs(n).max())


@pytest.mark.parametrize("d", [2, 3])
def test_the_contact_point_is_on_both_scaled_surfaces(d):
    """Eq. 2.13: r_A + (1 - lam) X_A^-1 n = r_B - lam X_B^-1 n, and r_C is on both particles scaled by mu
    (zeta_A(r_C) = zeta_B(r_C) = zeta, Eq. 2.2) with antiparallel normals (Eq. 2.1)."""
    rng = np.random.default_rng(4)
    for _ in range(100):
        a_inv, b_inv = random_inverse_shape(rng, d), random_inverse_shape(rng, d)
        r_a, r_b = rng.normal(size=d), rng.normal(size=d) * 5
        zeta, lam, n = pw_contact(r_b - r_a, a_inv, b_inv, 0.5)
        r_c = np.empty(d)
        contact_point(r_a, a_inv, lam, n, r_c)
        np.testing.assert_allclose(r_c, r_b - lam * b_inv @ n, atol=1e-12 * np.linalg.norm(r_b - r_a))
        for centre, inv in ((r_a, a_inv), (r_b, b_inv)):
            x = r_c - centre
            assert x @ np.linalg.solve(inv, x) == pytest.approx(zeta + 1, rel=1e-12)
        grad_a, grad_b = np.linalg.solve(a_inv, r_c - r_a), np.linalg.solve(b_inv, r_c - r_b)
        cos = grad_a @ grad_b / np.linalg.norm(grad_a) / np.linalg.norm(grad_b)
        assert cos == pytest.approx(-1, abs=1e-12)


# ---------------------------------------------------------------- the maximiser, independently
def mp_maximiser(r, a_inv, b_inv):
    """Lambda as the root of f'(lambda) = 0 at 30 digits (mpmath bisection on the exact derivative)."""
    mp.mp.dps = 30
    r_m, a_m, b_m = mp.matrix(r.tolist()), mp.matrix(a_inv.tolist()), mp.matrix(b_inv.tolist())

    def fprime(lam):
        y = lam * b_m + (1 - lam) * a_m
        n = mp.lu_solve(y, r_m)
        dn = (b_m - a_m) * n
        return (1 - 2 * lam) * (r_m.T * n)[0] - lam * (1 - lam) * (n.T * dn)[0]

    lo, hi = mp.mpf(0), mp.mpf(1)
    for _ in range(110):
        mid = (lo + hi) / 2
        if fprime(mid) > 0:
            lo = mid
        else:
            hi = mid
    lam = (lo + hi) / 2
    y = lam * b_m + (1 - lam) * a_m
    zeta = lam * (1 - lam) * (r_m.T * mp.lu_solve(y, r_m))[0] - 1
    return float(lam), float(zeta)


CASES = {
    "aspect 1:10 prolate vs oblate": ([1.0, 1.0, 10.0], [10.0, 10.0, 1.0], 1.0),
    "aspect 1:10 needles": ([0.1, 0.1, 1.0], [0.1, 0.1, 1.0], 1.0),
    "aspect 1:10 ellipses": ([1.0, 10.0], [10.0, 1.0], 1.0),
    "near-tangent": ([0.2, 0.5, 2.0], [1.0, 0.3, 0.4], None),
    "near-coincident centres": ([0.2, 0.5, 2.0], [1.0, 0.3, 0.4], 1e-9),
    "near-coincident ellipses": ([0.1, 1.0], [1.0, 0.1], 1e-12),
    "tiny vs large": ([1e-3, 2e-3, 1e-3], [1.0, 10.0, 3.0], 1.0),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_newton_reaches_the_30_digit_maximiser(case):
    axes_a, axes_b, distance = CASES[case]
    d = len(axes_a)
    rng = np.random.default_rng(sum(map(ord, case)))
    for _ in range(8):
        a_inv = inverse_shape(axes_a, random_orientation(rng, d))
        b_inv = inverse_shape(axes_b, random_orientation(rng, d))
        u = rng.normal(size=d)
        u /= np.linalg.norm(u)
        if distance is None:  # scale to contact, then perturb by 1e-10
            zeta, _, _ = pw_contact(u, a_inv, b_inv, 0.5)
            r = u / np.sqrt(zeta + 1) * (1 + 1e-10)
        else:
            r = u * distance
        lam_exact, zeta_exact = mp_maximiser(r, a_inv, b_inv)
        for lam0 in (0.0, 1e-12, 0.5, 1 - 1e-12, 1.0):
            zeta, lam, _ = pw_contact(r, a_inv, b_inv, lam0)
            assert lam == pytest.approx(lam_exact, rel=1e-12), (lam0, lam, lam_exact)
            assert zeta == pytest.approx(zeta_exact, rel=1e-12, abs=1e-14)


def test_coincident_centres_overlap_completely():
    zeta, lam, n = pw_contact(np.zeros(3), np.eye(3), np.eye(3) * 4, 0.3)
    assert (zeta, lam) == (-1.0, 0.3) and not n.any()


@pytest.mark.parametrize("bad", [-0.1, 1.5, np.nan])
def test_an_initial_guess_outside_the_unit_interval_is_refused(bad):
    with pytest.raises(ValueError, match="lam0"):
        pw_contact(np.ones(3), np.eye(3), np.eye(3), bad)


def test_a_non_finite_separation_is_refused():
    with pytest.raises(ValueError, match="finite"):
        pw_contact(np.array([np.inf, 0.0]), np.eye(2), np.eye(2), 0.5)


# ---------------------------------------------------------------- the rate
def rodrigues(w, t):
    """Rotation matrix after spinning at angular velocity w (3,) or a scalar (2D) for time t."""
    if np.ndim(w) == 0 or len(np.atleast_1d(w)) == 1:
        phi = float(np.atleast_1d(w)[0]) * t
        return np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    angle = np.linalg.norm(w) * t
    k = w / np.linalg.norm(w)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


@pytest.mark.parametrize("d,scalar_spin", [(3, False), (2, True), (2, False)])
def test_the_rate_matches_a_finite_difference_along_a_trajectory(d, scalar_spin):
    """Eq. 2.21 with translation, rotation (X^-1(t) = R(t) X^-1 R(t)^T) and growth (semiaxes
    times 1 + g t) against a central difference of zeta(t), step 1e-5 (error ~ 1e-10)."""
    rng = np.random.default_rng(5)
    for _ in range(50):
        a0, b0 = random_inverse_shape(rng, d), random_inverse_shape(rng, d)
        ra0, rb0 = rng.normal(size=d), rng.normal(size=d) * 4
        va, vb = rng.normal(size=d), rng.normal(size=d)
        if d == 3:
            wa, wb = rng.normal(size=3), rng.normal(size=3)
        else:
            wa, wb = (rng.normal(), rng.normal()) if scalar_spin else (rng.normal(size=1), rng.normal(size=1))
        ga, gb = rng.uniform(-0.5, 0.5, size=2)

        def state(t):
            ra, rb = ra0 + va * t, rb0 + vb * t
            rot_a, rot_b = rodrigues(wa, t), rodrigues(wb, t)
            a_inv = (1 + ga * t) ** 2 * rot_a @ a0 @ rot_a.T
            b_inv = (1 + gb * t) ** 2 * rot_b @ b0 @ rot_b.T
            return ra, rb, a_inv, b_inv

        def zeta(t):
            ra, rb, a_inv, b_inv = state(t)
            return pw_contact(rb - ra, a_inv, b_inv, 0.5)[0]

        ra, rb, a_inv, b_inv = state(0.0)
        z, lam, n = pw_contact(rb - ra, a_inv, b_inv, 0.5)
        rc = np.empty(d)
        contact_point(ra, a_inv, lam, n, rc)
        rate = pw_rate(lam, n, ra, rb, rc, va, vb, wa, wb, ga, gb)
        h = 1e-5
        fd = (zeta(h) - zeta(-h)) / (2 * h)
        assert rate == pytest.approx(fd, rel=1e-7, abs=1e-8 * (1 + abs(z)))


@pytest.mark.parametrize("d", [2, 3])
def test_newton_converges_quadratically(d):
    """Random pairs (aspect ratios up to 4, lambda across (0, 1) including tiny-vs-large pairs with
    lambda near 1) need a handful of iterations: once the Newton step drops below the last
    representable digit the iteration stops instead of bisecting on (seen before: mean 28, and the
    cap of 200 whenever lambda was near 1)."""
    rng = np.random.default_rng(8)
    counts = []
    for k in range(4000):
        scale = 10.0 ** rng.uniform(-2, 0) if k % 2 else 1.0
        a_inv, b_inv = random_inverse_shape(rng, d), random_inverse_shape(rng, d) * scale**2
        r = rng.normal(size=d) * rng.uniform(0.1, 10)
        zeta, lam, _, iterations = _pw_maximise(r, a_inv, b_inv, 0.5)
        counts.append(iterations)
    assert np.mean(counts) < 10 and max(counts) <= 30
