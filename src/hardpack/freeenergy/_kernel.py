"""Numba event loop of bounding-cell MD (BCMD) for one schedule segment.

Model (Donev 2006, dissertation sec. 6.3.1, for spheres): sphere i has a fixed cell centre; its
displacement ``dr_i`` from that centre is stored separately (precision at small Delta mu) and
must satisfy |dr_i| <= rho_i(s) = R_i (dmu0 - gamma s), a spherical hard wall whose radius
shrinks at speed gamma R_i (s: time since the segment start). Pairs (i, j) of the static
neighbour list collide at |D_ij + dr_j - dr_i| = R_i + R_j, with D_ij the fixed vector between
the cell centres (periodic image included); entries nb_start[i]:nb_end[i] are the pairs whose
cells can still overlap (the caller prunes them as the cells shrink). Particles with inverse
mass 0 are frozen: never moved, never scheduled.

State, one row per particle as in :mod:`hardpack.md._kernel`: ``P[i] = (dr_0..dr_{d-1},
v_0..v_{d-1}, s_i)``, displacement and velocity at the particle's own last update time s_i.

Growing particles in fixed cells (the SOC compression of Donev 2006, sec. 13.3.1, Fig. 13.9):
radii a_i(s) = R_i (1 + kappa s) inside cells of fixed radius (1 + dmu0) R_i leave the centre
the room R_i (dmu0 - kappa s), which is the shrinking wall above with gamma = kappa; the pairs
then also grow, sigma(s) = (R_i + R_j)(1 + kappa_pair s), with ``kappa_pair`` = kappa (BCMD:
0). Pair collision law for growing pairs (as the md engine's, derived in
:mod:`hardpack.md._kernel`, here with masses 1 / invm): the normal velocity relative to the
contact, u_n - g with g = d sigma / ds, is reversed, so the impulse is
2 (g - u_n) / (invm_i + invm_j) for u_n < g (u_n = n.(v_j - v_i)).

Events follow the md engine's scheme (one predicted event per particle in a 4-ary min-heap with
the keys stored in heap order, lazy invalidation by the partner's collision counter); the
contact-time roots are :mod:`hardpack.events.roots`': pairs use ``contact_root`` (constant radii, g = 0, with its
early rejection against the best time so far); the cell wall solves the md bounding-sphere exit
equation |dr + v s| = rho - adot s (adot = gamma R_i) in a form stable right after a bounce
(:func:`_wall_root`).
Moving-wall law (Donev 2006, sec. 6.3.3): v_n' = 2 w - v_n along the outward normal, w = -gamma R_i.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hardpack.events.heap import heap_set
from hardpack.events.roots import contact_root, dot_products

WALL = -1  # event: the particle hits its cell wall
NONE = -2  # nothing predicted

# float accumulators
F_WALL_IMPULSE_R = 0  # sum over wall events of 2 m (v_n - w) R_i (for the cell pressure)
F_PAIR_VIRIAL = 1  # sum over pair events of |impulse| * sigma_ij at the collision
F_KE_INTEGRAL = 2  # time integral of the kinetic energy of the moving particles over the segment
F_END_TIME = 3  # the time the segment reached: s_end, or the last event's when max_events stopped it
N_FLOAT = 4
# integer counters
C_EVENTS, C_WALL, C_PAIR, C_STALE = 0, 1, 2, 3
N_INT = 4


@njit(cache=True, inline="always")
def _wall_root(dd, dv, vv, rho, adot):
    """First s >= 0 with |dr + v s| = rho - adot s, given |dr|^2 = dd, dr.v = dv, |v|^2 = vv,
    for a point inside (or, by round-off, on) a wall shrinking at adot >= 0; inf if none.

    A s^2 + 2 B s + C = 0 with A = vv - adot^2, B = dv + rho adot, C = dd - rho^2 (the md
    kernel's exit equation). The wanted root is the later one, (-B + sqrt(B^2 - AC)) / A, written
    as -C / (B + sqrt(B^2 - AC)) when B > 0. Unlike :func:`hardpack.events.roots.exit_root` (which uses the second
    form for every B), the first form is used for B <= 0: right after a bounce the point sits on
    the wall (C ~ 0) moving inwards (B < 0), where B + sqrt(B^2 - AC) cancels to 0 and the md
    form returns 0 or inf instead of the next hit -2B/A.
    On or beyond the wall (C >= 0) and moving outwards relative to it (B > 0): 0 (hit now).
    A <= 0 with B <= 0: the point moves inwards at least as fast as the wall, inf.
    """
    c = dd - rho * rho
    b = dv + rho * adot
    a = vv - adot * adot
    if b > 0.0:
        if c >= 0.0:
            return 0.0
        return -c / (b + np.sqrt(max(b * b - a * c, 0.0)))
    if a <= 0.0:
        return np.inf
    return (np.sqrt(max(b * b - a * c, 0.0)) - b) / a


@njit(cache=True)
def wall_time(dr, v, rho0, w):
    """First t >= 0 with |dr + v t| = rho0 + w t for a point inside a ball whose radius moves
    at w (<= 0: shrinking); inf if none (see :func:`_wall_root`)."""
    dd, dv, vv = dot_products(dr, v)
    return _wall_root(dd, dv, vv, rho0, -w)


@njit(cache=True)
def run_segment(P, radii, invm, nb_start, nb_end, nb_j, nb_disp, nb_sig, dmu0, gamma, s_end,
                facc, iacc, max_events, kappa_pair=0.0):
    """Run the events of s in [0, s_end) with cell radii R_i (dmu0 - gamma s) and pair contact
    distances nb_sig (1 + kappa_pair s); every particle is synchronised at s = 0 on entry and at
    the end on exit (P updated in place, s_i = 0 on exit). The end is s_end, or the time of the
    last event when max_events stopped the segment early; it is stored in facc[F_END_TIME]. facc
    gains the wall impulses, the pair virial and the integral of the kinetic energy up to the end.
    Returns the number of events processed.

    Single loop in the md engine's style (no sub-call takes arrays): (1) schedule reset, one
    prediction per moving particle; (2) events: stale pair -> re-predict i; wall -> reflect,
    re-predict i; pair -> collide, re-predict both.
    """
    n = P.shape[0]
    d = (P.shape[1] - 1) // 2
    ts = 2 * d
    coll = np.zeros(n, np.int64)
    ep = np.full(n, NONE, np.int64)  # partner of the predicted event
    ec = np.zeros(n, np.int64)  # partner's collision count at prediction time
    eq = np.zeros(n, np.int64)  # neighbour-list entry of the predicted pair event
    hkey = np.empty(n)
    heap = np.empty(n, np.int64)
    hpos = np.full(n, -1, np.int64)
    xi = np.empty(d)
    nrm = np.empty(d)
    upd = np.empty(2, np.int64)
    hsize = 0
    stage = 0
    count = 0
    ke = 0.0
    for i in range(n):
        if invm[i] > 0.0:
            for k in range(d):
                ke += 0.5 * P[i, d + k] * P[i, d + k] / invm[i]
    s_ke = 0.0  # time up to which ke has been integrated
    while True:
        npred = 0
        if stage < n:  # (1) schedule reset
            i = stage
            stage += 1
            s = 0.0
            if invm[i] > 0.0:
                upd[0] = i
                npred = 1
        else:  # (2) events
            if hsize == 0 or count >= max_events:
                break
            i = heap[0]
            s = hkey[0]
            if s >= s_end:
                break
            j = ep[i]
            upd[0] = i
            npred = 1
            if j >= 0 and coll[j] != ec[i]:  # the partner collided since: stale
                iacc[C_STALE] += 1
            else:
                count += 1
                iacc[C_EVENTS] += 1
                facc[F_KE_INTEGRAL] += ke * (s - s_ke)
                s_ke = s
                dti = s - P[i, ts]
                for k in range(d):
                    P[i, k] += P[i, d + k] * dti
                P[i, ts] = s
                coll[i] += 1
                if j == WALL:
                    w = -gamma * radii[i]
                    norm = 0.0
                    for k in range(d):
                        norm += P[i, k] * P[i, k]
                    norm = np.sqrt(norm)
                    vn = 0.0
                    for k in range(d):
                        nrm[k] = P[i, k] / norm
                        vn += P[i, d + k] * nrm[k]
                    if vn > w:
                        ke += 2.0 * (w - vn) * w / invm[i]  # 0.5 m (|v'|^2 - |v|^2), v_n' = 2 w - v_n
                        for k in range(d):
                            P[i, d + k] += 2.0 * (w - vn) * nrm[k]
                        facc[F_WALL_IMPULSE_R] += 2.0 * (vn - w) * radii[i] / invm[i]
                    iacc[C_WALL] += 1
                else:
                    dtj = s - P[j, ts]
                    for k in range(d):
                        P[j, k] += P[j, d + k] * dtj
                    P[j, ts] = s
                    qj = eq[i]
                    dist = 0.0
                    for k in range(d):
                        nrm[k] = nb_disp[qj, k] + P[j, k] - P[i, k]
                        dist += nrm[k] * nrm[k]
                    dist = np.sqrt(dist)
                    un = 0.0
                    for k in range(d):
                        nrm[k] /= dist
                        un += (P[j, d + k] - P[i, d + k]) * nrm[k]
                    g = nb_sig[qj] * kappa_pair
                    if un < g:
                        imp = 2.0 * (g - un) / (invm[i] + invm[j])
                        for k in range(d):
                            P[i, d + k] -= imp * invm[i] * nrm[k]
                            P[j, d + k] += imp * invm[j] * nrm[k]
                        ke += imp * (un + 0.5 * imp * (invm[i] + invm[j]))  # = imp * g
                        facc[F_PAIR_VIRIAL] += imp * nb_sig[qj] * (1.0 + kappa_pair * s)
                    iacc[C_PAIR] += 1
                    coll[j] += 1
                    if invm[j] > 0.0:
                        upd[1] = j
                        npred = 2

        for q in range(npred):  # predict the next event of upd[q] at time s
            i = upd[q]
            dt = s - P[i, ts]
            adot = gamma * radii[i]
            dd = 0.0
            dv = 0.0
            vv = 0.0
            for k in range(d):
                vk = P[i, d + k]
                x = P[i, k] + vk * dt
                xi[k] = x
                dd += x * x
                dv += x * vk
                vv += vk * vk
            best = _wall_root(dd, dv, vv, radii[i] * (dmu0 - gamma * s), adot)
            partner = WALL
            qbest = -1
            grown = 1.0 + kappa_pair * s  # sigma(s) / sigma(0) of every pair
            for m in range(nb_start[i], nb_end[i]):
                j = nb_j[m]
                dtj = s - P[j, ts]
                rr = 0.0
                ru = 0.0
                uu = 0.0
                for k in range(d):
                    vjk = P[j, d + k]
                    r = nb_disp[m, k] + P[j, k] + vjk * dtj - xi[k]
                    u = vjk - P[i, d + k]
                    rr += r * r
                    ru += r * u
                    uu += u * u
                tc = contact_root(rr, ru, uu, nb_sig[m] * grown, nb_sig[m] * kappa_pair, best)
                if tc < best:
                    best = tc
                    partner = j
                    qbest = m
            ep[i] = partner
            eq[i] = qbest
            if partner >= 0:
                ec[i] = coll[partner]
            hsize = heap_set(hkey, heap, hpos, hsize, i, s + best)

    s_stop = s_end if count < max_events else s_ke  # max_events: stop at the last event processed
    facc[F_KE_INTEGRAL] += ke * (s_stop - s_ke)
    facc[F_END_TIME] = s_stop
    for i in range(n):  # synchronise at s_stop
        if invm[i] > 0.0:
            dt = s_stop - P[i, ts]
            for k in range(d):
                P[i, k] += P[i, d + k] * dt
        P[i, ts] = 0.0
    return count
