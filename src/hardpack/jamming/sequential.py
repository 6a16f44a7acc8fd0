"""Algorithm 14 (sequential random loading) for packings with gaps, e.g. finite-rate LS packings.

Donev 2006, dissertation sec. 4.6.2 (Algorithm 14):

3. rattlers are marked (iterative local test) and kept as fixed obstacles (no load on them;
   the text keeps them as constraints, sec. 4.6.2.2; fixing them avoids the spurious
   large rattler displacements the text warns about there);
4. random load B (zero on rattlers);
5. solve LP 4.10 (+ 4.17 for the strict test) for a linearised motion (dR, eps);
   The LP box (|dr| <= box, sec. 4.3.2, footnote 8) is at most delta r_min, the trust region of the
   linearised neighbour list: a longer LP motion could not be taken in step 6 anyway;
6. move along it as far as possible: the largest tau such that no pair overlaps for
   t in [0, tau] (quadratic collision times of the straight-line motion, as in LS collision
   scheduling, sec. 4.6.2.3), no pair outside the contact list can collide (every particle
   moves less than the list's gap delta D_min), and det(I + tau eps) <= 1; then
   R <- R + tau dR, Lambda <- (I + tau eps) Lambda, and the contact network is rebuilt;
7. repeat 5-6 while some particle moved by more than beta D (at most ``max_steps`` LPs);
9. the same with -B; 10. ``n_loads`` loads in all (the text used 3 loads x 2 directions x 3 LPs,
   sec. 4.7.2.2), and, as step 10 says, stop with "not jammed" as soon as the displacement
   accumulated in a sequence exceeds the threshold (a valid packing that far from the start
   certifies the verdict; the remaining loads could only add statistics).

Every loading sequence starts from the given packing. The text goes on from wherever the
previous sequence ended (steps 9-10); we do not, for three reasons. (a) The test is about the
given packing: each sequence then probes its own jamming polytope J_dR in one load direction,
as B and -B do in Algorithm 13, instead of the neighbourhood of a packing the test itself
sheared (a strict sequence at N = 1e4 in 3D moves the particles by ~5e-4 D, the gaps of the
contacts it opened; the reversed load then mostly undoes it). (b) Speed: at the moved packing
the smallest gaps no longer mark the contact core: at N = 1e4 in 3D the first LPs of strict
sequences 2-6 took 530-850 s there, against 45-52 s at the given packing. (c) The sequences
are independent, so they can run side by side (``workers``).

The contact list must reach beyond the gaps that matter: step 6 moves no particle by more than
delta D_min / 2 per LP, so a sequence can never displace anything by more than
max_steps delta D_min / 2 and a small delta makes the test unable to fail (:func:`verify`
refuses such settings; Donev uses delta = 0.1-1, sec. 4.6.2.1). The LPs are solved by
:mod:`hardpack.jamming.workingset`; within a sequence each warm-starts from the previous one's
basis, and the first starts from the smallest gaps (a strict one through :func:`solve_motion`'s
strain continuation: its optimum shears the cell and closes hundreds of near contacts).

The statistic reported (Tables 4.2-4.7) is the displacement |dr_i| accumulated over one loading
sequence (one load direction), relative to the bulk (componentwise median over the non-rattlers
subtracted), in units of the mean diameter, averaged over the non-rattlers (rattlers are fixed
and excluded; Donev's Table 4.5 includes them, sec. 4.7.2.3). In the strict test dr_i includes the
affine part of a cell deformation, as the LP variables of the text do. The strain accumulated
over the sequence, |eps|_2 (the largest relative displacement the cell deformation gives two
touching particles, in units of their distance D), counts as well: with one particle per cell,
e.g. the square or simple cubic lattice sheared at decreasing volume (Donev Table 4.1: not
strictly jammed), that particle is its own bulk and no displacement relative to the bulk can
see the cell deform. The strain does not depend on the supercell (secs. 4.4.5.4-4.4.6), where the
affine part of the mean displacement grows with the cell. The verdict is "jammed" when no
sequence reaches ``threshold`` with its mean displacement or its strain (a judgement, as the
text says, sec. 4.6.2.5). It is undetermined (reported with the reason) when no sequence
reached it but one could not go on: a step that keeps overlapping after MAX_HALVINGS halvings,
or an LP strain that violates Tr eps <= 0 beyond the LP's accuracy (:class:`VolumeIncrease`).

Round-off: a pair already in contact may approach by the LP feasibility tolerance (~1e-10);
the collision time is therefore computed for a distance (1 - 1e-11) times the smaller of the
current distance and D_ij, which never lets overlaps grow beyond the packing tolerance.

Hard walls and spherical containers stay fixed (Donev 2006, sec. 4.4.2; only the collective test
runs, :func:`hardpack.jamming.verify.verify` takes it for the strict one of a closed container). A
wall contact is a contact with a fixed point of the wall (sec. 4.4.3): in the LP the one-sided
constraint n . dr_i <= h - r_i, in step 6 the exact wall (:func:`wall_step`). The displacement
relative to the bulk subtracts the trivial motions of the boundary: the median along the periodic
axes only, and in a spherical container the least-squares rotation about its centre. A concave
container wall is a limit of the straight step: a sphere touching it can slide along it only by
moving inwards at second order, which the linearised LP does not see, so the wall cuts the step a
few 1e-6 D into the motion. When that cut ends a sequence whose LP motion was beyond beta D, the
test is undetermined, with the reason: its "jammed" would only say that straight lines hit the wall
(measured: a 30-sphere container packing with one backbone sphere shrunk by 10 %, floppy by the
ideal test, moved 4e-6 D per sequence). Flat walls have no such limit.

A test is resumable after any loading sequence (``save`` / ``resume`` of
:func:`sequential_test`; :func:`hardpack.jamming.verify.verify` keeps them in a checkpoint file):
at N = 1e4 in 3D a strict loading sequence takes 1-1.5 min (2-3 LPs of 18-41 s).
"""

