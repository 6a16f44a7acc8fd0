"""Refinement of an ellipsoid packing near its jamming point to the jamming point of its contacts.

An LS packing at a high pressure is near, not at, a jamming point: its contact gaps are small
(~1/p) but the balance A F = 0 of its near self-stress holds only approximately (Donev 2006,
Sec. 5.6), and along the floppy modes, where only the stiffness restores, the distance can be
large. The jamming point of the contact network is a KKT point of growing the particles: maximise
the size factor s subject to the gaps h_c(Q, s) >= 0, whose multipliers are the self-stress F
(Donev 2006, Sec. 5.5.2: A F = 0, sum F = M after normalising, F >= 0) and whose second-order
condition is the stiffness on the floppy space (K_V >= 0, :mod:`hardpack.jamming.second_order`).
Newton's method on the KKT equations with the contacts held fixed,

    [ -K    A      0   T ] [dQ]   [  0 ]
    [ A^T   0     -b   0 ] [F ] = [ -h ]
    [ 0     1^T    0   0 ] [ds]   [  M ]
    [ T^T   0      0   0 ] [nu]   [  0 ]

with h_c = zeta_c / s_c the gap of contact c in length units (zeta the Perram-Wertheim function,
s_c its scale, :mod:`hardpack.jamming.ellipsoids`), A^T its gradient (the gap rows), K the
stiffness of the current stress F (-sum_c F_c Hess h_c, so that A(Q + dQ) F = A F - K dQ to
first order), b_c = 2 mu_c^2 / s_c = -dh_c / ds for a growth of every semiaxis by the factor
1 + ds, and T the trivial motions (fixed by the multipliers nu). It converges quadratically when
K_V is nonsingular (Donev's perturbation system, Eq. 5.18, is the same linearisation). The
update moves the centres by the translational part of dQ and turns each orientation by the
rotation vector of its rotational part (R = exp(W) applied in the lab frame, the parametrisation
of the Hessians).

Walls (:mod:`hardpack.jamming.ellipsoids`) enter as contacts of one particle with a fixed
boundary. A flat wall is tracked by (particle, wall number): the gap row is h = b - n . x - s
(s = n . (p - x) the support distance of the farthest point p along the outward normal n). A
spherical container (centre c, radius R) is tracked by (particle, tip): the gap is h = R - |p - c|
at the local farthest point p of the particle from c nearest the tip, a point fixed in the
particle's body frame that follows p from iterate to iterate (a particle can touch the container
at two tips, one at each end, which are far apart on the body, so the nearest one is the same
contact; :func:`hardpack.jamming.ellipsoids.contacts_of_pairs`). In both cases the gradient and
Hessian of h are those of the first- and second-order tests, and b_c = -dh_c / ds = n . (p - x)
with n the outward normal at p (by the envelope theorem, since p is a farthest point: growing the
semiaxes by 1 + ds about the centre moves it by ds (p - x)). The translations normal to a wall
are no longer trivial motions; in a container the rigid rotations about c are.

The refined configuration is the jamming point only if no pair outside the contact network
overlaps there: a network whose jamming point overlaps other pairs is not the network of the
packing's jamming point (Donev 2006, Sec. 5.6: a missed contact makes spurious floppy modes).
Such pairs join the network and Newton runs again (an active-set iteration, ``rounds``); the
result counts the pairs still overlapping (``overlaps``) and those added (``added``). Only pairs
that overlap join, to the current network: a rebuild from every touching pair would put back the
contacts just dropped for their negative forces (below), which touch at the stationary point.

Newton's method finds a stationary point of the KKT equations, whose multipliers may have either
sign. It is a jamming point only if every force is positive (a contact with a negative force
would open as the particles grow), so convergence asks for that besides gaps and balance at the
tolerance; such contacts leave the network and Newton runs again (the other half of the
active-set iteration, counted in ``dropped``). A particle with fewer than d + 1 contacts in the
network cannot be held (Donev 2006, Sec. 4.4.3.1): its free motions are a null space of the KKT
matrix (e.g. a particle without contacts, as the collective test of every particle near the
sphere point keeps them), so such particles leave the network with their contacts, repeatedly,
and stay where they are (``pinned``). The tolerance, 1e-12, lies above the round-off of
the gaps, a few eps L / a for centres in a cell of side L (measured: 3e-15 at N = 1000,
L = 28 a, by the same pairs taken in the other order), provided the Newton step is solved to
round-off in the gap rows, which needs iterative refinement of the sparse LU (:func:`_solve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.jamming.ascent import CONFIRM_AMPLITUDES, ascend, confirm_unjamming, lp_method
from hardpack.jamming.ellipsoids import (
    contact_centres,
    contact_hessians,
    contacts_of_pairs,
    container_tips,
    displaced,
    dof_per_particle,
    ellipsoid_contacts,
    rigidity_transpose_full,
    stiffness_matrix_full,
)
from hardpack.jamming.highs import LPFailure
from hardpack.jamming.result import Verdict
from hardpack.jamming.second_order import dof_basis, trivial_motions, verify_ellipsoids

__all__ = ["Refinement", "refine_jamming_point", "verify_at_jamming_point", "REFINE_STEPS"]

#: pairs within this mu - 1 are searched for overlaps at a network's jamming point
OVERLAP_SEARCH = 1e-2
#: Newton steps of :func:`verify_at_jamming_point` (it converges in 3-5 when it converges)
REFINE_STEPS = 12
#: convergence tolerance of :func:`refine_jamming_point` (gaps in smallest semiaxes, relative balance)
REFINE_TOL = 1e-12


@dataclass
class Refinement:
    """The outcome of :func:`refine_jamming_point`.

    Attributes
    ----------
    packing : Packing
        The refined configuration (the last Newton iterate).
    converged : bool
        Whether the gaps and the balance reached the tolerance.
    iterations : int
        Newton steps taken.
    gap : ndarray
        max |h_c| / a (a the smallest semiaxis) before each step and after the last.
    balance : ndarray
        |A F| / (|A| |F|) (Frobenius and Euclidean norms) at the same points.
    steps : ndarray
        Largest component of each Newton step (translations in units of a, angles in radians).
    size_change : float
        Product of the semiaxis factors 1 + ds over the steps, minus 1.
    forces : ndarray, shape (M,)
        The self-stress of the contacts at the last iterate (sum M).
    overlaps : int
        Pairs overlapping by more than the packing's ``overlap_tol`` at the last iterate (pairs of
        the contact network included: they overlap when the iteration did not converge).
    added : int
        Contacts added to the network over the rounds (pairs that overlapped at the jamming point
        of the smaller network).
    dropped : int
        Contacts dropped from the network over the rounds (those with a negative force at a
        stationary point of the larger network).
    pinned : int
        Particles of the starting backbone held fixed as rattlers, with fewer than d + 1 contacts
        in the network (after removing such particles and their contacts, repeatedly).
    negative : int
        Contacts with a negative force at the last iterate. A solution of the KKT equations with a
        negative multiplier is not a jamming point (those contacts would open as the particles
        grow), so ``converged`` is False then even when the gaps and the balance met the tolerance.
    """

    packing: Packing
    converged: bool
    iterations: int
    gap: np.ndarray
    balance: np.ndarray
    steps: np.ndarray
    size_change: float
    forces: np.ndarray
    overlaps: int
    added: int = 0
    negative: int = 0
    dropped: int = 0
    pinned: int = 0


def refine_jamming_point(packing: Packing, result, *, max_iter: int = 20, tol: float = REFINE_TOL,
                         rounds: int = 6) -> Refinement:
    """Newton's method to the jamming point of a packing's contact network (module docstring).

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell, between flat hard walls or in a spherical
        container, near a jamming point (an LS packing at a high pressure).
    result : EllipsoidJammingResult
        :func:`hardpack.jamming.second_order.verify_ellipsoids` of ``packing``: its backbone,
        contacts and self-stress (exact or near) start the iteration; rattlers stay where they are.
    max_iter : int, default 20
        Newton steps at most.
    tol : float, default REFINE_TOL (1e-12)
        Convergence: max |h_c| / a and |A F| / (|A| |F|) both below it, and every force positive.
    rounds : int, default 6
        Newton runs at most, an active-set iteration on the contact network: when Newton reaches
        a stationary point whose self-stress has negative forces, those contacts leave the
        network (they open as the particles grow); when it reaches a jamming point of the
        network at which other pairs overlap, those pairs join it (with the mean force to
        start); then Newton runs again.

    Returns
    -------
    Refinement

    Raises
    ------
    InvalidInputError
        For a result without a self-stress (the packing is not jammed at first order: there is no
        jamming point to refine to) or of another packing, or bad ``max_iter`` / ``tol``.
    """
    for name, value in (("max_iter", max_iter), ("rounds", rounds)):
        if not (isinstance(value, int) and value >= 1):
            raise InvalidInputError(f"{name} must be a positive integer, got {value!r}")
    if not (np.isfinite(tol) and 0 < tol < 1):
        raise InvalidInputError(f"tol must be in (0, 1), got {tol!r}")
    if result.network.n_particles != packing.n_particles:
        raise InvalidInputError(f"the result is of a packing of {result.network.n_particles} particles, "
                                f"not of this one ({packing.n_particles})")
    forces = np.asarray(result.collective.forces, float)
    if not forces.size or forces.min() <= 0:
        raise InvalidInputError("the result has no strictly positive self-stress (not jammed at first order): "
                                "there is no jamming point of its contacts to refine to")
    active = result.backbone.copy()
    frozen = result.frozen
    used = np.flatnonzero(result.contacts_used)
    net = result.network
    on_wall = net.is_wall[used]
    pair, wall = used[~on_wall], used[on_wall]
    pairs = net.i[pair], net.j[pair], net.shift[pair]
    walls = net.i[wall], net.wall[wall], container_tips(net.subset(wall), packing.shape.rotations())
    forces = np.concatenate([forces[~on_wall], forces[on_wall]])  # the order of contacts_of_pairs
    a = float(np.min(packing.shape.semiaxes))
    current, factor, added, dropped = packing, 1.0, 0, 0
    gaps, balances, steps = [], [], []
    backbone = int(active.sum())
    for round_ in range(rounds):
        # particles with fewer than d + 1 contacts cannot be held: their free motions would make the
        # KKT matrix singular, so they leave the network with their contacts and stay where they are
        pairs, walls, forces, active = _pinned(pairs, walls, forces, active, frozen, packing.dim)
        present = active | frozen
        if len(forces) < 2:
            converged = False
            break
        current, stationary, forces, growth, walls = _newton(current, pairs, walls, forces, active, max_iter, tol, a,
                                                             gaps, balances, steps)
        factor *= growth
        # a KKT point of growing the particles only if every multiplier (force) is positive
        converged = stationary and bool(forces.min() > 0)
        if not stationary or round_ == rounds - 1:
            break
        following, following_walls, start_forces, out, new = _next_network(current, pairs, walls, forces, present,
                                                                           active, packing.overlap_tol)
        if not (out or new) or len(start_forces) < 2:
            break
        pairs, walls, forces = following, following_walls, start_forces
        dropped += out
        added += new
    overlaps = current.overlap_report(packing.overlap_tol).n_overlapping
    if current.boundary.kind != "periodic":
        overlaps += current.containment_report(packing.overlap_tol).n_outside
    return Refinement(packing=current, converged=converged, iterations=len(steps), gap=np.array(gaps),
                      balance=np.array(balances), steps=np.array(steps), size_change=factor - 1.0,
                      forces=forces, overlaps=int(overlaps), added=added,
                      negative=int((forces < 0).sum()), dropped=dropped, pinned=backbone - int(active.sum()))


def _pinned(pairs, walls, forces: np.ndarray, active: np.ndarray, frozen: np.ndarray, d: int):
    """The network without its rattlers: active particles with fewer than d + 1 contacts (walls
    included; whose contacts cannot balance a force, Donev 2006, Sec. 4.4.3.1) leave it with their
    contacts, repeatedly. Returns (pairs, walls, forces rescaled to sum M, active); ``forces`` lists
    the pairs' forces, then the walls'."""
    active = active.copy()
    n = len(active)
    while True:
        present = active | frozen
        inside = present[pairs[0]] & present[pairs[1]]
        held = present[walls[0]]
        count = np.bincount(np.concatenate([pairs[0][inside], pairs[1][inside], walls[0][held]]), minlength=n)
        loose = active & (count < d + 1)
        if not loose.any():
            break
        active &= ~loose
    if inside.all() and held.all():
        return pairs, walls, forces, active
    pairs = tuple(p[inside] for p in pairs)
    walls = tuple(w[held] for w in walls)
    forces = forces[np.concatenate([inside, held])]
    if forces.size:
        forces = forces * (len(forces) / forces.sum())
    return pairs, walls, forces, active


def _next_network(current: Packing, pairs, walls, forces: np.ndarray, present: np.ndarray, active: np.ndarray,
                  overlap_tol: float):
    """The contact network of the next active-set round, from a stationary point ``current`` of
    the network ``pairs`` and ``walls`` with multipliers ``forces`` (pairs first): contacts with a
    force <= 0 leave (they open as the particles grow), pairs outside the network that overlap by
    more than ``overlap_tol`` (between particles in ``present``, one of them ``active``) and active
    particles that cross a flat wall by more than ``overlap_tol`` of a_max join with the mean force.
    Only overlapping contacts join, so a contact that leaves (touching, not overlapping) stays out.
    Returns (pairs, walls, forces rescaled to sum M, contacts dropped, contacts added)."""
    keep = forces > 0
    m = len(pairs[0])
    near = ellipsoid_contacts(current, OVERLAP_SEARCH)
    inside = {(int(i), int(j), *map(int, k)) for i, j, k in zip(*pairs)}
    inside |= {(int(j), int(i), *map(int, -np.asarray(k))) for i, j, k in zip(*pairs)}
    on_wall = near.is_wall
    outside = np.array([at_wall or (int(i), int(j), *map(int, k)) not in inside
                        for i, j, k, at_wall in zip(near.i, near.j, near.shift, on_wall)], dtype=bool)
    tips = np.zeros((len(near.i), current.dim))
    tips[on_wall] = container_tips(near, current.shape.rotations())
    outside[on_wall] = ~_tracked_walls(walls, near.i[on_wall], near.wall[on_wall], tips[on_wall],
                                       near.semiaxes[near.i[on_wall]].max(axis=1))
    join = (outside & (near.gap < -overlap_tol) & present[near.i] & present[near.j]
            & (active[near.i] | active[near.j]))
    join_pair, join_wall = join & ~on_wall, join & on_wall
    if not keep.any():
        return (tuple(p[keep[:m]] for p in pairs), tuple(w[keep[m:]] for w in walls), forces[keep],
                int(keep.size), 0)
    pairs = tuple(np.concatenate([p[keep[:m]], q[join_pair]]) for p, q in zip(pairs, (near.i, near.j, near.shift)))
    walls = tuple(np.concatenate([w[keep[m:]], q[join_wall]]) for w, q in zip(walls, (near.i, near.wall, tips)))
    mean = forces[keep].mean()
    forces = np.concatenate([forces[:m][keep[:m]], np.full(int(join_pair.sum()), mean),
                             forces[m:][keep[m:]], np.full(int(join_wall.sum()), mean)])
    return pairs, walls, forces * (len(forces) / forces.sum()), int((~keep).sum()), int(join.sum())


#: two wall contacts of a particle are the same when their body-frame points (tips) are closer
#: than this many of its largest semiaxes (the two tips of a particle in a container are ~2 a_max
#: apart; at one configuration the same contact is found again to round-off)
SAME_TIP = 1e-6


def _tracked_walls(walls, particle: np.ndarray, wall: np.ndarray, tips: np.ndarray, amax: np.ndarray) -> np.ndarray:
    """(K,) whether each wall contact (particle, wall number, tip) is one of ``walls`` (particle,
    wall number, tips: the network, at the same configuration)."""
    found = np.zeros(len(particle), dtype=bool)
    for k in range(len(particle)):
        same = (walls[0] == particle[k]) & (walls[1] == wall[k])
        found[k] = bool(np.any(np.linalg.norm(walls[2][same] - tips[k], axis=1) <= SAME_TIP * amax[k]))
    return found


def _newton(current, pairs, walls, forces, active, max_iter, tol, a, gaps, balances, steps):
    """Newton steps on the KKT equations of the contacts ``pairs`` and ``walls`` (module
    docstring), appending the history to ``gaps``, ``balances``, ``steps``. Returns (packing,
    stationary: whether the gaps and the balance met ``tol``, forces, growth factor of the
    semiaxes, ``walls`` with the tips of the last iterate)."""
    d, f = current.dim, dof_per_particle(current.dim)
    m = len(pairs[0]) + len(walls[0])
    x = contact_centres(current)
    factor = 1.0
    for it in range(max_iter + 1):
        net = contacts_of_pairs(current, *pairs, positions=x, walls=walls)
        walls = walls[0], walls[1], container_tips(net, current.shape.rotations())
        t, _ = dof_basis(net, active)
        at = (rigidity_transpose_full(net) @ t).tocsr()
        on_wall = net.is_wall
        amax = net.semiaxes[net.i].max(axis=1)
        h = np.where(on_wall, net.gap * amax, net.zeta / net.scale)  # wall contacts store gap = h / a_max
        gaps.append(float(np.abs(h).max() / a))
        balances.append(float(np.linalg.norm(at.T @ forces) / (spla.norm(at) * np.linalg.norm(forces))))
        if gaps[-1] <= tol and balances[-1] <= tol:
            return current, True, forces, factor, walls
        if it == max_iter:
            break
        k = (t.T @ stiffness_matrix_full(net, forces, contact_hessians(net)) @ t).tocsr()
        triv = trivial_motions(t, net, active)
        n, nt = at.shape[1], triv.shape[1]
        # -dh/ds: pairs 2 (zeta + 1) / s; a wall n . (p - x), the support distance, grows with the semiaxes
        b = np.where(on_wall, np.einsum("mk,mk->m", net.normal, net.lever_i), 2.0 * (net.zeta + 1.0) / net.scale)
        z = sp.csr_matrix
        kkt = sp.vstack([
            sp.hstack([-k, at.T, z((n, 1)), z(triv)]),
            sp.hstack([at, z((m, m)), z(-b[:, None]), z((m, nt))]),
            sp.hstack([z((1, n)), z(np.ones((1, m))), z((1, 1)), z((1, nt))]),
            sp.hstack([z(triv.T), z((nt, m)), z((nt, 1)), z((nt, nt))]),
        ]).tocsc()
        rhs = np.concatenate([np.zeros(n), -h, [float(m)], np.zeros(nt)])
        sol = _solve(kkt, rhs)
        if not np.all(np.isfinite(sol)):
            break
        dq, forces, ds = sol[:n], sol[n:n + m], float(sol[n + m])
        move = (t @ dq).reshape(current.n_particles, f)
        steps.append(float(max(np.abs(move[:, :d]).max() / a, np.abs(move[:, d:]).max())))
        if not (steps[-1] <= MAX_STEP and abs(ds) <= MAX_STEP):
            break  # beyond the reach of the linearised contacts: no jamming point of this network near
        x = x + move[:, :d]
        factor *= 1.0 + ds
        current = displaced(current, x, move[:, d:], 1.0 + ds)
    return current, False, forces, factor, walls


#: the largest Newton step taken (in smallest semiaxes, radians, or relative size change): a
#: larger one leaves the configuration the contact network describes (it diverged, e.g. after the
#: active set dropped contacts), and the iteration stops unconverged
MAX_STEP = 0.5
#: first trust radius of the size ascent that brings a packing closer to its jamming point when
#: Newton does not reach it from the packing as given (:func:`verify_at_jamming_point`)
ASCENT_RADIUS = 1e-2
#: the default largest packing for which :func:`verify_at_jamming_point` runs the size ascent (its
#: ``ascent_max_particles``): one ascent took 3 s at N = 100. Above :mod:`hardpack.jamming.ascent`'s
#: IPM_ABOVE its LPs go to the interior-point method: 3-10 CPU-s per LP at N = 640 (a tiling of
#: an M&M packing; the dual simplex took 53 s per LP there, and 111-372 s at N = 1000), ~45 CPU-s
#: per LP at N = 800 (a tiling of a prolate alpha = 1.02 packing: 39 of 80 steps in 29 min). An
#: ascent at N ~ 1000 takes tens of CPU-minutes, and a certificate up to six ascents
ASCENT_MAX_PARTICLES = 400
#: iterative-refinement steps of :func:`_solve` at most
SOLVE_REFINEMENTS = 3


def _solve(kkt: sp.csc_matrix, rhs: np.ndarray) -> np.ndarray:
    """The Newton step: sparse LU of the KKT matrix, then iterative refinement (Golub & Van Loan
    2013, Sec. 3.5.3) while the residual decreases.

    The LU's backward error is relative to the whole system, whose solution is dominated by the
    forces (O(1) each, the rows of -K and A of O(1 / a)): a residual of eps |KKT| |x| times the
    pivot growth lands in the gap rows too, where the gaps to be cancelled are ~1e-12 a near
    convergence. Measured at N = 1000 (M&M, 9964 unknowns): 2-3e-12 a in the gap rows after
    every step, so the gaps stalled at 2.9e-12 a while the steps converged quadratically; one
    refinement brings the residual to round-off. An exactly singular matrix gives NaNs (the
    caller stops unconverged)."""
    try:
        lu = spla.splu(kkt)
    except RuntimeError:  # exactly singular (e.g. a particle without contacts): no Newton step
        return np.full(rhs.shape, np.nan)
    sol = lu.solve(rhs)
    res = rhs - kkt @ sol
    size = np.abs(res).max()
    for _ in range(SOLVE_REFINEMENTS):
        if not (np.isfinite(size) and size > 0):
            break
        new = sol + lu.solve(res)
        new_res = rhs - kkt @ new
        new_size = np.abs(new_res).max()
        if not new_size < size:
            break
        sol, res, size = new, new_res, new_size
    return sol


def _obstacle(packing: Packing, result) -> str | None:
    """Why ``result`` cannot start :func:`refine_jamming_point` (None when it can)."""
    dec = result.collective
    if dec.approx_stress is None:
        return "not refined: no near self-stress (exact self-stresses, or none)"
    if not (dec.forces.size and dec.forces.min() > 0):
        return "not refined: the near self-stress is not strictly positive"
    return None


def _confirm(packing: Packing, result) -> None:
    """Certify the second-order flexible verdict ``result`` of the jamming point ``packing`` by the
    size ascent along its unjamming motion (:func:`hardpack.jamming.ascent.confirm_unjamming`);
    the outcome goes to ``result.params`` and the reason."""
    try:
        found = confirm_unjamming(packing, result)
    except LPFailure as exc:
        result.collective.reason += f"; not certified: the size ascent failed ({exc})"
        return
    result.params.update(ascent_confirmed=int(found.confirmed), ascent_gain=found.gain,
                         ascent_amplitude=found.amplitude, ascent_tried=found.tried)
    result.collective.reason += (
        f"; confirmed: moved by {found.amplitude:+g} along that mode and grown by SLP (LPs by "
        f"{lp_method(packing.n_particles)}), the particles reach "
        f"a packing without overlaps {found.gain:.3g} denser than the jamming point"
        if found.confirmed else
        f"; not confirmed: SLP from the jamming point moved along that mode ({found.tried} tries, "
        f"amplitudes to {max(CONFIRM_AMPLITUDES):g}) ended at most {found.gain:.3g} denser")


def verify_at_jamming_point(packing: Packing, *, confirm: bool = True, retry_after_ascent: bool = True,
                            ascent_max_particles: int = ASCENT_MAX_PARTICLES, **options):
    """The jamming test of an ellipsoid packing at the jamming point of its contacts, when the
    packing is near one.

    Runs :func:`hardpack.jamming.second_order.verify_ellipsoids`; when its backbone has a strictly
    positive near self-stress (a packing near, not at, its jamming point), refines
    the configuration with :func:`refine_jamming_point` and, when that converges with no pair
    overlapping, tests the refined configuration instead, whose balance A F = 0 is exact to
    round-off. When the local test of the packing as given finds no backbone with a near
    self-stress (near the sphere point the torques are of order alpha - 1, and a particle's own
    near self-stress can be lost in them, so that every particle looks like a rattler), the
    collective test of every particle (``local=False``) starts the refinement, and the refined
    configuration gets the full test; when that refinement fails too, the verdict is
    *undetermined* (a local test that loses every particle says nothing about the packing).
    The result's ``params`` say what happened: ``refined`` (1: the verdict is that of
    the jamming point; 0: of the packing as given), ``refine_note``, ``refine_iterations``,
    ``refine_step`` (the largest Newton step, in smallest semiaxes or radians),
    ``refine_size_change``, ``refine_added`` and ``refine_dropped`` (contacts added and dropped by
    the active-set rounds), ``refine_negative`` (negative forces at the last iterate) and
    ``refine_pinned`` (particles with fewer than d + 1 contacts held fixed as rattlers).

    When Newton starts but does not reach a jamming point without overlaps (it diverged, stalled,
    or ended with negative forces or overlapping pairs), the packing is first brought closer to
    its jamming point by the size ascent of :mod:`hardpack.jamming.ascent` (trust radius
    ASCENT_RADIUS: every particle moves by less than 0.04 smallest semiaxes or radians), and the
    refinement runs again from there. ``ascended`` (always recorded) is 1 when that second attempt
    reached the jamming point (its verdict is returned, with ``ascent_phi_change``, the ascent's
    relative density gain), 0 otherwise (the first verdict is returned). Near the sphere point the
    LS packing's floppy modes leave it far from its jamming point, and the ascent moves along
    them using first derivatives only, where Newton's quadratic model can fail. Measured on
    prolate alpha = 1.02 (N = 100, rate 1e-4, seed 2): Newton diverged from the packing as given
    and converged in 3 steps after the ascent.

    Both uses of the ascent need N <= ``ascent_max_particles``; above it, they are skipped and the
    note says so (the cost of an ascent grows fast with N: :data:`ASCENT_MAX_PARTICLES`).

    A verdict of the refined configuration that is second-order flexible is then checked by the
    size ascent (:func:`hardpack.jamming.ascent.confirm_unjamming`, unless ``confirm`` is False):
    ``ascent_confirmed`` (1 when an explicit denser packing without overlaps was found along the
    unjamming motion, 0 when not, -1 when no ascent was tried), ``ascent_gain`` (its relative
    density gain), ``ascent_amplitude`` and ``ascent_tried``.

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell, between flat hard walls or in a spherical
        container. With walls there is no size ascent (neither the retry nor the certificate: the
        notes say so).
    confirm : bool, default True
        Certify a second-order flexible verdict at the jamming point by the size ascent.
    retry_after_ascent : bool, default True
        When Newton fails from the packing as given, try again after the size ascent.
    ascent_max_particles : int, default ASCENT_MAX_PARTICLES (400)
        The largest packing for which the ascent runs (the retry and the certificate).
    **options
        Passed to :func:`hardpack.jamming.second_order.verify_ellipsoids` for both tests.

    Returns
    -------
    EllipsoidJammingResult
    """
    if (isinstance(ascent_max_particles, bool) or not isinstance(ascent_max_particles, (int, np.integer))
            or ascent_max_particles < 0):
        raise InvalidInputError(f"ascent_max_particles must be a non-negative integer, got {ascent_max_particles!r}")
    affordable = packing.n_particles <= ascent_max_particles
    first = _at_jamming_point(packing, confirm and affordable, options, ascent_max_particles)
    first.params.setdefault("ascended", 0)
    if first.params.get("refined") != 0 or "refine_iterations" not in first.params:
        return first  # refined, or Newton never started (no near self-stress)
    if retry_after_ascent and packing.boundary.kind != "periodic":
        first.params["refine_note"] += "; no retry after the size ascent (it handles periodic packings only)"
        return first
    if retry_after_ascent and not affordable:
        first.params["refine_note"] += (f"; no retry after the size ascent above N = {ascent_max_particles} "
                                        "(ascent_max_particles; an ascent takes tens of CPU-minutes at N ~ 1000)")
    if not (retry_after_ascent and affordable):
        return first
    try:
        climbed = ascend(packing, frozen=options.get("frozen"), radius=ASCENT_RADIUS)
    except LPFailure as exc:
        first.params["refine_note"] += f"; the size ascent failed ({exc}), so Newton was not retried"
        return first
    second = _at_jamming_point(climbed.packing, confirm, options, ascent_max_particles)
    gain = (climbed.phi - packing.phi) / packing.phi
    if second.params.get("refined") != 1:
        first.params.update(ascended=0, refine_note=first.params["refine_note"] + (
            f"; nor after an SLP ascent of the size ({gain:.2g} denser): {second.params.get('refine_note', '')}"))
        return first
    second.params.update(ascended=1, ascent_phi_change=gain, refine_note=(
        f"Newton from the packing as given failed ({first.params['refine_note']}); after an SLP ascent of the "
        f"size ({gain:.2g} denser, LPs by {climbed.lp_method}): {second.params['refine_note']}"))
    return second


def _at_jamming_point(packing: Packing, confirm: bool, options: dict, ascent_max_particles: int):
    """:func:`verify_at_jamming_point` without the ascent: the test of ``packing`` at the jamming
    point Newton reaches from it, or of ``packing`` itself (``refined`` 0)."""
    result = verify_ellipsoids(packing, **options)
    dec = result.collective
    note, start, whole = _obstacle(packing, result), result, ""
    if note is not None and options.get("local", True):
        # the local test needs each particle's own near self-stress, which an LS packing near the
        # sphere point (torques of order alpha - 1) can miss: every particle then looks like a
        # rattler; the collective test of all particles can still start the refinement
        collective = verify_ellipsoids(packing, **{**options, "local": False})
        if _obstacle(packing, collective) is None:
            note, start = None, collective
            whole = ("; Newton started from the collective test of every particle (the local test of the "
                     f"packing as given found {int(result.rattler.sum())} rattler(s))")
    result.params.update(ascent_confirmed=-1)
    if note is None:
        ref = refine_jamming_point(packing, start, max_iter=REFINE_STEPS)
        info = dict(refine_iterations=ref.iterations, refine_step=float(ref.steps.max(initial=0.0)),
                    refine_size_change=ref.size_change, refine_added=ref.added,
                    refine_dropped=ref.dropped, refine_negative=ref.negative, refine_pinned=ref.pinned)
        if ref.converged and not ref.overlaps:
            refined = verify_ellipsoids(ref.packing, **options)
            same = (refined.collective.n_constraints == dec.n_constraints
                    and np.array_equal(refined.rattler, result.rattler))
            refined.params.update(refined=1, ascent_confirmed=-1, refine_note=(
                f"the jamming point of the contacts: Newton converged in {ref.iterations} steps "
                f"(largest {info['refine_step']:.3g}), gaps {ref.gap[-1]:.2g}, balance {ref.balance[-1]:.2g}"
                + (f"; {ref.added} pair(s) that overlapped at the jamming point of the packing's contacts "
                   "joined them" if ref.added else "")
                + (f"; {ref.dropped} contact(s) with negative forces at a stationary point left them"
                   if ref.dropped else "")
                + (f"; {ref.pinned} particle(s) with fewer than {packing.dim + 1} contacts held fixed as rattlers"
                   if ref.pinned else "") + whole
                + ("" if same else f"; the test there found {refined.collective.n_constraints} backbone contacts "
                   f"and {int(refined.rattler.sum())} rattlers (before: {dec.n_constraints}, "
                   f"{int(result.rattler.sum())})")), **info)
            refined.collective.reason = f"at the jamming point of the contacts: {refined.collective.reason}"
            if refined.verdict == Verdict.NOT_JAMMED and refined.unjamming_motion() is not None:
                if packing.boundary.kind != "periodic":
                    refined.collective.reason += ("; not certified by the size ascent (it handles periodic "
                                                  "packings only)")
                elif confirm:
                    _confirm(ref.packing, refined)
                elif packing.n_particles > ascent_max_particles:
                    refined.collective.reason += (f"; not certified by the size ascent (skipped above "
                                                  f"N = {ascent_max_particles}, ascent_max_particles)")
            return refined
        solved = ref.gap[-1] <= REFINE_TOL and ref.balance[-1] <= REFINE_TOL
        note = (f"not refined: Newton reached the stationary point of the contacts in {ref.iterations} steps "
                f"(gaps {ref.gap[-1]:.2g}, balance {ref.balance[-1]:.2g}, largest step {info['refine_step']:.3g}) "
                f"but {ref.negative} of its forces are negative (smallest {ref.forces.min() / ref.forces.mean():.2g} "
                "of the mean): those contacts would open, so it is not a jamming point"
                + (f"; {ref.overlaps} other pair(s) overlap there" if ref.overlaps else "")
                if not ref.converged and solved and ref.negative else
                "not refined: the Newton system of the contacts is singular (a particle without contacts, "
                "or a floppy mode the stress does not hold)"
                if not (ref.converged or ref.iterations) else
                f"not refined: Newton did not converge: it diverged at step {ref.iterations} (a step of "
                f"{ref.steps[-1]:.3g} smallest semiaxes or radians, beyond {MAX_STEP:g}; balance {ref.balance[-1]:.2g}"
                + (f", after {ref.dropped} contact(s) left and {ref.added} joined the network"
                   if ref.dropped or ref.added else "")
                + "): the jamming point of these contacts, if any, is beyond the reach of Newton from the packing"
                if not ref.converged and ref.steps.size and ref.steps[-1] > MAX_STEP else
                f"not refined: Newton did not converge in {ref.iterations} steps (balance {ref.balance[-1]:.2g}, "
                f"largest step {info['refine_step']:.3g}): the jamming point is ill-defined at second order"
                if not ref.converged else
                f"not refined: at the jamming point of the contacts {ref.overlaps} pair(s) overlap, so the "
                "packing is not near the jamming point of its own contacts")
        result.params.update(info)
        if ref.pinned:
            note += f"; {ref.pinned} particle(s) with fewer than {packing.dim + 1} contacts held fixed as rattlers"
    result.params.update(refined=0, refine_note=note + whole)
    if whole and not result.backbone.any():
        # every particle a "rattler" only because its own near self-stress was lost: no verdict
        dec.verdict, dec.order = Verdict.UNDETERMINED, "undetermined"
        dec.reason = ("the local test lost every particle (no particle's own near self-stress stands out; "
                      "torques near the sphere point are small) and the jamming point of all the contacts "
                      "was not reached")
    result.collective.reason = f"{result.collective.reason} ({note})"
    return result
