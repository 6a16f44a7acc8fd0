"""An ascent of the particle size by sequential linear programming: an independent check of the
second-order verdicts on ellipse and ellipsoid packings.

A packing is jammed when no motion of its particles lets them all grow. Donev 2006, Sec. 5.5.2,
poses this as an optimisation: the jamming point is a strict local maximum of the common size
factor s subject to h_c >= 0 for every pair. The second-order test
(:mod:`hardpack.jamming.second_order`) decides it from the stress matrix on the floppy space.
This module checks that verdict by the optimisation itself, with first derivatives only. It runs
trust-region sequential linear programming (SLP) on

    max ds  subject to  h_c + A_c^T dQ - b_c ds >= 0  for every pair with mu - 1 <= CANDIDATE_DELTA,
                        |dQ_k| <= r a (translations), |dQ_k| <= r (angles), |ds| <= r.

The notation is that of :mod:`hardpack.jamming.refine`:

- h_c = zeta_c / s_c is the gap of pair c in length units;
- A^T holds the rigidity rows;
- b_c = -dh_c / ds;
- a is the smallest semiaxis.

Every step re-linearises at the current configuration from the Perram-Wertheim function. The
trust radius r shrinks by ``shrink`` per step. This is the LP ascent of Donev, Torquato,
Stillinger & Connelly 2004 (J. Comput. Phys. 197, 139), whose deforming-cell sphere version is
:mod:`hardpack.slp`; here it runs in a fixed cell, with rotations.

A step's overlaps are of second order in r, so the last configuration overlaps by about the
square of the last radius, plus the LP tolerance (1e-10 on the gaps). A uniform shrink by the
smallest Perram-Wertheim factor mu then removes them. Every packing this module returns
therefore has mu >= 1 for every pair: it is free of overlaps, not merely within a tolerance.

:func:`confirm_unjamming` uses the ascent as a certificate. Suppose the jamming point of a
packing is second-order flexible: a floppy mode x has negative stiffness lambda (Donev 2006,
Sec. 5.5.2.1). The particles can then grow along x at second order, by about |lambda| eps^2 for
an amplitude eps. The linear motion alone does not grow them: growth needs the second-order
correction, which the ascent finds. So the jamming point is moved by +-eps x (the sign of an
eigenvector is arbitrary) and ascended. A packing without overlaps that is denser than the
jamming point is an explicit unjamming: proof that the verdict "not jammed" is right, by a
method that does not use the stress matrix.

The converse is measured, not proven. The near-sphere LS packings of the full config were moved
by amplitudes 0.01-0.1 along their softest floppy mode and along random floppy directions, and
ascended. The 16 second-order jammed ones never ended denser than their jamming point (258
ascents, gains -8e-11 to -1.9e-6). A larger
amplitude can leave the basin of the jamming point for another one, denser or not, so a gain
only counts as a certificate at the amplitudes of :data:`CONFIRM_AMPLITUDES`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours.pairs import wrapped_positions
from hardpack.geometry.packing import Packing
from hardpack.jamming.ellipsoids import (
    check_ellipsoid_packing,
    displaced,
    dof_per_particle,
    ellipsoid_contacts,
    rigidity_transpose_full,
)
from hardpack.jamming.highs import LPFailure, solve_lp
from hardpack.jamming.rigidity import strain_pairs
from hardpack.jamming.second_order import dof_basis

__all__ = ["Ascent", "Unjamming", "ascend", "confirm_unjamming", "lp_method", "CONFIRM_AMPLITUDES", "IPM_ABOVE"]

#: pairs with mu - 1 up to this enter each LP (a step moves particles by at most r a << this)
CANDIDATE_DELTA = 2e-2
#: steps of :func:`ascend` and the factor of the trust radius per step: the last radius is
#: radius * ASCENT_SHRINK**ASCENT_STEPS (3e-11 of the first)
ASCENT_STEPS = 80
ASCENT_SHRINK = 0.74
#: a round of :func:`ascend` that gains less than this (relative phi) ends the ascent
ROUND_GAIN = 1e-10
#: the amplitudes (largest component of the motion, in smallest semiaxes or radians) that
#: :func:`confirm_unjamming` tries, each with both signs, in this order
CONFIRM_AMPLITUDES = (0.03, 0.01, 0.1)
#: a relative density gain above this certifies an unjamming (the Perram-Wertheim factors that
#: decide "no overlap" are exact to ~1e-14)
CERTIFICATE_GAIN = 1e-10
#: above this many particles the LPs are solved by HiGHS's interior-point method (with crossover
#: to a vertex) instead of its dual simplex. The LPs are highly degenerate: at N = 640 (a 2 x 2 x 2
#: tiling of an N = 80 M&M packing, 3201 variables, 3376 rows) the dual simplex took 21828
#: iterations and 53 CPU-s for the first LP (the primal simplex 35 s, with or without the dense
#: growth column split into blocks), the interior-point method 3-10 s per LP and 384 CPU-s for
#: 40 steps. Warm-starting the dual simplex from the previous step's basis took 2-47 s per LP
#: (0-5800 iterations), no faster. Below, the dual simplex stays: its vertices are those the
#: tests of :mod:`hardpack.jamming.refine` were measured with (an interior-point vertex left the
#: retry of the prolate alpha = 1.02 test packing unconverged).
IPM_ABOVE = 400


@dataclass
class Ascent:
    """The outcome of :func:`ascend`.

    Attributes
    ----------
    packing : Packing
        The last configuration, shrunk uniformly so that no pair overlaps (mu >= 1 for every pair).
    phi_start : float
        Volume fraction of the start.
    phi : float
        Volume fraction of ``packing``.
    mu_min : float
        Smallest Perram-Wertheim factor at the last configuration before the shrink.
    steps : int
        LP steps taken.
    rounds : int
        Schedules run.
    repairs : int
        Steps whose LP was infeasible, a numerical fallback: the previous step left overlaps that
        the trust radius could not undo, and a uniform shrink by the smallest mu removed them.
    lp_method : str
        The HiGHS method tried first for every LP: "highs-ds" (dual simplex) up to IPM_ABOVE
        particles, "highs-ipm" (interior point with crossover) above.
    """

    packing: Packing
    phi_start: float
    phi: float
    mu_min: float
    steps: int
    rounds: int = 1
    repairs: int = 0
    lp_method: str = "highs-ds"


@dataclass
class Unjamming:
    """The outcome of :func:`confirm_unjamming`.

    Attributes
    ----------
    confirmed : bool
        Whether an ascent ended denser than the jamming point by more than CERTIFICATE_GAIN.
    gain : float
        The largest relative density gain (phi - phi_J) / phi_J over the ascents tried.
    amplitude : float
        The signed amplitude of the ascent with that gain.
    packing : Packing
        That ascent's packing (free of overlaps).
    tried : int
        Ascents run.
    """

    confirmed: bool
    gain: float
    amplitude: float
    packing: Packing
    tried: int


def _check_periodic_ellipsoids(packing: Packing) -> None:
    check_ellipsoid_packing(packing)
    if packing.boundary.kind != "periodic":
        raise InvalidInputError("the size ascent handles periodic packings only (no walls): "
                                f"this packing's boundary is {packing.boundary}")


def _smallest_mu(net) -> float:
    """The smallest Perram-Wertheim factor mu of the pairs of ``net`` (pairs beyond CANDIDATE_DELTA
    do not overlap)."""
    return float(np.sqrt(net.zeta.min() + 1.0)) if net.n_contacts else 1.0 + CANDIDATE_DELTA


def _shrunk(packing: Packing, positions: np.ndarray, mu: float) -> Packing:
    """``packing`` at ``positions`` with every semiaxis scaled by mu (1 - 1e-12): no pair whose
    smallest factor was mu overlaps."""
    spins = np.zeros((packing.n_particles, dof_per_particle(packing.dim) - packing.dim))
    return displaced(packing, positions, spins, mu * (1.0 - 1e-12))


def _moving(packing: Packing, frozen) -> np.ndarray:
    if frozen is None:
        return np.ones(packing.n_particles, dtype=bool)
    frozen = np.asarray(frozen)
    if frozen.shape != (packing.n_particles,) or frozen.dtype != bool:
        raise InvalidInputError(f"frozen must be a boolean array of shape ({packing.n_particles},), "
                                f"got {frozen.dtype} of shape {frozen.shape}")
    return ~frozen


def _strain_rows(net, d: int) -> np.ndarray:
    """(M, d(d+1)/2): the gap rate of each contact under a symmetric strain E of the cell and the
    centres, dr = E r for the separation r (u . E r, u the unit normal); columns in the order of
    :func:`hardpack.jamming.rigidity.strain_pairs`, E_pq with p < q counted twice."""
    u, r = net.normal, net.separation
    return np.column_stack([u[:, p] * r[:, q] + (u[:, q] * r[:, p] if p != q else 0.0)
                            for p, q in strain_pairs(d)])


def _strain_matrix(e: np.ndarray, d: int) -> np.ndarray:
    """The symmetric strain of the LP's variables (in the order of ``strain_pairs``)."""
    strain = np.zeros((d, d))
    for value, (p, q) in zip(e, strain_pairs(d)):
        strain[p, q] = strain[q, p] = value
    return strain