from __future__ import annotations

import json
import logging
import os
import time
from collections import Counter
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from functools import partial
from multiprocessing import get_context

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.geometry.packing import Packing
from hardpack.jamming.contacts import ContactNetwork, contact_network
from hardpack.jamming.highs import FALLBACKS, recording_fallbacks
from hardpack.jamming.ideal import cell_length
from hardpack.jamming.lp import VolumeIncrease, random_load, random_strain_load, solve_motion
from hardpack.jamming.rigidity import rotation_velocities

log = logging.getLogger(__name__)

#: relative approach allowed for pairs in contact (see the module docstring)
APPROACH_SLACK = 1e-11
#: environment of the worker processes: one BLAS thread each. Two workers with OpenBLAS's own
#: thread pools (a second thread each, or as many as Snakemake gives the job) took 2.6 times as
#: long per LP on 2 cores; with one thread each, as long as one process alone (N = 1e4 in 3D)
ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
#: layout of a saved test state (1: sequences went on from the moved packing, with LP warm starts;
#: 2: without the undetermined reason and the fallback counts)
STATE_VERSION = 3
#: halvings of a step that round-off makes overlap before the sequence is given up (undetermined)
MAX_HALVINGS = 60


@dataclass
class SequentialOutcome:
    """Result of one sequential test. ``jammed`` is False also when ``undetermined`` holds a
    reason: no sequence reached the threshold, but one of them could not go on (a step that
    round-off kept overlapping, or an LP whose strain violates the volume constraint), so
    jamming is not shown either.

    Attributes
    ----------
    test : str
        "collective" or "strict".
    jammed : bool
        The verdict.
    threshold : float
        Size above which a loading sequence unjams the packing.
    mean_displacement : list of float
        Per sequence, the mean |dr_i| over the mean diameter.
    strain_norm : list of float
        Per sequence, |sum tau eps|_2.
    max_displacement : list of float
        Per sequence, the largest |dr_i| over the mean diameter.
    steps : list of int
        LPs per sequence.
    displacement : numpy.ndarray of float, shape (N,), or None
        Largest |dr_i| / D over the sequences.
    motion : numpy.ndarray of float, shape (N, d), or None
        Displacements of the sequence with the largest mean displacement.
    strain : numpy.ndarray of float, shape (d, d), or None
        Total strain of that sequence.
    final : Packing or None
        The packing at the end of the last loading sequence.
    n_lp : int
        LPs solved.
    n_lp_highs : int
        LPs HiGHS solved (the others: :mod:`hardpack.jamming.workingset`).
    seconds : float
        Wall time.
    method : str
        "sequential".
    undetermined : str
        Why the test could not decide ("" when it did).
    fallbacks : collections.Counter
        Numerical fallbacks used (:data:`hardpack.jamming.highs.FALLBACKS`).
    """

    test: str
    jammed: bool
    threshold: float
    mean_displacement: list = field(default_factory=list)  # per sequence, / mean diameter
    strain_norm: list = field(default_factory=list)  # per sequence, |sum tau eps|_2
    max_displacement: list = field(default_factory=list)  # per sequence, / mean diameter
    steps: list = field(default_factory=list)  # LPs per sequence
    displacement: np.ndarray | None = None  # (N,) largest |dr_i| / D over sequences
    motion: np.ndarray | None = None  # (N, d) sequence with the largest mean displacement
    strain: np.ndarray | None = None  # (d, d) total strain of that sequence
    final: Packing | None = None  # the packing at the end of the last loading sequence
    n_lp: int = 0
    n_lp_highs: int = 0  # LPs HiGHS solved (the others: hardpack.jamming.workingset)
    seconds: float = 0.0
    method: str = "sequential"
    undetermined: str = ""  # why the test could not decide ("" when it did)
    fallbacks: Counter = field(default_factory=Counter)  # hardpack.jamming.highs.FALLBACKS

    def size(self, sequence: int) -> float:
        """How far loading sequence ``sequence`` unjammed the packing, compared with the threshold
        (module docstring): the larger of its mean displacement / D and its strain.

        Parameters
        ----------
        sequence : int
            Index of the loading sequence.

        Returns
        -------
        float
            max(mean |dr_i| / D, |eps|_2) of that sequence.
        """
        return max(self.mean_displacement[sequence], self.strain_norm[sequence])

    @property
    def unjammed(self) -> bool:
        """Some loading sequence reached the threshold."""
        return any(self.size(k) >= self.threshold for k in range(len(self.steps)))


