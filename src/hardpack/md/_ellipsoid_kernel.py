"""Numba kernels of event-driven MD of hard ellipsoids (d = 3) and ellipses (d = 2).

The event loop is the one of the sphere engine (:mod:`hardpack.md._kernel`: one predicted event
per particle in a 4-ary heap with lazy invalidation by collision counters, neighbour lists with
immobile bounding spheres rebuilt particle by particle on a cell grid, time measured from the last
synchronisation); what differs is the particle state, the pair prediction and the collision law
(Donev 2006, dissertation sec. 3.5).

**State.** Row i of ``P`` (``ncol(d)`` columns, masses 1), at the particle's own update time t_i:
position x (d), velocity v (d), t_i, bounding radius R_i (the largest semiaxis) at window time 0,
semiaxes at window time 0 (d), orientation (a unit quaternion (s, p_1, p_2, p_3) in 3D, the angle
of the first semiaxis with the x axis in 2D; conventions of :mod:`hardpack.geometry.shapes`),
angular velocity w in the lab frame (3 components in 3D, one in 2D) and the inverse moment of
inertia 1/I_i. Column offsets: :func:`columns`.

**Free flight.** x(t) = x + v (t - t_i); the orientation turns uniformly about the fixed axis w
(Donev 2006, sec. 1.4.3, Algorithm 1): the body-to-lab rotation R = Q^T of the quaternion w_q
(Q as in :mod:`hardpack.geometry.shapes`) is that of the active quaternion rotation, so a turn by
phi = |w| dt about the lab axis w-hat is w_q <- [cos(phi/2), sin(phi/2) w-hat] w_q (composition
Eq. 1.9 with the turn on the LEFT because w is a lab-frame vector; checked against
dX/dt = W X - X W, Donev 2006, Eq. 2.9, in the tests); in 2D phi <- phi + w dt.
Free rotation is uniform only because the moment of inertia is taken spherically symmetric
(Donev 2006, sec. 3.5: "we assume a spherically symmetric moment of inertia"): I is the mean of
the three principal moments of a uniform ellipsoid, I = (2/15)(a^2 + b^2 + c^2) (the exact value
2 a^2 / 5 for a sphere, the trace of the true tensor kept), and in 2D the exact moment of an
ellipse, I = (a^2 + b^2) / 4 (one rotational axis, so always "spherical"). Rotations then do not
couple to the shape and w is constant between collisions; equilibrium (equation of state,
packings) does not depend on the moments of inertia.

**Growth.** Every semiaxis grows at one relative rate, a(t) = a(0) (1 + kappa t) (as the radii of
the sphere engine), so the relative rate at window time t is g = kappa / (1 + kappa t). The moment
of inertia is kept at its window-start value within a window (it is recomputed at every
synchronisation, where the growing runs rescale the velocities anyway); with kappa = 0 the
dynamics is exactly energy conserving.

**Pair prediction** (Donev 2006, sec. 3.5.1, Algorithm 11). The Perram-Wertheim potential zeta(t)
(> 0 disjoint; :func:`hardpack.geometry.contact.pw_contact`) and its rate (Eq. 2.21,
:func:`hardpack.geometry.contact.pw_rate`) are followed only while the bounding spheres overlap:
the overlap interval [t_in, t_out] of the two growing bounding spheres comes from the same
quadratic as a sphere collision (:func:`hardpack.events.roots.contact_root` for t_in, the other
root for t_out). On it, trace event location. *Safe steps* first (Donev 2006, sec. 3.5.1: jump
ahead with a bound on the rate): every evaluation also gives the width of the slab between the
particles' support planes normal to the contact normal n, r . n^ (1 - 1 / sqrt(1 + zeta)), a lower
bound on the distance of the surfaces; along that fixed n^ the width changes at the rate n^ . (v_j
- v_i) of the centres less the rates of the two support functions (at most c |w x n^| each for a spin w,
:func:`support_rate_bound`, or c |w^perp| for a spheroid, :func:`_spin_rate`) and the growth, so no
contact happens before the safe time
:func:`_safe_time`, and the trace jumps there with one evaluation (no midpoint). When the safe time
is shorter than the step below, an ordinary step: [t0, t0 + h] with zeta and zeta_dot at both ends
define a cubic Hermite interpolant, whose error is estimated at the midpoint, e = |H(1/2) - zeta(t0
+ h/2)|. A step is accepted when e <= max(eps_F, RELATIVE_TOL m) and m > 2 e, with m the
interpolant's minimum over the step (so no dip below zero hides between the samples unless the
interpolant errs by more than twice its estimated error; far from contact, where m is large, the
steps may err by a tenth of m, which keeps them long without any risk of missing the zero);
otherwise h is halved (the midpoint becomes the new end). The next step is h (tol / e)^(1/4) times
0.8, within [h / 2, 4 h]. The first sample with zeta <= zc (the contact level, 0 unless the trace
started in contact) after one with zeta > zc brackets a crossing, which a safeguarded Newton
iteration (bisection when a Newton step leaves the bracket) locates to the round-off of zeta
(|zeta - zc| <= ZETA_TOL, 64 ulps).

*Progress.* Every predicted collision approaches: its zeta_dot is below -GRAZE_RATE times the
pair's rate scale (a bound on the relative speed of the surfaces over the smallest semiaxis), far
above round-off, so the collision law (which skips v_n >= 0) never skips it and the pair separates
after it. A crossing with a smaller rate is a graze: the trace goes on from just past it. If zeta
<= 0 at t_in: a collision now when the pair approaches; otherwise (round-off after a collision of
the pair, or a pair in contact since a graze) the pair is *touching* at the level zc = zeta(t_in)
(Algorithm 11 step d): samples at or below zc that do not approach move the trace on (no bracket
can start from a non-positive sample), and the first one that approaches is the collision (the step
halved to the time resolution to find it). Steps are at least a few ulps of the time and at least
``MIN_STEP_FRACTION`` of the first one (such steps are accepted unconditionally), and a rest of the
interval shorter than that holds no event; after MAX_TRACE_STEPS accepted steps the trace stops
with a CHECK event at the time reached, later than the start: the particle re-predicts from there
(a "safe time", Algorithm 11 step e). The neighbours are searched best first (:func:`_predict`):
each has a lower bound on its collision time, t_in (or, when the bounding spheres overlap already,
the safe time of a slab normal to a guessed direction, :func:`_screen_time`), then that bound plus
the safe time once zeta there is known, then the bound its trace has reached; the pair with the
smallest bound is started there or traced one stretch, until its bound passes the second smallest
(so a pair that does not collide is not traced past the earliest collision of the others), and
the search ends when the smallest bound is after the earliest event found. The horizon of every
trace is also capped by the first contact time of the inscribed spheres (radius the smallest
semiaxis) of any pair whose inscribed spheres are apart: the particle collides by then at the latest
(if no collision is located before it, a CHECK is scheduled there). So every event but a collision
advances the time; the event loop still stops a window as STALLED (an engine failure the driver
reports) after a long run of other events at one time.

**Collision law** (Donev 2006, Algorithm 12, with the signs and the squared lever arms derived
here; the printed update pushes an approaching pair together, see the sphere kernel): with n the
unit normal from A to B at the contact point r_C, the contact velocity
v_C = [v_B + w_B x (r_C - r_B) + g (r_C - r_B)] - [v_A + w_A x (r_C - r_A) + g (r_C - r_A)]
and v_n = n . v_C < 0 for an approaching pair, the impulse J n on B (-J n on A) with
J = -2 v_n / (1/m_A + 1/m_B + |(r_C - r_A) x n|^2 / I_A + |(r_C - r_B) x n|^2 / I_B)
reverses v_n and conserves momentum, angular momentum about any point and, without growth, the
kinetic energy (translational plus rotational): v_B += J n, v_A -= J n,
w_B += J (r_C - r_B) x n / I_B, w_A -= J (r_C - r_A) x n / I_A (2D: the cross products are
scalars). With growth the energy rises by the growth part of v_n, as for spheres. Collisions with
v_n >= 0 are skipped (grazing or mispredicted, Algorithm 12 step 3).

**Walls** (Donev 2006, sec. 3.2.2.1: each axis of the cell periodic or a hard wall; Ch. 7: a
spherical container). A wall is handled as a pair with an immobile partner: its gap h to the
particle (:func:`wall_gap`: the distance from the wall of the particle's support point along the
wall's outward normal, exact and in closed form for a flat wall, R - rho for the container) is
traced as zeta is (:func:`wall_predict`, with the safe time of a bound on its rate), and the
collision law is the pair law with an infinitely massive partner (:func:`wall_collide`). Flat
walls are predicted only once the particle's bounding sphere can reach them.

**Pressure.** The virial accumulates r_AB . J n (centre-to-centre vector, the molecular virial), so
Z = PV/(NkT) = 1 + virial / (2 integral of the translational kinetic energy dt), as for spheres.

**Compilation.** The kernels work on rows and slices of scratch arrays (``ws``, ``wm``, ``pst``),
and every slice is an array view whose creation and release numba's reference counting (NRT)
brackets with atomic increments and decrements of the parent's counter. In the event loop these
took more than half of the run time (measured with ``perf`` on a 2D NVE fluid of N = 2000,
alpha = 1.5). The functions that allocate nothing (all but :func:`run_events`, which allocates
the scratch arrays of :func:`_run`, and the set-up and diagnostic functions) are therefore
compiled without NRT (``_nrt=False``): their views borrow the arrays of the caller, which outlive
them. The arithmetic is unchanged (trajectories are bit-identical); an allocation inside such a
function fails to compile instead of leaking.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hardpack.events.heap import heap_set
from hardpack.events.roots import contact_root, exit_root
from hardpack.geometry.contact import pw_contact_into
from hardpack.geometry.ellipsoid_container import farthest_point_body
from hardpack.md._kernel import (
    A_T,
    A_VIRIAL,
    FLAT_WALLS_MODE,
    I_COLL,
    I_EVENTS,
    I_EXIT,
    I_GRAZE,
    I_STALE,
    PERIODIC_MODE,
    SPHERE_MODE,
    WindowStatus,
    end_window,
    kinetic_step,
    prefetch_next_events,
    update_neighbour_list,
)

EXIT = -1  # event: the particle leaves its bounding sphere
NONE = -2  # nothing predicted
CHECK = -3  # a trace stopped at its step cap: re-predict then (a "safe time")
WALL = -4  # event: the particle hits wall 0 (the spherical container); WALL - w: flat wall w

#: The boundary of this kernel is a run-time code, the length of the sphere kernel's mode tuple,
#: so that one compiled kernel serves every boundary (each compile-time mode would cost another
#: ~80 s of compilation); its branches cost nothing next to a contact-function evaluation.
PERIODIC_CODE, FLAT_WALLS_CODE, SPHERE_CODE = len(PERIODIC_MODE), len(FLAT_WALLS_MODE), len(SPHERE_MODE)

#: what a pair trace (:func:`pair_trace`, :func:`predict_pair`) or a wall search
#: (:func:`wall_predict`) found at the time it returns (plain ints: compile-time constants that
#: numba compares as fast as literals): the collision (or nothing, with time inf); the step cap
#: (predict again from then, a "safe time"); a lower bound at or after the yield time (the trace
#: state is saved); nothing before tmax, which comes before the end of the overlap (saved too)
TRACE_COLLISION, TRACE_CHECK, TRACE_SUSPENDED, TRACE_STOPPED = 0, 1, 2, 3

#: where the best-first search of :func:`_predict_shared` stands with a pair of the list
#: (``done``): NEW, its key the start of the bounding-sphere overlap; STARTED, a trace state, its
#: key the lower bound the trace reached; FINISHED, its event known (or none); SCREENED, its key
#: the slab bound of :func:`_screen_time`; BALL_SCREENED, its key the sphere bound of
#: :func:`_ball_screen_time` (the slab bound comes next); SHARED, a trace state of the other
#: particle of the collided pair (pair functions as (other, i)); SHARED_STOPPED, SHARED stopped by
#: i's earliest event; STOPPED, STARTED stopped by i's earliest event (a shared record keeps its
#: state). The codes from SHARED_STOPPED on are out of the search.
(PAIR_NEW, PAIR_STARTED, PAIR_FINISHED, PAIR_SCREENED, PAIR_BALL_SCREENED, PAIR_SHARED, PAIR_SHARED_STOPPED,
 PAIR_STOPPED) = range(8)

#: the collided pair's search in :func:`_predict_shared` (``shmode``): none; the first particle of
#: the pair searches it and writes the record; the second takes the search from the record
SHARE_NONE, SHARE_WRITE, SHARE_READ = 0, 1, 2


#: extra counters (after the sphere engine's): CHECK events; the particle and partner of the
#: last event of a STALLED window
I_CHECK = 5
I_STALL_PARTICLE = 6
I_STALL_PARTNER = 7
#: wall collisions (container mode)
I_WALL = 8
N_COUNTERS = 9
#: a window stops as STALLED after this many consecutive events at one time without a collision,
#: plus 10 per particle
STALL_EVENTS = 1000
#: extra accumulators: contact-function evaluations; the momentum given to the walls, from A_WALL
#: on: the container wall's in entry A_WALL, that of the two flat walls of axis k in A_WALL + k
A_EVAL = 5
A_WALL = 6
N_ACC = 9

#: default tolerance on the Hermite interpolation error of zeta (Donev 2006, sec. 3.5.1: 1e-4..1e-3)
EPS_F = 1e-4
#: far from contact a step may also err by this fraction of the interpolant's minimum
RELATIVE_TOL = 0.1
#: relative gap (squared distance over squared sum of inscribed radii, minus 1) above which a
#: pair's inscribed-sphere contact caps the prediction horizon
INSCRIBED_GAP = 1e-6
#: accepted trace steps before a CHECK event (Donev 2006, Algorithm 11: 100-250)
MAX_TRACE_STEPS = 200
#: steps shorter than this fraction of the first step of a trace are accepted unconditionally
MIN_STEP_FRACTION = 1e-9
#: first trace step: this fraction of the smallest semiaxis of the pair over its relative speed
FIRST_STEP = 0.25
#: a collision time is located when |zeta| is below this (64 ulps; the round-off of zeta is a few)
ZETA_TOL = 64.0 * np.finfo(np.float64).eps
#: approach rates zeta_dot above -GRAZE_RATE times the pair's rate scale (relative surface speed
#: bound over the smallest semiaxis) are grazing: no collision is predicted there
GRAZE_RATE = 1e-9
EPS = np.finfo(np.float64).eps


@njit(cache=True, inline="always", _nrt=False)
def columns(d):
    """Column offsets of a row of P: (velocity, time, bounding radius, semiaxes, orientation,
    angular velocity, inverse inertia, width).

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    tuple of 8 int
        Offsets cv, ct, cr, cax, cor, cw, cii and the row width ``ncol(d)``.
    """
    no = 4 if d == 3 else 1
    nw = 3 if d == 3 else 1
    cax = 2 * d + 2
    cor = cax + d
    cw = cor + no
    cii = cw + nw
    return d, 2 * d, 2 * d + 1, cax, cor, cw, cii, cii + 1


def ncol(d: int) -> int:
    """Width of a row of P in d dimensions (19 in 3D, 11 in 2D).

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    int
        Number of columns of P.
    """
    return columns(d)[7]


@njit(cache=True, inline="always", _nrt=False)
def orientation_at(P, i, t, out):
    """Orientation of particle i at window time t (Algorithm 1, module docstring) into ``out``.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (module docstring).
    i : int
        The particle.
    t : float
        Window time.
    out : numpy.ndarray of float64, shape (>= 4,) in 3D, (>= 1,) in 2D
        Receives the unit quaternion (s, p_1, p_2, p_3) in 3D, the angle in 2D.
    """
    d = 2 if P.shape[1] == 11 else 3
    _, ct, _, _, cor, cw, _, _ = columns(d)
    dt = t - P[i, ct]
    if d == 2:
        out[0] = P[i, cor] + P[i, cw] * dt
        return
    w0, w1, w2 = P[i, cw], P[i, cw + 1], P[i, cw + 2]
    wn = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    s, p1, p2, p3 = P[i, cor], P[i, cor + 1], P[i, cor + 2], P[i, cor + 3]
    if wn == 0.0 or dt == 0.0:
        out[0], out[1], out[2], out[3] = s, p1, p2, p3
        return
    half = 0.5 * wn * dt
    c = np.cos(half)
    f = np.sin(half) / wn
    a1, a2, a3 = f * w0, f * w1, f * w2
    # [c, a] [s, p] = [c s - a.p, c p + s a + a x p]  (Donev 2006, Eq. 1.9)
    out[0] = c * s - (a1 * p1 + a2 * p2 + a3 * p3)
    out[1] = c * p1 + s * a1 + (a2 * p3 - a3 * p2)
    out[2] = c * p2 + s * a2 + (a3 * p1 - a1 * p3)
    out[3] = c * p3 + s * a3 + (a1 * p2 - a2 * p1)


@njit(cache=True, _nrt=False)
def advance(P, i, t, scratch):
    """Move particle i to window time t (position and orientation) and set t_i = t.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, row i modified in place.
    i : int
        The particle.
    t : float
        Window time.
    scratch : numpy.ndarray of float64, shape (>= 4,)
        Scratch for the orientation.
    """
    d = 2 if P.shape[1] == 11 else 3
    cv, ct, _, _, cor, _, _, _ = columns(d)
    dt = t - P[i, ct]
    if dt == 0.0:
        return
    orientation_at(P, i, t, scratch)
    no = 4 if d == 3 else 1
    for k in range(no):
        P[i, cor + k] = scratch[k]
    for k in range(d):
        P[i, k] += P[i, cv + k] * dt
    P[i, ct] = t


@njit(cache=True)
def work_arrays(d):
    """Scratch arrays (ws, wm) of :func:`pair_zeta` and the kernels that call it: ws (12, 4) with
    row 8 zeros, wm (4, d, d) (ws[11] and wm[2] hold the pose of the particle that
    :func:`_predict` screens for).

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    ws : numpy.ndarray of float64, shape (12, 4)
        Zeroed vector scratch (row 8 must stay zero: the null shift).
    wm : numpy.ndarray of float64, shape (4, d, d)
        Matrix scratch.
    """
    return np.zeros((12, 4)), np.empty((4, d, d))


@njit(cache=True, inline="always", _nrt=False)
def _pose(P, i, t, kappa, shift, ws, row, wm, mi):
    """Centre (plus ``shift``) of particle i at window time t into ws[row, :d] and its inverse
    shape matrix X^-1 into wm[mi]: :func:`orientation_at` and
    :func:`hardpack.geometry.contact.shape_inverse_into` on scalars (no scratch arrays)."""
    d = 2 if P.shape[1] == 11 else 3
    cv, ct, _, cax, cor, cw, _, _ = columns(d)
    dt = t - P[i, ct]
    grow = 1.0 + kappa * t
    for k in range(d):
        ws[row, k] = P[i, k] + P[i, cv + k] * dt + shift[k]
    if d == 2:
        phi = P[i, cor] + P[i, cw] * dt
        c, s = np.cos(phi), np.sin(phi)
        a0, a1 = P[i, cax] * grow, P[i, cax + 1] * grow
        a2, b2 = a0 * a0, a1 * a1
        wm[mi, 0, 0] = c * c * a2 + s * s * b2
        wm[mi, 1, 1] = s * s * a2 + c * c * b2
        wm[mi, 0, 1] = wm[mi, 1, 0] = c * s * (a2 - b2)
        return
    s, p1, p2, p3 = P[i, cor], P[i, cor + 1], P[i, cor + 2], P[i, cor + 3]
    w0, w1, w2 = P[i, cw], P[i, cw + 1], P[i, cw + 2]
    wn = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if wn != 0.0 and dt != 0.0:
        half = 0.5 * wn * dt
        c = np.cos(half)
        f = np.sin(half) / wn
        a1, a2, a3 = f * w0, f * w1, f * w2
        # [c, a] [s, p] = [c s - a.p, c p + s a + a x p]  (Donev 2006, Eq. 1.9)
        s, p1, p2, p3 = (c * s - (a1 * p1 + a2 * p2 + a3 * p3), c * p1 + s * a1 + (a2 * p3 - a3 * p2),
                         c * p2 + s * a2 + (a3 * p1 - a1 * p3), c * p3 + s * a3 + (a1 * p2 - a2 * p1))
    diag = s * s - 0.5
    q00, q01, q02 = 2 * (p1 * p1 + diag), 2 * (p1 * p2 + s * p3), 2 * (p1 * p3 - s * p2)
    q10, q11, q12 = 2 * (p2 * p1 - s * p3), 2 * (p2 * p2 + diag), 2 * (p2 * p3 + s * p1)
    q20, q21, q22 = 2 * (p3 * p1 + s * p2), 2 * (p3 * p2 - s * p1), 2 * (p3 * p3 + diag)
    e0, e1, e2 = P[i, cax] * grow, P[i, cax + 1] * grow, P[i, cax + 2] * grow
    a0, a1, a2 = e0 * e0, e1 * e1, e2 * e2
    u00, u01, u02 = a0 * q00, a0 * q01, a0 * q02
    u10, u11, u12 = a1 * q10, a1 * q11, a1 * q12
    u20, u21, u22 = a2 * q20, a2 * q21, a2 * q22
    wm[mi, 0, 0] = q00 * u00 + q10 * u10 + q20 * u20
    wm[mi, 1, 1] = q01 * u01 + q11 * u11 + q21 * u21
    wm[mi, 2, 2] = q02 * u02 + q12 * u12 + q22 * u22
    wm[mi, 0, 1] = wm[mi, 1, 0] = q00 * u01 + q10 * u11 + q20 * u21
    wm[mi, 0, 2] = wm[mi, 2, 0] = q00 * u02 + q10 * u12 + q20 * u22
    wm[mi, 1, 2] = wm[mi, 2, 1] = q01 * u02 + q11 * u12 + q21 * u22


@njit(cache=True, _nrt=False)
def pair_zeta(P, i, j, shift, t, kappa, lam0, ws, wm):
    """(zeta, zeta_dot, lambda) of particles i and j (j shifted by ``shift``) at window time t.

    ``ws`` (row 8 zeros, ws[10, 0] counts the evaluations) and ``wm`` are the scratch arrays of
    :func:`work_arrays`; on return ws[0, :d],
    ws[1, :d] hold the centres, ws[4, :d] the contact point, ws[5, :d] the normal n, wm[0],
    wm[1] the inverse shape matrices, ws[10, 1] the width of the slab between the particles'
    support planes normal to n, r . n / |n| (1 - 1 / sqrt(1 + zeta)), a lower bound on the distance
    of the surfaces (0 unless zeta > 0), ws[10, 2] the rate n . (v_j - v_i) / |n| at which the
    centres separate along n and ws[10, 3] the bound on the rate of
    the support functions along n^ from the spins (:func:`_spin_rate`; for
    :func:`_safe_time`).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (read only).
    i, j : int
        The particles.
    shift : numpy.ndarray of float64, shape (d,)
        Periodic shift added to j's position.
    t : float
        Window time.
    kappa : float
        Relative growth rate of the semiaxes.
    lam0 : float
        Starting guess of the Perram-Wertheim parameter lambda in (0, 1).
    ws, wm : numpy.ndarray
        Scratch of :func:`work_arrays`, outputs as above.

    Returns
    -------
    zeta : float
        Perram-Wertheim overlap potential mu^2 - 1 (> 0 disjoint; Donev 2006, sec. 2.2.2.1).
    zeta_dot : float
        Its time derivative (Donev 2006, Eq. 2.21).
    lam : float
        The maximising lambda.
    """
    d = shift.shape[0]
    cv, _, _, _, _, cw, _, _ = columns(d)
    xa, xb, rc = ws[0, :d], ws[1, :d], ws[4, :d]
    _pose(P, i, t, kappa, ws[8], ws, 0, wm, 0)
    _pose(P, j, t, kappa, shift, ws, 1, wm, 1)
    r = ws[7, :d]
    for k in range(d):
        r[k] = xb[k] - xa[k]
    n = ws[5, :d]
    zeta, lam, _ = pw_contact_into(r, wm[0], wm[1], lam0, n)
    ws[10, 0] += 1.0
    mu = 1.0 - lam
    for k in range(d):  # the contact point (:func:`hardpack.geometry.contact.contact_point`)
        acc = 0.0
        for m in range(d):
            acc += wm[0, k, m] * n[m]
        rc[k] = xa[k] + mu * acc
    rn = 0.0
    nn = 0.0
    nv = 0.0
    for k in range(d):
        rn += r[k] * n[k]
        nn += n[k] * n[k]
        nv += n[k] * (P[j, cv + k] - P[i, cv + k])
    nn = np.sqrt(nn)
    ws[10, 1] = rn / nn * (1.0 - 1.0 / np.sqrt(1.0 + zeta)) if zeta > 0.0 else 0.0
    ws[10, 2] = nv / nn
    ws[10, 3] = _spin_rate(P, i, n, nn) + _spin_rate(P, j, n, nn)
    # zeta_dot = 2 lam (1 - lam) n . v_C (Donev 2006, Eq. 2.21; :func:`hardpack.geometry.contact.pw_rate`)
    g = kappa / (1.0 + kappa * t)
    if d == 2:
        vc = P[j, cw] * ((rc[0] - xb[0]) * n[1] - (rc[1] - xb[1]) * n[0]) \
            - P[i, cw] * ((rc[0] - xa[0]) * n[1] - (rc[1] - xa[1]) * n[0])
    else:
        b0, b1, b2 = rc[0] - xb[0], rc[1] - xb[1], rc[2] - xb[2]
        a0, a1, a2 = rc[0] - xa[0], rc[1] - xa[1], rc[2] - xa[2]
        wb0, wb1, wb2 = P[j, cw], P[j, cw + 1], P[j, cw + 2]
        wa0, wa1, wa2 = P[i, cw], P[i, cw + 1], P[i, cw + 2]
        vc = (n[0] * (wb1 * b2 - wb2 * b1) + n[1] * (wb2 * b0 - wb0 * b2) + n[2] * (wb0 * b1 - wb1 * b0)) \
            - (n[0] * (wa1 * a2 - wa2 * a1) + n[1] * (wa2 * a0 - wa0 * a2) + n[2] * (wa0 * a1 - wa1 * a0))
    for k in range(d):
        vc += n[k] * (P[j, cv + k] - P[i, cv + k] + g * (rc[k] - xb[k]) - g * (rc[k] - xa[k]))
    zdot = 2.0 * lam * (1.0 - lam) * vc
    return zeta, zdot, lam


@njit(cache=True, inline="always", _nrt=False)
def _hermite_min(z0, z1, d0, d1):
    """Minimum over s in (0, 1] of the cubic Hermite interpolant with values z0, z1 and
    derivatives d0, d1 (per unit s) at s = 0, 1."""
    # H(s) = z0 + d0 s + c2 s^2 + c3 s^3
    c2 = 3.0 * (z1 - z0) - 2.0 * d0 - d1
    c3 = 2.0 * (z0 - z1) + d0 + d1
    hmin = z1
    # critical points: d0 + 2 c2 s + 3 c3 s^2 = 0
    qa, qb, qc = 3.0 * c3, 2.0 * c2, d0
    if qa == 0.0:
        if qb != 0.0:
            s = -qc / qb
            if 0.0 < s < 1.0:
                hmin = min(hmin, z0 + s * (d0 + s * (c2 + s * c3)))
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            sq = np.sqrt(disc)
            for s in ((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)):
                if 0.0 < s < 1.0:
                    hmin = min(hmin, z0 + s * (d0 + s * (c2 + s * c3)))
    return hmin


@njit(cache=True, _nrt=False)
def _hermite_root(z0, z1, d0, d1):
    """First root s in (0, 1] of the cubic Hermite interpolant of :func:`_hermite_min` (z0 > 0),
    or 2.0 when it stays positive: the first sign change on a grid of 16, then safeguarded Newton
    on the cubic inside that cell (bisection when a step leaves it) to a few ulps of s."""
    c2 = 3.0 * (z1 - z0) - 2.0 * d0 - d1
    c3 = 2.0 * (z0 - z1) + d0 + d1
    prev = 0.0
    m = 16
    for q in range(1, m + 1):
        s = q / m
        if z0 + s * (d0 + s * (c2 + s * c3)) <= 0.0:
            lo, hi = prev, s
            x = hi
            for _ in range(60):
                f = z0 + x * (d0 + x * (c2 + x * c3))
                if f <= 0.0:
                    hi = x
                else:
                    lo = x
                fp = d0 + x * (2.0 * c2 + 3.0 * x * c3)
                nx = x - f / fp if fp != 0.0 else -1.0
                if lo <= nx <= hi and abs(nx - x) <= 4.0 * EPS:
                    return nx
                if not (lo < nx < hi):
                    nx = 0.5 * (lo + hi)
                if hi - lo <= 4.0 * EPS:
                    break
                x = nx
            return hi
        prev = s
    return 2.0


@njit(cache=True, _nrt=False)
def _refine(P, i, j, shift, t, kappa, zc, lo, dlo, hi, zhi, dhi, lamhi, guess, lam, ws, wm):
    """First crossing of zeta = zc in the bracket [lo, hi] (zeta(lo) >= zc >= zeta(hi); ``dlo``,
    ``dhi`` the rates at the ends) by safeguarded Newton from ``guess`` (bisection when a step
    leaves the bracket). Returns (t_c, rate at t_c, hi, zeta(hi), rate at hi, lambda at hi) for
    the final bracket: t_c is a time with |zeta - zc| <= ZETA_TOL (the round-off of zeta, which
    Newton cannot improve on), or with zeta >= zc and a Newton step below round-off of the time,
    or the earlier end of a bracket narrowed to round-off; hi the later end."""
    tt = guess if lo < guess < hi else 0.5 * (lo + hi)
    for _ in range(100):
        z, zd, lam = pair_zeta(P, i, j, shift, t + tt, kappa, lam, ws, wm)
        f = z - zc
        if f >= 0.0:
            lo, dlo = tt, zd
        else:
            hi, zhi, dhi, lamhi = tt, z, zd, lam
        if abs(f) <= ZETA_TOL:
            return tt, zd, hi, zhi, dhi, lamhi
        nt = tt - f / zd if zd != 0.0 else -1.0
        if f >= 0.0 and abs(nt - tt) <= 4e-16 * (t + tt):
            break
        if hi - lo <= 4e-16 * (t + hi) + 1e-300:
            break
        if not (lo < nt < hi):
            nt = 0.5 * (lo + hi)
        if nt == tt:
            break
        tt = nt
    return lo, dlo, hi, zhi, dhi, lamhi


@njit(cache=True, inline="always", _nrt=False)
def _safe_time(gap, sep_rate, spin, grow_speed, kappa, t):
    """Time from window time t during which a pair cannot touch: the width ``gap`` of the slab
    between the particles' support planes normal to a fixed unit vector u is a lower bound on the
    distance of the surfaces at all times; it grows at the rate ``sep_rate`` = u . (v_j - v_i) of
    the centres less the rates of the support functions h(u) = sqrt(u^T X^-1 u), each at most
    c |w x u| (1 + kappa t') for a spin w (``spin`` = c_i |w_i x u| + c_j |w_j x u|,
    c = a_max - a_min at the window start: derived in :func:`support_rate_bound`; a spheroid's
    term may be c |w^perp| instead, :func:`_spin_rate`)
    plus |kappa| R for the growth (``grow_speed``). The first root of
    gap - (grow_speed + spin (1 + kappa t) - sep_rate) s - spin kappa s^2 / 2 = 0, or inf."""
    if gap <= 0.0:
        return 0.0
    s0 = grow_speed + spin * (1.0 + kappa * t) - sep_rate
    a = 0.5 * spin * kappa
    if a > 0.0:  # the positive root, each form without cancellation
        sq = np.sqrt(s0 * s0 + 4.0 * a * gap)
        return 2.0 * gap / (s0 + sq) if s0 >= 0.0 else (sq - s0) / (2.0 * a)
    if s0 <= 0.0:
        return np.inf
    return gap / s0


@njit(cache=True, _nrt=False)
def _screen_time(P, i, j, shift, t, kappa, ws, wm):
    """A lower bound on the time from window time t to the first contact of i and j (shifted),
    without the Perram-Wertheim maximisation: the slab between the support planes normal to
    u = Y(lam)^-1 r for the guess lam = h_i / (h_i + h_j) (h the support functions along r, exact
    for spheres) bounds their distance from below (any u does; this one is nearly the contact
    normal), and :func:`_safe_time` turns its width into a time. 0 when the slab is empty. The
    pose of i at t is in ws[11], wm[2] (:func:`_pose`); ws[1], ws[5:8], wm[1], wm[3] are
    overwritten."""
    d = shift.shape[0]
    cv, _, cr, _, _, _, _, _ = columns(d)
    xi, mi, xj, mj = ws[11, :d], wm[2], ws[1, :d], wm[1]
    _pose(P, j, t, kappa, shift, ws, 1, wm, 1)
    r = ws[7, :d]
    for k in range(d):
        r[k] = xj[k] - xi[k]
    hi = np.sqrt(_quad(mi, r))
    hj = np.sqrt(_quad(mj, r))
    lam = hi / (hi + hj)
    y = wm[3]
    for a in range(d):
        for b in range(d):
            y[a, b] = lam * mj[a, b] + (1.0 - lam) * mi[a, b]
    u = ws[5, :d]
    _adjugate_times(y, r, u)  # along Y^-1 r (det Y > 0)
    uu = 0.0
    for a in range(d):
        uu += u[a] * u[a]
    uu = 1.0 / np.sqrt(uu)
    ur = 0.0
    sep = 0.0
    for a in range(d):
        u[a] *= uu
        ur += u[a] * r[a]
        sep += u[a] * (P[j, cv + a] - P[i, cv + a])
    width = ur - np.sqrt(_quad(mi, u)) - np.sqrt(_quad(mj, u))
    if width <= 0.0:
        return 0.0
    spin = _spin_rate(P, i, u, 1.0) + _spin_rate(P, j, u, 1.0)
    return _safe_time(width, sep, spin, abs(kappa) * (P[i, cr] + P[j, cr]), kappa, t)


@njit(cache=True, inline="always", _nrt=False)
def _ball_screen_time(P, i, j, shift, t, kappa, ws, wm):
    """A cheaper and weaker lower bound than :func:`_screen_time` (no pose of j): the slab between
    the support plane of i normal to the centre line and the bounding sphere of j (radius R_j,
    turning does not move it), turned into a time by :func:`_safe_time` with the spin of i only.
    0 when the slab is empty. The pose of i at t is in ws[11], wm[2]; ws[7] is overwritten."""
    d = shift.shape[0]
    cv, ct, cr, _, _, _, _, _ = columns(d)
    xi, mi = ws[11, :d], wm[2]
    r = ws[7, :d]
    dtj = t - P[j, ct]
    rr = 0.0
    for k in range(d):
        r[k] = P[j, k] + P[j, cv + k] * dtj + shift[k] - xi[k]
        rr += r[k] * r[k]
    rn = np.sqrt(rr)
    width = rn - np.sqrt(_quad(mi, r)) / rn - P[j, cr] * (1.0 + kappa * t)
    if width <= 0.0:
        return 0.0
    sep = 0.0
    for k in range(d):
        r[k] /= rn
        sep += r[k] * (P[j, cv + k] - P[i, cv + k])
    return _safe_time(width, sep, _spin_rate(P, i, r, 1.0), abs(kappa) * (P[i, cr] + P[j, cr]), kappa, t)


@njit(cache=True, inline="always", _nrt=False)
def _quad(m, x):
    """x^T m x for a symmetric m (its upper triangle)."""
    if x.shape[0] == 2:
        return m[0, 0] * x[0] * x[0] + m[1, 1] * x[1] * x[1] + 2.0 * m[0, 1] * x[0] * x[1]
    return m[0, 0] * x[0] * x[0] + m[1, 1] * x[1] * x[1] + m[2, 2] * x[2] * x[2] \
        + 2.0 * (m[0, 1] * x[0] * x[1] + m[0, 2] * x[0] * x[2] + m[1, 2] * x[1] * x[2])


@njit(cache=True, inline="always", _nrt=False)
def _adjugate_times(y, r, out):
    """out = adj(y) r = det(y) y^-1 r for a symmetric 2 x 2 or 3 x 3 y (its upper triangle)."""
    if r.shape[0] == 2:
        out[0] = y[1, 1] * r[0] - y[0, 1] * r[1]
        out[1] = y[0, 0] * r[1] - y[0, 1] * r[0]
        return
    y00, y01, y02, y11, y12, y22 = y[0, 0], y[0, 1], y[0, 2], y[1, 1], y[1, 2], y[2, 2]
    c00 = y11 * y22 - y12 * y12
    c01 = y12 * y02 - y01 * y22
    c02 = y01 * y12 - y11 * y02
    c11 = y00 * y22 - y02 * y02
    c12 = y02 * y01 - y00 * y12
    c22 = y00 * y11 - y01 * y01
    out[0] = c00 * r[0] + c01 * r[1] + c02 * r[2]
    out[1] = c01 * r[0] + c11 * r[1] + c12 * r[2]
    out[2] = c02 * r[0] + c12 * r[1] + c22 * r[2]


@njit(cache=True, inline="always", _nrt=False)
def _back_safe_time(gap, sep_rate, spin, grow_speed, kappa, t0, t1):
    """Time before window time t1 (back to t0 at most) during which a pair whose slab width at t1
    is ``gap`` cannot have touched: :func:`_safe_time` run backwards, with the largest rate on
    [t0, t1]."""
    if gap <= 0.0:
        return 0.0
    s = grow_speed + spin * max(1.0 + kappa * t0, 1.0 + kappa * t1) + sep_rate
    return gap / s if s > 0.0 else np.inf


@njit(cache=True, inline="always", _nrt=False)
def _spin_across(P, i, n, nn):
    """|w_i x n| / nn: the part of the spin of i that turns the direction n (norm nn); |w_i| in 2D."""
    d = n.shape[0]
    _, _, _, _, _, cw, _, _ = columns(d)
    if d == 2:
        return abs(P[i, cw])
    w0, w1, w2 = P[i, cw], P[i, cw + 1], P[i, cw + 2]
    c0 = w1 * n[2] - w2 * n[1]
    c1 = w2 * n[0] - w0 * n[2]
    c2 = w0 * n[1] - w1 * n[0]
    return np.sqrt(c0 * c0 + c1 * c1 + c2 * c2) / nn


@njit(cache=True, inline="always", _nrt=False)
def _spin_rate(P, i, n, nn):
    """Bound on |dh/dt| from the spin of i for the support function h(u) of i along the fixed
    unit vector u = n / nn: c_i |w_i x u| (:func:`support_rate_bound`), and for a spheroid
    (two equal semiaxes) at most c_i |w_i^perp|, w_i^perp the part of the spin normal to the
    symmetry axis e_i.

    Derived here: X^-1 = a_eq^2 I + (a_s^2 - a_eq^2) e e^T for a spheroid, so its rate under the
    spin, (a_s^2 - a_eq^2)(de/dt e^T + e de/dt^T) with de/dt = w x e = w^perp x e, is the same
    for w and w^perp: the bound of :func:`support_rate_bound` holds with w^perp, |dh/dt| <=
    c |w^perp x u| <= c |w^perp|. Under free rotation at a constant w, e turns about w, so
    w . e and |w^perp| = sqrt(|w|^2 - (w . e)^2) are constant over the whole flight (computed
    from the stored orientation). In 2D, and for triaxial ellipsoids, c_i |w_i x u|."""
    d = n.shape[0]
    c = support_rate_bound(P, i, d)
    across = _spin_across(P, i, n, nn)
    if d == 2 or c == 0.0:
        return c * across
    _, _, _, cax, cor, cw, _, _ = columns(d)
    a0, a1, a2 = P[i, cax], P[i, cax + 1], P[i, cax + 2]
    if a1 == a2:
        k = 0
    elif a0 == a2:
        k = 1
    elif a0 == a1:
        k = 2
    else:
        return c * across
    s, p1, p2, p3 = P[i, cor], P[i, cor + 1], P[i, cor + 2], P[i, cor + 3]
    diag = s * s - 0.5
    # row k of the rotation of :func:`_pose` (X^-1 = Q^T diag(a^2) Q): body axis k in the lab
    if k == 0:
        e0, e1, e2 = 2 * (p1 * p1 + diag), 2 * (p1 * p2 + s * p3), 2 * (p1 * p3 - s * p2)
    elif k == 1:
        e0, e1, e2 = 2 * (p2 * p1 - s * p3), 2 * (p2 * p2 + diag), 2 * (p2 * p3 + s * p1)
    else:
        e0, e1, e2 = 2 * (p3 * p1 + s * p2), 2 * (p3 * p2 - s * p1), 2 * (p3 * p3 + diag)
    w0, w1, w2 = P[i, cw], P[i, cw + 1], P[i, cw + 2]
    we = w0 * e0 + w1 * e1 + w2 * e2
    ee = e0 * e0 + e1 * e1 + e2 * e2  # 1 up to the round-off of the stored quaternion
    perp = np.sqrt(max(w0 * w0 + w1 * w1 + w2 * w2 - we * we / ee, 0.0))
    return c * min(across, perp * (1.0 + 1e-12))


@njit(cache=True, inline="always", _nrt=False)
def support_rate_bound(P, i, d):
    """c_i = a_max - a_min with the window-start semiaxes: |dh/dt| <= c_i |w_i x u| for the
    support function h(u) = sqrt(u^T X^-1 u) of particle i along a fixed unit vector u while it
    spins at w_i.

    Derived here: with M = X^-1, dM/dt = W M - M W, so d(u^T M u)/dt = -2 (w x u) . (M u) and
    dh/dt = -(w x u) . (M u) / h, the speed along u of the support point p = M u / h turning about
    the centre; w x u is normal to u, so |dh/dt| <= |w x u| |p_perp|, p_perp the part of p normal
    to u. In the body frame (M = diag(a_k^2), weights x_k = u_k^2 summing to 1),
    |p_perp|^2 = (sum a_k^4 x_k - (sum a_k^2 x_k)^2) / sum a_k^2 x_k, the variance over the mean
    of a_k^2 under the weights x. For a mean m the variance is at most (a_max^2 - m)(m - a_min^2)
    (all weight on the extreme semiaxes), and (a_max^2 - m)(m - a_min^2) / m is largest at
    m = a_max a_min, where it equals (a_max - a_min)^2: so |p_perp| <= a_max - a_min, attained
    in the plane of the longest and shortest semiaxes (the support function of an ellipse turns
    fastest there). A spin about u does not change h(u).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows.
    i : int
        The particle.
    d : int
        Dimension.

    Returns
    -------
    float
        a_max - a_min of its window-start semiaxes.
    """
    _, _, _, cax, _, _, _, _ = columns(d)
    amin = P[i, cax]
    amax = P[i, cax]
    for k in range(1, d):
        amin = min(amin, P[i, cax + k])
        amax = max(amax, P[i, cax + k])
    return amax - amin


#: length of a pair's trace state (:func:`pair_start`)
PAIR_STATE = 14


@njit(cache=True, _nrt=False)
def pair_start(P, i, j, shift, t, tin, kappa, ws, wm, st):
    """Start of the trace of i and j (shifted) at window time t + tin: zeta there and the pair's
    constants into the state row ``st`` (PAIR_STATE entries) that :func:`pair_trace` continues.
    Returns (lower bound on the collision time, relative to t; True for a collision now). The
    bound is t_in plus the safe time of the distance bound (:func:`_safe_time`), or t_in for a
    touching pair. A pair that starts in contact or overlapping (round-off after its collision,
    or a missed collision) collides now if it approaches (rate below -rate_tol); otherwise it is
    "touching" at the contact level zc = zeta(t_in): it collides only when it approaches at or
    below that level (Donev 2006, Algorithm 11 step d).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (read only).
    i, j : int
        The particles.
    shift : numpy.ndarray of float64, shape (d,)
        Periodic shift added to j's position.
    t : float
        Window time of the prediction.
    tin : float
        Start of the bounding spheres' overlap, relative to t.
    kappa : float
        Relative growth rate of the semiaxes.
    ws, wm : numpy.ndarray
        Scratch of :func:`work_arrays`.
    st : numpy.ndarray of float64, shape (PAIR_STATE,)
        Receives the trace state.

    Returns
    -------
    lower : float
        Lower bound on the collision time relative to t (inf when nothing moves).
    now : bool
        Whether the pair collides at t + tin.
    """
    d = shift.shape[0]
    cv, _, cr, cax, _, cw, _, _ = columns(d)
    lam = P[i, cr] / (P[i, cr] + P[j, cr])
    z0, d0, lam = pair_zeta(P, i, j, shift, t + tin, kappa, lam, ws, wm)
    gap0, sep0, spin0 = ws[10, 1], ws[10, 2], ws[10, 3]
    # rate scale: bound on the relative speed of the surfaces over the smallest semiaxis
    amin = P[i, cax]
    for k in range(1, d):
        amin = min(amin, P[i, cax + k])
    for k in range(d):
        amin = min(amin, P[j, cax + k])
    amin *= 1.0 + kappa * (t + tin)
    uu = 0.0
    for k in range(d):
        du = P[j, cv + k] - P[i, cv + k]
        uu += du * du
    ww_i = 0.0
    ww_j = 0.0
    nw = 3 if d == 3 else 1
    for k in range(nw):
        ww_i += P[i, cw + k] ** 2
        ww_j += P[j, cw + k] ** 2
    grow_speed = abs(kappa) * (P[i, cr] + P[j, cr])
    speed = np.sqrt(uu) + (np.sqrt(ww_i) * P[i, cr] + np.sqrt(ww_j) * P[j, cr] + grow_speed) \
        * (1.0 + kappa * (t + tin))
    rate_tol = GRAZE_RATE * speed / amin
    zc = 0.0
    touching = 0.0
    if z0 <= 0.0:
        if d0 < -rate_tol:
            return tin, True
        zc = z0
        touching = 1.0
    h = FIRST_STEP * amin / speed if speed > 0.0 else np.inf
    st[0], st[1], st[2], st[3], st[4], st[5], st[6] = tin, z0, d0, lam, gap0, sep0, zc
    st[7], st[8], st[9], st[10], st[11], st[12] = touching, spin0, grow_speed, rate_tol, h, MIN_STEP_FRACTION * h
    st[13] = 0.0
    if speed == 0.0:  # nothing moves: zeta is constant
        return np.inf, False
    if touching:
        return tin, False
    return tin + _safe_time(gap0, sep0, spin0, grow_speed, kappa, t + tin), False


@njit(cache=True)
def predict_pair(P, i, j, shift, t, tmax, tin, tout, kappa, eps_f, ws, wm):
    """Earliest collision of i and j (shifted) in window time [t + tin, min(t + tout, tmax)) by
    trace event location (module docstring): :func:`pair_start` and :func:`pair_trace`. Returns
    (time, kind) with kind TRACE_COLLISION or TRACE_CHECK, and time inf when nothing happens before
    the end.
    A returned collision always approaches: its rate zeta_dot is below -GRAZE_RATE times the
    pair's rate scale (the relative surface speed bound over the smallest semiaxis), so the
    collision law never skips it for round-off.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (read only).
    i, j : int
        The particles.
    shift : numpy.ndarray of float64, shape (d,)
        Periodic shift added to j's position.
    t : float
        Window time of the prediction.
    tmax : float
        Window time at which the search stops.
    tin, tout : float
        Overlap interval of the bounding spheres, relative to t.
    kappa : float
        Relative growth rate of the semiaxes.
    eps_f : float
        Tolerance on the Hermite interpolation error of zeta (module docstring).
    ws, wm : numpy.ndarray
        Scratch of :func:`work_arrays`.

    Returns
    -------
    time : float
        Window time of the event, inf for none.
    kind : int
        TRACE_COLLISION or TRACE_CHECK.
    """
    st = np.empty(PAIR_STATE)
    lower, now = pair_start(P, i, j, shift, t, tin, kappa, ws, wm, st)
    if now:
        return t + tin, TRACE_COLLISION
    if lower >= min(tout, tmax - t):
        return np.inf, TRACE_COLLISION
    tc, kind = pair_trace(P, i, j, shift, t, tmax, tout, kappa, eps_f, ws, wm, st, np.inf)
    return (np.inf, TRACE_COLLISION) if kind == TRACE_STOPPED else (tc, kind)


@njit(cache=True, _nrt=False)
def pair_trace(P, i, j, shift, t, tmax, tout, kappa, eps_f, ws, wm, st, tyield):
    """Trace of i and j (shifted) from the state ``st`` of :func:`pair_start` to
    min(t + tout, tmax): (time, kind) as :func:`predict_pair`, or, after at least one step, a
    suspension (lower bound on the collision time, 2) as soon as that lower bound (the time
    reached plus its safe time) is at or after window time ``tyield``; ``st`` then holds the state
    to continue from. When tmax comes before t + tout and no event is found before it, the state
    is saved as well and the result is (lower bound, 3): nothing before tmax, a trace to a later
    tmax may continue from ``st``.

    Parameters
    ----------
    P, i, j, shift, t, tmax, tout, kappa, eps_f, ws, wm
        As in :func:`predict_pair`.
    st : numpy.ndarray of float64, shape (PAIR_STATE,)
        Trace state of :func:`pair_start` or of a suspended trace, updated on a suspension or a
        stop at tmax.
    tyield : float
        Window time from which the trace suspends (inf: never).

    Returns
    -------
    time : float
        Window time of the event or suspension bound, inf for none.
    kind : int
        TRACE_COLLISION, TRACE_CHECK, TRACE_SUSPENDED or TRACE_STOPPED.
    """
    end = min(tout, tmax - t)
    t0, z0, d0, lam, gap0, sep0, zc = st[0], st[1], st[2], st[3], st[4], st[5], st[6]
    touching = st[7] != 0.0
    spin0, grow_speed, rate_tol, h, hmin_step = st[8], st[9], st[10], st[11], st[12]
    if h == np.inf:  # nothing moves
        return np.inf, TRACE_COLLISION
    steps = int(st[13])
    steps0 = steps
    while True:
        # the shortest step moves the time by a few ulps: a rest of the interval shorter than
        # that holds no event the time can resolve, and every CHECK advances the time
        hfloor = max(hmin_step, 8.0 * EPS * abs(t + t0))
        if end - t0 <= hfloor:
            if end < tout:
                st[0], st[1], st[2], st[3], st[4], st[5], st[6] = t0, z0, d0, lam, gap0, sep0, zc
                st[7], st[8], st[11], st[13] = 1.0 if touching else 0.0, spin0, h, steps
                return t + t0, TRACE_STOPPED
            return np.inf, TRACE_COLLISION
        if steps >= MAX_TRACE_STEPS:
            return t + t0, TRACE_CHECK
        # a safe step: no contact before the distance bound is used up (Donev 2006, sec. 3.5.1)
        safe = _safe_time(gap0, sep0, spin0, grow_speed, kappa, t + t0)
        if t0 + safe >= end or (steps > steps0 and t + t0 + safe >= tyield):
            if t0 + safe < end or end < tout:
                st[0], st[1], st[2], st[3], st[4], st[5], st[6] = t0, z0, d0, lam, gap0, sep0, zc
                st[7], st[8], st[11], st[13] = 1.0 if touching else 0.0, spin0, h, steps
                return t + t0 + safe, TRACE_SUSPENDED if t0 + safe < end else TRACE_STOPPED
            return np.inf, TRACE_COLLISION
        h = min(max(h, hfloor), end - t0)
        if safe > h:
            t1 = t0 + safe
            z1, d1, lam1 = pair_zeta(P, i, j, shift, t + t1, kappa, lam, ws, wm)
            if z1 > zc:
                steps += 1
                t0, z0, d0, lam, gap0, sep0, spin0 = t1, z1, d1, lam1, ws[10, 1], ws[10, 2], ws[10, 3]
                continue
            h = safe  # round-off of the bound: an ordinary step over the same interval
        else:
            t1 = t0 + h
            z1, d1, lam1 = pair_zeta(P, i, j, shift, t + t1, kappa, lam, ws, wm)
            # the safe times forwards from t0 and backwards from t1 cover the step: no midpoint
            if z1 > zc and not touching and \
                    safe + _back_safe_time(ws[10, 1], ws[10, 2], ws[10, 3], grow_speed, kappa, t + t0, t + t1) >= h:
                steps += 1
                t0, z0, d0, lam, gap0, sep0, spin0 = t1, z1, d1, lam1, ws[10, 1], ws[10, 2], ws[10, 3]
                h *= 2.0
                continue
        gap1, sep1, spin1 = ws[10, 1], ws[10, 2], ws[10, 3]
        accepted = False  # a step past a crossing of zc (a graze) or a touching stretch
        while True:
            tm = t0 + 0.5 * h
            zm, dm, lamm = pair_zeta(P, i, j, shift, t + tm, kappa, lam, ws, wm)
            gapm, sepm, spinm = ws[10, 1], ws[10, 2], ws[10, 3]
            if zm <= zc and touching:  # still in contact at the midpoint
                if dm < -rate_tol:  # approaching: the collision is at the latest here
                    if h <= hfloor:
                        return t + tm, TRACE_COLLISION
                    h *= 0.5
                    t1, z1, d1, lam1, gap1, sep1, spin1 = tm, zm, dm, lamm, gapm, sepm, spinm
                    continue
                # touching, not approaching: move on
                t1, z1, d1, lam1, gap1, sep1, spin1 = tm, zm, dm, lamm, gapm, sepm, spinm
                zc = min(zc, zm)
                accepted = True
                break
            if zm <= zc or z1 <= zc:  # a crossing of zc from above
                if zm <= zc:
                    root = _hermite_root(z0 - zc, zm - zc, d0 * 0.5 * h, dm * 0.5 * h)
                    tc, dc, thi, zhi, dhi, lamhi = _refine(
                        P, i, j, shift, t, kappa, zc, t0, d0, tm, zm, dm, lamm,
                        t0 + 0.5 * h * min(root, 1.0), lam, ws, wm)
                else:
                    root = _hermite_root(zm - zc, z1 - zc, dm * 0.5 * h, d1 * 0.5 * h)
                    tc, dc, thi, zhi, dhi, lamhi = _refine(
                        P, i, j, shift, t, kappa, zc, tm, dm, t1, z1, d1, lam1,
                        t0 + 0.5 * h * (1.0 + min(root, 1.0)), lamm, ws, wm)
                if dc < -rate_tol:
                    return t + tc, TRACE_COLLISION
                # a grazing touch: the pair is touching from just past it on
                t1, z1, d1, lam1, gap1, sep1, spin1 = thi, zhi, dhi, lamhi, 0.0, 0.0, 0.0
                zc = min(zc, z1)
                touching = True
                accepted = True
                break
            err = abs(0.5 * (z0 + z1) + 0.125 * h * (d0 - d1) - zm)
            hmin = _hermite_min(z0 - zc, z1 - zc, d0 * h, d1 * h)
            tol = max(eps_f, RELATIVE_TOL * hmin)
            if (err <= tol and hmin > 2.0 * err) or h <= hfloor:
                touching = False
                break
            # halve: the midpoint becomes the end
            h *= 0.5
            t1 = t0 + h
            z1, d1, lam1, gap1, sep1, spin1 = zm, dm, lamm, gapm, sepm, spinm
        steps += 1
        t0 = t1
        z0, d0, lam, gap0, sep0, spin0 = z1, d1, lam1, gap1, sep1, spin1
        if accepted:
            continue
        if err > 0.0:
            fac = 0.8 * (max(min(tol, 0.5 * hmin), 0.0) / err) ** 0.25
            h *= min(max(fac, 0.5), 4.0)
        else:
            h *= 4.0

# ------------------------------------------------------------------ the container wall
#: a wall collision time is located when |h - h_c| is below this many ulps of the container radius
H_TOL_ULPS = 64.0
#: wall traces accept steps below this fraction of their first step unconditionally (a wall
#: evaluation is cheap; the pairs' MIN_STEP_FRACTION, 1e-9, is longer than the flight between two
#: wall contacts of a particle pinned across the container at reduced wall pressures ~1e10)
WALL_MIN_STEP_FRACTION = 1e-14


@njit(cache=True, inline="always", _nrt=False)
def _rotation_into(o, q):
    """Rotation Q (lab to body; :mod:`hardpack.geometry.shapes`) of an orientation row into q."""
    if q.shape[0] == 2:
        c, s = np.cos(o[0]), np.sin(o[0])
        q[0, 0], q[0, 1], q[1, 0], q[1, 1] = c, s, -s, c
        return
    s, p1, p2, p3 = o[0], o[1], o[2], o[3]
    diag = s * s - 0.5
    q[0, 0], q[0, 1], q[0, 2] = 2 * (p1 * p1 + diag), 2 * (p1 * p2 + s * p3), 2 * (p1 * p3 - s * p2)
    q[1, 0], q[1, 1], q[1, 2] = 2 * (p2 * p1 - s * p3), 2 * (p2 * p2 + diag), 2 * (p2 * p3 + s * p1)
    q[2, 0], q[2, 1], q[2, 2] = 2 * (p3 * p1 + s * p2), 2 * (p3 * p2 - s * p1), 2 * (p3 * p3 + diag)


@njit(cache=True)
def wall_arrays(d):
    """Scratch arrays (ww (8, 4), wq (d, d)) of the wall functions.

    Parameters
    ----------
    d : int
        Dimension, 2 or 3.

    Returns
    -------
    ww : numpy.ndarray of float64, shape (8, 4)
        Zeroed vector scratch.
    wq : numpy.ndarray of float64, shape (d, d)
        Matrix scratch.
    """
    return np.zeros((8, 4)), np.empty((d, d))


@njit(cache=True, _nrt=False)
def wall_gap(P, i, t, kappa, wmode, wspec, wid, ww, wq):
    """(h, dh/dt) of particle i at window time t and wall ``wid`` (module docstring, *Walls*): the
    gap h between the wall and the particle's farthest surface point along the wall's outward
    normal n, and its rate by the envelope theorem (the point is stationary on the surface),
    dh/dt = -n . (v + w x r_c + g r_c) (r_c that point less the particle centre, g the relative
    growth rate). In a spherical container (SPHERE_CODE, centre wspec[:d], radius wspec[d]) the
    point is the farthest from the centre
    (:func:`hardpack.geometry.ellipsoid_container.farthest_point_body`), h = R - rho, and n is
    radial there; at the flat wall ``wid`` (FLAT_WALLS_CODE: x_k = 0 for wid = 2 k, x_k = L_k =
    wspec[k] for wid = 2 k + 1) the support point along n = -e_k or +e_k,
    r_c = X^-1 n / sqrt(n . X^-1 n), and h = x_k - n . r_c or L_k - x_k - n . r_c. On return
    ww[5, :d] holds r_c, ww[6, :d] n.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (read only).
    i : int
        The particle.
    t : float
        Window time.
    kappa : float
        Relative growth rate of the semiaxes.
    wmode : int
        SPHERE_CODE or FLAT_WALLS_CODE.
    wspec : numpy.ndarray of float64, shape (d + 1,)
        Container centre and radius, or the wall positions L_k of the walled axes (0 for the
        periodic ones) and a length scale (:func:`run_events`).
    wid : int
        The flat wall (unused in a container).
    ww, wq : numpy.ndarray
        Scratch of :func:`wall_arrays`, outputs as above.

    Returns
    -------
    h : float
        Gap to the wall (negative: the particle pokes through it).
    hdot : float
        dh/dt.
    """
    d = wq.shape[0]
    cv, ct, _, cax, _, cw, _, _ = columns(d)
    dt = t - P[i, ct]
    grow = 1.0 + kappa * t
    x, o, a, b, xb, rc, n = ww[0, :d], ww[1], ww[2, :d], ww[3, :d], ww[4, :d], ww[5, :d], ww[6, :d]
    for k in range(d):
        x[k] = P[i, k] + P[i, cv + k] * dt
        a[k] = P[i, cax + k] * grow
    orientation_at(P, i, t, o)
    _rotation_into(o, wq)
    if wmode == FLAT_WALLS_CODE:  # flat wall: the support point along n = sgn e_k, body frame b = Q n
        kw = wid >> 1
        sgn = 1.0 if wid & 1 else -1.0
        ss = 0.0
        for k in range(d):
            b[k] = sgn * wq[k, kw]
            ss += a[k] * a[k] * b[k] * b[k]
        sup = np.sqrt(ss)
        for k in range(d):
            xb[k] = a[k] * a[k] * b[k] / sup
        for m in range(d):
            acc = 0.0
            for k in range(d):
                acc += wq[k, m] * xb[k]
            rc[m] = acc
            n[m] = 0.0
        n[kw] = sgn
        h = (wspec[kw] - x[kw] if wid & 1 else x[kw]) - sup
    else:
        for k in range(d):
            x[k] -= wspec[k]
        for k in range(d):
            acc = 0.0
            for m in range(d):
                acc += wq[k, m] * x[m]
            b[k] = acc
        rho = np.sqrt(farthest_point_body(b, a, xb))
        for m in range(d):
            acc = 0.0
            for k in range(d):
                acc += wq[k, m] * xb[k]
            n[m] = acc / rho
            rc[m] = acc - x[m]
        h = wspec[d] - rho
    g = kappa / grow
    rate = 0.0
    for k in range(d):
        rate += n[k] * (P[i, cv + k] + g * rc[k])
    c = ww[7]
    _cross_n(rc, n, c)  # n . (w x r_c) = w . (r_c x n)
    nw = 3 if d == 3 else 1
    for k in range(nw):
        rate += P[i, cw + k] * c[k]
    return h, -rate


@njit(cache=True, _nrt=False)
def _wall_refine(P, i, kappa, wmode, wspec, wid, hc, lo, dlo, hi, hhi, dhi, guess, ww, wq):
    """First crossing of h = hc in [lo, hi] (h(lo) >= hc > h(hi)), safeguarded Newton as
    :func:`_refine`: (t_c, rate there, hi, h(hi), rate at hi)."""
    htol = H_TOL_ULPS * EPS * wspec[wspec.shape[0] - 1]
    tt = guess if lo < guess < hi else 0.5 * (lo + hi)
    for _ in range(100):
        z, zd = wall_gap(P, i, tt, kappa, wmode, wspec, wid, ww, wq)
        f = z - hc
        if f >= 0.0:
            lo, dlo = tt, zd
        else:
            hi, hhi, dhi = tt, z, zd
        if abs(f) <= htol:
            return tt, zd, hi, hhi, dhi
        nt = tt - f / zd if zd != 0.0 else -1.0
        if f >= 0.0 and abs(nt - tt) <= 4e-16 * abs(tt):
            break
        if hi - lo <= 4e-16 * abs(hi) + 1e-300:
            break
        if not (lo < nt < hi):
            nt = 0.5 * (lo + hi)
        if nt == tt:
            break
        tt = nt
    return lo, dlo, hi, hhi, dhi


@njit(cache=True, _nrt=False)
def wall_predict(P, i, t, tmax, kappa, wmode, wspec, wid, eps_f, ww, wq):
    """First collision of particle i with wall ``wid`` in window time [t, tmax): (time, kind),
    kind 0 a collision, 1 a CHECK (step cap reached), time inf for none.

    The gap h(t) (:func:`wall_gap`) decreases at most at the rate
    |v| + |kappa| a_max(0) + |w| a_max(t) (the centre, the growth and the spin of the farthest
    point, at distance <= a_max from the centre), so no contact happens within the safe time of
    :func:`_safe_time` (Donev 2006, sec. 3.5.1: jump ahead with a bound on the rate). When the safe
    time is shorter than the trace step, an ordinary step as in :func:`pair_trace`: the cubic
    Hermite interpolant of h and dh/dt at both ends, checked at the midpoint against the tolerance
    eps_f times the smallest semiaxis (or a tenth of the interpolant's minimum, far from the wall),
    halved until it passes; a sample at or below the contact level (0, or h(t) if the particle
    starts touching: after a wall collision, or a graze) brackets a crossing located by
    :func:`_wall_refine`. A crossing whose rate is not below -GRAZE_RATE times the particle's
    speed scale is a graze; the trace goes on from just past it.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (read only).
    i : int
        The particle.
    t, tmax : float
        Window-time interval searched.
    kappa : float
        Relative growth rate of the semiaxes.
    wmode, wspec, wid
        The wall, as in :func:`wall_gap`.
    eps_f : float
        Tolerance on the Hermite interpolation error, relative to the smallest semiaxis.
    ww, wq : numpy.ndarray
        Scratch of :func:`wall_arrays`.

    Returns
    -------
    time : float
        Window time of the event, inf for none.
    kind : int
        TRACE_COLLISION or TRACE_CHECK.
    """
    d = wq.shape[0]
    cv, _, cr, cax, _, cw, _, _ = columns(d)
    if not tmax > t:
        return np.inf, TRACE_COLLISION
    amax0 = P[i, cr]
    amin0 = P[i, cax]
    for k in range(1, d):
        amin0 = min(amin0, P[i, cax + k])
    vv = 0.0
    for k in range(d):
        vv += P[i, cv + k] ** 2
    w2 = 0.0
    nw = 3 if d == 3 else 1
    for k in range(nw):
        w2 += P[i, cw + k] ** 2
    spin = np.sqrt(w2) * amax0
    grow_speed = np.sqrt(vv) + abs(kappa) * amax0
    speed = grow_speed + spin * (1.0 + kappa * t)
    if speed == 0.0:
        return np.inf, TRACE_COLLISION
    rate_tol = GRAZE_RATE * speed
    h0, d0 = wall_gap(P, i, t, kappa, wmode, wspec, wid, ww, wq)
    hc = 0.0
    touching = False
    if h0 <= 0.0:
        if d0 < -rate_tol:
            return t, TRACE_COLLISION
        hc = h0
        touching = True
    step = FIRST_STEP * amin0 * (1.0 + kappa * t) / speed
    hmin_step = WALL_MIN_STEP_FRACTION * step
    tol_abs = eps_f * amin0 * (1.0 + kappa * t)
    t0 = t
    steps = 0
    while True:
        hfloor = max(hmin_step, 8.0 * EPS * abs(t0))
        if tmax - t0 <= hfloor:
            return np.inf, TRACE_COLLISION
        if steps >= MAX_TRACE_STEPS:
            return t0, TRACE_CHECK
        safe = 0.0 if touching else _safe_time(h0 - hc, 0.0, spin, grow_speed, kappa, t0)
        if t0 + safe >= tmax:
            return np.inf, TRACE_COLLISION
        if safe > step:
            t1 = t0 + safe
            h1, d1 = wall_gap(P, i, t1, kappa, wmode, wspec, wid, ww, wq)
            steps += 1
            if h1 > hc:
                t0, h0, d0 = t1, h1, d1
                continue
            step = safe  # round-off of the bound: an ordinary step over the same interval
        step = min(max(step, hfloor), tmax - t0)
        t1 = t0 + step
        tm = t0 + 0.5 * step
        h1, d1 = wall_gap(P, i, t1, kappa, wmode, wspec, wid, ww, wq)
        hm, dm = wall_gap(P, i, tm, kappa, wmode, wspec, wid, ww, wq)
        steps += 1
        if touching and hm <= hc:  # still in contact at the midpoint
            if dm < -rate_tol:  # approaching: the collision is at the latest here
                if step <= hfloor:
                    return tm, TRACE_COLLISION
                step *= 0.5
                continue
            hc = min(hc, hm)  # touching, not approaching: move on
            t0, h0, d0 = tm, hm, dm
            continue
        if hm <= hc or h1 <= hc:  # a crossing of hc from above
            if hm <= hc:
                root = _hermite_root(h0 - hc, hm - hc, d0 * 0.5 * step, dm * 0.5 * step)
                tc, dc, thi, hhi, dhi = _wall_refine(P, i, kappa, wmode, wspec, wid, hc, t0, d0, tm, hm, dm,
                                                     t0 + 0.5 * step * min(root, 1.0), ww, wq)
            else:
                root = _hermite_root(hm - hc, h1 - hc, dm * 0.5 * step, d1 * 0.5 * step)
                tc, dc, thi, hhi, dhi = _wall_refine(P, i, kappa, wmode, wspec, wid, hc, tm, dm, t1, h1, d1,
                                                     tm + 0.5 * step * min(root, 1.0), ww, wq)
            if dc < -rate_tol:
                return tc, TRACE_COLLISION
            touching = True  # a grazing touch: touching from just past it on
            hc = min(hc, hhi)
            t0, h0, d0 = thi, hhi, dhi
            continue
        err = abs(0.5 * (h0 + h1) + 0.125 * step * (d0 - d1) - hm)
        hmn = _hermite_min(h0 - hc, h1 - hc, d0 * step, d1 * step)
        tol = max(tol_abs, RELATIVE_TOL * hmn)
        if (err <= tol and hmn > 2.0 * err) or step <= hfloor:
            touching = False
            t0, h0, d0 = t1, h1, d1
            if err > 0.0:
                fac = 0.8 * (max(min(tol, 0.5 * hmn), 0.0) / err) ** 0.25
                step *= min(max(fac, 0.5), 4.0)
            else:
                step *= 4.0
        else:
            step *= 0.5


@njit(cache=True, _nrt=False)
def wall_collide(P, i, t, kappa, wmode, wspec, wid, ww, wq):
    """Collision of particle i with wall ``wid`` at window time t (the particle is first
    advanced to t): the collision law of :func:`collide` with an infinitely massive wall, at the
    contact point r_C of :func:`wall_gap` with the wall's outward normal n:
    v_n = n . (v + w x (r_C - x) + g (r_C - x)) > 0 for an approaching particle, impulse -J n on the particle with
    J = 2 v_n / (1/m + |(r_C - x) x n|^2 / I), which reverses v_n: v -= J n,
    w -= J (r_C - x) x n / I. Returns (J, the momentum given to the wall, >= 0; change of the
    translational kinetic energy), J = 0 for a skipped (separating) particle.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, row i modified in place.
    i : int
        The particle.
    t : float
        Window time of the collision.
    kappa : float
        Relative growth rate of the semiaxes.
    wmode, wspec, wid
        The wall, as in :func:`wall_gap`.
    ww, wq : numpy.ndarray
        Scratch of :func:`wall_arrays`.

    Returns
    -------
    impulse : float
        J >= 0, the momentum given to the wall (0: skipped).
    dke : float
        Change of the translational kinetic energy.
    """
    d = wq.shape[0]
    cv, _, _, _, _, cw, cii, _ = columns(d)
    advance(P, i, t, ww[1])
    _, hd = wall_gap(P, i, t, kappa, wmode, wspec, wid, ww, wq)
    vn = -hd
    if not vn > 0.0:
        return 0.0, 0.0
    rc, n, c = ww[5, :d], ww[6, :d], ww[7]
    lev = _cross_n(rc, n, c)
    jimp = 2.0 * vn / (1.0 + lev * P[i, cii])
    ke0 = 0.0
    ke1 = 0.0
    for k in range(d):
        ke0 += P[i, cv + k] ** 2
        P[i, cv + k] -= jimp * n[k]
        ke1 += P[i, cv + k] ** 2
    nw = 3 if d == 3 else 1
    for k in range(nw):
        P[i, cw + k] -= jimp * P[i, cii] * c[k]
    return jimp, 0.5 * (ke1 - ke0)


@njit(cache=True, _nrt=False)
def _rebuild(i, t, P, L, invL, kappa, skin, sfac, lvl, rcap, ncl, coff, ccount, cid, cbs, slot_of,
             bs, nb, nn, mark, oldnb, clo, cspan, codo, scratch, wmode, walled):
    """Partial NNL update of particle i at window time t (Donev 2006, Algorithm 10): advance i to
    t and :func:`hardpack.md._kernel.update_neighbour_list` with the bounding radius R_i (largest
    semiaxis) in place of the sphere radius; along the ``walled`` axes (all of them in a container)
    without periodic images and wraps (``walled`` alone decides, so the sphere kernel's flat-wall
    mode serves every boundary). Returns 0 or a :class:`WindowStatus` to stop with."""
    _, _, cr, _, _, _, _, _ = columns(L.shape[0])
    advance(P, i, t, scratch)
    return update_neighbour_list(i, P[i, cr] * (1.0 + kappa * t), P, L, invL, skin, sfac, lvl, rcap, ncl, coff,
                                 ccount, cid, cbs, slot_of, bs, nb, nn, mark, oldnb, clo, cspan, codo,
                                 FLAT_WALLS_MODE, walled)


@njit(cache=True, _nrt=False)
def _predict(i, t, P, kappa, eps_f, imgvec, bs, nb, nn, tins, touts, done, pst, ws, wm, wmode, wspec,
             ww, wq):
    """:func:`_predict_shared` without a shared pair: (time, partner) of the next event of i."""
    return _predict_shared(i, t, P, kappa, eps_f, imgvec, bs, nb, nn, tins, touts, done, pst, ws, wm, wmode,
                           wspec, ww, wq, np.int64(-1), np.int64(SHARE_NONE), ws[10])


#: length of the record of a shared pair (:func:`_predict_shared`): key, status, result time and
#: kind, the shift of the partner, the trace state
SHARE_LEN = 8 + PAIR_STATE


@njit(cache=True, _nrt=False)
def _predict_shared(i, t, P, kappa, eps_f, imgvec, bs, nb, nn, tins, touts, done, pst, ws, wm, wmode, wspec,
                    ww, wq, other, shmode, share):
    """Next event of particle i from window time t: (time, partner), partner EXIT, CHECK or a
    particle index (Algorithm 5 with NNLs). The pairs are searched best first: each has a key, a
    lower bound on its collision time, first the start t_in of its bounding-sphere overlap (or,
    for the pairs whose bounding spheres overlap now, the cheap bound of :func:`_screen_time`),
    then, once :func:`pair_start` has evaluated zeta at that first key, the key plus its safe
    time, then the lower bound its trace has reached; the pair of the smallest key is started
    or, if started, traced one stretch (:func:`pair_trace`, suspended once its lower bound passes
    the second smallest key), until the smallest key is after the earliest event found (``done``:
    a PAIR_ code per pair; ``pst`` the states of the started pairs). In a
    container (``wmode``) the wall collision (:func:`wall_predict`) before the exit comes first
    and bounds the pair search (partner WALL, or CHECK when its trace reached the step cap).
    ``imgvec`` has 2^c rows for image codes of c bits (4^d for the orthorhombic box; the general
    cells of :mod:`hardpack.md._ellipsoid_deforming_kernel` use longer tables).

    *A shared pair.* After a collision of i and j both particles predict, and both would search the
    pair (i, j) from the same time. With ``shmode`` SHARE_WRITE (i's prediction, ``other`` = j) the search
    state of that pair at the end is written to ``share`` (SHARE_LEN entries: its key, status, the
    result of a finished trace, j's shift and the trace state; a trace stopped by i's earliest
    event keeps its state, :func:`pair_trace` kind TRACE_STOPPED); with ``shmode`` SHARE_READ (j's prediction,
    ``other`` = i) j's search takes the pair from there instead of starting it again, with the
    pair functions called as (i, j) and i's shift (the negative of j's), as i traced it (``done``
    PAIR_SHARED, or PAIR_SHARED_STOPPED once stopped by j's earliest event; PAIR_STOPPED for a pair
    of i stopped by i's earliest event, whose state a shared record keeps). ``shmode`` SHARE_NONE:
    no shared pair."""
    d = bs.shape[1] - 1
    cv, ct, cr, cax, _, _, _, _ = columns(d)
    cbits = 0  # list entries are j << cbits | image code, 2^cbits the length of imgvec
    while (1 << cbits) < imgvec.shape[0]:
        cbits += 1
    cmask = (1 << cbits) - 1
    dt = t - P[i, ct]
    ri = P[i, cr]
    grow = 1.0 + kappa * t
    dd = 0.0
    dv = 0.0
    vv = 0.0
    for k in range(d):
        vk = P[i, cv + k]
        dx = P[i, k] + vk * dt - bs[i, k]
        dd += dx * dx
        dv += dx * vk
        vv += vk * vk
    best = exit_root(dd, dv, vv, bs[i, d] - ri * grow, ri * kappa)
    partner = EXIT if best < np.inf else NONE
    best += t
    if wmode == SPHERE_CODE:
        tw, kind = wall_predict(P, i, t, best, kappa, wmode, wspec, np.int64(0), eps_f, ww, wq)
        if tw < best:
            best = tw
            partner = WALL if kind == TRACE_COLLISION else CHECK
    elif wmode == FLAT_WALLS_CODE:  # flat walls: each one that the bounding sphere can reach before best
        rb = ri * grow
        for kw in range(d):
            if wspec[kw] <= 0.0:
                continue
            xk = P[i, kw] + P[i, cv + kw] * dt
            for side in range(2):
                # bounding sphere: gap and approach speed (exact, both linear in time)
                gap = (wspec[kw] - xk if side else xk) - rb
                speed = (P[i, cv + kw] if side else -P[i, cv + kw]) + ri * kappa
                tb = 0.0
                if gap > 0.0:
                    if not speed > 0.0:
                        continue
                    tb = gap / speed
                if t + tb >= best:
                    continue
                tw, kind = wall_predict(P, i, t + tb, best, kappa, wmode, wspec, 2 * kw + side, eps_f, ww, wq)
                if tw < best:
                    best = tw
                    partner = WALL - (2 * kw + side) if kind == TRACE_COLLISION else CHECK
    horizon = best  # no collision of i is later than the first contact of inscribed spheres
    amin_i = P[i, cax]
    for k in range(1, d):
        amin_i = min(amin_i, P[i, cax + k])
    m_n = nn[i]
    for m in range(m_n):  # bounding-sphere overlap intervals
        e = nb[i, m]
        j = e >> cbits
        im = e & cmask
        dtj = t - P[j, ct]
        rr = 0.0
        ru = 0.0
        uu = 0.0
        for k in range(d):
            r = P[j, k] + P[j, cv + k] * dtj + imgvec[im, k] - P[i, k] - P[i, cv + k] * dt
            u = P[j, cv + k] - P[i, cv + k]
            rr += r * r
            ru += r * u
            uu += u * u
        s = ri + P[j, cr]
        sig0 = s * grow
        g = s * kappa
        a = uu - g * g
        b = ru - sig0 * g
        c = rr - sig0 * sig0
        # start of the overlap interval: now if the bounding spheres overlap already (the sphere
        # root would skip a separating pair), else their first contact
        tin = 0.0 if c <= 0.0 else contact_root(rr, ru, uu, sig0, g, horizon - t)
        tins[m] = tin
        done[m] = PAIR_NEW
        if tin < np.inf:
            amin_j = P[j, cax]
            for k in range(1, d):
                amin_j = min(amin_j, P[j, cax + k])
            s_in = (amin_i + amin_j) * grow
            if rr > s_in * s_in * (1.0 + INSCRIBED_GAP):
                # only pairs whose inscribed spheres are clearly apart now (touching ones, e.g.
                # spheres at contact, would cap the horizon at t); a little beyond t_ins, so
                # that a trace can bracket a collision exactly at t_ins (spheres)
                t_ins = contact_root(rr, ru, uu, s_in, s_in * kappa / grow, horizon - t)
                horizon = min(horizon, t + t_ins * (1.0 + 1e-6))
        if tin < np.inf:
            if a <= 0.0:
                touts[m] = np.inf
            else:
                disc = max(b * b - a * c, 0.0)
                if b <= 0.0:
                    touts[m] = (-b + np.sqrt(disc)) / a
                else:
                    den = b + np.sqrt(disc)
                    touts[m] = -c / den if den > 0.0 else 0.0
    sh = ws[9, :d]
    oq = -1  # the slot of the shared pair
    o_time, o_kind = np.inf, TRACE_COLLISION
    if shmode != SHARE_NONE:
        for m in range(m_n):
            if nb[i, m] >> cbits == other:
                oq = m
                break
    if shmode == SHARE_READ and oq >= 0 and share[SHARE_LEN - 1] == 1.0:
        ok = True  # the same pair: j's shift is the negative of i's
        for k in range(d):
            ok = ok and share[4 + k] == -imgvec[nb[i, oq] & cmask, k]
        if ok:  # share[1]: the PAIR_ code as a float, STARTED becoming SHARED here
            done[oq] = PAIR_SHARED if share[1] == PAIR_STARTED else np.int8(share[1])
            tins[oq] = share[0]
            for k in range(PAIR_STATE):
                pst[oq, k] = share[8 + k]
            if share[1] == PAIR_FINISHED and share[2] < best:
                best = share[2]
                partner = other if share[3] == TRACE_COLLISION else CHECK
        else:
            oq = -1
    # screen the pairs whose bounding spheres overlap now with cheap bounds: the sphere bound of
    # _ball_screen_time, the slab of _screen_time once that pair comes first (or now, when the
    # sphere bound is 0)
    posed = False
    for m in range(m_n):
        if tins[m] == 0.0 and done[m] == PAIR_NEW and t < min(best, horizon):
            if not posed:
                _pose(P, i, t, kappa, ws[8], ws, 11, wm, 2)
                posed = True
            e = nb[i, m]
            for k in range(d):
                sh[k] = imgvec[e & cmask, k]
            lower = _ball_screen_time(P, i, e >> cbits, sh, t, kappa, ws, wm)
            if lower > 0.0:
                tins[m] = lower
                done[m] = PAIR_BALL_SCREENED
                continue
            lower = _screen_time(P, i, e >> cbits, sh, t, kappa, ws, wm)
            if lower > 0.0:
                tins[m] = lower
                done[m] = PAIR_SCREENED
    while True:  # best first: each pair is (screened,) started, then traced step by step
        q = -1
        tq = np.inf
        t2 = np.inf  # the second smallest key
        for m in range(m_n):
            if done[m] != PAIR_FINISHED and done[m] < PAIR_SHARED_STOPPED:
                if tins[m] < tq:
                    t2 = tq
                    tq = tins[m]
                    q = m
                elif tins[m] < t2:
                    t2 = tins[m]
        if q < 0 or t + tq >= min(best, horizon):
            break
        e = nb[i, q]
        j = e >> cbits
        im = e & cmask
        for k in range(d):
            sh[k] = imgvec[im, k]
        if done[q] == PAIR_BALL_SCREENED:  # the slab bound, no earlier than the sphere bound
            tins[q] = max(tq, _screen_time(P, i, j, sh, t, kappa, ws, wm))
            done[q] = PAIR_SCREENED
            continue
        if done[q] == PAIR_NEW or done[q] == PAIR_SCREENED:
            # no contact before the key (t_in or the screening bound): the trace starts there
            if tq >= touts[q]:
                done[q] = PAIR_FINISHED
                continue
            lower, now = pair_start(P, i, j, sh, t, tq, kappa, ws, wm, pst[q])
            if now:
                done[q] = PAIR_FINISHED
                if q == oq:
                    o_time, o_kind = t + tq, TRACE_COLLISION
                if t + tq < best:
                    best = t + tq
                    partner = j
            else:
                lower = max(lower, tq)
                done[q] = PAIR_STARTED if lower < touts[q] else PAIR_FINISHED
                tins[q] = lower
            continue
        if done[q] == PAIR_SHARED:  # traced by the other particle: the pair functions as (other, i)
            for k in range(d):
                sh[k] = -sh[k]
            tc, kind = pair_trace(P, j, i, sh, t, min(best, horizon), touts[q], kappa, eps_f, ws, wm, pst[q],
                                  t + t2)
        else:
            tc, kind = pair_trace(P, i, j, sh, t, min(best, horizon), touts[q], kappa, eps_f, ws, wm, pst[q],
                                  t + t2)
        if kind == TRACE_SUSPENDED or kind == TRACE_STOPPED:  # its lower bound is past the second key
            tins[q] = tc - t
            if kind == TRACE_STOPPED:  # nothing before the earliest event (a state to go on from when shared)
                done[q] = PAIR_SHARED_STOPPED if done[q] == PAIR_SHARED else PAIR_STOPPED
            continue
        if q == oq:
            o_time, o_kind = tc, kind
        done[q] = PAIR_FINISHED
        if tc < best:
            best = tc
            partner = j if kind == TRACE_COLLISION else CHECK
    if horizon < best:  # the inscribed spheres of a pair touch, yet no collision was located
        best = horizon
        partner = CHECK
    if shmode == SHARE_WRITE:
        share[SHARE_LEN - 1] = 0.0
        if oq >= 0:
            dq = done[oq]
            share[0] = tins[oq]
            share[1] = PAIR_FINISHED if dq == PAIR_FINISHED else (
                PAIR_STARTED if dq == PAIR_STARTED or dq == PAIR_STOPPED else PAIR_SCREENED)
            share[2], share[3] = o_time, o_kind
            for k in range(d):
                share[4 + k] = imgvec[nb[i, oq] & cmask, k]
            for k in range(PAIR_STATE):
                share[8 + k] = pst[oq, k]
            share[SHARE_LEN - 1] = 1.0
    return best, partner


@njit(cache=True, _nrt=False)
def _cross_n(x, n, out):
    """out = x cross n (3D); in 2D out[0] = x_0 n_1 - x_1 n_0."""
    if x.shape[0] == 2:
        out[0] = x[0] * n[1] - x[1] * n[0]
        return out[0] * out[0]
    out[0] = x[1] * n[2] - x[2] * n[1]
    out[1] = x[2] * n[0] - x[0] * n[2]
    out[2] = x[0] * n[1] - x[1] * n[0]
    return out[0] * out[0] + out[1] * out[1] + out[2] * out[2]


@njit(cache=True, _nrt=False)
def collide(P, i, j, t, L, kappa, ws, wm):
    """Collision of i and j at window time t (module docstring, Algorithm 12); both particles are
    first advanced to t. Returns (impulse J >= 0 on j along n, r_ij . n J, change of the
    translational kinetic energy), J = 0 for a skipped (separating) pair.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, rows i and j modified in place.
    i, j : int
        The colliding particles.
    t : float
        Window time of the collision.
    L : numpy.ndarray of float64, shape (d,)
        Box side lengths (j is taken at its nearest image).
    kappa : float
        Relative growth rate of the semiaxes.
    ws, wm : numpy.ndarray
        Scratch of :func:`work_arrays`.

    Returns
    -------
    impulse : float
        J >= 0 (0: skipped).
    virial : float
        r_ij . n J, the pair's virial term.
    dke : float
        Change of the translational kinetic energy.
    """
    d = L.shape[0]
    advance(P, i, t, ws[2])
    advance(P, j, t, ws[2])
    sh = ws[9, :d]
    for k in range(d):
        dx = P[j, k] - P[i, k]
        sh[k] = -L[k] * np.floor(dx / L[k] + 0.5)
    return collide_at(P, i, j, t, sh, kappa, ws, wm)


@njit(cache=True, _nrt=False)
def collide_at(P, i, j, t, sh, kappa, ws, wm):
    """Collision of i and j, j shifted by the periodic image ``sh``, at window time t, both
    already advanced to t (:func:`collide`, which finds the image in an orthorhombic box).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, rows i and j modified in place.
    i, j : int
        The colliding particles.
    t : float
        Window time of the collision.
    sh : numpy.ndarray of float64, shape (d,)
        Periodic shift added to j's position.
    kappa : float
        Relative growth rate of the semiaxes.
    ws, wm : numpy.ndarray
        Scratch of :func:`work_arrays`; on return ws[0, :d], ws[1, :d] hold the centres and
        ws[5, :d] the unit normal.

    Returns
    -------
    impulse, virial, dke : float
        As :func:`collide`.
    """
    d = sh.shape[0]
    cv, ct, cr, _, _, cw, cii, _ = columns(d)
    nw = 3 if d == 3 else 1
    lam0 = P[i, cr] / (P[i, cr] + P[j, cr])
    zeta, zdot, lam = pair_zeta(P, i, j, sh, t, kappa, lam0, ws, wm)
    xa, xb, rc, n = ws[0, :d], ws[1, :d], ws[4, :d], ws[5, :d]
    nrm = 0.0
    for k in range(d):
        nrm += n[k] * n[k]
    nrm = np.sqrt(nrm)
    for k in range(d):
        n[k] /= nrm
    # normal contact velocity (zeta_dot = 2 lam (1 - lam) |n_raw| v_n)
    vn = zdot / (2.0 * lam * (1.0 - lam) * nrm)
    if not vn < 0.0:
        return 0.0, 0.0, 0.0
    ra = ws[6, :d]
    rb = ws[7, :d]
    ca = ws[2]
    cb = ws[3]
    for k in range(d):
        ra[k] = rc[k] - xa[k]
        rb[k] = rc[k] - xb[k]
    la = _cross_n(ra, n, ca)
    lb = _cross_n(rb, n, cb)
    inv = 2.0 + la * P[i, cii] + lb * P[j, cii]
    jimp = -2.0 * vn / inv
    ke0 = 0.0
    ke1 = 0.0
    rn = 0.0
    for k in range(d):
        ke0 += P[i, cv + k] ** 2 + P[j, cv + k] ** 2
        P[i, cv + k] -= jimp * n[k]
        P[j, cv + k] += jimp * n[k]
        ke1 += P[i, cv + k] ** 2 + P[j, cv + k] ** 2
        rn += (xb[k] - xa[k]) * n[k]
    for k in range(nw):
        P[i, cw + k] -= jimp * P[i, cii] * ca[k]
        P[j, cw + k] += jimp * P[j, cii] * cb[k]
    return jimp, rn * jimp, 0.5 * (ke1 - ke0)


@njit(cache=True)
def run_events(P, L, kappa, eps_f, skin, sfac, imgvec, lvl, rcap, ncl, coff, ccount, cid, cbs,
               slot_of, bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos, acc, iacc,
               coll_target, t_cap, rebuild_lists, wmode=PERIODIC_CODE, wspec=None):
    """One window of ellipsoid MD; arguments, accumulators and return codes as in
    :func:`hardpack.md._kernel.run_events` (no ``dims``: d is the length of ``L``; ``eps_f`` the
    trace tolerance; ``iacc`` has N_COUNTERS entries: after the sphere engine's, I_CHECK counts
    CHECK events and I_STALL_PARTICLE, I_STALL_PARTNER name the last event of a STALLED window (its
    time in acc[A_T]); acc[A_KE]
    enters the current translational kinetic energy; ``acc`` has N_ACC entries: A_EVAL receives
    the number of contact-function evaluations, A_WALL + k the momentum given to the walls of
    axis k, or to the container wall for k = 0).
    ``wmode`` PERIODIC_CODE, FLAT_WALLS_CODE (hard walls at x_k = 0 and x_k = L_k on the axes k
    with wspec[k] = L_k > 0, periodic images along the others, wspec[d] the largest L_k) or
    SPHERE_CODE (a spherical container of centre wspec[:d] and radius wspec[d] inside the box L,
    which then has no periodic images); wall collisions, counted in iacc[I_WALL], count towards
    ``coll_target``.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows (module docstring), modified in place.
    L : numpy.ndarray of float64, shape (d,), read-only
        Box side lengths.
    kappa : float
        Relative growth rate of the semiaxes.
    eps_f : float
        Trace tolerance (module docstring, :data:`EPS_F`).
    skin, sfac, imgvec, lvl, rcap, ncl, coff, ccount, cid, cbs, slot_of, bs, nb, nn, mark
        Bounding spheres, grid and neighbour lists, as in :func:`hardpack.md._kernel.run_events`.
    cnt, ep, ec, hkey, heap, hpos
        Event heap, as in :func:`hardpack.md._kernel.run_events` (ep also CHECK and WALL).
    acc : numpy.ndarray of float64, shape (N_ACC,)
        Float accumulators (above).
    iacc : numpy.ndarray of int64, shape (N_COUNTERS,)
        Counters (above).
    coll_target : int
        Stop after this many collisions.
    t_cap : float
        Stop before the first event later than this window time.
    rebuild_lists : bool
        Start with a complete rebuild of grid and neighbour lists.
    wmode : int, optional
        PERIODIC_CODE, FLAT_WALLS_CODE or SPHERE_CODE.
    wspec : numpy.ndarray of float64, shape (d + 1,), optional
        Wall positions and scale (FLAT_WALLS_CODE) or container centre and radius (SPHERE_CODE).

    Returns
    -------
    int
        A :class:`hardpack.md._kernel.WindowStatus`.
    """
    d = L.shape[0]
    cap = nb.shape[1]
    ws, wm = work_arrays(d)
    ww, wq = wall_arrays(d)
    spec = np.zeros(d + 1) if wspec is None else wspec
    walled = np.zeros(d, dtype=np.int8)  # axes without images: all in a container, the flat walls' axes
    lcoll = L.copy()  # collision images: none along walled axes (every pair is within the box, |dx| < L)
    for k in range(d):
        if wmode == SPHERE_CODE or (wmode == FLAT_WALLS_CODE and spec[k] > 0.0):
            walled[k] = 1
            lcoll[k] = 4.0 * L[k]
    scratch = (np.empty(cap, dtype=np.int64), np.empty(d, dtype=np.int64), np.empty(d, dtype=np.int64),
               np.empty(d, dtype=np.int64), np.empty(cap), np.empty(cap), np.empty((cap, PAIR_STATE)),
               np.empty(cap, dtype=np.int8), np.empty(4), np.empty(2, dtype=np.int64), np.zeros(SHARE_LEN))
    status = _run(P, L, kappa, eps_f, skin, sfac, imgvec, lvl, rcap, ncl, coff, ccount, cid, cbs,
                  slot_of, bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos, acc, iacc,
                  coll_target, t_cap, rebuild_lists, ws, wm, wmode, spec, ww, wq, walled, lcoll, 1.0 / L, *scratch)
    acc[A_EVAL] = ws[10, 0]
    return status


@njit(cache=True, _nrt=False)
def _run(P, L, kappa, eps_f, skin, sfac, imgvec, lvl, rcap, ncl, coff, ccount, cid, cbs,
         slot_of, bs, nb, nn, mark, cnt, ep, ec, hkey, heap, hpos, acc, iacc,
         coll_target, t_cap, rebuild_lists, ws, wm, wmode, wspec, ww, wq, walled, lcoll, invL,
         oldnb, clo, cspan, codo, tins, touts, pst, done, scratch, upd, share):
    n = P.shape[0]
    cbits = 2 * L.shape[0]
    mark[:] = 0
    hpos[:] = -1
    hsize = 0
    if rebuild_lists:
        ccount[:] = 0
        slot_of[:] = -1
        nn[:] = 0
        for i in range(n):
            status = _rebuild(i, 0.0, P, L, invL, kappa, skin, sfac, lvl, rcap, ncl, coff, ccount,
                              cid, cbs, slot_of, bs, nb, nn, mark, oldnb, clo, cspan, codo, scratch, wmode, walled)
            if status != 0:
                acc[A_T] = 0.0
                return status
    for i in range(n):
        key, partner = _predict(i, 0.0, P, kappa, eps_f, imgvec, bs, nb, nn, tins, touts, done, pst, ws, wm,
                                wmode, wspec, ww, wq)
        ep[i] = partner
        if partner >= 0:
            ec[i] = cnt[partner]
        hsize = heap_set(hkey, heap, hpos, hsize, i, key)
    t_last = -1.0
    same = 0
    max_same = STALL_EVENTS + 10 * n
    while True:
        i = np.int64(heap[0])  # one type for particle indices: one compilation of the pair functions
        t = hkey[0]
        if t > t_cap:
            end_window(acc, t_cap)
            return WindowStatus.DONE_TIME
        if t == np.inf:
            return WindowStatus.STUCK
        p = np.int64(ep[i])
        # progress guard: every event but a collision advances the time (collisions at one
        # instant change the velocities); a long run of other events at one time is a failure
        if t == t_last:
            same += 1
            if same > max_same:
                acc[A_T] = t
                iacc[I_STALL_PARTICLE] = i
                iacc[I_STALL_PARTNER] = p
                return WindowStatus.STALLED
        else:
            t_last = t
            same = 0
        iacc[I_EVENTS] += 1
        npred = 1
        upd[0] = i
        wall_hit = False
        if p == EXIT:
            iacc[I_EXIT] += 1
            status = _rebuild(i, t, P, L, invL, kappa, skin, sfac, lvl, rcap, ncl, coff, ccount,
                              cid, cbs, slot_of, bs, nb, nn, mark, oldnb, clo, cspan, codo, scratch, wmode, walled)
            if status != 0:
                acc[A_T] = t
                return status
        elif p == CHECK:
            iacc[I_CHECK] += 1
        elif wmode != PERIODIC_CODE and p <= WALL:
            wid = WALL - p
            jimp, dke = wall_collide(P, i, t, kappa, wmode, wspec, wid, ww, wq)
            if jimp > 0.0:
                same = 0
                wall_hit = True
                acc[A_WALL + (wid >> 1)] += jimp
                kinetic_step(acc, t, dke)
                cnt[i] += 1
                iacc[I_WALL] += 1
            else:
                iacc[I_GRAZE] += 1
        elif p < 0 or ec[i] != cnt[p]:
            iacc[I_STALE] += 1
        else:
            j = p
            jimp, vir, dke = collide(P, i, j, t, lcoll, kappa, ws, wm)
            if jimp > 0.0:
                same = 0
                acc[A_VIRIAL] += vir
                kinetic_step(acc, t, dke)
                cnt[i] += 1
                cnt[j] += 1
                iacc[I_COLL] += 1
            else:
                iacc[I_GRAZE] += 1
            upd[1] = j
            npred = 2
        for q in range(npred):  # after a collision the pair is searched once (_predict_shared)
            k = upd[q]
            shmode = SHARE_NONE if npred == 1 else SHARE_WRITE + q  # the first of the pair writes, the second reads
            key, partner = _predict_shared(k, t, P, kappa, eps_f, imgvec, bs, nb, nn, tins, touts, done, pst,
                                           ws, wm, wmode, wspec, ww, wq, upd[1 - q], shmode, share)
            ep[k] = partner
            if partner >= 0:
                ec[k] = cnt[partner]
            hsize = heap_set(hkey, heap, hpos, hsize, k, key)
        if hsize > 1:
            prefetch_next_events(P, bs, nb, nn, ep, heap, hsize, cbits)
        if iacc[I_COLL] >= coll_target and npred == 2:
            end_window(acc, t)
            return WindowStatus.DONE_COLLISIONS
        if wmode != PERIODIC_CODE and wall_hit and iacc[I_COLL] + iacc[I_WALL] >= coll_target:
            end_window(acc, t)
            return WindowStatus.DONE_COLLISIONS


@njit(cache=True)
def synchronise(P, t, kappa):
    """Advance every particle to window time t, grow semiaxes, bounding radii and moments of
    inertia to their size at t, renormalise quaternions (Algorithm 1) and wrap 2D angles into
    [0, 2 pi), and reset the time origin (Algorithm 3).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows, modified in place.
    t : float
        Window time of the synchronisation.
    kappa : float
        Relative growth rate of the semiaxes.
    """
    d = 2 if P.shape[1] == 11 else 3
    _, ct, cr, cax, cor, _, cii, _ = columns(d)
    grow = 1.0 + kappa * t
    scratch = np.empty(4)
    for i in range(P.shape[0]):
        advance(P, i, t, scratch)
        P[i, ct] = 0.0
        P[i, cr] *= grow
        for k in range(d):
            P[i, cax + k] *= grow
        P[i, cii] /= grow * grow
        if d == 3:
            nq = 0.0
            for k in range(4):
                nq += P[i, cor + k] ** 2
            if abs(nq - 1.0) > 1e-14:
                nq = np.sqrt(nq)
                for k in range(4):
                    P[i, cor + k] /= nq
        else:
            P[i, cor] -= 2.0 * np.pi * np.floor(P[i, cor] / (2.0 * np.pi))


@njit(cache=True, _nrt=False)
def totals(P):
    """(translational KE, rotational KE, sum of volume-equivalent radii (prod a)^(1/d),
    sum of prod a) in a fixed summation order (bit-identical after a resume).

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point.

    Returns
    -------
    ket, ker : float
        Translational and rotational kinetic energy.
    s1 : float
        Sum of the volume-equivalent radii.
    sd : float
        Sum of the semiaxis products.
    """
    d = 2 if P.shape[1] == 11 else 3
    cv, _, _, cax, _, cw, cii, _ = columns(d)
    nw = 3 if d == 3 else 1
    ket = 0.0
    ker = 0.0
    s1 = 0.0
    sd = 0.0
    for i in range(P.shape[0]):
        for k in range(d):
            ket += 0.5 * P[i, cv + k] ** 2
        w2 = 0.0
        for k in range(nw):
            w2 += P[i, cw + k] ** 2
        ker += 0.5 * w2 / P[i, cii]
        pa = 1.0
        for k in range(d):
            pa *= P[i, cax + k]
        s1 += pa ** (1.0 / d)
        sd += pa
    return ket, ker, s1, sd


@njit(cache=True)
def max_overlap(P, imgvec, nb, nn):
    """Largest relative overlap 1 - mu (mu = sqrt(1 + zeta), the Perram-Wertheim scaling factor to
    tangency; 1 - r / (a_i + a_j) for spheres) over the listed pairs at a synchronisation point, and
    the number of pairs with a positive one. Every touching pair is listed.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point.
    imgvec : numpy.ndarray of float64, shape (4**d, d)
        Periodic shift of each image code.
    nb : numpy.ndarray of int, shape (N, cap)
        Neighbour lists, entries j << 2d | image code.
    nn : numpy.ndarray of int32, shape (N,)
        List lengths.

    Returns
    -------
    worst : float
        Largest 1 - mu (-inf without listed pairs).
    count : int
        Number of listed pairs with a positive overlap.
    """
    d = imgvec.shape[1]
    cbits = 2 * d
    ws, wm = work_arrays(d)
    worst = -np.inf
    count = 0
    _, _, cr, _, _, _, _, _ = columns(d)
    for i in range(P.shape[0]):
        for m in range(nn[i]):
            j = nb[i, m] >> cbits
            if j < i:
                continue
            im = nb[i, m] & ((1 << cbits) - 1)
            sh = ws[9, :d]
            d2 = 0.0
            for k in range(d):
                sh[k] = imgvec[im, k]
                dx = P[j, k] + sh[k] - P[i, k]
                d2 += dx * dx
            if d2 >= (P[i, cr] + P[j, cr]) ** 2:
                continue
            zeta, _, _ = pair_zeta(P, i, j, sh, 0.0, 0.0, P[i, cr] / (P[i, cr] + P[j, cr]), ws, wm)
            ov = 1.0 - np.sqrt(max(1.0 + zeta, 0.0))
            worst = max(worst, ov)
            if ov > 0.0:
                count += 1
    return worst, count


#: a pair within this Perram-Wertheim zeta of contact, or a particle within this fraction of its
#: bounding radius of the container wall, is a contact of :func:`end_contacts` (a collision located
#: at the window end leaves its pair within ZETA_TOL, and its particle within 64 ulps of the wall)
END_CONTACT_GAP = 1e-8


@njit(cache=True)
def end_contacts(P, ended, imgvec, nb, nn, wmode, wspec):
    """The contacts at a synchronisation point of the particles in ``ended`` (those whose last
    event was at the window end): listed pairs with zeta <= END_CONTACT_GAP, and, with walls
    (``wmode``), particles within END_CONTACT_GAP R_i of a wall.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point.
    ended : numpy.ndarray of int64, shape (M,)
        The particles searched.
    imgvec : numpy.ndarray of float64, shape (4**d, d)
        Periodic shift of each image code.
    nb : numpy.ndarray of int, shape (N, cap)
        Neighbour lists, entries j << 2d | image code.
    nn : numpy.ndarray of int32, shape (N,)
        List lengths.
    wmode : int
        PERIODIC_CODE, FLAT_WALLS_CODE or SPHERE_CODE.
    wspec : numpy.ndarray of float64, shape (d + 1,)
        The walls (:func:`run_events`).

    Returns
    -------
    numpy.ndarray of int64, shape (K, 3)
        Rows (i, j, image code) of the pairs (each pair once per list it is found in) and
        (i, WALL - w, 0) of the contacts with wall w (w = 0 the container wall).
    """
    d = imgvec.shape[1]
    cbits = 2 * d
    _, _, cr, _, _, _, _, _ = columns(d)
    ws, wm = work_arrays(d)
    ww, wq = wall_arrays(d)
    total = 0
    for q in range(ended.shape[0]):
        total += nn[ended[q]] + 2 * d
    out = np.empty((total, 3), dtype=np.int64)
    k = 0
    for q in range(ended.shape[0]):
        i = np.int64(ended[q])
        n_walls = 2 * d if wmode == FLAT_WALLS_CODE else (1 if wmode == SPHERE_CODE else 0)
        for wid in range(n_walls):
            if wmode == FLAT_WALLS_CODE and wspec[wid >> 1] <= 0.0:
                continue
            h, _ = wall_gap(P, i, 0.0, 0.0, wmode, wspec, wid, ww, wq)
            if h <= END_CONTACT_GAP * P[i, cr]:
                out[k, 0], out[k, 1], out[k, 2] = i, WALL - wid, 0
                k += 1
        for m in range(nn[i]):
            j = np.int64(nb[i, m] >> cbits)
            im = np.int64(nb[i, m] & ((1 << cbits) - 1))
            sh = ws[9, :d]
            d2 = 0.0
            for c in range(d):
                sh[c] = imgvec[im, c]
                dx = P[j, c] + sh[c] - P[i, c]
                d2 += dx * dx
            if d2 > (P[i, cr] + P[j, cr]) ** 2 * (1.0 + 4.0 * END_CONTACT_GAP):  # apart (spheres: at
                continue  # contact, d2 = (R_i + R_j)^2 to round-off, on either side)
            zeta, _, _ = pair_zeta(P, i, j, sh, 0.0, 0.0, P[i, cr] / (P[i, cr] + P[j, cr]), ws, wm)
            if zeta <= END_CONTACT_GAP:
                out[k, 0], out[k, 1], out[k, 2] = i, j, im
                k += 1
    return out[:k]


@njit(cache=True)
def contact_rates(P, contacts, imgvec, kappa, wmode, wspec):
    """Normal separation speed of each contact of :func:`end_contacts` at window time 0 with the
    relative growth rate ``kappa``: n . v_C (module docstring, collision law; < 0 approaching) for a
    pair, dh/dt (:func:`wall_gap`; < 0 approaching) for a wall contact.

    Parameters
    ----------
    P : numpy.ndarray of float64, shape (N, ncol(d))
        Particle state rows at a synchronisation point.
    contacts : numpy.ndarray of int64, shape (K, 3)
        From :func:`end_contacts`.
    imgvec : numpy.ndarray of float64, shape (4**d, d)
        Periodic shift of each image code.
    kappa : float
        Relative growth rate of the semiaxes.
    wmode : int
        PERIODIC_CODE, FLAT_WALLS_CODE or SPHERE_CODE.
    wspec : numpy.ndarray of float64, shape (d + 1,)
        The walls (:func:`run_events`).

    Returns
    -------
    numpy.ndarray of float64, shape (K,)
        The separation speeds.
    """
    d = imgvec.shape[1]
    _, _, cr, _, _, _, _, _ = columns(d)
    ws, wm = work_arrays(d)
    ww, wq = wall_arrays(d)
    out = np.empty(contacts.shape[0])
    for q in range(contacts.shape[0]):
        i, j, im = contacts[q, 0], contacts[q, 1], contacts[q, 2]
        if j <= WALL:
            _, out[q] = wall_gap(P, i, 0.0, kappa, wmode, wspec, WALL - j, ww, wq)
            continue
        sh = ws[9, :d]
        for c in range(d):
            sh[c] = imgvec[im, c]
        _, zdot, lam = pair_zeta(P, i, j, sh, 0.0, kappa, P[i, cr] / (P[i, cr] + P[j, cr]), ws, wm)
        n = ws[5, :d]
        nrm = 0.0
        for c in range(d):
            nrm += n[c] * n[c]
        out[q] = zdot / (2.0 * lam * (1.0 - lam) * np.sqrt(nrm))
    return out