def ascend(packing: Packing, *, frozen=None, deform: bool = False, radius: float = 1e-3,
           steps: int = ASCENT_STEPS, shrink: float = ASCENT_SHRINK, rounds: int = 1) -> Ascent:
    """Grow the particles by trust-region SLP (module docstring), then shrink away the overlaps.

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell. Small overlaps are allowed (the first steps
        remove them).
    frozen : array_like of bool, shape (N,), optional
        Particles that do not move (they grow with the others, about fixed centres).
    deform : bool, default False
        Also deform the cell: a symmetric strain E (each entry within the trust radius) moves the
        lattice vectors and the centres affinely, and the LP maximises the growth of the
        volume fraction, d ds - Tr E, instead of ds (the SLP of Donev et al. 2004 with rotations).
    radius : float, default 1e-3
        First trust radius: the largest move per step, in smallest semiaxes (translations),
        radians (rotations) and relative size.
    steps : int, default ASCENT_STEPS
        LP steps.
    shrink : float, default ASCENT_SHRINK
        Factor of the trust radius per step.
    rounds : int, default 1
        Schedules at most: each round restarts from ``radius`` at the previous round's packing, and
        the ascent stops after a round that gains less than ROUND_GAIN (relative). One schedule
        travels at most radius / (1 - shrink) per component, so a packing far from its maximum (an
        LS crystal in a small deforming cell) needs several.

    Returns
    -------
    Ascent

    Raises
    ------
    InvalidInputError
        For a packing that is not of ellipses or ellipsoids in a periodic cell, or bad options.
    """
    _check_periodic_ellipsoids(packing)
    if not (np.isfinite(radius) and 0 < radius <= 0.5):
        raise InvalidInputError(f"radius must be in (0, 0.5], got {radius!r}")
    if not (isinstance(steps, int) and steps >= 1):
        raise InvalidInputError(f"steps must be a positive integer, got {steps!r}")
    if not (np.isfinite(shrink) and 0 < shrink <= 1):
        raise InvalidInputError(f"shrink must be in (0, 1], got {shrink!r}")
    if not (isinstance(rounds, int) and rounds >= 1):
        raise InvalidInputError(f"rounds must be a positive integer, got {rounds!r}")
    moving = _moving(packing, frozen)
    current, mu, done, repairs = packing, 1.0, 0, 0
    while done < rounds:
        start = current
        current, mu, repaired = _round(start, moving, deform, float(radius), steps, shrink)
        done += 1
        repairs += repaired
        if current.phi - start.phi <= ROUND_GAIN * start.phi:
            break
    return Ascent(packing=current, phi_start=float(packing.phi), phi=float(current.phi), mu_min=mu,
                  steps=steps * done, rounds=done, repairs=repairs, lp_method=lp_method(packing.n_particles))


