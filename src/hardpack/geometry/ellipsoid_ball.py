"""Exact volume of the intersection of an ellipsoid (d = 3) or ellipse (d = 2) with a ball (disk).

Body frame of the particle: the ellipsoid is sum_k x_k^2 / a_k^2 <= 1, the ball |x - b| <= r.

**2D, closed form.** The area of the convex set K = ellipse ∩ disk is (1/2) of the contour
integral of x dy - y dx along its boundary, made of ellipse arcs inside the disk and circle arcs
inside the ellipse, both integrated in closed form: an ellipse arc (p cos t, q sin t), t in
[t_0, t_1], gives p q (t_1 - t_0) / 2, a circle arc (u + R cos f, v + R sin f) gives
(R^2 (f_1 - f_0) + u R (sin f_1 - sin f_0) - v R (cos f_1 - cos f_0)) / 2. The arcs end at the
points where the circle crosses the ellipse, the roots of F(t) = |P(t) - c|^2 - R^2 on the ellipse.
F is monotone between consecutive stationary points of the distance from c to the ellipse (the feet
of the normals from c, at most 4), so every root is bracketed and found by bisection to round-off.
The stationary points are x_k = a_k^2 c_k / (a_k^2 - mu) with sum_k a_k^2 c_k^2 / (a_k^2 - mu)^2 = 1
(Lagrange): with a_1 < a_2 one root mu < a_1^2, one mu > a_2^2 and, in between, where the secular
function is convex with its minimum (w_1^(1/3) + w_2^(1/3))^3 / (a_2^2 - a_1^2)^2 at a closed-form
point (w_k = a_k^2 c_k^2), none or two. Each root is found by bisection in the distance from its
pole, so that the point keeps its relative precision; a zero component of c is replaced by 1e-30
times the ellipse size (an exact symmetric centre has infinitely many normals otherwise), which moves
nothing measurable. Equal semiaxes (a circle) take the disk-disk lens.

**3D, slices.** V = int A(z) dz over the slices n.x = z, n the unit vector from b to its nearest
point on the ellipsoid (near-tangent contacts then sit at the ends of the range). A slice of the
ellipsoid is the ellipse y^T X_P y <= 1 - z^2 / h^2 (X_P = diag(a^-2) restricted to the plane,
h^2 = n^T diag(a^2) n) centred at z diag(a^2) n / h^2; the slice of the ball is the disk of radius
(r^2 - (z - n.b)^2)^(1/2) about the projection of b; A(z) is their exact 2D area. The range of z is
the exact extent of the convex body K = E ∩ B along n: min n.x over K equals max_t D(t) (Lagrange
duality of this convex problem with two quadratic constraints), D(t) the minimum of n.x over the
ellipsoid (1 - t) g_E(x) + t g_B(x) <= 0 (closed form: its matrix (1 - t) diag(a^-2) + t I is
diagonal); D is quasi-concave (its superlevel sets are the angles of rays meeting a convex set),
so golden section finds the maximum, and every D(t) is a lower bound (weak duality). On that range
A(z) is continuous (sqrt A is concave, Brunn-Minkowski) and smooth except where the configuration
of the slice changes (the circle tangent to the ellipse, or, for coaxial circles, crossing it all
at once): the configuration (disjoint, one inside the other, or the number of crossings) is
sampled at SAMPLES points of the range and every change located by bisection; each piece is
integrated by adaptive Gauss-Kronrod (7-15 points) after the substitution
z = z_0 + (z_1 - z_0)(1 - cos pi t) / 2, which makes the end behaviour polynomial, an interval
accepted when |K15 - G7| <= tol V_E times its share of the range.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hardpack.geometry.ellipsoid_container import body_offset, farthest_point_body

#: relative size of the stand-in for an exactly zero component of the disk centre (module docstring)
TINY = 1e-30
#: points of the range of slices where their configuration is sampled (3D)
SAMPLES = 16
#: default accuracy of the 3D volume, relative to the ellipsoid's volume
TOLERANCE = 1e-10

_XGK = np.array([0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                 0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                 0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                 0.207784955007898467600689403773245, 0.000000000000000000000000000000000])
_WGK = np.array([0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                 0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                 0.204432940075298892414161999234649, 0.209482141084727828012999174891714])
_WG = np.array([0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                0.381830050505118944950369775488975, 0.417959183673469387755102040816327])


@njit(cache=True)
def lens_area(r1, r2, s):
    """Area of the intersection of two disks of radii r1, r2 with centres s apart.

    Parameters
    ----------
    r1, r2 : float
        Disk radii.
    s : float
        Distance of the centres.

    Returns
    -------
    float
        The lens area (0 if they do not meet, pi min(r1, r2)^2 if one holds the other).
    """
    if r1 <= 0.0 or r2 <= 0.0 or s >= r1 + r2:
        return 0.0
    lo, hi = min(r1, r2), max(r1, r2)
    if s <= hi - lo:
        return np.pi * lo * lo
    c1 = min(1.0, max(-1.0, (s * s + r1 * r1 - r2 * r2) / (2.0 * s * r1)))
    c2 = min(1.0, max(-1.0, (s * s + r2 * r2 - r1 * r1) / (2.0 * s * r2)))
    t1, t2 = np.arccos(c1), np.arccos(c2)
    return r1 * r1 * (t1 - np.sin(2.0 * t1) / 2.0) + r2 * r2 * (t2 - np.sin(2.0 * t2) / 2.0)


@njit(cache=True)
def _secular_root(w_near, w_far, gap, sign, lo, hi):
    """u in [lo, hi] (lo > 0) with h(u) = w_near / u^2 + w_far / (gap + sign u)^2 = 1, h decreasing
    on the bracket: Newton on h^(-1/2) - 1 (nearly linear) kept in the bracket by geometric
    bisection, which keeps the relative precision of u.

    When the far weight is negligible (a centre on an axis, its zero component replaced by TINY)
    the bracket's end next to the far pole rounds onto the pole itself, gap + sign u = 0, where h
    is infinite in floating point although it is below 1 at the true end: that end is moved
    inside by a bisection step."""
    u = hi
    for _ in range(200):
        den = gap + sign * u
        if den == 0.0:
            hi = u
            u = np.sqrt(lo * hi)
            continue
        h = w_near / (u * u) + w_far / (den * den)
        dh = -2.0 * w_near / (u * u * u) - 2.0 * sign * w_far / (den * den * den)
        if h > 1.0:
            lo = u
        elif h < 1.0:
            hi = u
        else:
            return u
        if dh >= 0.0:  # at the bracket's end by the minimum of h
            nu = np.sqrt(lo * hi)
        else:
            nu = u - (1.0 / np.sqrt(h) - 1.0) / (-0.5 * dh / (h * np.sqrt(h)))
            if abs(nu - u) <= 1e-11 * u:  # quadratic convergence: the next step is below round-off
                return min(max(nu, lo), hi)
        if not (lo < nu < hi):
            nu = np.sqrt(lo * hi)
        if hi - lo <= 1e-15 * hi:
            return nu
        u = nu
    return u


@njit(cache=True)
def _stationary_angles(p, q, u, v, out):
    """Parameter angles t of the stationary points of |P(t) - (u, v)| on the ellipse
    P(t) = (p cos t, q sin t), p != q, into ``out``; returns their number (2 or 4)."""
    size = max(p, q)
    if abs(u) < TINY * size:
        u = TINY * size
    if abs(v) < TINY * size:
        v = TINY * size
    # alpha: the shorter axis
    if p < q:
        al, be, ca, cb, first = p * p, q * q, u, v, True
    else:
        al, be, ca, cb, first = q * q, p * p, v, u, False
    wa, wb = al * ca * ca, be * cb * cb
    gap = be - al
    n = 0
    xa = np.empty(4)
    xb = np.empty(4)
    # mu < alpha^2: u = alpha^2 - mu
    t = _secular_root(wa, wb, gap, 1.0, np.sqrt(wa), np.sqrt(wa + wb))
    xa[n], xb[n] = al * ca / t, be * cb / (gap + t)
    n += 1
    # mu > beta^2: u = mu - beta^2
    t = _secular_root(wb, wa, gap, 1.0, np.sqrt(wb), np.sqrt(wa + wb))
    xa[n], xb[n] = -al * ca / (gap + t), -be * cb / t
    n += 1
    # alpha^2 < mu < beta^2: u = mu - alpha^2 in (0, gap), convex with a closed-form minimum
    ra, rb = np.cbrt(wa), np.cbrt(wb)
    if (ra + rb) ** 3 < gap * gap:
        ustar = gap * ra / (ra + rb)
        vstar = gap * rb / (ra + rb)  # gap - ustar without the cancellation (ustar ~ gap on an axis)
        t = _secular_root(wa, wb, gap, -1.0, min(np.sqrt(wa), ustar), ustar)
        xa[n], xb[n] = -al * ca / t, be * cb / (gap - t)
        n += 1
        t = _secular_root(wb, wa, gap, -1.0, min(np.sqrt(wb), vstar), vstar)
        xa[n], xb[n] = -al * ca / (gap - t), be * cb / t
        n += 1
    for k in range(n):
        x, y = (xa[k], xb[k]) if first else (xb[k], xa[k])
        out[k] = np.arctan2(y / q, x / p)
    return n


@njit(cache=True, inline="always")
def _excess(t, p, q, u, v, r2):
    """|P(t) - c|^2 - R^2: negative inside the disk."""
    x = p * np.cos(t) - u
    y = q * np.sin(t) - v
    return x * x + y * y - r2


@njit(cache=True, inline="always")
def _decisive(e1, e2):
    """Of the signed excesses of an arc's points at its thirds, the one farther from zero: it
    says whether the arc is inside the other curve (one of the two could be a point where the
    circle touches the ellipse, where the excess is zero)."""
    return e1 if abs(e1) >= abs(e2) else e2


@njit(cache=True)
def ellipse_disk_area(p, q, u, v, r):
    """Area of the ellipse x^2 / p^2 + y^2 / q^2 <= 1 intersected with the disk of radius r about
    (u, v), in closed form to round-off (module docstring).

    Parameters
    ----------
    p, q : float
        Semiaxes of the ellipse along x and y.
    u, v : float
        Disk centre.
    r : float
        Disk radius.

    Returns
    -------
    float
        The area of the intersection.
    """
    return _ellipse_disk(p, q, u, v, r)[0]


@njit(cache=True)
def _ellipse_disk(p, q, u, v, r):
    """The area of :func:`ellipse_disk_area` and the configuration: 0 disjoint, 1 the ellipse in the
    disk, 2 the disk in the ellipse, 10 + n when the circle crosses the ellipse at n points."""
    if r <= 0.0 or p <= 0.0 or q <= 0.0:
        return 0.0, 0
    if abs(p - q) <= 1e-14 * max(p, q):
        rad, dist = np.sqrt(p * q), np.hypot(u, v)
        state = 0 if dist >= rad + r else (12 if dist > abs(rad - r) else (1 if rad <= r else 2))
        return lens_area(rad, r, dist), state
    r2 = r * r
    stat = np.empty(4)
    ns = _stationary_angles(p, q, u, v, stat)
    stat[:ns] = np.sort(stat[:ns])
    roots = np.empty(4)
    nr = 0
    for k in range(ns):
        lo = stat[k]
        hi = stat[k + 1] if k + 1 < ns else stat[0] + 2.0 * np.pi
        flo = _excess(lo, p, q, u, v, r2)
        fhi = _excess(hi, p, q, u, v, r2)
        if (flo < 0.0) == (fhi < 0.0):
            continue
        t = 0.5 * (lo + hi)
        rising = flo < 0.0
        for _ in range(100):  # Newton kept in the bracket by bisection; F is monotone on it
            x, y = p * np.cos(t), q * np.sin(t)
            f = (x - u) ** 2 + (y - v) ** 2 - r2
            if (f < 0.0) == rising:
                lo = t
            else:
                hi = t
            df = 2.0 * (-y * p / q * (x - u) + x * q / p * (y - v))
            nt = t - f / df if df != 0.0 else 0.5 * (lo + hi)
            if abs(nt - t) <= 1e-11 * (1.0 + abs(t)):  # the next step is below round-off
                t = min(max(nt, lo), hi)
                break
            if not (lo < nt < hi):
                nt = 0.5 * (lo + hi)
            t = nt
            if hi - lo <= 1e-15 * (1.0 + abs(t)):
                break
        if nr < 4:
            roots[nr] = t
            nr += 1
    if nr < 2:
        if _excess(0.0, p, q, u, v, r2) <= 0.0:  # a point of the ellipse in the disk: the ellipse inside
            return np.pi * p * q, 1
        x, y = (u + r) / p, v / q
        if x * x + y * y <= 1.0:  # a point of the circle in the ellipse: the disk inside
            return np.pi * r2, 2
        return 0.0, 0
    for k in range(nr):
        roots[k] = roots[k] % (2.0 * np.pi)
    roots[:nr] = np.sort(roots[:nr])
    area = 0.0
    phi = np.empty(4)
    for k in range(nr):
        t0 = roots[k]
        t1 = roots[k + 1] if k + 1 < nr else roots[0] + 2.0 * np.pi
        e1 = _excess(t0 + (t1 - t0) / 3.0, p, q, u, v, r2)
        e2 = _excess(t0 + 2.0 * (t1 - t0) / 3.0, p, q, u, v, r2)
        if _decisive(e1, e2) < 0.0:
            area += 0.5 * p * q * (t1 - t0)
        phi[k] = np.arctan2(q * np.sin(t0) - v, p * np.cos(t0) - u)
    phi[:nr] = np.sort(phi[:nr])
    for k in range(nr):
        f0 = phi[k]
        f1 = phi[k + 1] if k + 1 < nr else phi[0] + 2.0 * np.pi
        g1, g2 = f0 + (f1 - f0) / 3.0, f0 + 2.0 * (f1 - f0) / 3.0
        x, y = (u + r * np.cos(g1)) / p, (v + r * np.sin(g1)) / q
        e1 = x * x + y * y - 1.0
        x, y = (u + r * np.cos(g2)) / p, (v + r * np.sin(g2)) / q
        e2 = x * x + y * y - 1.0
        if _decisive(e1, e2) < 0.0:
            area += 0.5 * (r2 * (f1 - f0) + u * r * (np.sin(f1) - np.sin(f0)) - v * r * (np.cos(f1) - np.cos(f0)))
    return area, 10 + nr


@njit(cache=True)
def _dual_min(t, a, b, r, n):
    """D(t): the minimum of n.x over (1 - t) (x^T diag(a^-2) x - 1) + t (|x - b|^2 - r^2) <= 0
    (+inf when empty); a lower bound of min n.x over the ellipsoid ∩ ball (module docstring)."""
    rho2 = (1.0 - t) - t * (np.dot(b, b) - r * r)
    x0 = 0.0
    spread = 0.0
    for i in range(a.shape[0]):
        m = (1.0 - t) / (a[i] * a[i]) + t
        rho2 += t * t * b[i] * b[i] / m
        x0 += n[i] * t * b[i] / m
        spread += n[i] * n[i] / m
    if rho2 < 0.0:
        return np.inf
    return x0 - np.sqrt(rho2 * spread)


@njit(cache=True)
def intersection_extent(a, b, r, n):
    """min n.x over the ellipsoid sum x_i^2 / a_i^2 <= 1 intersected with the ball |x - b| <= r:
    the maximum over t in [0, 1] of the quasi-concave D(t), by golden section (module docstring);
    +inf (or a value above the ellipsoid's) when they do not meet.

    Parameters
    ----------
    a : numpy.ndarray of float, shape (d,)
        Semiaxes (body frame).
    b : numpy.ndarray of float, shape (d,)
        Ball centre (body frame).
    r : float
        Ball radius.
    n : numpy.ndarray of float, shape (d,)
        Unit direction.

    Returns
    -------
    float
        The lower end of the intersection along n.
    """
    g = 0.5 * (np.sqrt(5.0) - 1.0)
    lo, hi = 0.0, 1.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = _dual_min(x1, a, b, r, n), _dual_min(x2, a, b, r, n)
    best = max(_dual_min(0.0, a, b, r, n), _dual_min(1.0, a, b, r, n))
    for _ in range(90):
        if f1 < f2:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = _dual_min(x2, a, b, r, n)
        else:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = _dual_min(x1, a, b, r, n)
    return max(best, f1, f2)


@njit(cache=True)
def nearest_direction(a, b):
    """Unit vector from b to its nearest point on the ellipsoid's surface (body frame): the root
    mu < a_min^2 of sum_k a_k^2 b_k^2 / (a_k^2 - mu)^2 = 1 (Eberly 2011, "Distance from a point to
    an ellipse, an ellipsoid, or a hyperellipsoid", Sec. 3), x_k = a_k^2 b_k / (a_k^2 - mu), by
    geometric bisection in u = a_min^2 - mu; zero components of b as in :func:`_stationary_angles`.

    Parameters
    ----------
    a : numpy.ndarray of float, shape (d,)
        Semiaxes (body frame).
    b : numpy.ndarray of float, shape (d,)
        A point (body frame).

    Returns
    -------
    numpy.ndarray of float, shape (d,)
        The unit vector.
    """
    d = a.shape[0]
    size = a.max()
    a2min = a.min() ** 2
    bb = b.copy()
    w = np.empty(d)
    wsum = 0.0
    wmin = 0.0
    for k in range(d):
        if abs(bb[k]) < TINY * size:
            bb[k] = TINY * size
        w[k] = a[k] * a[k] * bb[k] * bb[k]
        wsum += w[k]
        if a[k] * a[k] == a2min:
            wmin += w[k]
    lo, hi = np.sqrt(wmin), np.sqrt(wsum)
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        h = 0.0
        for k in range(d):
            den = a[k] * a[k] - a2min + mid
            h += w[k] / (den * den)
        if h > 1.0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    u = np.sqrt(lo * hi)
    n = np.empty(d)
    norm = 0.0
    for k in range(d):
        n[k] = a[k] * a[k] * bb[k] / (a[k] * a[k] - a2min + u) - b[k]
        norm += n[k] * n[k]
    if norm == 0.0:  # b on the surface: the outward normal
        for k in range(d):
            n[k] = b[k] / (a[k] * a[k])
            norm += n[k] * n[k]
    return n / np.sqrt(norm)


@njit(cache=True)
def _slice_area(z, geo):
    """Area of the slice n.x = z of the ellipsoid ∩ ball; ``geo`` (module docstring): h^2, p0, q0,
    the in-plane shift of the ellipse's centre per unit z (2, principal frame), the ball's in-plane
    centre (2, principal frame), n.b, r."""
    h2, p0, q0, sx, sy, bx, by, nb, r = geo[0], geo[1], geo[2], geo[3], geo[4], geo[5], geo[6], geo[7], geo[8]
    w = 1.0 - z * z / h2
    dz = z - nb
    rr = r * r - dz * dz
    if w <= 0.0 or rr <= 0.0:
        return 0.0, 0
    sw = np.sqrt(w)
    return _ellipse_disk(p0 * sw, q0 * sw, bx - z * sx, by - z * sy, np.sqrt(rr))


@njit(cache=True, inline="always")
def _z_of(s, zlo, span):
    return zlo + span * 0.5 * (1.0 - np.cos(np.pi * s))


@njit(cache=True, inline="always")
def _integrand(t, sa, sb, zlo, span, geo):
    """A(z) dz/dt: z(s) maps [0, 1] to the range, s(t) = sa + (sb - sa)(1 - cos pi t) / 2 a piece."""
    s = sa + (sb - sa) * 0.5 * (1.0 - np.cos(np.pi * t))
    ds = (sb - sa) * 0.5 * np.pi * np.sin(np.pi * t)
    return _slice_area(_z_of(s, zlo, span), geo)[0] * span * 0.5 * np.pi * np.sin(np.pi * s) * ds


@njit(cache=True)
def _gk15(t0, t1, sa, sb, zlo, span, geo):
    """Kronrod and Gauss estimates of the integral over [t0, t1] of a piece [sa, sb]."""
    c, h = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    fc = _integrand(c, sa, sb, zlo, span, geo)
    kron = _WGK[7] * fc
    gauss = _WG[3] * fc
    for m in range(7):
        f = (_integrand(c - h * _XGK[m], sa, sb, zlo, span, geo)
             + _integrand(c + h * _XGK[m], sa, sb, zlo, span, geo))
        kron += _WGK[m] * f
        if m % 2 == 1:
            gauss += _WG[m // 2] * f
    return kron * h, gauss * h


@njit(cache=True)
def _piece(sa, sb, zlo, span, geo, budget):
    """Adaptive Gauss-Kronrod over one piece, each interval accepted at its share of the budget."""
    stack = np.empty((256, 2))
    stack[0, 0], stack[0, 1] = 0.0, 1.0
    top = 1
    total = 0.0
    while top > 0:
        top -= 1
        t0, t1 = stack[top, 0], stack[top, 1]
        kron, gauss = _gk15(t0, t1, sa, sb, zlo, span, geo)
        if abs(kron - gauss) <= budget * (t1 - t0) or t1 - t0 < 1e-12 or top >= 254:
            total += kron
        else:
            mid = 0.5 * (t0 + t1)
            stack[top, 0], stack[top, 1] = t0, mid
            stack[top + 1, 0], stack[top + 1, 1] = mid, t1
            top += 2
    return total


@njit(cache=True)
def _slice_geometry(a, b, r, n):
    """The constants of :func:`_slice_area` for slices normal to the unit vector n."""
    # an orthonormal basis e1, e2 of the plane normal to n
    k = np.argmin(np.abs(n))
    e1 = np.zeros(3)
    e1[k] = 1.0
    e1 -= np.dot(e1, n) * n
    e1 /= np.sqrt(np.dot(e1, e1))
    e2 = np.cross(n, e1)
    inv = 1.0 / (a * a)
    pxx, pyy, pxy = np.sum(inv * e1 * e1), np.sum(inv * e2 * e2), np.sum(inv * e1 * e2)
    # eigenvectors of the in-plane matrix [[pxx, pxy], [pxy, pyy]]
    ang = 0.5 * np.arctan2(2.0 * pxy, pxx - pyy)
    c, s = np.cos(ang), np.sin(ang)
    f1 = c * e1 + s * e2
    f2 = -s * e1 + c * e2
    m1, m2 = np.sum(inv * f1 * f1), np.sum(inv * f2 * f2)
    h2 = np.sum(a * a * n * n)
    shift = a * a * n / h2 - n  # in-plane shift of the ellipse's centre per unit z
    geo = np.empty(9)
    geo[0], geo[1], geo[2] = h2, 1.0 / np.sqrt(m1), 1.0 / np.sqrt(m2)
    geo[3], geo[4] = np.dot(shift, f1), np.dot(shift, f2)
    geo[5], geo[6] = np.dot(b, f1), np.dot(b, f2)
    geo[7], geo[8] = np.dot(b, n), r
    return geo


@njit(cache=True)
def ellipsoid_ball_volume(a, b, r, tol):
    """Volume of the ellipsoid sum x_i^2 / a_i^2 <= 1 (d = 3; the area of the ellipse, d = 2)
    intersected with the ball |x - b| <= r, to ``tol`` times the particle's volume in 3D and to
    round-off in 2D (module docstring). ``a``, ``b``: body frame, length d.

    Parameters
    ----------
    a : numpy.ndarray of float, shape (d,)
        Semiaxes (body frame), d = 2 or 3.
    b : numpy.ndarray of float, shape (d,)
        Ball centre relative to the particle centre (body frame).
    r : float
        Ball radius.
    tol : float
        Relative tolerance of the 3D quadrature.

    Returns
    -------
    float
        The volume (area in 2D) of the intersection.
    """
    d = a.shape[0]
    if r <= 0.0:
        return 0.0
    if d == 2:
        return ellipse_disk_area(a[0], a[1], b[0], b[1], r)
    n = nearest_direction(a, b)
    zlo = intersection_extent(a, b, r, n)
    zhi = -intersection_extent(a, b, r, -n)
    h = np.sqrt(np.sum(a * a * n * n))
    nb = np.dot(n, b)
    zlo, zhi = max(zlo, -h, nb - r), min(zhi, h, nb + r)
    if not zlo < zhi:
        return 0.0
    geo = _slice_geometry(a, b, r, n)
    span = zhi - zlo
    budget = tol * 4.0 / 3.0 * np.pi * a[0] * a[1] * a[2]
    # the pieces: between the changes of the slice's configuration seen on SAMPLES points, located
    # by bisection to round-off
    breaks = np.empty(4 * SAMPLES + 2)
    nb_ = 1
    breaks[0] = 0.0
    prev = _slice_area(_z_of(0.0, zlo, span), geo)[1]
    for k in range(1, SAMPLES + 1):
        s1 = k / SAMPLES
        end = _slice_area(_z_of(s1, zlo, span), geo)[1]
        lo, state = (k - 1) / SAMPLES, prev
        for _ in range(4):
            if state == end:
                break
            hi = s1
            for _ in range(45):  # to 2^-45 of the sample spacing
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if _slice_area(_z_of(mid, zlo, span), geo)[1] == state:
                    lo = mid
                else:
                    hi = mid
            if nb_ < breaks.shape[0] - 1:
                breaks[nb_] = hi
                nb_ += 1
            lo, state = hi, _slice_area(_z_of(hi, zlo, span), geo)[1]
        prev = end
    breaks[nb_] = 1.0
    total = 0.0
    for k in range(nb_):
        if breaks[k + 1] > breaks[k]:
            total += _piece(breaks[k], breaks[k + 1], zlo, span, geo, budget * (breaks[k + 1] - breaks[k]))
    return total


@njit(cache=True)
def covered_volumes(positions, semiaxes, rotations, centre, radii, tol):
    """Sum over the particles of the volume of each inside the ball of every radius about
    ``centre`` (n_radii,), and the number of particle-radius pairs that needed the quadrature.

    ``rotations`` (N, d, d) lab to body. A particle lies wholly inside the ball when its farthest
    surface point from the centre does (:func:`farthest_point_body`), wholly outside when
    r <= |c| - a_max, and holds the ball when |c| + r <= a_min; the others are integrated.

    Parameters
    ----------
    positions : numpy.ndarray of float, shape (N, d)
        Particle centres.
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes.
    rotations : numpy.ndarray of float, shape (N, d, d)
        Lab-to-body rotations Q.
    centre : numpy.ndarray of float, shape (d,)
        Ball centre.
    radii : numpy.ndarray of float, shape (n_radii,)
        Ball radii.
    tol : float
        Relative tolerance of each quadrature (:func:`ellipsoid_ball_volume`).

    Returns
    -------
    volumes : numpy.ndarray of float, shape (n_radii,)
        Particle volume inside each ball.
    work : int
        Particle-radius pairs integrated.
    """
    n, d = positions.shape
    out = np.zeros(radii.shape[0])
    rel = np.empty(d)
    ball = np.empty(d)
    x = np.empty(d)
    work = 0
    for p in range(n):
        a = semiaxes[p]
        body_offset(rotations, p, positions, centre, rel)
        for m in range(d):
            ball[m] = -rel[m]
        dist = np.sqrt(np.dot(rel, rel))
        far = np.sqrt(farthest_point_body(rel, a, x))
        vol = np.pi * a[0] * a[1] if d == 2 else 4.0 / 3.0 * np.pi * a[0] * a[1] * a[2]
        amax, amin = a.max(), a.min()
        for q in range(radii.shape[0]):
            r = radii[q]
            if r >= far:
                out[q] += vol
            elif r <= dist - amax or r <= 0.0:
                continue
            elif dist + r <= amin:
                out[q] += np.pi * r * r if d == 2 else 4.0 / 3.0 * np.pi * r ** 3
            else:
                out[q] += ellipsoid_ball_volume(a, ball, r, tol)
                work += 1
    return out, work