def collision_step(net: ContactNetwork, disp: np.ndarray, eps: np.ndarray | None) -> float:
    """Largest tau keeping every listed pair apart along x + t dR, Lambda + t eps Lambda, and
    every sphere with a listed wall contact inside its wall (:func:`wall_step`).

    Parameters
    ----------
    net : ContactNetwork
        The contact list.
    disp : numpy.ndarray of float, shape (N, d)
        Direction dR of the particles.
    eps : numpy.ndarray of float, shape (d, d), or None
        Strain rate of the cell (None: fixed cell).

    Returns
    -------
    float
        The step tau (inf if nothing limits it).
    """
    pair = ~net.is_wall if net.n_wall_contacts else slice(None)
    w = disp[net.j[pair]] - disp[net.i[pair]]
    if eps is not None:
        w = w + net.image_offset[pair] @ eps.T
    s0 = net.separation[pair]
    distance = net.distance[pair]
    target = (1.0 - APPROACH_SLACK) * np.minimum(distance, net.contact_distance[pair])
    a = np.einsum("ij,ij->i", w, w)
    b = 2.0 * np.einsum("ij,ij->i", s0, w)
    c = distance**2 - target**2
    disc = b * b - 4.0 * a * c
    hit = (b < 0) & (disc >= 0) & (a > 0)
    step = wall_step(net, disp)
    if not hit.any():
        return step
    root = (2.0 * c[hit]) / (-b[hit] + np.sqrt(disc[hit]))  # smaller root, cancellation-free
    return min(float(root.min()), step)