def lp_method(n_particles: int) -> str:
    """The HiGHS method :func:`ascend` tries first for the LPs of ``n_particles`` particles.

    Parameters
    ----------
    n_particles : int
        Particles of the packing.

    Returns
    -------
    str
        "highs-ds" up to IPM_ABOVE particles, "highs-ipm" above (measured costs at IPM_ABOVE).
    """
    return "highs-ipm" if n_particles > IPM_ABOVE else "highs-ds"


def _round(packing: Packing, moving: np.ndarray, deform: bool, radius: float, steps: int, shrink: float):
    """One schedule of :func:`ascend`: (the packing shrunk free of overlaps, mu_min before that,
    repaired steps)."""
    d, f = packing.dim, dof_per_particle(packing.dim)
    a = float(np.min(packing.shape.semiaxes))
    current, x, r, repairs = packing, wrapped_positions(packing), radius, 0
    method = lp_method(packing.n_particles)
    for _ in range(steps):
        net = ellipsoid_contacts(current, CANDIDATE_DELTA)
        t, _ = dof_basis(net, moving)
        at = (rigidity_transpose_full(net) @ t).tocsr()
        n = at.shape[1]
        gaps = net.zeta / net.scale
        growth = 2.0 * (net.zeta + 1.0) / net.scale
        strain = _strain_rows(net, d) if deform else np.zeros((net.n_contacts, 0))
        k = strain.shape[1]
        objective = np.zeros(n + k + 1)
        objective[n:n + min(k, d)] = 1.0  # Tr E
        objective[-1] = -float(d)
        rows = sp.hstack([-at, sp.csr_matrix(-strain), sp.csr_matrix(growth[:, None])]).tocsr()
        try:
            lp = solve_lp(objective, method=method, A_ub=rows, b_ub=gaps,
                          bounds=[(-r * a, r * a)] * n + [(-r, r)] * (k + 1))
        except LPFailure:
            mu = _smallest_mu(net)
            if mu >= 1.0:
                raise  # the LP is feasible (nothing moves): a solver failure, not a repair
            # the previous step left overlaps the trust radius cannot undo: shrink them away
            current = _shrunk(current, x, mu)
            repairs += 1
            r *= shrink
            continue
        move = (t @ lp.x[:n]).reshape(packing.n_particles, f)
        lattice = None
        if deform:
            affine = np.eye(d) + _strain_matrix(lp.x[n:n + k], d)
            x, lattice = x @ affine.T, affine @ current.lattice
        x = x + move[:, :d]
        current = displaced(current, x, move[:, d:], 1.0 + float(lp.x[-1]), lattice)
        r *= shrink
    mu = _smallest_mu(ellipsoid_contacts(current, CANDIDATE_DELTA))
    if mu < 1.0:
        current = _shrunk(current, x, mu)
    return current, mu, repairs


