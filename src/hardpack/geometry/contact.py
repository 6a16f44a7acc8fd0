"""Contact function of two ellipsoids (d = 3) or ellipses (d = 2): the Perram-Wertheim overlap potential.

Conventions as in :mod:`hardpack.geometry.shapes`: a particle is (r - r0)^T X (r - r0) <= 1 with
X = Q^T O^-2 Q (Donev 2006, Sec. 2.2, Eqs. 2.7-2.8); a sphere of radius a is X = I / a^2. Every
function here works on the inverse shape matrix X^-1 = Q^T O^2 Q (:func:`shape_inverse`).

Perram-Wertheim potential (Donev 2006, Sec. 2.2.2.1, Eqs. 2.10-2.11). With r = r_B - r_A,
A = X_A^-1, B = X_B^-1 and Y(lam) = lam B + (1 - lam) A,

    f(lam) = lam (1 - lam) r^T Y^-1 r,     mu^2 = max_{0 <= lam <= 1} f(lam),    zeta = mu^2 - 1,

where mu is the common factor by which both particles must be scaled about their centres to be
externally tangent: zeta > 0 disjoint, = 0 tangent, < 0 overlapping. The printed Eq. 2.11 writes
zeta = f(Lambda); the "- 1" is needed for zeta to vanish at contact (spheres: Eq. 2.3,
zeta = |r|^2 / (a + b)^2 - 1, which the tests check). f is strictly concave on [0, 1] (Donev 2006,
Sec. 2.2.2.1) with f'(0) = r^T A^-1 r > 0 and f'(1) = -r^T B^-1 r < 0, so the maximiser Lambda is
the unique root of f' in (0, 1).

Derivatives used by the Newton iteration (derived here; Donev evaluates the maximiser instead as
the root of a degree-2d polynomial, Eq. 2.12). With n = Y^-1 r (the unnormalised contact normal
A -> B, Eq. 2.14), D = dY/dlam = B - A and dY^-1/dlam = -Y^-1 D Y^-1, so dn/dlam = -Y^-1 D n:

    f'(lam)  = (1 - 2 lam) r.n - lam (1 - lam) n^T D n,
    f''(lam) = -2 r.n - 2 (1 - 2 lam) n^T D n + 2 lam (1 - lam) (D n)^T Y^-1 (D n).

f'' < 0 by concavity (at the maximiser it equals Donev's zeta_lambda_lambda = -2 n^T Z n,
Z = [lam X_A + (1 - lam) X_B]^-1). The iteration is a safeguarded Newton method on f' over the
bracket [lo, hi] that holds the root (f'(lo) > 0 > f'(hi)): a Newton step that leaves the bracket,
or does not halve the previous step, is replaced by bisection, so it converges for every valid input.
It ends when the Newton step is below 4 machine epsilons of lam, or when a step below 1e-9 lam stops
shrinking (round-off in f' then sets the precision: a few to a hundred epsilons for aspect ratios
up to 10), or when bisection has narrowed the bracket to 4 epsilons of lam. Random pairs take about
7 iterations from lam0 = 1/2.

Time derivative (Donev 2006, Sec. 2.2.3, Eq. 2.21): d zeta/dt = 2 lam (1 - lam) n . v_C, where v_C
is the velocity of the contact point r_C (Eq. 2.13) as a point of B minus as a point of A. It
follows from the envelope theorem (d zeta/dt = partial f/partial t at fixed Lambda) with
dX^-1/dt = W X^-1 - X^-1 W + 2 g X^-1 for a particle spinning with angular velocity w (W v = w x v)
and growing uniformly at relative rate g (semiaxes O(t) = O (1 + g t)), together with
r_C - r_A = (1 - lam) A n and r_C - r_B = -lam B n.

All functions are numba-compiled on plain float64 arrays, for d = 2 and d = 3.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import types
from numba.extending import overload

__all__ = ["shape_inverse", "shape_inverse_into", "pw_contact", "pw_contact_into", "contact_point", "pw_rate",
           "inverse_shapes", "pair_potentials"]

_EPS = np.finfo(np.float64).eps
_NOISE = 1e-9  # relative Newton step below which a step that stops shrinking is round-off
MAX_ITERATIONS = 200


@numba.njit(cache=True)
def shape_inverse(semiaxes, orientation_row, out):
    """Inverse shape matrix X^-1 = Q^T O^2 Q of one ellipsoid or ellipse (Donev 2006, Eq. 2.8).

    Parameters
    ----------
    semiaxes : ndarray, shape (d,)
        Body-frame semiaxes, d = 2 or 3.
    orientation_row : ndarray, shape (4,) in 3D or (1,) in 2D
        Unit quaternion (s, p_1, p_2, p_3) (Donev 2006, Eq. 1.7; used as given, the caller keeps it
        normalised, Algorithm 1) or the angle in radians of the first semiaxis with the x axis.
    out : ndarray, shape (d, d)
        Receives X^-1 (symmetric positive definite).

    Returns
    -------
    None
        The result is written to ``out``.
    """
    shape_inverse_into(semiaxes, orientation_row, out, np.empty((semiaxes.shape[0], semiaxes.shape[0])))


@numba.njit(cache=True, inline="always")
def shape_inverse_into(semiaxes, orientation_row, out, q):
    """:func:`shape_inverse` with a (d, d) scratch array ``q`` for the rotation (no allocation:
    the event-driven MD calls it in its innermost loop).

    Parameters
    ----------
    semiaxes : numpy.ndarray of float, shape (d,)
        Body-frame semiaxes, d = 2 or 3.
    orientation_row : numpy.ndarray of float, shape (4,) in 3D or (1,) in 2D
        Unit quaternion or angle, as in :func:`shape_inverse`.
    out : numpy.ndarray of float, shape (d, d)
        Receives X^-1.
    q : numpy.ndarray of float, shape (d, d)
        Scratch (unused in 2D).
    """
    d = semiaxes.shape[0]
    if d == 2:
        c, s = np.cos(orientation_row[0]), np.sin(orientation_row[0])
        a2, b2 = semiaxes[0] * semiaxes[0], semiaxes[1] * semiaxes[1]
        out[0, 0] = c * c * a2 + s * s * b2
        out[1, 1] = s * s * a2 + c * c * b2
        out[0, 1] = out[1, 0] = c * s * (a2 - b2)
        return
    s, p1, p2, p3 = orientation_row[0], orientation_row[1], orientation_row[2], orientation_row[3]
    diag = s * s - 0.5
    # Q = 2 [p p^T - s P + (s^2 - 1/2) I], P the cross-product matrix of p (Donev 2006, Sec. 1.4.3);
    # X^-1 = Q^T O^2 Q, (X^-1)_ij = sum_k Q_ki a_k^2 Q_kj
    q00, q01, q02 = 2 * (p1 * p1 + diag), 2 * (p1 * p2 + s * p3), 2 * (p1 * p3 - s * p2)
    q10, q11, q12 = 2 * (p2 * p1 - s * p3), 2 * (p2 * p2 + diag), 2 * (p2 * p3 + s * p1)
    q20, q21, q22 = 2 * (p3 * p1 + s * p2), 2 * (p3 * p2 - s * p1), 2 * (p3 * p3 + diag)
    a0, a1, a2 = semiaxes[0] * semiaxes[0], semiaxes[1] * semiaxes[1], semiaxes[2] * semiaxes[2]
    u00, u01, u02 = a0 * q00, a0 * q01, a0 * q02
    u10, u11, u12 = a1 * q10, a1 * q11, a1 * q12
    u20, u21, u22 = a2 * q20, a2 * q21, a2 * q22
    out[0, 0] = q00 * u00 + q10 * u10 + q20 * u20
    out[1, 1] = q01 * u01 + q11 * u11 + q21 * u21
    out[2, 2] = q02 * u02 + q12 * u12 + q22 * u22
    out[0, 1] = out[1, 0] = q00 * u01 + q10 * u11 + q20 * u21
    out[0, 2] = out[2, 0] = q00 * u02 + q10 * u12 + q20 * u22
    out[1, 2] = out[2, 1] = q01 * u02 + q11 * u12 + q21 * u22


@numba.njit(cache=True)
def pw_contact(r_ab, a_inv, b_inv, lam0):
    """Perram-Wertheim overlap potential of two ellipsoids (Donev 2006, Sec. 2.2.2.1, Eqs. 2.10-2.14).

    Maximises f(lam) = lam (1 - lam) r^T Y^-1 r over [0, 1] by safeguarded Newton iteration
    (derivation in the module docstring); converges to machine precision on lambda for every valid
    input.

    Parameters
    ----------
    r_ab : ndarray, shape (d,)
        r_B - r_A, d = 2 or 3.
    a_inv, b_inv : ndarray, shape (d, d)
        X_A^-1 and X_B^-1 (:func:`shape_inverse`), symmetric positive definite.
    lam0 : float
        Initial guess for the maximiser in [0, 1] (e.g. the previous lambda, or O_A / (O_A + O_B)
        with O the bounding radii, Donev 2006, Sec. 2.2.2.1); an endpoint is replaced by 1/2.

    Returns
    -------
    zeta : float
        mu^2 - 1: > 0 disjoint, 0 externally tangent, < 0 overlapping (-1 for coincident centres).
    lam : float
        The maximiser Lambda in (0, 1) (``lam0`` when the centres coincide, where f vanishes).
    n : ndarray, shape (d,)
        Y^-1 r_ab, the unnormalised contact normal from A to B (Eq. 2.14); zero for coincident
        centres.

    Raises
    ------
    ValueError
        If ``lam0`` is not in [0, 1] or ``r_ab`` is not finite.
    """
    zeta, lam, n, _ = _pw_maximise(r_ab, a_inv, b_inv, lam0)
    return zeta, lam, n


@numba.njit(cache=True)
def _pw_maximise(r_ab, a_inv, b_inv, lam0):
    """:func:`pw_contact` and the number of Newton/bisection iterations it took."""
    d = r_ab.shape[0]
    n = np.zeros(d)
    zeta, lam, iterations = pw_contact_into(r_ab, a_inv, b_inv, lam0, n)
    return zeta, lam, n, iterations


@numba.njit(cache=True, inline="always")
def pw_contact_into(r_ab, a_inv, b_inv, lam0, n):
    """:func:`pw_contact` without allocation: the normal goes into ``n`` (d,). Returns (zeta, lam,
    number of iterations). The iteration runs on scalars, one routine per dimension
    (:func:`_pw_newton2`, :func:`_pw_newton3`; only the upper triangles of the symmetric
    matrices are read).

    Parameters
    ----------
    r_ab, a_inv, b_inv, lam0
        As in :func:`pw_contact`.
    n : numpy.ndarray of float, shape (d,)
        Receives the unnormalised contact normal Y^-1 r_ab.

    Returns
    -------
    zeta : float
        mu^2 - 1 (-1 for coincident centres).
    lam : float
        The maximiser Lambda.
    iterations : int
        Newton iterations used.
    """
    d = r_ab.shape[0]
    if not (lam0 >= 0.0 and lam0 <= 1.0):
        raise ValueError("pw_contact: the initial guess lam0 must be in [0, 1]")
    rr = 0.0
    for i in range(d):
        rr += r_ab[i] * r_ab[i]
    if not np.isfinite(rr):
        raise ValueError("pw_contact: the separation r_ab must be finite")
    if rr == 0.0:
        for i in range(d):
            n[i] = 0.0
        return -1.0, lam0, 0
    lam = lam0 if 0.0 < lam0 < 1.0 else 0.5
    if d == 3:
        return _pw_newton3(r_ab, a_inv, b_inv, lam, n)
    return _pw_newton2(r_ab, a_inv, b_inv, lam, n)


@numba.njit(cache=True, inline="always")
def _newton_step(lam, lo, hi, last_step, fp, fpp):
    """One safeguarded Newton step of :func:`pw_contact_into` on f' (module docstring): returns
    (new lambda, lo, hi, step, done)."""
    if fp > 0.0:
        lo = lam
    elif fp < 0.0:
        hi = lam
    else:
        return lam, lo, hi, last_step, True
    tol = 4.0 * _EPS * lam
    new = lam - fp / fpp if fpp < 0.0 else -1.0
    step = abs(new - lam)
    if step <= tol:
        return lam, lo, hi, last_step, True
    if lo < new < hi and step >= 0.5 * last_step and last_step <= _NOISE * lam:
        return lam, lo, hi, last_step, True  # round-off in f' stops Newton: lambda is as exact as f' allows
    if not (lo < new < hi and step < 0.5 * last_step):
        if hi - lo <= tol:
            return lam, lo, hi, last_step, True
        new = 0.5 * (lo + hi)
        step = abs(new - lam)
    return new, lo, hi, step, False


@numba.njit(cache=True, inline="always")
def _pw_newton3(r_ab, a_inv, b_inv, lam, n):
    """The Newton iteration of :func:`pw_contact_into` in 3D on scalars (the upper triangles of
    the symmetric X_A^-1, X_B^-1), from lam in (0, 1)."""
    r0, r1, r2 = r_ab[0], r_ab[1], r_ab[2]
    a00, a01, a02, a11, a12, a22 = a_inv[0, 0], a_inv[0, 1], a_inv[0, 2], a_inv[1, 1], a_inv[1, 2], a_inv[2, 2]
    b00, b01, b02, b11, b12, b22 = b_inv[0, 0], b_inv[0, 1], b_inv[0, 2], b_inv[1, 1], b_inv[1, 2], b_inv[2, 2]
    d00, d01, d02, d11, d12, d22 = b00 - a00, b01 - a01, b02 - a02, b11 - a11, b12 - a12, b22 - a22
    lo, hi = 0.0, 1.0
    last_step = 1.0
    rn = 0.0
    n0 = n1 = n2 = 0.0
    iterations = 0
    while iterations < MAX_ITERATIONS:
        iterations += 1
        # Y = lam B + (1 - lam) A (not A + lam D: that cancels when B << A), inverted by its adjugate
        mu = 1.0 - lam
        y00, y01, y02 = lam * b00 + mu * a00, lam * b01 + mu * a01, lam * b02 + mu * a02
        y11, y12, y22 = lam * b11 + mu * a11, lam * b12 + mu * a12, lam * b22 + mu * a22
        c00 = y11 * y22 - y12 * y12
        c01 = y12 * y02 - y01 * y22
        c02 = y01 * y12 - y11 * y02
        inv = 1.0 / (y00 * c00 + y01 * c01 + y02 * c02)
        i00, i01, i02 = c00 * inv, c01 * inv, c02 * inv
        i11 = (y00 * y22 - y02 * y02) * inv
        i12 = (y02 * y01 - y00 * y12) * inv
        i22 = (y00 * y11 - y01 * y01) * inv
        n0 = i00 * r0 + i01 * r1 + i02 * r2
        n1 = i01 * r0 + i11 * r1 + i12 * r2
        n2 = i02 * r0 + i12 * r1 + i22 * r2
        rn = r0 * n0 + r1 * n1 + r2 * n2
        e0 = d00 * n0 + d01 * n1 + d02 * n2
        e1 = d01 * n0 + d11 * n1 + d12 * n2
        e2 = d02 * n0 + d12 * n1 + d22 * n2
        ndn = n0 * e0 + n1 * e1 + n2 * e2
        dyd = e0 * (i00 * e0 + i01 * e1 + i02 * e2) + e1 * (i01 * e0 + i11 * e1 + i12 * e2) \
            + e2 * (i02 * e0 + i12 * e1 + i22 * e2)
        fp = (1.0 - 2.0 * lam) * rn - lam * (1.0 - lam) * ndn
        fpp = -2.0 * rn - 2.0 * (1.0 - 2.0 * lam) * ndn + 2.0 * lam * (1.0 - lam) * dyd
        lam, lo, hi, last_step, done = _newton_step(lam, lo, hi, last_step, fp, fpp)
        if done:
            break
    n[0], n[1], n[2] = n0, n1, n2
    return lam * (1.0 - lam) * rn - 1.0, lam, iterations


@numba.njit(cache=True, inline="always")
def _pw_newton2(r_ab, a_inv, b_inv, lam, n):
    """The Newton iteration of :func:`pw_contact_into` in 2D on scalars, from lam in (0, 1)."""
    r0, r1 = r_ab[0], r_ab[1]
    a00, a01, a11 = a_inv[0, 0], a_inv[0, 1], a_inv[1, 1]
    b00, b01, b11 = b_inv[0, 0], b_inv[0, 1], b_inv[1, 1]
    d00, d01, d11 = b00 - a00, b01 - a01, b11 - a11
    lo, hi = 0.0, 1.0
    last_step = 1.0
    rn = 0.0
    n0 = n1 = 0.0
    iterations = 0
    while iterations < MAX_ITERATIONS:
        iterations += 1
        mu = 1.0 - lam
        y00, y01, y11 = lam * b00 + mu * a00, lam * b01 + mu * a01, lam * b11 + mu * a11
        inv = 1.0 / (y00 * y11 - y01 * y01)
        i00, i01, i11 = y11 * inv, -y01 * inv, y00 * inv
        n0 = i00 * r0 + i01 * r1
        n1 = i01 * r0 + i11 * r1
        rn = r0 * n0 + r1 * n1
        e0 = d00 * n0 + d01 * n1
        e1 = d01 * n0 + d11 * n1
        ndn = n0 * e0 + n1 * e1
        dyd = e0 * (i00 * e0 + i01 * e1) + e1 * (i01 * e0 + i11 * e1)
        fp = (1.0 - 2.0 * lam) * rn - lam * (1.0 - lam) * ndn
        fpp = -2.0 * rn - 2.0 * (1.0 - 2.0 * lam) * ndn + 2.0 * lam * (1.0 - lam) * dyd
        lam, lo, hi, last_step, done = _newton_step(lam, lo, hi, last_step, fp, fpp)
        if done:
            break
    n[0], n[1] = n0, n1
    return lam * (1.0 - lam) * rn - 1.0, lam, iterations


@numba.njit(cache=True, inline="always")
def contact_point(r_a, a_inv, lam, n, out):
    """Contact point r_C = r_A + (1 - lam) X_A^-1 n (Donev 2006, Eq. 2.13).

    At the maximiser it also equals r_B - lam X_B^-1 n. When zeta != 0 it is the point where the
    particles, both scaled by mu about their centres, touch.

    Parameters
    ----------
    r_a : ndarray, shape (d,)
        Centre of A.
    a_inv : ndarray, shape (d, d)
        X_A^-1.
    lam : float
        The maximiser returned by :func:`pw_contact`.
    n : ndarray, shape (d,)
        The normal returned by :func:`pw_contact`.
    out : ndarray, shape (d,)
        Receives r_C.

    Returns
    -------
    None
        The result is written to ``out``.
    """
    d = r_a.shape[0]
    for i in range(d):
        acc = 0.0
        for j in range(d):
            acc += a_inv[i, j] * n[j]
        out[i] = r_a[i] + (1.0 - lam) * acc


def _spin_dot(w, p, c, n):
    """n . (w x (p - c)); in 2D w is the scalar angular velocity (or a (1,) array)."""


@overload(_spin_dot)
def _spin_dot_impl(w, p, c, n):
    if isinstance(w, (types.Float, types.Integer)):
        def scalar(w, p, c, n):
            return w * ((p[0] - c[0]) * n[1] - (p[1] - c[1]) * n[0])
        return scalar

    def vector(w, p, c, n):
        x0 = p[0] - c[0]
        x1 = p[1] - c[1]
        if w.shape[0] == 1:
            return w[0] * (x0 * n[1] - x1 * n[0])
        x2 = p[2] - c[2]
        return (n[0] * (w[1] * x2 - w[2] * x1) + n[1] * (w[2] * x0 - w[0] * x2)
                + n[2] * (w[0] * x1 - w[1] * x0))
    return vector


@numba.njit(cache=True, inline="always")
def pw_rate(lam, n, r_a, r_b, r_c, v_a, v_b, w_a, w_b, g_a, g_b):
    """Time derivative of the Perram-Wertheim potential, 2 lam (1 - lam) n . v_C (Donev 2006, Eq. 2.21).

    v_C is the velocity of the contact point as a point of B minus as a point of A, each particle
    moving with its centre velocity, spinning and growing uniformly:
    v_C = [v_B + w_B x (r_C - r_B) + g_B (r_C - r_B)] - [v_A + w_A x (r_C - r_A) + g_A (r_C - r_A)].
    Derivation in the module docstring.

    Parameters
    ----------
    lam : float
        The maximiser from :func:`pw_contact`.
    n : ndarray, shape (d,)
        The normal Y^-1 r_AB from :func:`pw_contact`.
    r_a, r_b, r_c : ndarray, shape (d,)
        Centres of A and B and the contact point (:func:`contact_point`).
    v_a, v_b : ndarray, shape (d,)
        Centre velocities.
    w_a, w_b : float (2D) or ndarray, shape (3,) (3D)
        Angular velocities in the lab frame (a scalar or a (1,) array in 2D).
    g_a, g_b : float
        Relative growth rates of the semiaxes (d O / dt = g O).

    Returns
    -------
    float
        d zeta / dt.
    """
    d = n.shape[0]
    nv = _spin_dot(w_b, r_c, r_b, n) - _spin_dot(w_a, r_c, r_a, n)
    for i in range(d):
        nv += n[i] * (v_b[i] - v_a[i] + g_b * (r_c[i] - r_b[i]) - g_a * (r_c[i] - r_a[i]))
    return 2.0 * lam * (1.0 - lam) * nv


@numba.njit(cache=True)
def inverse_shapes(semiaxes, orientations):
    """X^-1 of every particle (:func:`shape_inverse` applied row by row).

    Parameters
    ----------
    semiaxes : ndarray, shape (N, d)
        Body-frame semiaxes.
    orientations : ndarray, shape (N, 4) in 3D or (N, 1) in 2D
        Unit quaternions or angles (2D angles of shape (N,) are reshaped to (N, 1) by the caller).

    Returns
    -------
    ndarray, shape (N, d, d)
        The inverse shape matrices.
    """
    n, d = semiaxes.shape
    out = np.empty((n, d, d))
    for k in range(n):
        shape_inverse(semiaxes[k], orientations[k], out[k])
    return out


@numba.njit(cache=True)
def pair_potentials(separations, i, j, inv_shapes, bounding_radii):
    """Perram-Wertheim potential and maximiser of many pairs (:func:`pw_contact` on each).

    Parameters
    ----------
    separations : ndarray, shape (M, d)
        r_j - r_i of each pair (the image already chosen).
    i, j : ndarray of int, shape (M,)
        The particles of each pair.
    inv_shapes : ndarray, shape (N, d, d)
        X^-1 of every particle (:func:`inverse_shapes`).
    bounding_radii : ndarray, shape (N,)
        Largest semiaxes; the initial guess is O_i / (O_i + O_j) (Donev 2006, Sec. 2.2.2.1).

    Returns
    -------
    zeta : ndarray, shape (M,)
        mu^2 - 1 of each pair.
    lam : ndarray, shape (M,)
        The maximiser of each pair.
    """
    m = separations.shape[0]
    zeta = np.empty(m)
    lam = np.empty(m)
    for k in range(m):
        a, b = i[k], j[k]
        guess = bounding_radii[a] / (bounding_radii[a] + bounding_radii[b])
        zeta[k], lam[k], _ = pw_contact(separations[k], inv_shapes[a], inv_shapes[b], guess)
    return zeta, lam