def wall_step(net: ContactNetwork, disp: np.ndarray) -> float:
    """Largest tau keeping the spheres of the listed wall contacts inside their fixed walls along
    x + t dR (Donev 2006, sec. 4.4.3: the wall stays put; exact, not the linearised contact).

    A wall contact (:mod:`hardpack.jamming.contacts`) of sphere i at centre-wall distance h with
    outward normal n: a flat wall is reached when n . dr_i t = h - r_i; the wall of a spherical
    container of radius R about c when |x_i - c + t dr_i| = R - r_i, the positive root of a
    quadratic (the other is negative: the sphere is inside). The target distance is lowered by
    APPROACH_SLACK as for the pairs.

    Parameters
    ----------
    net : ContactNetwork
        The contact list.
    disp : numpy.ndarray of float, shape (N, d)
        Direction dR of the particles.

    Returns
    -------
    float
        The step tau (inf without wall contacts or motion towards a wall).
    """
    wall = net.is_wall
    if not wall.any():
        return np.inf
    i = net.i[wall]
    v = disp[i]
    h = net.distance[wall]
    target = (1.0 - APPROACH_SLACK) * np.minimum(h, net.contact_distance[wall])
    if net.centre is None:  # flat walls: the distance h - t n . dr_i
        speed = np.einsum("ij,ij->i", net.normal[wall], v)
        out = speed > 0
        return float(((h[out] - target[out]) / speed[out]).min(initial=np.inf))
    a = np.einsum("ij,ij->i", v, v)
    moves = a > 0
    if not moves.any():
        return np.inf
    y = net.positions[i] - net.centre
    yy = np.einsum("ij,ij->i", y, y)
    reach = np.sqrt(yy) + h - target  # R - target
    b = 2.0 * np.einsum("ij,ij->i", y, v)
    c = np.minimum(yy - reach**2, 0.0)
    a, b, c = a[moves], b[moves], c[moves]
    root = np.sqrt(b * b - 4.0 * a * c)
    # positive root (-b + root) / 2a, written without cancellation for b > 0
    tau = np.where(b > 0, -2.0 * c / np.maximum(b + root, np.finfo(float).tiny), (root - b) / (2.0 * a))
    return float(tau.min())


def list_step(net: ContactNetwork, radii: np.ndarray, disp: np.ndarray, eps: np.ndarray | None) -> float:
    """Largest tau for which no pair outside the contact list (gap > delta D_ij) can touch.

    A pair's relative velocity is dr_j - dr_i + eps Lambda n; for a pair within reach,
    |Lambda n| <= |r_ij| + |x_j - x_i| <= (1 + delta) 2 r_max + sum of the lattice vector lengths.

    Parameters
    ----------
    net : ContactNetwork
        The contact list (tolerance delta).
    radii : numpy.ndarray of float, shape (N,)
        Particle radii.
    disp : numpy.ndarray of float, shape (N, d)
        Direction dR of the particles.
    eps : numpy.ndarray of float, shape (d, d), or None
        Strain rate of the cell (None: fixed cell).

    Returns
    -------
    float
        The step tau (inf if nothing moves).
    """
    speed = 2.0 * np.linalg.norm(disp, axis=1).max(initial=0.0)
    if eps is not None:
        span = np.linalg.norm(net.lattice, axis=0).sum()
        speed += np.linalg.norm(eps, 2) * ((1.0 + net.delta) * 2.0 * radii.max() + span)
    return np.inf if speed == 0 else net.delta * 2.0 * radii.min() / speed


def volume_step(eps: np.ndarray | None) -> float:
    """Largest tau with det(I + t eps) <= 1 for all t in [0, tau] (strict test only).

    det(I + t eps) - 1 = prod_k (1 + t lambda_k) - 1 = t q(t); the first positive root of q.

    Parameters
    ----------
    eps : numpy.ndarray of float, shape (d, d), or None
        Symmetric strain rate (None: fixed cell).

    Returns
    -------
    float
        The step tau (inf if the volume never grows back to 1).
    """
    if eps is None:
        return np.inf
    lams = np.linalg.eigvalsh(eps)
    poly = np.array([1.0])  # ascending powers of t
    for lam in lams:
        poly = np.convolve(poly, [1.0, lam])
    q = poly[1:]
    q[np.abs(q) <= 1e-12 * np.abs(lams).max(initial=0.0) ** np.arange(1, q.size + 1)] = 0.0
    while q.size and q[0] == 0.0:  # a zero low-order coefficient is a root at t = 0: divide it out
        q = q[1:]
    if q.size < 2:
        return np.inf
    roots = np.roots(q[::-1])
    real = roots[np.abs(roots.imag) <= 1e-12 * np.abs(roots).max(initial=1.0)].real
    positive = real[real > 0]
    return float(positive.min()) if positive.size else np.inf