def confirm_unjamming(packing: Packing, result, *, amplitudes=CONFIRM_AMPLITUDES) -> Unjamming:
    """Certify a second-order flexible verdict by an ascent from the jamming point moved along
    its unjamming motion (module docstring).

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell at a jamming point of their contacts (e.g. the
        refined packing of :func:`hardpack.jamming.refine.refine_jamming_point`).
    result : EllipsoidJammingResult
        :func:`hardpack.jamming.second_order.verify_ellipsoids` of ``packing``, with an unjamming
        motion (a floppy mode of negative or zero stiffness).
    amplitudes : sequence of float, default CONFIRM_AMPLITUDES
        Largest component of the displacement (smallest semiaxes, radians), each tried with both
        signs, in order, until one ascent certifies.

    Returns
    -------
    Unjamming

    Raises
    ------
    InvalidInputError
        For a result without an unjamming motion or of another packing, bad amplitudes, or a
        packing the ascent does not handle.
    """
    _check_periodic_ellipsoids(packing)
    motion = result.unjamming_motion()
    if motion is None:
        raise InvalidInputError("the result has no unjamming motion (a jammed verdict, or one decided at first "
                                "order): there is nothing to confirm")
    if motion.shape[0] != packing.n_particles:
        raise InvalidInputError(f"the result is of a packing of {motion.shape[0]} particles, not of this one "
                                f"({packing.n_particles})")
    amplitudes = [float(e) for e in amplitudes]
    if not amplitudes or not all(np.isfinite(e) and 0 < e <= 0.5 for e in amplitudes):
        raise InvalidInputError(f"amplitudes must be numbers in (0, 0.5], got {amplitudes!r}")
    d = packing.dim
    a = float(np.min(packing.shape.semiaxes))
    # the largest component 1, translations in smallest semiaxes (the direction kept)
    motion = motion / max(np.abs(motion[:, :d]).max() / a, np.abs(motion[:, d:]).max())
    x0 = wrapped_positions(packing)
    best, tried = None, 0
    for eps in amplitudes:
        for amplitude in (eps, -eps):
            start = displaced(packing, x0 + amplitude * motion[:, :d], amplitude * motion[:, d:], 1.0)
            out = ascend(start, frozen=result.frozen, radius=eps)
            tried += 1
            gain = (out.phi - packing.phi) / packing.phi
            if best is None or gain > best[0]:
                best = (gain, amplitude, out.packing)
            if gain > CERTIFICATE_GAIN:
                return Unjamming(True, gain, amplitude, out.packing, tried)
    return Unjamming(False, best[0], best[1], best[2], tried)
