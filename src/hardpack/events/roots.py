"""Event times of hard-particle dynamics: the roots shared by every event-driven engine.

- :func:`contact_root` / :func:`pair_time`: first contact of two spheres whose contact distance
  grows linearly, sigma(t) = sigma_0 + g t (derived in :mod:`hardpack.md._kernel`); the MD engine
  uses it with growth, the bounding-cell MD (:mod:`hardpack.freeenergy`) with g = 0.
- :func:`exit_time`: a growing sphere touches the inside of its fixed bounding sphere (the
  near-neighbour lists of Donev 2006, sec. 3.3.2).
- :func:`container_time`: a growing sphere hits the wall of a fixed spherical container (Donev 2006,
  Ch. 7); flat walls need only a linear root (in :mod:`hardpack.md._kernel`).

The ``*_root`` functions take the dot products and are inlined into the numba kernels' loops;
the ``*_time`` functions take vectors.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def dot_products(a, b):
    """The dot products of two vectors: the inputs of the ``*_root`` functions.

    Parameters
    ----------
    a, b : numpy.ndarray
        (d,) vectors.

    Returns
    -------
    tuple of float
        (a.a, a.b, b.b).
    """
    aa = 0.0
    ab = 0.0
    bb = 0.0
    for k in range(a.shape[0]):
        aa += a[k] * a[k]
        ab += a[k] * b[k]
        bb += b[k] * b[k]
    return aa, ab, bb


@njit(cache=True)
def pair_time(r, u, sig0, g):
    """First contact time >= 0 of a pair whose contact distance grows linearly; inf if none.

    Solves |r + u t| = sig0 + g t (derivation in :mod:`hardpack.md._kernel`) through
    :func:`contact_root` with no upper time limit.

    Parameters
    ----------
    r : numpy.ndarray
        (d,) separation x_j - x_i now.
    u : numpy.ndarray
        (d,) relative velocity v_j - v_i.
    sig0 : float
        Contact distance now (r_i + r_j).
    g : float
        Growth rate of the contact distance (0 for fixed radii).

    Returns
    -------
    float
        The first contact time t >= 0 (0 for a pair already overlapping and approaching), or
        inf if the pair never touches.
    """
    rr, ru, uu = dot_products(r, u)
    return contact_root(rr, ru, uu, sig0, g, np.inf)


@njit(cache=True, inline="always")
def contact_root(rr, ru, uu, sig0, g, tmax):
    """First contact time >= 0 of a pair from its dot products; inf if none, or early.

    The root of A t^2 + 2 B t + C = 0 with A = uu - g^2, B = ru - sig0 g, C = rr - sig0^2
    (derivation in :mod:`hardpack.md._kernel`). When A >= 0 the root is at least C / (-2B), which
    rejects most pairs before the square root.

    Parameters
    ----------
    rr, ru, uu : float
        r.r, r.u and u.u of the separation r = x_j - x_i and relative velocity u = v_j - v_i
        (:func:`dot_products`).
    sig0 : float
        Contact distance now (r_i + r_j).
    g : float
        Growth rate of the contact distance (0 for fixed radii).
    tmax : float
        Horizon: a pair with A >= 0 whose contact cannot come before it gets inf without the
        square root (inf: no limit).

    Returns
    -------
    float
        The first contact time t >= 0 (0 for an overlapping pair that approaches; the later
        root, the re-contact, for one that separates more slowly than it grows), or inf if there is
        none or it was rejected early. Only the early rejection uses ``tmax``: a root found
        may exceed it.
    """
    b = ru - sig0 * g
    a = uu - g * g
    if b >= 0.0 and a >= 0.0:
        return np.inf
    c = rr - sig0 * sig0
    if c <= 0.0:
        if b < 0.0:
            return 0.0
        disc = b * b - a * c
        disc = max(disc, 0.0)
        return (b + np.sqrt(disc)) / (-a)
    if a >= 0.0 and c >= -2.0 * b * tmax:
        return np.inf
    disc = b * b - a * c
    if disc < 0.0:
        return np.inf
    if b < 0.0:
        return c / (-b + np.sqrt(disc))
    return (b + np.sqrt(disc)) / (-a)  # A < 0 here; same root, no cancellation when B >= 0


@njit(cache=True)
def exit_time(dr, v, rrem, adot):
    """Time for a sphere (centre offset dr from its bounding centre, velocity v, radius growing at
    adot) to touch its bounding sphere, whose radius exceeds the particle's by rrem now.

    |dr + v t| = rrem - adot t  ->  A t^2 + 2 B t + C = 0 with A = v.v - adot^2,
    B = dr.v + rrem adot, C = dr.dr - rrem^2 < 0; first root t = -C / (B + sqrt(B^2 - AC))
    (derived here, valid for any sign of A). For shrinking particles (adot < 0) the root is
    genuine because rrem - adot t stays positive.

    Parameters
    ----------
    dr : numpy.ndarray
        (d,) offset of the particle's centre from the centre of its bounding sphere.
    v : numpy.ndarray
        (d,) velocity of the particle.
    rrem : float
        Bounding radius less the particle's radius, now.
    adot : float
        Growth rate of the particle's radius (negative when shrinking).

    Returns
    -------
    float
        The exit time t >= 0: 0 if the particle already touches or crosses its bounding sphere
        (and, for a growing particle, when round-off leaves no positive root); inf if it never
        reaches it (a shrinking particle, or one at rest with a fixed radius).
    """
    dd, dv, vv = dot_products(dr, v)
    return exit_root(dd, dv, vv, rrem, adot)


@njit(cache=True, inline="always")
def exit_root(dd, dv, vv, rrem, adot):
    """:func:`exit_time` from the dot products.

    Parameters
    ----------
    dd, dv, vv : float
        dr.dr, dr.v and v.v (:func:`dot_products`).
    rrem, adot : float
        As :func:`exit_time`.

    Returns
    -------
    float
        As :func:`exit_time`.
    """
    c = dd - rrem * rrem
    if c >= 0.0:
        return 0.0
    a = vv - adot * adot
    b = dv + rrem * adot
    disc = b * b - a * c
    if disc < 0.0:
        if adot > 0.0:  # round-off: a growing sphere always leaves
            disc = 0.0
        else:
            return np.inf
    den = b + np.sqrt(disc)
    if den > 0.0:
        return -c / den
    if adot > 0.0:
        return 0.0
    return np.inf



@njit(cache=True)
def container_time(dr, v, rho, adot):
    """Time for a sphere inside a hard spherical container (centre offset dr from the container's
    centre, velocity v, radius growing at adot) to hit the wall: |dr + v t| = rho - adot t with
    rho = R - a the container radius less the particle's radius now (Donev 2006, Ch. 7: the wall
    event of a spherical container). Unlike :func:`exit_time` a sphere touching the wall and
    moving away from it (just reflected) gets its NEXT hit, not t = 0.

    Parameters
    ----------
    dr : numpy.ndarray
        (d,) offset of the particle's centre from the container's centre.
    v : numpy.ndarray
        (d,) velocity of the particle.
    rho : float
        Container radius less the particle's radius, now.
    adot : float
        Growth rate of the particle's radius (negative when shrinking).

    Returns
    -------
    float
        The wall time t >= 0 (:func:`container_root`), inf if there is none.
    """
    dd, dv, vv = dot_products(dr, v)
    return container_root(dd, dv, vv, rho, adot)


@njit(cache=True, inline="always")
def container_root(dd, dv, vv, rho, adot):
    """First wall time >= 0 of :func:`container_time` from dd = dr.dr, dv = dr.v, vv = v.v.

    A t^2 + 2 B t + C = 0 with A = v.v - adot^2, B = dv + rho adot, C = dd - rho^2 (as in
    :func:`exit_time`), each root in the form without cancellation. Inside (C < 0) the hit is the
    positive root: (-B + sqrt(B^2 - AC)) / A when B < 0 (moving away from the wall, A > 0), and
    -C / (B + sqrt(B^2 - AC)) when B >= 0 (for A < 0, a particle growing faster than it moves,
    this is the smaller of two positive roots). :func:`exit_root` returns 0 instead when the
    first form cancels for a sphere touching its bound and moving inward, which is harmless for a
    neighbour-list exit but would repeat a wall event forever. On or beyond the wall (C >= 0,
    round-off after a reflection): B >= 0 (approach speed n.v + adot >= 0) hits now; B < 0 gets
    the later root (-B + sqrt(B^2 - AC)) / A (a reflection leaves |n.v| > adot, so A > 0).
    Roots that cannot exist give inf (B^2 - AC < 0 for a shrinking sphere; A <= 0 with B < 0).

    Parameters
    ----------
    dd, dv, vv : float
        dr.dr, dr.v and v.v (:func:`dot_products`).
    rho, adot : float
        As :func:`container_time`.

    Returns
    -------
    float
        The first wall time t >= 0, inf if there is none.
    """
    c = dd - rho * rho
    b = dv + rho * adot
    a = vv - adot * adot
    if c >= 0.0 and b >= 0.0:
        return 0.0
    disc = b * b - a * c
    if disc < 0.0:
        if adot > 0.0 and c < 0.0:  # round-off: a growing sphere inside always reaches the wall
            disc = 0.0
        else:
            return np.inf
    if b < 0.0:
        if a <= 0.0:
            return np.inf
        return (-b + np.sqrt(disc)) / a
    den = b + np.sqrt(disc)
    if den > 0.0:
        return -c / den
    return np.inf