def sequential_test(
    packing: Packing,
    delta: float,
    *,
    strict: bool,
    rattlers: np.ndarray,
    rng: np.random.Generator,
    box: float,
    threshold: float = 1e-3,
    beta: float = 0.01,
    n_loads: int = 3,
    max_steps: int = 3,
    resume: dict | None = None,
    save: Callable[[dict], None] | None = None,
    workers: int = 1,
) -> SequentialOutcome:
    """Algorithm 14 from ``packing`` (see the module docstring).

    The ``n_loads`` random loads are drawn from ``rng`` first; the loading sequences (B, -B for
    each load) are independent, since each starts from ``packing``: ``workers`` > 1 runs that
    many at once in worker processes. The outcome does not depend on ``workers``: sequences are
    recorded in order, and those after the one that settles the verdict are discarded.

    Resumable: after each loading sequence, ``save`` (if given) receives the test's state, a
    dict of arrays and scalars; passing such a dict back as ``resume`` (same packing, rng seed and
    parameters) continues after that sequence, with the same loads, so the outcome is that of
    an uninterrupted test.

    Parameters
    ----------
    packing : Packing
        The sphere packing to load (periodic, between hard walls or in a spherical container:
        ``strict`` needs a periodic cell); every loading sequence starts from it.
    delta : float
        Relative gap tolerance of the contact list; also bounds each LP step by delta r_min.
    strict : bool
        False: collective test (fixed cell); True: strict test (strain with Tr eps <= 0).
    rattlers : numpy.ndarray of bool, shape (N,)
        Particles kept as fixed obstacles, without load.
    rng : numpy.random.Generator
        Source of the random loads (all ``n_loads`` drawn first).
    box : float
        Bound on each displacement component in the LPs (capped at delta r_min).
    threshold : float, default 1e-3
        Mean displacement / D (or strain |eps|_2) from which a sequence unjams the packing.
    beta : float, default 0.01
        A sequence stops once no particle moved by more than beta D in its last step.
    n_loads : int, default 3
        Random loads; each is applied as B and -B.
    max_steps : int, default 3
        Most LPs per loading sequence.
    resume : dict, optional
        A state received by ``save`` to continue from.
    save : callable, optional
        Called with the test's state (a dict) after each loading sequence.
    workers : int, default 1
        Loading sequences run at once in worker processes.

    Returns
    -------
    SequentialOutcome
        ``jammed``, per-sequence ``mean_displacement``, ``strain_norm``, ``max_displacement``
        and ``steps``, the per-particle largest ``displacement`` / D, the ``motion`` and
        ``strain`` of the sequence with the largest mean displacement, the ``final`` packing,
        LP counts, ``seconds``, ``fallbacks`` and ``undetermined`` with the reason when a
        sequence could not go on (then ``jammed`` is False).

    Raises
    ------
    InvalidInputError
        If ``resume`` is a state of another layout (saved by an older hardpack).
    """
    t0 = time.perf_counter()
    n, d = packing.n_particles, packing.dim
    moving = ~rattlers
    out = SequentialOutcome(test="strict" if strict else "collective", jammed=True, threshold=threshold)
    out.displacement = np.zeros(n)
    out.final = packing
    start_rng = json.dumps(rng.bit_generator.state)
    first, earlier = 0, 0.0  # the first loading sequence to run, seconds spent before a resume
    if resume is not None:
        start_rng, first, earlier = _restore(resume, out, packing, rng)
    loads = [(random_load(rng, moving, d),
              random_strain_load(rng, d, cell_length(packing.lattice)) if strict else None)
             for _ in range(n_loads)]
    todo = []  # (sequence, load, strain load): B and -B for each load
    if moving.any() and not out.unjammed:  # else settled before a resume, or nothing to load
        for sequence in range(first, 2 * n_loads):
            load, strain_load = loads[sequence // 2]
            sign = 1.0 if sequence % 2 == 0 else -1.0
            todo.append((sequence, sign * load, None if strain_load is None else sign * strain_load))
    # LP box = the step's trust region: no LP motion beyond delta r_min can be taken (list_step)
    box = min(box, delta * float(packing.radii.min()))
    run = partial(_loading_sequence, packing, delta, rattlers, box=box, threshold=threshold,
                  beta=beta, max_steps=max_steps)
    for sequence, result in _in_order(run, todo, workers):
        _record(out, result, moving, packing)
        if save is not None:
            save(_state(out, start_rng, sequence + 1, earlier + time.perf_counter() - t0))
        if out.size(-1) >= threshold:
            break  # step 10: the verdict is settled
    if not moving.any():  # every particle is a rattler: no backbone, nothing is jammed (Alg. 13 step 3)
        out.method = "no backbone: every particle is a rattler"
    out.jammed = bool(moving.any() and not out.unjammed and not out.undetermined)
    if out.unjammed:
        out.undetermined = ""  # a sequence beyond the threshold settles it, whatever another did
    out.seconds = earlier + time.perf_counter() - t0
    return out


@dataclass(frozen=True)
class _Sequence:
    """What one loading sequence (steps 5-7) did."""

    total: np.ndarray  # (N, d) displacement accumulated over its LPs
    strain: np.ndarray | None  # (d, d) strain accumulated (strict test)
    steps: int  # LPs solved
    n_lp_highs: int  # of which HiGHS solved
    final: Packing  # the packing at its end
    undetermined: str  # why it had to stop before its end ("" if it did not)
    fallbacks: Counter  # the numerical fallbacks of its LPs


def _loading_sequence(packing: Packing, delta: float, rattlers: np.ndarray, sequence: int,
                      load: np.ndarray, strain_load: np.ndarray | None, *, box: float,
                      threshold: float, beta: float, max_steps: int) -> _Sequence:
    """Steps 5-7 of Algorithm 14 from ``packing`` under ``load`` (and ``strain_load``: strict
    test). Each LP warm-starts from the previous one's basis; the first starts cold, and a
    strict one goes through the strain continuation of :func:`solve_motion`. The fallbacks of
    its LPs are recorded here (also in a worker process) and returned with it."""
    with recording_fallbacks() as fallbacks:
        result = _steps(packing, delta, rattlers, sequence, load, strain_load, box=box,
                        threshold=threshold, beta=beta, max_steps=max_steps)
    return replace(result, fallbacks=fallbacks)


def _steps(packing: Packing, delta: float, rattlers: np.ndarray, sequence: int, load: np.ndarray,
           strain_load: np.ndarray | None, *, box: float, threshold: float, beta: float,
           max_steps: int) -> _Sequence:
    """The LPs and steps of :func:`_loading_sequence`."""
    d = packing.dim
    moving = ~rattlers
    diameter = 2.0 * packing.radii.mean()
    test = "collective" if strain_load is None else "strict"
    name = f"{sequence // 2 + 1}{'+' if sequence % 2 == 0 else '-'}"
    current, warm = packing, None
    total = np.zeros((packing.n_particles, d))
    strain_total = None if strain_load is None else np.zeros((d, d))
    steps = highs = 0
    undetermined = ""
    for _step in range(max_steps):
        net = contact_network(current, delta)
        if warm is not None:  # particles that left the cell come back through the other side
            warm = warm.rewrapped(_wraps(current, net))
        try:
            mot = solve_motion(net, moving, load, fixed=rattlers, box=box,
                               cell_length=cell_length(current.lattice), strain_load=strain_load, warm=warm)
        except VolumeIncrease as exc:
            undetermined = f"loading sequence {name}, LP {steps + 1}: {exc}"
            break
        warm = mot.warm
        highs += mot.solver == "highs"
        steps += 1
        if not (np.isfinite(mot.displacement).all() and (mot.strain is None or np.isfinite(mot.strain).all())):
            undetermined = f"loading sequence {name}, LP {steps}: the LP motion is not finite"
            break
        tau = min(  # inf: the motion is zero, nothing moves
            collision_step(net, mot.displacement, mot.strain),
            list_step(net, current.radii, mot.displacement, mot.strain),
            volume_step(mot.strain),
        )
        curved = net.centre is not None and wall_step(net, mot.displacement) <= tau
        if np.isfinite(tau):
            moved = _advance(current, net, mot.displacement, mot.strain, tau)
            if moved is None:
                undetermined = (f"loading sequence {name}, LP {steps}: a step of {tau:.3g} times the LP "
                                f"motion overlaps even after {MAX_HALVINGS} halvings (round-off), so "
                                "the sequence cannot go on")
                break
            current, tau = moved
        else:
            tau = 0.0
        step = tau * mot.displacement
        largest = np.linalg.norm(step[moving], axis=1).max(initial=0.0)
        log.info("%s test, load %s, LP %d: %s, %.1f s; step %.3g: mean %.3g D, largest %.3g D", test, name,
                 steps, mot.solver, mot.seconds, tau, _mean_size(step, moving, packing), largest / diameter)
        if tau == 0.0:
            break
        total += step
        if strain_total is not None:
            strain_total += tau * mot.strain
        strain_size = 0.0 if strain_total is None else np.linalg.norm(strain_total, 2)
        if max(_mean_size(total, moving, packing), strain_size) >= threshold:
            break  # step 10: unjammed beyond the threshold, the verdict is settled
        if largest <= beta * diameter:
            lp_largest = np.linalg.norm(mot.displacement[moving], axis=1).max(initial=0.0)
            if curved and lp_largest > beta * diameter:
                undetermined = (f"loading sequence {name}, LP {steps}: the container wall cut the step to "
                                f"{largest / diameter:.3g} D of the LP motion's {lp_largest / diameter:.3g} D; a "
                                "straight step cannot follow a sphere sliding along the curved wall (it "
                                "must move inwards at second order), so jamming is not shown")
            break
    if undetermined:
        log.warning("%s test: %s", test, undetermined)
    return _Sequence(total, strain_total, steps, highs, current, undetermined, Counter())


def _wraps(packing: Packing, net: ContactNetwork) -> np.ndarray:
    """(N, d) integer lattice vectors w_i with x_i = net.x_i + lattice @ w_i: how the contact
    network wrapped the packing's positions into the cell (the image shifts of its contacts
    change accordingly, :meth:`hardpack.jamming.workingset.WarmStart.rewrapped`)."""
    return np.rint(np.linalg.solve(net.lattice, (packing.positions - net.positions).T).T).astype(np.int64)


def _in_order(run: Callable, todo: list, workers: int):
    """(sequence, run(sequence, load, strain_load)) for the ``todo`` items, in their order;
    with ``workers`` > 1 computed that many at a time in worker processes, the next ones
    already running while the caller handles a result. A caller that stops early cancels those
    not yet started; the running ones end first (their results are discarded)."""
    if workers <= 1 or len(todo) <= 1:
        for item in todo:
            yield item[0], run(*item)
        return
    level = logging.getLogger("hardpack").getEffectiveLevel()
    with _environment(ONE_THREAD), ProcessPoolExecutor(
            min(workers, len(todo)), mp_context=get_context("spawn"), initializer=_worker_logging,
            initargs=(level,)) as pool:
        futures = [pool.submit(run, *item) for item in todo]  # the workers start here
        try:
            for item, future in zip(todo, futures):
                yield item[0], future.result()
        finally:
            for future in futures:
                future.cancel()


@contextmanager
def _environment(values: dict[str, str]):
    """os.environ updated with ``values`` inside the block (for the processes started there)."""
    saved = {key: os.environ.get(key) for key in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _worker_logging(level: int) -> None:
    """Progress lines of a worker process go to its standard error, as the parent's do."""
    logging.basicConfig(level=level, format="%(asctime)s %(name)s: %(message)s", datefmt="%H:%M:%S")


def _record(out: SequentialOutcome, result: _Sequence, moving: np.ndarray, packing: Packing) -> None:
    """Add one loading sequence's statistics to ``out`` (module docstring)."""
    rel = _relative(result.total, moving, packing)
    size = np.linalg.norm(rel, axis=1) / (2.0 * packing.radii.mean())
    size[~moving] = 0.0
    mean = float(size[moving].mean())
    strain = 0.0 if result.strain is None else float(np.linalg.norm(result.strain, 2))
    if not out.steps or max(mean, strain) > max(out.size(k) for k in range(len(out.steps))):
        out.motion, out.strain = rel, result.strain
    out.mean_displacement.append(mean)
    out.max_displacement.append(float(size.max(initial=0.0)))
    out.steps.append(result.steps)
    out.strain_norm.append(strain)
    out.displacement = np.maximum(out.displacement, size)
    out.n_lp += result.steps
    out.n_lp_highs += result.n_lp_highs
    out.final = result.final
    out.fallbacks.update(result.fallbacks)
    if result.undetermined and not out.undetermined:
        out.undetermined = result.undetermined
    log.info("%s test: loading sequence %d moved the particles by %.3g D on average and strained "
             "the cell by %.3g (threshold %.3g)", out.test, len(out.steps), mean, strain, out.threshold)


def _state(out: SequentialOutcome, start_rng: str, next_sequence: int, seconds: float) -> dict:
    """The state of a test after a loading sequence, as arrays and scalars (see sequential_test):
    the random generator as the test found it (the loads are drawn from it again)."""
    state = {
        "version": STATE_VERSION, "next_sequence": next_sequence, "seconds": seconds, "rng": start_rng,
        "positions": out.final.positions, "lattice": out.final.lattice,
        "mean_displacement": np.asarray(out.mean_displacement), "strain_norm": np.asarray(out.strain_norm),
        "max_displacement": np.asarray(out.max_displacement), "steps": np.asarray(out.steps),
        "displacement": out.displacement, "motion": out.motion,
        "n_lp": out.n_lp, "n_lp_highs": out.n_lp_highs, "undetermined": out.undetermined,
        **{f"fallback_{name}": out.fallbacks[name] for name in FALLBACKS},
    }
    if out.strain is not None:
        state["strain"] = out.strain
    return state


def _restore(state: dict, out: SequentialOutcome, packing: Packing, rng: np.random.Generator):
    """Load a :func:`_state` into ``out`` and ``rng``; returns (the generator's state at the
    test's start, the next sequence, the seconds spent)."""
    if state.get("version") != STATE_VERSION:
        raise InvalidInputError(f"the checkpoint holds a sequential test saved by an older hardpack "
                                f"(state layout {state.get('version', 1)}, this one reads {STATE_VERSION}: "
                                "see STATE_VERSION); delete it to start the verification afresh")
    rng.bit_generator.state = json.loads(state["rng"])
    out.mean_displacement = [float(v) for v in state["mean_displacement"]]
    out.strain_norm = [float(v) for v in state["strain_norm"]]
    out.max_displacement = [float(v) for v in state["max_displacement"]]
    out.steps = [int(v) for v in state["steps"]]
    out.displacement, out.motion, out.strain = state["displacement"], state["motion"], state.get("strain")
    out.n_lp, out.n_lp_highs = int(state["n_lp"]), int(state["n_lp_highs"])
    out.undetermined = str(state["undetermined"])
    out.fallbacks = Counter({name: int(state[f"fallback_{name}"]) for name in FALLBACKS})
    out.final = packing.replace(positions=state["positions"], lattice=state["lattice"])
    return state["rng"], int(state["next_sequence"]), float(state["seconds"])


def _relative(total: np.ndarray, moving: np.ndarray, packing: Packing) -> np.ndarray:
    """Displacements less their trivial part (module docstring): the componentwise median over
    the moving particles along the periodic axes (translations; hard walls leave the walled
    axes alone), or in a spherical container the least-squares rotation of the moving particles
    about its centre (at the start positions: the displacements are small)."""
    if not moving.any():
        return total
    if packing.boundary.kind == "spherical_container":
        arm = packing.positions - np.array(packing.boundary.centre)
        gens = rotation_velocities(arm[moving])
        if not gens.size:
            return total
        omega = np.linalg.lstsq(gens.T, total[moving].ravel(), rcond=None)[0]
        return total - (omega @ rotation_velocities(arm)).reshape(total.shape)
    axes = packing.boundary.periodic_axes(packing.dim)
    out = total.copy()
    out[:, axes] -= np.median(total[moving][:, axes], axis=0)
    return out


def _mean_size(total: np.ndarray, moving: np.ndarray, packing: Packing) -> float:
    """Mean |dr_i| / D over the moving particles, relative to the bulk (:func:`_relative`)."""
    if not moving.any():
        return 0.0
    rel = _relative(total, moving, packing)[moving]
    return float(np.linalg.norm(rel, axis=1).mean() / (2.0 * packing.radii.mean()))


def _advance(packing: Packing, net: ContactNetwork, disp: np.ndarray, eps: np.ndarray | None,
             tau: float) -> tuple[Packing, float] | None:
    """The packing moved by tau (dR, eps) and that tau; tau is halved if round-off would create
    an overlap. None if it still overlaps after MAX_HALVINGS halvings (tau 1e-18 times smaller):
    then not round-off but the motion itself is at fault, and the caller must not read the
    missing step as a jammed packing."""
    for _ in range(MAX_HALVINGS):
        lattice = packing.lattice if eps is None else (np.eye(packing.dim) + tau * eps) @ packing.lattice
        try:
            return packing.replace(positions=net.positions + tau * disp, lattice=lattice), tau
        except InvalidInputError:
            tau *= 0.5
    return None
