"""Point billiard in a polytope intersected with a shrinking ball: the BCMD volume identity in
its barest form (Donev 2006, dissertation sec. 6.3.3 and Fig. 6.1; Donev et al. 2007, Appendix A).

A point moves freely inside P = {x : A x <= b} intersected with the ball |x - c| <= xi(t),
reflecting elastically off the planes and with v_n' = 2 w - v_n off the ball wall moving at
w = d xi/dt. For a quasi-static shrink from xi_max (ball contains P) to xi_min (ball inside P),
Eq. 6.13 gives ln(|P| / |B(xi_min)|) = (n/2) ln(K / K_0), so ``volume_estimate`` returns
|B(xi_min)| (K/K_0)^{n/2}. Polytope billiards are not ergodic by themselves, so the velocity
direction is re-drawn uniformly at fixed speed every ``redraw_every`` bounces; this preserves the
microcanonical measure (uniform in position x direction at fixed K) and hence the identity.
The re-draws happen at fixed time intervals (``redraw_every`` times xi / speed), never at a
bounce: a uniform direction drawn on the boundary would violate the cosine law of the
equilibrium wall flux and bias the estimate by several per cent (observed).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hardpack.errors import InvalidInputError
from hardpack.freeenergy._kernel import wall_time
from hardpack.geometry.balls import ball_volume


@njit(cache=True)
def _shrink(x, v, a, b, c, xi_max, xi_min, wall_ratio, fraction, redraw_every, seed):
    np.random.seed(seed)  # noqa: NPY002 (numba kernels have only the legacy generator)
    n = x.shape[0]
    m = a.shape[0]
    xi = xi_max
    dx = np.empty(n)
    bounces = 0
    while xi > xi_min:
        speed = np.sqrt(np.sum(v * v))
        gamma = wall_ratio * speed
        xi_next = max(xi * (1.0 - fraction), xi_min)
        t_left = (xi - xi_next) / gamma
        t_seg = 0.0
        tau = redraw_every * xi / speed
        t_redraw = tau
        while True:
            for k in range(n):
                dx[k] = x[k] - c[k]
            best = wall_time(dx, v, xi - gamma * t_seg, -gamma)
            plane = -1
            for p in range(m):
                av = 0.0
                ax = 0.0
                for k in range(n):
                    av += a[p, k] * v[k]
                    ax += a[p, k] * x[k]
                if av > 0.0:
                    tp = (b[p] - ax) / av
                    tp = max(tp, 0.0)
                    if tp < best:
                        best = tp
                        plane = p
            if t_seg + best >= t_left:
                x += v * (t_left - t_seg)
                break
            if t_seg + best >= t_redraw:
                x += v * (t_redraw - t_seg)
                t_seg = t_redraw
                t_redraw += tau
                speed = np.sqrt(np.sum(v * v))
                for k in range(n):
                    v[k] = np.random.normal()  # noqa: NPY002
                v *= speed / np.sqrt(np.sum(v * v))
                continue
            x += v * best
            t_seg += best
            if plane >= 0:
                av = 0.0
                aa = 0.0
                for k in range(n):
                    av += a[plane, k] * v[k]
                    aa += a[plane, k] * a[plane, k]
                v -= (2.0 * av / aa) * a[plane]
            else:
                w = -gamma
                for k in range(n):
                    dx[k] = x[k] - c[k]
                nrm = dx / np.sqrt(np.sum(dx * dx))
                vn = np.sum(v * nrm)
                if vn > w:
                    v += 2.0 * (w - vn) * nrm
            bounces += 1
        xi = xi_next
    return bounces


def volume_estimate(
    a,
    b,
    centre,
    xi_max: float,
    xi_min: float,
    *,
    wall_ratio: float = 1e-3,
    fraction: float = 0.01,
    redraw_every: float = 2.0,
    seed: int = 0,
) -> tuple[float, int]:
    """BCMD estimate of |P|, P = {x : a x <= b}, from a point billiard started at ``centre``.

    Requires the ball B(centre, xi_max) to contain P and B(centre, xi_min) to lie inside P (the
    caller checks; the estimate is meaningless otherwise). Eq. 6.13 (Donev 2006, sec. 6.3.3):
    |P| = |B(xi_min)| (K/K_0)^{n/2}.

    Parameters
    ----------
    a : array_like, shape (m, n)
        Facet normals of the polytope.
    b : array_like, shape (m,)
        Right-hand sides of a x <= b.
    centre : array_like, shape (n,)
        Centre of the ball and start of the point; strictly inside P.
    xi_max : float
        Initial ball radius (the ball contains P).
    xi_min : float
        Final ball radius (the ball lies inside P), 0 < xi_min < xi_max.
    wall_ratio : float, default 1e-3
        Wall speed / particle speed (adiabaticity of the shrink).
    fraction : float, default 0.01
        Relative fall of xi per shrink segment.
    redraw_every : float, default 2.0
        The velocity direction is re-drawn uniformly every ``redraw_every`` xi / speed of time.
    seed : int, default 0
        Seed of the initial and re-drawn directions.

    Returns
    -------
    estimate : float
        The estimate of the volume |P|.
    bounces : int
        Number of bounces off the planes and the ball.

    Raises
    ------
    InvalidInputError
        If the shapes of ``a``, ``b`` and ``centre`` disagree, the centre is not strictly
        inside P, or not 0 < xi_min < xi_max.
    """
    a = np.ascontiguousarray(a, dtype=float)
    b = np.ascontiguousarray(b, dtype=float)
    c = np.ascontiguousarray(centre, dtype=float)
    n = c.size
    if a.ndim != 2 or a.shape[1] != n or b.shape != (a.shape[0],):
        raise InvalidInputError(
            f"a must be (m, {n}) and b (m,), got {a.shape} and {b.shape}"
        )
    if np.any(a @ c >= b):
        raise InvalidInputError("the centre must lie strictly inside the polytope")
    if not 0 < xi_min < xi_max:
        raise InvalidInputError("need 0 < xi_min < xi_max")
    rng = np.random.default_rng(seed)
    v = rng.normal(size=n)
    v /= np.linalg.norm(v)
    x = c.copy()
    bounces = _shrink(
        x,
        v,
        a,
        b,
        c,
        float(xi_max),
        float(xi_min),
        float(wall_ratio),
        float(fraction),
        float(redraw_every),
        int(seed),
    )
    k_ratio = float(v @ v)  # K_0 = 1/2
    return ball_volume(xi_min, n) * k_ratio ** (n / 2), int(bounces)
