"""Event-driven kernel of linearised BCMD for ellipses (:mod:`hardpack.freeenergy.ellipse_bcmd`).

State of particle i: q_i = (dx, dy, dphi), its displacement from the cell centre and initial
orientation at time tq_i, and the constant velocity qd_i between events. Inverse masses
``im`` (translation) and ``ii`` (rotation) are 0 for frozen degrees of freedom.

Pair contact c (particles i != j): gap G_c = h_c + ai_c . q_i + aj_c . q_j >= 0; a collision
reverses dG/dt with the impulse J M^-1 a (kinetic energy and momentum conserved).

Cell of i (Donev 2006, Eq. 6.14 / Donev et al. 2007, Eq. C1): in the body frame of the cell,
X = R(-phi0_i) dr, with the boundary point r(t) = (A1 cos t, A2 sin t) and outward normal
n(t) = (A2 cos t, A1 sin t) / N(t), N(t) = sqrt(A2^2 cos^2 t + A1^2 sin^2 t), the constraint
n . (X + dphi z x r) <= dmu n . r for every t is, times N(t) > 0,

    P(t) = A2 cos t X_x + A1 sin t X_y + dphi (A1^2 - A2^2) sin(2t) / 2 - dmu A1 A2 <= 0.

P is linear in time for fixed t (X, dphi and dmu are), so G(time) = max_t P is convex in time:
from a time t_hi with G >= 0 (found from the boundary point of fastest approach), Newton steps
move monotonically down onto the first root after the present. A wall collision reverses the
gap rate dg/dt = -gamma h - (n . v + omega r x n) (h = n . r; the wall moves inward at gamma h).
"""

from __future__ import annotations

import numba
import numpy as np

N_GRID = 32


@numba.njit(cache=True, inline="always")
def _p_and_derivs(t, a, b, k, c0):
    """P(t) = a cos t + b sin t + k sin 2t / 2 - c0 and its first two derivatives."""
    c, s = np.cos(t), np.sin(t)
    s2, c2 = 2.0 * s * c, c * c - s * s
    p = a * c + b * s + 0.5 * k * s2 - c0
    p1 = -a * s + b * c + k * c2
    p2 = -a * c - b * s - 2.0 * k * s2
    return p, p1, p2


@numba.njit(cache=True)
def _max_p(a, b, k, c0):
    """(max_t P, argmax t) of P(t) = a cos t + b sin t + k sin 2t / 2 - c0: grid then Newton on
    P' = 0 from each grid local maximum (P has at most two)."""
    h = 2.0 * np.pi / N_GRID
    vals = np.empty(N_GRID)
    for g in range(N_GRID):
        vals[g] = _p_and_derivs(g * h, a, b, k, c0)[0]
    best, tbest = -np.inf, 0.0
    for g in range(N_GRID):
        if vals[g] >= vals[(g - 1) % N_GRID] and vals[g] >= vals[(g + 1) % N_GRID]:
            t = g * h
            for _ in range(30):
                p, p1, p2 = _p_and_derivs(t, a, b, k, c0)
                if p2 >= 0.0:
                    step = h * 0.5 if p1 > 0 else -h * 0.5
                else:
                    step = -p1 / p2
                    if step > h:
                        step = h
                    elif step < -h:
                        step = -h
                t += step
                if abs(step) < 1e-15:
                    break
            p = _p_and_derivs(t, a, b, k, c0)[0]
            if p > best:
                best, tbest = p, t
    return best, tbest


@numba.njit(cache=True)
def _cell_coefficients(i, time, q, qd, tq, cell, dmu, gamma, tseg):
    """P's coefficients (a, b, k, c0) at ``time`` and their time derivatives."""
    dt = time - tq[i]
    x = q[i, 0] + qd[i, 0] * dt
    y = q[i, 1] + qd[i, 1] * dt
    ph = q[i, 2] + qd[i, 2] * dt
    c, s, a1, a2 = cell[i, 0], cell[i, 1], cell[i, 2], cell[i, 3]
    bx, by = c * x + s * y, -s * x + c * y  # R(-phi0) dr
    vx, vy = c * qd[i, 0] + s * qd[i, 1], -s * qd[i, 0] + c * qd[i, 1]
    dm = dmu - gamma * (time - tseg)
    e = a1 * a1 - a2 * a2
    return (a2 * bx, a1 * by, ph * e, dm * a1 * a2,
            a2 * vx, a1 * vy, qd[i, 2] * e, -gamma * a1 * a2)


