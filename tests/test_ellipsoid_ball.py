"""The intersection volume of an ellipsoid (ellipse) with a ball (disk):
:mod:`hardpack.geometry.ellipsoid_ball`.

Proofs against independent results: the sphere-ball lens formula; the closed form of an ellipse
with a concentric disk (polar integral of the ellipse's radius); Monte Carlo estimates (>= 1e6
points) within 4 standard errors over all relative positions; a fine quadrature of the polar
formula V = int (min(t_+, r)^3 - min(t_-, r)^3)_+ / 3 dOmega about the ball's centre;
dV/dr equal to the area of the sphere (length of the circle) of radius r inside the particle,
measured on a fine grid of directions; V = 0 below the nearest distance and the particle's volume
beyond the farthest."""

import numpy as np
import pytest

from hardpack.geometry.ellipsoid_ball import ellipse_disk_area, ellipsoid_ball_volume
from hardpack.structure.containers import ball_intersection_volume

TOL = 1e-10


def _volume(a, b, r):
    return ellipsoid_ball_volume(np.asarray(a, float), np.asarray(b, float), float(r), TOL)


def test_spheres_equal_the_lens_formula():
    rng = np.random.default_rng(0)
    for _ in range(80):
        a, r = rng.uniform(0.2, 2.0, 2)
        direction = rng.standard_normal(3)
        b = direction / np.linalg.norm(direction) * rng.uniform(0.0, a + r + 0.1)
        exact = ball_intersection_volume(r, a, np.linalg.norm(b), 3)
        assert _volume([a, a, a], b, r) == pytest.approx(exact, abs=1e-10 * a**3)
        exact2 = ball_intersection_volume(r, a, np.linalg.norm(b[:2]), 2)
        assert _volume([a, a], b[:2], r) == pytest.approx(exact2, abs=1e-12 * a**2)


def test_ellipse_with_a_concentric_disk_is_the_polar_closed_form():
    """b < R < a: the ellipse's polar radius exceeds R for |theta| < theta_0, tan^2 theta_0 =
    b^2 (a^2 - R^2) / (a^2 (R^2 - b^2)), and (1/2) int rho^2 dtheta = (a b / 2) atan((a / b) tan theta):
    A = 2 R^2 theta_0 + 2 a b (pi / 2 - atan((a / b) tan theta_0))."""
    for a, b in ((1.0, 0.5), (3.0, 1.0), (1.3, 1.2)):
        for radius in np.linspace(b, a, 9)[1:-1]:
            t0 = np.arctan(np.sqrt(b * b * (a * a - radius**2) / (a * a * (radius**2 - b * b))))
            exact = 2 * radius**2 * t0 + 2 * a * b * (np.pi / 2 - np.arctan(a / b * np.tan(t0)))
            assert ellipse_disk_area(a, b, 0.0, 0.0, radius) == pytest.approx(exact, rel=1e-13)
            assert ellipse_disk_area(b, a, 0.0, 0.0, radius) == pytest.approx(exact, rel=1e-13)


