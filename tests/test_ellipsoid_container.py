"""The farthest point of an ellipsoid or ellipse from a container centre
(:mod:`hardpack.geometry.ellipsoid_container`).

- Against a dense sampling of the surface of 10^4 random ellipsoids (and 10^4 ellipses), centres
  inside, on and outside the particle, aspect ratios up to 20: the exact rho is never below the
  sampled maximum (beyond round-off) and exceeds it by no more than the sampling error, and the
  returned point is on the surface at distance rho.
- Independent check: a local maximisation (scipy) from the best sample agrees to 1e-10.
- Exact cases: spheres (rho = |c| + r), centred ellipsoids (rho = a_max), centres on a principal
  axis, spheroids with the centre in the equatorial plane (the hard case of the secular equation),
  near-hard cases (a tiny component along the longest axis), extreme aspect ratios.
- The packing check: n_outside and the worst particle.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from hardpack.errors import InvalidInputError
from hardpack.geometry.boundaries import SphericalContainer
from hardpack.geometry.ellipsoid_container import container_gaps, farthest_point_body, farthest_points
from hardpack.geometry.packing import Packing
from hardpack.geometry.shapes import Ellipsoids


def _random_shapes(rng, n, d):
    a = np.exp(rng.uniform(np.log(0.05), np.log(1.0), (n, d)))
    if d == 3:
        q = rng.standard_normal((n, 4))
        q /= np.linalg.norm(q, axis=1, keepdims=True)
    else:
        q = rng.uniform(0, 2 * np.pi, n)
    return Ellipsoids(a, q)


def _surface_directions(m, d, rng):
    if d == 2:
        t = np.linspace(0, 2 * np.pi, m, endpoint=False)
        return np.stack([np.cos(t), np.sin(t)], 1)
    # Fibonacci sphere plus the 6 axis points
    k = np.arange(m) + 0.5
    phi = np.arccos(1 - 2 * k / m)
    th = np.pi * (1 + 5**0.5) * k
    u = np.stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)], 1)
    return np.concatenate([u, np.eye(3), -np.eye(3)])


@pytest.mark.parametrize("d,m", [(3, 4000), (2, 2000)])
def test_farthest_point_against_a_dense_surface_sampling(d, m):
    rng = np.random.default_rng(7 + d)
    n = 10_000
    shape = _random_shapes(rng, n, d)
    # centres: scaled so that many are inside the particle, on its scale and far away
    c = rng.standard_normal((n, d)) * np.exp(rng.uniform(np.log(1e-3), np.log(5.0), n))[:, None]
    rho, pts = farthest_points(c, shape.semiaxes, shape.rotations(), np.zeros(d))
    u = _surface_directions(m, d, rng)
    q = shape.rotations()
    a = shape.semiaxes
    sampled = np.empty(n)
    for s in range(0, n, 500):  # body-frame surface points a * u, to the lab frame: Q^T
        z = a[s:s + 500, None, :] * u[None]
        x = c[s:s + 500, None, :] + np.einsum("nkm,npk->npm", q[s:s + 500], z)
        sampled[s:s + 500] = np.sqrt(np.einsum("npm,npm->np", x, x)).max(axis=1)
    # the exact maximum is never below a sample beyond round-off
    assert (rho - sampled).min() >= -1e-13 * rho.max()
    # and above it by at most the sampling error: a point at angular spacing delta from the
    # maximum of a smooth function is within (curvature) delta^2 of it; here a_max delta^2 / 2
    # times the ratio of the curvature radius to the distance at worst (loose: a_max^2/a_min^2)
    delta = 2 * np.pi / m if d == 2 else np.sqrt(4 * np.pi / m)
    bound = a.max(1) * delta**2 * (a.max(1) / a.min(1)) ** 2
    excess = rho - sampled
    assert (excess <= bound).all(), float((excess / bound).max())
    # the point: on the surface, at distance rho
    assert np.allclose(np.linalg.norm(pts, axis=1), rho, rtol=1e-12, atol=1e-14)
    body = np.einsum("nkm,nm->nk", q, pts - c)
    level = np.einsum("nk,nk->n", body / a, body / a)
    assert np.abs(level - 1.0).max() < 1e-9
    # typical excess is tiny compared with the particle: the sampling is dense
    assert np.median(excess / a.max(1)) < 1e-3


def test_farthest_point_agrees_with_a_local_optimiser():
    rng = np.random.default_rng(3)
    n, d = 300, 3
    shape = _random_shapes(rng, n, d)
    c = rng.standard_normal((n, d)) * rng.uniform(0.01, 2.0, n)[:, None]
    rho, _ = farthest_points(c, shape.semiaxes, shape.rotations(), np.zeros(d))
    u = _surface_directions(2000, d, rng)
    worst = 0.0
    for i in range(n):
        q, a = shape.rotations()[i], shape.semiaxes[i]

        def neg(ang):
            v = np.array([np.sin(ang[0]) * np.cos(ang[1]), np.sin(ang[0]) * np.sin(ang[1]), np.cos(ang[0])])
            x = c[i] + q.T @ (a * v)
            return -(x @ x)

        x = c[i] + (a * u) @ q
        k = int(np.argmax(np.einsum("pm,pm->p", x, x)))
        v0 = u[k]
        res = minimize(neg, [np.arccos(np.clip(v0[2], -1, 1)), np.arctan2(v0[1], v0[0])],
                       method="Nelder-Mead", options={"xatol": 1e-13, "fatol": 1e-16, "maxiter": 5000})
        worst = max(worst, abs(np.sqrt(-res.fun) - rho[i]) / a.max())
        assert np.sqrt(-res.fun) <= rho[i] * (1 + 1e-13)
    assert worst < 1e-9


@pytest.mark.parametrize("d", [2, 3])
def test_exact_cases(d):
    rng = np.random.default_rng(11)
    x = np.empty(d)
    # spheres: rho = |c| + r, for any centre (the secular equation is linear in 1/sqrt(g))
    for _ in range(200):
        r = rng.uniform(0.01, 2)
        b = rng.standard_normal(d) * rng.uniform(0, 3)
        rho2 = farthest_point_body(b, np.full(d, r), x)
        assert np.sqrt(rho2) == pytest.approx(np.linalg.norm(b) + r, rel=1e-14)
    # centred: rho = a_max
    a = np.array([0.3, 1.7, 0.9][:d])
    assert np.sqrt(farthest_point_body(np.zeros(d), a, x)) == pytest.approx(a.max(), rel=1e-15)
    assert abs(abs(x[1]) - 1.7) < 1e-15
    # on the longest axis: |c| + a_max; on a shorter axis k at distance s: the farthest point is
    # at the end of that axis (s + a_k) or, past the evolute (s < (a_max^2 - a_k^2)/a_k),
    # sqrt(a_max^2 + s^2 a_max^2 / (a_max^2 - a_k^2)) off axis
    for s in (0.0, 1e-9, 0.1, 1.0, 5.0):
        b = np.zeros(d)
        b[1] = s
        assert np.sqrt(farthest_point_body(b, a, x)) == pytest.approx(s + 1.7, rel=1e-14)
        b = np.zeros(d)
        b[0] = s
        ak, am = 0.3, 1.7
        if s * ak >= am**2 - ak**2:
            expect = s + ak
        else:
            expect = np.sqrt(am**2 + s**2 * am**2 / (am**2 - ak**2))
        assert np.sqrt(farthest_point_body(b, a, x)) == pytest.approx(expect, rel=1e-13)
    # near the hard case: a tiny component along the longest axis changes rho continuously
    b = np.zeros(d)
    b[0] = 0.5
    hard = np.sqrt(farthest_point_body(b, a, x))
    for eps in (1e-300, 1e-200, 1e-30, 1e-15, 1e-8):
        b[1] = eps
        near = np.sqrt(farthest_point_body(b, a, x))
        assert hard <= near <= hard + 2 * eps + 1e-15
        assert np.isfinite(x).all()


def test_spheroids_in_the_equatorial_plane_hard_case():
    """Oblate spheroid (a, a, c), c < a, centre in its equatorial plane: the two longest semiaxes
    are equal and carry the whole centre, so the maximum is at the equator along the centre,
    |b| + a (not a hard case); prolate (c, c, a) with the centre in the equatorial plane at distance
    s < (a^2 - c^2)/c: the hard case, rho^2 = a^2 + s^2 a^2 / (a^2 - c^2)."""
    x = np.empty(3)
    rho = np.sqrt(farthest_point_body(np.array([0.2, -0.3, 0.0]), np.array([1.0, 1.0, 0.5]), x))
    assert rho == pytest.approx(np.hypot(0.2, 0.3) + 1.0, rel=1e-14)
    s = 0.4
    rho = np.sqrt(farthest_point_body(np.array([s * 0.6, s * 0.8, 0.0]), np.array([0.5, 0.5, 1.0]), x))
    assert rho == pytest.approx(np.sqrt(1 + s**2 / (1 - 0.25)), rel=1e-14)
    assert np.sqrt((x[:2] ** 2).sum()) == pytest.approx(s / 0.75, rel=1e-13)


def test_extreme_aspect_ratios_converge():
    """Semiaxes 1e-4 : 1 : 1e3, centres from 1e-6 to 1e4: finite, on the surface (where the
    subtraction x - b is well conditioned), never below a dense sampling of the surface, and the
    outward normal at the point is along x (the Lagrange condition)."""
    x = np.empty(3)
    rng = np.random.default_rng(5)
    u = _surface_directions(20000, 3, rng)
    for _ in range(2000):
        a = np.array([1e-4, 1.0, 1e3]) * rng.uniform(0.5, 2, 3)
        b = rng.standard_normal(3) * 10 ** rng.uniform(-6, 4)
        rho2 = farthest_point_body(b, a, x)
        assert np.isfinite(x).all() and np.sqrt(rho2) == pytest.approx(np.linalg.norm(x), rel=1e-10)
        samples = b + a * u
        assert np.sqrt(rho2) >= np.sqrt(np.einsum("pk,pk->p", samples, samples).max()) * (1 - 1e-14)
        if np.abs(b).max() < 1e-2 * a.min():
            z = x - b
            assert abs((z**2 / a**2).sum() - 1) < 1e-8
            nrm = z / a**2
            assert nrm @ x / np.linalg.norm(nrm) / np.linalg.norm(x) > 1 - 1e-8


def test_packing_check_names_the_worst_particle():
    shape = Ellipsoids([[1.0, 0.25, 0.25]] * 3, [[1, 0, 0, 0], [np.cos(0.3), 0, np.sin(0.3), 0], [1, 0, 0, 0]])
    box = 10 * np.eye(3)
    cont = SphericalContainer((5, 5, 5), 4.0)
    pos = np.array([[5.0, 5, 5], [5, 5, 8.6], [5, 5 + 3.75, 5]])
    p = Packing(pos, lattice=box, shape=shape, boundary=cont, allow_overlap=True)
    gap, pts = container_gaps(pos, shape, cont.centre, cont.radius)
    assert gap[0] == pytest.approx(3.0) and gap[2] == pytest.approx(0.0, abs=1e-14)
    rep = p.containment_report(1e-9)
    assert rep.n_outside == 1 and rep.worst == 1 and rep.overlap == pytest.approx(-gap[1])
    with pytest.raises(InvalidInputError, match="particle 1 crosses the container wall"):
        Packing(pos, lattice=box, shape=shape, boundary=cont)