@numba.njit(cache=True)
def cell_value(i, time, q, qd, tq, cell, dmu, gamma, tseg):
    """max_t P at ``time`` (<= 0 inside the cell)."""
    a, b, k, c0, _, _, _, _ = _cell_coefficients(i, time, q, qd, tq, cell, dmu, gamma, tseg)
    return _max_p(a, b, k, c0)[0]


@numba.njit(cache=True)
def predict_cell(i, now, q, qd, tq, cell, dmu, gamma, tseg, scale_tol):
    """First time >= now at which particle i reaches its cell wall (inf if never)."""
    a, b, k, c0, da, db, dk, dc0 = _cell_coefficients(i, now, q, qd, tq, cell, dmu, gamma, tseg)
    # fastest approach: the boundary point maximising dP/dtime (a lower bound on G(time))
    rate, tr = _max_p(da, db, dk, dc0)
    if not rate > 0.0:
        return np.inf
    p0 = _p_and_derivs(tr, a, b, k, c0)[0]
    t_hi = now + max(-p0, 0.0) / rate
    for _ in range(200):
        a, b, k, c0, da, db, dk, dc0 = _cell_coefficients(i, t_hi, q, qd, tq, cell, dmu, gamma, tseg)
        g, tm = _max_p(a, b, k, c0)
        if g <= scale_tol:
            break
        slope = _p_and_derivs(tm, da, db, dk, dc0)[0]
        if not slope > 0.0:
            break
        step = g / slope
        t_hi -= step
        if t_hi <= now:
            return now
        if step <= 1e-15 * abs(t_hi):
            break
    return t_hi


@numba.njit(cache=True)
def collide_cell(i, now, q, qd, tq, cell, dmu, gamma, tseg, im, ii):
    """Elastic bounce of particle i off its moving cell wall at ``now``; returns the change of
    the kinetic energy."""
    a, b, k, c0, _, _, _, _ = _cell_coefficients(i, now, q, qd, tq, cell, dmu, gamma, tseg)
    _, t = _max_p(a, b, k, c0)
    c, s, a1, a2 = cell[i, 0], cell[i, 1], cell[i, 2], cell[i, 3]
    ct, st = np.cos(t), np.sin(t)
    nn = np.sqrt(a2 * a2 * ct * ct + a1 * a1 * st * st)
    nbx, nby = a2 * ct / nn, a1 * st / nn  # body-frame normal
    lever = (a1 * a1 - a2 * a2) * ct * st / nn  # r x n
    h = a1 * a2 / nn  # n . r
    nx, ny = c * nbx - s * nby, s * nbx + c * nby  # lab frame
    _advance(i, now, q, qd, tq)
    gdot = -gamma * h - (nx * qd[i, 0] + ny * qd[i, 1] + lever * qd[i, 2])
    if gdot >= 0.0:
        return 0.0
    k_before = _kinetic(i, qd, im, ii)
    j = -2.0 * gdot / (im[i] + ii[i] * lever * lever)
    qd[i, 0] -= j * im[i] * nx
    qd[i, 1] -= j * im[i] * ny
    qd[i, 2] -= j * ii[i] * lever
    return _kinetic(i, qd, im, ii) - k_before


@numba.njit(cache=True, inline="always")
def _kinetic(i, qd, im, ii):
    k = 0.0
    if im[i] > 0:
        k += 0.5 * (qd[i, 0] ** 2 + qd[i, 1] ** 2) / im[i]
    if ii[i] > 0:
        k += 0.5 * qd[i, 2] ** 2 / ii[i]
    return k


@numba.njit(cache=True, inline="always")
def _advance(i, now, q, qd, tq):
    dt = now - tq[i]
    for k in range(3):
        q[i, k] += qd[i, k] * dt
    tq[i] = now


