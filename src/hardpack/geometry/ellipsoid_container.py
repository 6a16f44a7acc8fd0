"""An ellipsoid (d = 3) or ellipse (d = 2) inside a spherical container: the farthest point.

Donev 2006 (dissertation, Ch. 7 and Sec. 2.2.2) puts ellipsoids in a spherical container with the
"ellipsoid inside a larger ellipsoid" potential; here the container is a sphere, and the exact gap
is a one-dimensional problem (derived here). With the container centre at the origin, the particle
centre at c and the body-frame semiaxes a_k (rotation Q, lab to body), the body-frame centre is
b = Q c and a surface point is c + Q^T z with sum_k z_k^2 / a_k^2 = 1. The container of radius R
holds the particle iff rho = max_z |b + z| <= R, and the gap is h = R - rho.

**Secular equation.** Maximising |b + z|^2 over the ellipsoid z^T A^-1 z <= 1 (A = diag a_k^2) is a
trust-region problem, for which the Lagrange (S-lemma) dual is exact:

    rho^2 = min_{mu >= a_max^2} phi(mu),  phi(mu) = mu + |b|^2 + sum_k a_k^2 b_k^2 / (mu - a_k^2),

phi is convex with phi'(mu) = 1 - g(mu), g(mu) = sum_k a_k^2 b_k^2 / (mu - a_k^2)^2 (decreasing
on mu > a_max^2). If g(mu) = 1 has a root mu* > a_max^2 (always, unless b has no component along
the longest semiaxes), rho^2 = phi(mu*) and the farthest point is z_k = a_k^2 b_k / (mu* - a_k^2),
x = b + z with x_k = mu* b_k / (mu* - a_k^2). The root is bracketed in
[max(a_max^2, a_min^2 + s), a_max^2 + s] with s = sqrt(sum_k a_k^2 b_k^2) (bounding the
denominators by a_min^2 and a_max^2), and found by Newton on 1/sqrt(g) - 1 (exactly linear for a
sphere) kept inside the bracket by bisection. Otherwise (the "hard case": the centre lies in the
plane normal to the longest axis, e.g. c at the centre, or a spheroid's centre on the container's
radius through its equator) mu* = a_max^2: the other components are as above and the longest-axis
component takes the rest of the constraint, z_max^2 = a_max^2 (1 - sum_{k not max} z_k^2 / a_k^2).
Every mu >= a_max^2 gives phi(mu) >= rho^2 (weak duality), so round-off in mu* only makes the gap a
little smaller (safe), and the value is stationary in mu (second-order error).

Exact cases: a sphere of radius r has rho = |c| + r; an ellipsoid centred in the container has
rho = a_max.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Newton iterations of the secular equation (it converges in a handful)
MAX_ITER = 100



@njit(cache=True, inline="always")
def body_offset(rotations, i, positions, centre, out):
    """out = Q_i (x_i - c): the centre of particle i relative to ``centre`` in its body frame.

    Parameters
    ----------
    rotations : numpy.ndarray of float, shape (N, d, d)
        Lab-to-body rotations Q.
    i : int
        The particle.
    positions : numpy.ndarray of float, shape (N, d)
        Particle centres.
    centre : numpy.ndarray of float, shape (d,)
        Container centre.
    out : numpy.ndarray of float, shape (d,)
        Receives Q_i (x_i - c).

    Returns
    -------
    None
    """
    d = out.shape[0]
    for k in range(d):
        s = 0.0
        for m in range(d):
            s += rotations[i, k, m] * (positions[i, m] - centre[m])
        out[k] = s


@njit(cache=True, inline="always")
def lab_point(rotations, i, x, centre, out, row):
    """out[row] = c + Q_i^T x: a point x given in particle i's body frame relative to ``centre``,
    in the lab frame.

    Parameters
    ----------
    rotations, i, centre
        As in :func:`body_offset`.
    x : numpy.ndarray of float, shape (d,)
        The point, body frame, relative to the container centre.
    out : numpy.ndarray of float, shape (M, d)
        Receives the lab-frame point in row ``row``.
    row : int
        The row of ``out``.

    Returns
    -------
    None
    """
    d = x.shape[0]
    for m in range(d):
        s = centre[m]
        for k in range(d):
            s += rotations[i, k, m] * x[k]
        out[row, m] = s

@njit(cache=True, inline="always")
def _hard_case_g(b, a, a2max):
    """The secular function at mu = a_max^2 over the shorter axes, sum (a_k b_k / (a_max^2 - a_k^2))^2
    (module docstring): the hard case, no component along the longest axes, holds when it is <= 1."""
    g = 0.0
    for k in range(b.shape[0]):
        a2 = a[k] * a[k]
        if a2 < a2max:
            q = a[k] * b[k] / (a2max - a2)
            g += q * q
    return g


@njit(cache=True)
def farthest_point_body(b, a, x):
    """rho^2 = max |b + z|^2 over the body-frame ellipsoid sum z_k^2 / a_k^2 <= 1, and the farthest
    point x = b + z (body frame, into ``x``) (module docstring). ``b``, ``a``, ``x``: length d.

    Parameters
    ----------
    b : numpy.ndarray of float, shape (d,)
        Particle centre relative to the container centre (body frame).
    a : numpy.ndarray of float, shape (d,)
        Semiaxes.
    x : numpy.ndarray of float, shape (d,)
        Receives the farthest point.

    Returns
    -------
    float
        rho^2.
    """
    d = b.shape[0]
    a2max = 0.0
    a2min = np.inf
    for k in range(d):
        a2 = a[k] * a[k]
        a2max = max(a2max, a2)
        a2min = min(a2min, a2)
    w = 0.0  # sum a_k^2 b_k^2
    wmax = 0.0  # the part along the longest semiaxes
    for k in range(d):
        a2 = a[k] * a[k]
        t = a2 * b[k] * b[k]
        w += t
        if a2 == a2max:
            wmax += t
    # hard case: no component along the longest axes and g(a_max^2) <= 1
    if wmax == 0.0:
        g = _hard_case_g(b, a, a2max)
        if g <= 1.0:
            rest = a2max * (1.0 - g)
            first = True
            rho2 = 0.0
            for k in range(d):
                a2 = a[k] * a[k]
                if a2 < a2max:
                    x[k] = a2max * b[k] / (a2max - a2)
                elif first:
                    x[k] = np.sqrt(rest)
                    first = False
                else:
                    x[k] = 0.0
                rho2 += x[k] * x[k]
            return rho2
    # the unknown is u = mu - a_max^2 > 0, so that the denominators mu - a_k^2 = u + (a_max^2 - a_k^2)
    # carry no cancellation when mu* is close to a_max^2 (a small component along the longest axis)
    s = np.sqrt(w)
    lo = max(0.0, a2min + s - a2max)
    hi = s
    u = hi
    tiny = np.finfo(np.float64).eps
    for _ in range(MAX_ITER):
        g = 0.0
        dg = 0.0
        for k in range(d):
            a2 = a[k] * a[k]
            den = u + (a2max - a2)
            if den <= 0.0:
                g = np.inf
                break
            q = a2 * b[k] * b[k] / (den * den)
            g += q
            dg -= 2.0 * q / den
        if g > 1.0:
            lo = u
        elif g < 1.0:
            hi = u
        else:
            break
        if g < np.inf:  # Newton on F = g^-1/2 - 1, F' = -g^-3/2 dg / 2 > 0
            f = 1.0 / np.sqrt(g) - 1.0
            fp = -0.5 * dg / (g * np.sqrt(g))
            nu = u - f / fp if fp > 0.0 else 0.5 * (lo + hi)
            if not (lo < nu < hi):
                nu = 0.5 * (lo + hi)
        else:
            nu = 0.5 * (lo + hi)
        done = abs(nu - u) <= 4.0 * tiny * u or hi - lo <= 4.0 * tiny * hi
        u = nu
        if done:
            break
    u = max(u, lo)
    # phi(mu) >= rho^2 for every mu > a_max^2 (weak duality): the safe value
    mu = u + a2max
    phi = mu
    for k in range(d):
        a2 = a[k] * a[k]
        den = u + (a2max - a2)
        bb = b[k] * b[k]
        phi += bb + (a2 * bb / den if den > 0.0 else 0.0)
        x[k] = mu * b[k] / den if den > 0.0 else 0.0
    return phi


@njit(cache=True)
def farthest_points(positions, semiaxes, rotations, centre):
    """rho (N,) and the farthest surface points (N, d) (lab frame) of N ellipsoids from ``centre``
    (module docstring); ``rotations`` (N, d, d) lab to body (Q).

    Parameters
    ----------
    positions : numpy.ndarray of float, shape (N, d)
        Particle centres.
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes.
    rotations : numpy.ndarray of float, shape (N, d, d)
        Lab-to-body rotations Q.
    centre : numpy.ndarray of float, shape (d,)
        Container centre.

    Returns
    -------
    rho : numpy.ndarray of float, shape (N,)
        Largest distance of each particle's surface from the centre.
    points : numpy.ndarray of float, shape (N, d)
        The farthest points (lab frame).
    """
    n, d = positions.shape
    rho = np.empty(n)
    pts = np.empty((n, d))
    b = np.empty(d)
    x = np.empty(d)
    for i in range(n):
        body_offset(rotations, i, positions, centre, b)
        rho[i] = np.sqrt(farthest_point_body(b, semiaxes[i], x))
        lab_point(rotations, i, x, centre, pts, i)
    return rho, pts


def container_gaps(positions, shape, centre, radius):
    """Gap h = R - rho of every ellipsoid to the wall of a spherical container (negative when it
    crosses the wall), and the farthest surface points (lab frame).

    Parameters
    ----------
    positions : numpy.ndarray, shape (N, d)
        Particle centres.
    shape : hardpack.geometry.shapes.Ellipsoids
        Semiaxes and orientations.
    centre : sequence of float, shape (d,)
        Container centre.
    radius : float
        Container radius R.

    Returns
    -------
    gap : numpy.ndarray, shape (N,)
    points : numpy.ndarray, shape (N, d)
    """
    rot = np.ascontiguousarray(shape.rotations(), dtype=float)
    rho, pts = farthest_points(np.ascontiguousarray(positions, dtype=float),
                               np.ascontiguousarray(shape.semiaxes, dtype=float), rot,
                               np.asarray(centre, dtype=float))
    return float(radius) - rho, pts


#: local maxima per particle returned by :func:`local_farthest_body` (at most two exist)
MAX_LOCAL = 2


@njit(cache=True)
def _secular(u, a, b, kd, a2d):
    """g at mu = a_d^2 - u (module docstring), with the longest-axis denominator written as -u."""
    g = 0.0
    for k in range(a.shape[0]):
        a2 = a[k] * a[k]
        den = -u if k == kd else (a2d - a2) - u
        g += a2 * b[k] * b[k] / (den * den)
    return g


@njit(cache=True)
def local_farthest_body(b, a, points):
    """Every strict local maximum of |b + z| over the body-frame ellipsoid surface
    sum z_k^2 / a_k^2 = 1: their number (0, 1 or 2; -1 when the maximum is attained on a
    continuum), the points x = b + z in ``points`` (MAX_LOCAL, d) (body frame, relative to the
    container centre).

    Derivation (the notation of the module docstring). Every stationary point of |b + z|^2 on the
    surface is x_k = mu b_k / (mu - a_k^2) with g(mu) = 1 (or a "hard case" point at mu = a_k^2).
    The Hessian of the Lagrangian on the tangent plane is diag(1 - mu / a_k^2); with
    D = diag(1 - mu / a_k^2) and normal m_k = b_k / (mu - a_k^2) it is negative definite on m^perp
    iff D < 0 (mu > a_max^2: the global maximum) or D has one positive entry and
    m^T D^-1 m = g'(mu) / 2 > 0 (Haynsworth inertia of the bordered matrix). So besides the global
    maximum there is at most one more, in mu in (a_2nd^2, a_max^2) (a_2nd the second longest
    semiaxis; none when it equals a_max), at the larger root of g = 1 there, where g' > 0. g is
    convex on that interval: its minimiser is found by bisection on g', and the root, at
    u = a_max^2 - mu in [sqrt(w_d), u_min] (w_d = a_max^2 b_d^2: g >= w_d / u^2), by geometric
    bisection in u, so that the longest-axis component -mu b_d / u keeps its relative precision.
    In the hard case (b_d = 0) the global maximum is the pair x_d = +-sqrt(rest): both returned
    (one when rest = 0). An ellipse or ellipsoid whose longest semiaxes are equal (a disk, a sphere,
    an oblate spheroid) and whose centre has no component along them has a circle or sphere of
    farthest points: -1.

    Exact case: a prolate spheroid centred in the container has the two tips x = +-a_max e_d.

    Parameters
    ----------
    b : numpy.ndarray of float, shape (d,)
        Particle centre relative to the container centre (body frame).
    a : numpy.ndarray of float, shape (d,)
        Semiaxes.
    points : numpy.ndarray of float, shape (MAX_LOCAL, d)
        Receives the local maxima.

    Returns
    -------
    int
        Their number (0, 1 or 2), or -1 for a continuum.
    """
    d = b.shape[0]
    kd = 0
    for k in range(d):
        if a[k] > a[kd]:
            kd = k
    a2d = a[kd] * a[kd]
    a2s = 0.0
    n_long = 0
    for k in range(d):
        a2 = a[k] * a[k]
        if a2 == a2d:
            n_long += 1
        elif a2 > a2s:
            a2s = a2
    x = np.empty(d)
    farthest_point_body(b, a, x)
    wd = 0.0
    for k in range(d):
        if a[k] * a[k] == a2d:
            wd += a2d * b[k] * b[k]
    hard = wd == 0.0 and _hard_case_g(b, a, a2d) <= 1.0
    for k in range(d):
        points[0, k] = x[k]
    if hard:
        if n_long > 1:
            return -1
        if x[kd] == 0.0:
            return 1
        for k in range(d):
            points[1, k] = x[k]
        points[1, kd] = -x[kd]
        return 2
    if n_long > 1 or d < 2:
        return 1
    # second local maximum: u = a_d^2 - mu in (0, a_d^2 - a_2nd^2)
    width = a2d - a2s
    lo, hi = 0.0, width
    for _ in range(200):  # minimiser of the convex g: g'(u) changes sign from - to +
        mid = 0.5 * (lo + hi)
        dg = 0.0  # d g / d u
        for k in range(d):
            a2 = a[k] * a[k]
            den = -mid if k == kd else (a2d - a2) - mid
            dg += 2.0 * a2 * b[k] * b[k] / (den * den * den)
        if dg < 0.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * width:
            break
    umin = 0.5 * (lo + hi)
    if _secular(umin, a, b, kd, a2d) >= 1.0:
        return 1
    lo, hi = min(np.sqrt(wd), umin), umin  # g(lo) >= 1 > g(hi): g decreases on (0, umin)
    for _ in range(400):
        mid = np.sqrt(lo * hi) if lo > 0.0 else 0.5 * hi
        if _secular(mid, a, b, kd, a2d) >= 1.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 2.0 * np.finfo(np.float64).eps * hi:
            break
    u = hi
    mu = a2d - u
    for k in range(d):
        a2 = a[k] * a[k]
        den = -u if k == kd else mu - a2
        points[1, k] = mu * b[k] / den
    return 2
