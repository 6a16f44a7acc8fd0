"""Numba event loop of bounding-cell MD (BCMD) for one schedule segment.

Model (note ``bcmd_free_energy.md`` sec. 2 steps 3-4): sphere i has a fixed cell centre; its
displacement ``dr_i`` from that centre is stored separately (precision at small Delta mu) and
must satisfy |dr_i| <= rho_i(t) = R_i * (dmu0 - gamma (t - t0)), a spherical hard wall whose
radius shrinks at speed w_i = -gamma R_i. Pairs (i, j) in the static neighbour list collide at
|D_ij + dr_j - dr_i| = R_i + R_j, with D_ij the fixed vector between the cell centres (periodic
image included). Particles with inverse mass 0 are frozen: never moved, never scheduled.

Events: one per particle in a binary min-heap (``heap``, ``hpos``) keyed by ``ev_t``; the
partner's collision counter at prediction time invalidates stale pair events lazily.
Moving-wall law (Donev Eq. in [C:589-613]): v_n' = 2 w - v_n along the outward normal.
Particle positions are advanced lazily: ``dr_i`` is valid at time ``tl_i``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

WALL = -1
NONE = -2

# float accumulators
F_WALL_IMPULSE_R = (
    0  # sum over wall events of 2 m (v_n - w) R_i (for the cell pressure)
)
F_PAIR_VIRIAL = 1  # sum over pair events of |impulse| * (R_i + R_j)
N_FLOAT = 2
# integer counters
C_EVENTS, C_WALL, C_PAIR, C_STALE = 0, 1, 2, 3
N_INT = 4


@njit(cache=True)
def _sift_up(heap, hpos, ev_t, k):
    item = heap[k]
    while k > 0:
        parent = (k - 1) >> 1
        if ev_t[heap[parent]] <= ev_t[item]:
            break
        heap[k] = heap[parent]
        hpos[heap[k]] = k
        k = parent
    heap[k] = item
    hpos[item] = k


@njit(cache=True)
def _sift_down(heap, hpos, ev_t, k, size):
    item = heap[k]
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        if child + 1 < size and ev_t[heap[child + 1]] < ev_t[heap[child]]:
            child += 1
        if ev_t[heap[child]] >= ev_t[item]:
            break
        heap[k] = heap[child]
        hpos[heap[k]] = k
        k = child
    heap[k] = item
    hpos[item] = k


@njit(cache=True)
def _reschedule(heap, hpos, ev_t, i, size):
    k = hpos[i]
    _sift_up(heap, hpos, ev_t, k)
    _sift_down(heap, hpos, ev_t, hpos[i], size)


@njit(cache=True)
def wall_time(dr, v, rho0, w):
    """First t >= 0 with |dr + v t| = rho0 + w t and rho0 + w t >= 0, for a point inside the
    ball (|dr| <= rho0, round-off tolerated); inf if none. Returns 0 when the point is at or
    beyond the wall and moving outward relative to it."""
    dd = 0.0
    dv = 0.0
    vv = 0.0
    for k in range(dr.shape[0]):
        dd += dr[k] * dr[k]
        dv += dr[k] * v[k]
        vv += v[k] * v[k]
    a = vv - w * w
    b = dv - rho0 * w  # f(t) = a t^2 + 2 b t + c = |dr+vt|^2 - (rho0+wt)^2
    c = dd - rho0 * rho0
    if c >= 0.0 and b > 0.0:
        return 0.0
    disc = b * b - a * c
    disc = max(disc, 0.0)
    s = np.sqrt(disc)
    if a > 0.0:
        # the larger root: the exit through the wall (the smaller one is <= 0, or ~0 just
        # after a bounce, and must be skipped to avoid re-colliding at the same point)
        t = (s - b) / a if b <= 0.0 else -c / (b + s)
    elif b > 0.0:
        # a <= 0 (wall faster than the particle): the wall catches up at the smaller root
        t = -c / (b + s)
    else:
        return np.inf
    t = max(t, 0.0)
    if rho0 + w * t < 0.0:
        return np.inf
    return t


@njit(cache=True)
def _pair_time(r, u, sig):
    """First t >= 0 with |r + u t| = sig for an approaching pair, else inf."""
    rr = 0.0
    ru = 0.0
    uu = 0.0
    for k in range(r.shape[0]):
        rr += r[k] * r[k]
        ru += r[k] * u[k]
        uu += u[k] * u[k]
    if ru >= 0.0:
        return np.inf
    c = rr - sig * sig
    if c <= 0.0:
        return 0.0
    disc = ru * ru - uu * c
    if disc < 0.0:
        return np.inf
    return c / (-ru + np.sqrt(disc))


@njit(cache=True)
def _advance(i, t, dr, v, tl):
    dt = t - tl[i]
    for k in range(dr.shape[1]):
        dr[i, k] += v[i, k] * dt
    tl[i] = t


@njit(cache=True)
def _predict(
    i,
    t,
    t0,
    dmu0,
    gamma,
    dr,
    v,
    tl,
    radii,
    invm,
    nb_start,
    nb_j,
    nb_disp,
    nb_sig,
    coll,
    ev_t,
    ev_p,
    ev_c,
    ev_q,
    r,
    u,
):
    """Next event of particle i (advanced to time t): its wall or a neighbour."""
    _advance(i, t, dr, v, tl)
    d = dr.shape[1]
    rho0 = radii[i] * (dmu0 - gamma * (t - t0))
    best = t + wall_time(dr[i], v[i], rho0, -gamma * radii[i])
    partner = WALL
    qbest = -1
    for q in range(nb_start[i], nb_start[i + 1]):
        j = nb_j[q]
        dtj = t - tl[j]
        for k in range(d):
            r[k] = nb_disp[q, k] + dr[j, k] + v[j, k] * dtj - dr[i, k]
            u[k] = v[j, k] - v[i, k]
        tc = t + _pair_time(r, u, nb_sig[q])
        if tc < best:
            best = tc
            partner = j
            qbest = q
    ev_t[i] = best
    ev_p[i] = partner
    ev_c[i] = coll[partner] if partner >= 0 else 0
    ev_q[i] = qbest


@njit(cache=True)
def run_segment(
    t0,
    t1,
    dmu0,
    gamma,
    dr,
    v,
    radii,
    invm,
    nb_start,
    nb_j,
    nb_disp,
    nb_sig,
    facc,
    iacc,
    max_events,
):
    """Run events in [t0, t1) with cell radii R_i (dmu0 - gamma (t - t0)); all particles are
    synchronised at t0 on entry and at t1 on exit (dr, v updated in place). Returns the number
    of events processed (stops early after max_events; then the caller treats the run as
    failed)."""
    n, d = dr.shape
    tl = np.full(n, t0)
    coll = np.zeros(n, np.int64)
    ev_t = np.full(n, np.inf)
    ev_p = np.full(n, NONE, np.int64)
    ev_c = np.zeros(n, np.int64)
    ev_q = np.full(n, -1, np.int64)
    r = np.empty(d)
    u = np.empty(d)
    heap = np.empty(n, np.int64)
    hpos = np.full(n, -1, np.int64)
    size = 0
    for i in range(n):
        if invm[i] > 0.0:
            _predict(
                i,
                t0,
                t0,
                dmu0,
                gamma,
                dr,
                v,
                tl,
                radii,
                invm,
                nb_start,
                nb_j,
                nb_disp,
                nb_sig,
                coll,
                ev_t,
                ev_p,
                ev_c,
                ev_q,
                r,
                u,
            )
            heap[size] = i
            hpos[i] = size
            size += 1
    for k in range(size // 2 - 1, -1, -1):
        _sift_down(heap, hpos, ev_t, k, size)
    count = 0
    nrm = np.empty(d)
    while size > 0 and count < max_events:
        i = heap[0]
        t = ev_t[i]
        if t >= t1:
            break
        j = ev_p[i]
        if j >= 0 and coll[j] != ev_c[i]:
            iacc[C_STALE] += 1
            _predict(
                i,
                t,
                t0,
                dmu0,
                gamma,
                dr,
                v,
                tl,
                radii,
                invm,
                nb_start,
                nb_j,
                nb_disp,
                nb_sig,
                coll,
                ev_t,
                ev_p,
                ev_c,
                ev_q,
                r,
                u,
            )
            _reschedule(heap, hpos, ev_t, i, size)
            continue
        count += 1
        iacc[C_EVENTS] += 1
        _advance(i, t, dr, v, tl)
        if j == WALL:
            w = -gamma * radii[i]
            norm = 0.0
            for k in range(d):
                norm += dr[i, k] * dr[i, k]
            norm = np.sqrt(norm)
            vn = 0.0
            for k in range(d):
                nrm[k] = dr[i, k] / norm
                vn += v[i, k] * nrm[k]
            if vn > w:
                for k in range(d):
                    v[i, k] += 2.0 * (w - vn) * nrm[k]
                facc[F_WALL_IMPULSE_R] += 2.0 * (vn - w) * radii[i] / invm[i]
            iacc[C_WALL] += 1
            coll[i] += 1
        else:
            _advance(j, t, dr, v, tl)
            dist = 0.0
            qj = ev_q[i]
            for k in range(d):
                nrm[k] = nb_disp[qj, k] + dr[j, k] - dr[i, k]
                dist += nrm[k] * nrm[k]
            dist = np.sqrt(dist)
            un = 0.0
            for k in range(d):
                nrm[k] /= dist
                un += (v[j, k] - v[i, k]) * nrm[k]
            if un < 0.0:
                imp = -2.0 * un / (invm[i] + invm[j])
                for k in range(d):
                    v[i, k] -= imp * invm[i] * nrm[k]
                    v[j, k] += imp * invm[j] * nrm[k]
                facc[F_PAIR_VIRIAL] += imp * nb_sig[qj]
            iacc[C_PAIR] += 1
            coll[i] += 1
            coll[j] += 1
            if invm[j] > 0.0:
                _predict(
                    j,
                    t,
                    t0,
                    dmu0,
                    gamma,
                    dr,
                    v,
                    tl,
                    radii,
                    invm,
                    nb_start,
                    nb_j,
                    nb_disp,
                    nb_sig,
                    coll,
                    ev_t,
                    ev_p,
                    ev_c,
                    ev_q,
                    r,
                    u,
                )
                _reschedule(heap, hpos, ev_t, j, size)
        _predict(
            i,
            t,
            t0,
            dmu0,
            gamma,
            dr,
            v,
            tl,
            radii,
            invm,
            nb_start,
            nb_j,
            nb_disp,
            nb_sig,
            coll,
            ev_t,
            ev_p,
            ev_c,
            ev_q,
            r,
            u,
        )
        _reschedule(heap, hpos, ev_t, i, size)
    for i in range(n):
        if invm[i] > 0.0:
            _advance(i, t1, dr, v, tl)
    return count