@numba.njit(cache=True, inline="always")
def _pair_gap(c, now, q, qd, tq, ci, cj, ai, aj, h):
    i, j = ci[c], cj[c]
    g, gd = h[c], 0.0
    for k in range(3):
        g += ai[c, k] * (q[i, k] + qd[i, k] * (now - tq[i])) + aj[c, k] * (q[j, k] + qd[j, k] * (now - tq[j]))
        gd += ai[c, k] * qd[i, k] + aj[c, k] * qd[j, k]
    return g, gd


@numba.njit(cache=True)
def predict_pair(c, now, q, qd, tq, ci, cj, ai, aj, h):
    g, gd = _pair_gap(c, now, q, qd, tq, ci, cj, ai, aj, h)
    if gd >= 0.0:
        return np.inf
    return now + max(g, 0.0) / (-gd)


@numba.njit(cache=True)
def collide_pair(c, now, q, qd, tq, ci, cj, ai, aj, h, im, ii):
    i, j = ci[c], cj[c]
    _advance(i, now, q, qd, tq)
    _advance(j, now, q, qd, tq)
    _, gd = _pair_gap(c, now, q, qd, tq, ci, cj, ai, aj, h)
    if gd >= 0.0:
        return
    w = im[i] * (ai[c, 0] ** 2 + ai[c, 1] ** 2) + ii[i] * ai[c, 2] ** 2
    w += im[j] * (aj[c, 0] ** 2 + aj[c, 1] ** 2) + ii[j] * aj[c, 2] ** 2
    jmp = -2.0 * gd / w
    for k in range(2):
        qd[i, k] += jmp * im[i] * ai[c, k]
        qd[j, k] += jmp * im[j] * aj[c, k]
    qd[i, 2] += jmp * ii[i] * ai[c, 2]
    qd[j, 2] += jmp * ii[j] * aj[c, 2]


@numba.njit(cache=True)
def run_segment(q, qd, tq, cell, im, ii, ci, cj, ai, aj, h, start, clist,
                t0, duration, dmu, gamma, scale_tol, counts, max_events):
    """Run from t0 for ``duration`` with the cell size dmu(t) = dmu - gamma (t - t0). Returns the
    kinetic energy change of the wall collisions; counts += (pair events, wall events)."""
    n, m = q.shape[0], ci.shape[0]
    tcell = np.full(n, np.inf)
    tpair = np.full(m, np.inf)
    moving = (im > 0) | (ii > 0)
    for i in range(n):
        if moving[i]:
            tcell[i] = predict_cell(i, t0, q, qd, tq, cell, dmu, gamma, t0, scale_tol)
    for c in range(m):
        tpair[c] = predict_pair(c, t0, q, qd, tq, ci, cj, ai, aj, h)
    t_end = t0 + duration
    dk = 0.0
    events = 0
    while events < max_events:
        ic = np.argmin(tcell)
        cc = np.argmin(tpair) if m > 0 else -1
        tc = tcell[ic]
        tp = tpair[cc] if m > 0 else np.inf
        now = min(tc, tp)
        if now >= t_end:
            break
        events += 1
        if tc <= tp:
            dk += collide_cell(ic, now, q, qd, tq, cell, dmu, gamma, t0, im, ii)
            counts[1] += 1
            touched_a, touched_b = ic, -1
        else:
            collide_pair(cc, now, q, qd, tq, ci, cj, ai, aj, h, im, ii)
            counts[0] += 1
            touched_a, touched_b = ci[cc], cj[cc]
        for p in (touched_a, touched_b):
            if p < 0:
                continue
            if moving[p]:
                tcell[p] = predict_cell(p, now, q, qd, tq, cell, dmu, gamma, t0, scale_tol)
            for e in range(start[p], start[p + 1]):
                c = clist[e]
                tpair[c] = predict_pair(c, now, q, qd, tq, ci, cj, ai, aj, h)
    for i in range(n):
        _advance(i, t_end, q, qd, tq)
    return dk, events