def _cases(d, n, seed):
    """Semiaxes with aspect ratios up to 3 and balls all around: wholly outside, crossing, holding
    the particle, inside it."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        a = rng.uniform(0.4, 1.2, d)
        a[rng.integers(d)] = a.min() * rng.uniform(1.0, 3.0)
        b = rng.standard_normal(d) * rng.uniform(0.0, 1.5)
        r = [rng.uniform(0.05, 0.3) * a.min(), rng.uniform(0.2, 2.5), 3.5][k % 3] if k % 5 else 0.2 * a.min()
        if k % 5 == 0:
            b = b / max(1.0, np.sqrt(np.sum((b / a) ** 2))) * 0.5  # the ball inside the particle
        out.append((a, b, r))
    return out


def _monte_carlo(a, b, r, m, rng):
    d = len(a)
    y = rng.standard_normal((m, d))
    y *= (rng.random(m) ** (1 / d) / np.linalg.norm(y, axis=1))[:, None]
    hit = np.sum((y * a - b) ** 2, axis=1) <= r * r
    vol = np.prod(a) * (np.pi if d == 2 else 4 * np.pi / 3)
    frac = hit.mean()
    return vol * frac, vol * np.sqrt(max(frac * (1 - frac), 1.0 / m) / m)


@pytest.mark.parametrize("d", [3, 2])
def test_random_cases_agree_with_monte_carlo(d):
    rng = np.random.default_rng(7)
    for a, b, r in _cases(d, 15, seed=d):
        est, se = _monte_carlo(a, b, r, 1_000_000, rng)
        assert abs(_volume(a, b, r) - est) <= 4 * se


@pytest.mark.parametrize("d", [2, 3])
def test_centres_on_the_axes_agree_with_monte_carlo_and_their_neighbours(d):
    # a ball centre with exactly zero components in the particle's frame (on an axis or a plane of
    # symmetry) is an ordinary valid case (a jammed container packing produced one); it must give
    # the Monte Carlo volume and the volume of a centre 1e-7 away
    rng = np.random.default_rng(11)
    a = np.array([1.0, 2.0, 1.5][:d])
    for b in ([0.3, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.4], [0.2, 0.0, 0.3], [0.0, 0.0, 0.0]):
        b = np.array(b[:d])
        for r in (0.6, 1.3, 1.9):
            v = _volume(a, b, r)
            est, se = _monte_carlo(a, b, r, 1_000_000, rng)
            assert abs(v - est) <= 4 * se
            assert v == pytest.approx(_volume(a, b + 1e-7, r), abs=1e-6 * np.prod(a))


def test_a_circle_touching_the_ellipse_at_an_arcs_midpoint():
    # the circle about (0.3, 0) of radius 1.3 touches the ellipse (1, 2) from inside at (-1, 0), the
    # midpoint of its arc between the crossings; the disk there is inside the ellipse
    rng = np.random.default_rng(12)
    for u, v, p, q in ((0.3, 0.0, 1.0, 2.0), (0.0, 0.3, 2.0, 1.0)):
        est, se = _monte_carlo(np.array([p, q]), np.array([u, v]), 1.3, 2_000_000, rng)
        assert abs(ellipse_disk_area(p, q, u, v, 1.3) - est) <= 4 * se
        assert ellipse_disk_area(p, q, u, v, 1.3) == pytest.approx(ellipse_disk_area(p, q, u + 1e-7, v + 1e-7, 1.3),
                                                                   abs=1e-6)


def test_against_an_independent_polar_quadrature():
    """An independent deterministic integral: about the ball's centre the ray of direction u meets
    the ellipsoid for t in [t_-, t_+] (a quadratic), and V = int (clip(t_+)^3 - clip(t_-)^3) / 3
    over directions, clip to [0, r]; midpoint rule in (cos theta, phi) on 1200 x 2400 points (the
    integrand has kinks, so the rule converges as h^2: about 1e-6 of the volume)."""
    m = 1200
    mu = 1 - (np.arange(m) + 0.5) * 2 / m
    phi = (np.arange(2 * m) + 0.5) * np.pi / m
    s = np.sqrt(1 - mu * mu)[:, None]
    u = np.stack(np.broadcast_arrays(s * np.cos(phi), s * np.sin(phi), mu[:, None]), axis=-1)
    for a, b, r in (([1.5, 1.0, 0.5], [0.7, -0.3, 0.2], 0.9), ([0.6, 1.8, 0.9], [1.1, 0.8, -0.5], 1.4),
                    ([1.0, 1.0, 0.4], [0.2, 0.1, 0.6], 0.5), ([1.2, 0.5, 0.8], [1.0, 0.9, 0.2], 0.8)):
        inv, b = 1.0 / np.asarray(a) ** 2, np.asarray(b, float)
        qa, qb, qc = (inv * u * u).sum(-1), (inv * u * b).sum(-1), np.sum(inv * b * b) - 1.0
        disc = np.maximum(qb * qb - qa * qc, 0.0)
        lo = np.clip((-qb - np.sqrt(disc)) / qa, 0.0, r)
        hi = np.clip((-qb + np.sqrt(disc)) / qa, 0.0, r)
        polar = np.sum(hi**3 - lo**3) / 3 * (2 / m) * (np.pi / m)
        assert _volume(a, b, r) == pytest.approx(polar, abs=3e-6 * np.prod(a))


def _surface_measure_inside(a, b, r, n):
    """Area (3D) or length (2D) of the sphere (circle) of radius r about b inside the particle,
    on a Fibonacci grid (3D) or a uniform grid of angles (2D) of n directions."""
    d = len(a)
    if d == 2:
        t = (np.arange(n) + 0.5) * 2 * np.pi / n
        u = np.stack([np.cos(t), np.sin(t)], axis=1)
        total = 2 * np.pi * r
    else:
        k = np.arange(n) + 0.5
        z = 1 - 2 * k / n
        phi = np.pi * (1 + 5**0.5) * k
        s = np.sqrt(1 - z * z)
        u = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
        total = 4 * np.pi * r * r
    inside = np.sum(((b + r * u) / a) ** 2, axis=1) <= 1.0
    return total * inside.mean()


@pytest.mark.parametrize("d", [3, 2])
def test_derivative_is_the_sphere_inside_and_the_limits(d):
    rng = np.random.default_rng(3)
    for a, b, _ in _cases(d, 3 if d == 3 else 6, seed=10 + d):
        # nearest and farthest distances from b to the particle on a fine surface grid
        m = 400_000
        y = rng.standard_normal((m, d))
        y /= np.linalg.norm(y, axis=1)[:, None]
        dist = np.linalg.norm(y * a - b, axis=1)
        inside = np.sum((b / a) ** 2) < 1
        near, far = (0.0 if inside else dist.min()), dist.max()
        vol = np.prod(a) * (np.pi if d == 2 else 4 * np.pi / 3)
        assert _volume(a, b, far * 1.001) == pytest.approx(vol, rel=1e-10)
        if not inside:
            assert _volume(a, b, near * 0.999) == 0.0
            assert _volume(a, b, near * 1.01) > 0.0
        for r in np.linspace(near, far, 7)[1:-1]:
            h = 1e-4 * r
            slope = (_volume(a, b, r + h) - _volume(a, b, r - h)) / (2 * h)
            measure = _surface_measure_inside(a, b, r, 4_000_000 if d == 3 else 1_000_000)
            assert slope == pytest.approx(measure, rel=3e-4, abs=1e-5)
