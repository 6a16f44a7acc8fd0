"""The randomised displacement LP (Donev Eq. 4.10, with Eq. 4.17 for strict jamming).

    max  B^T dR + b_eps^T eps        (virtual work of a random load)
    s.t. A^T (dR, eps) >= -h          (linearised impenetrability, Eq. 4.7)
         Tr eps <= 0                  (volume non-increasing, Eq. 4.17/4.19; strict test only)
         |dR| <= box, |eps| <= box/L  (keeps the LP bounded; sec. 4.3.2, footnote 8)
         dr_a = 0 for one "anchor" particle a   (removes the trivial translation, sec. 4.3.2)

(Donev 2006, dissertation secs. 4.3.2 and 4.4.5). Only the ``moving`` particles carry
displacement variables; particles in ``fixed`` stay put but still constrain their moving
neighbours (Donev 2006, sec. 4.4.3), and so do wall contacts, whose wall end is fixed. With
hard walls or a container the trivial motions are removed by fixing the coordinates of
:func:`hardpack.jamming.rigidity.gauge_dofs` instead (the periodic axes' coordinates of one
particle, or the coordinates the container's rotations act on). In a periodic cell one moving
particle is anchored (fixed), which removes
the translations (sec. 4.3.2, the text's alternative of fixing one sphere; fixed particles such as
rattlers alone would leave them to the rattlers' cages); the solution differs from a mean-pinned
one only by a translation, which the callers remove (componentwise median), and no dense pinning
row is needed.

Solvers: :mod:`hardpack.jamming.workingset` (sparse LU of the contact core + a small LP,
exact; 10-30 times faster than HiGHS on jammed packings, and warm-started from the previous LP
of a test via ``warm``) first. A strict LP without a warm start goes through a continuation in
the strain bound (:func:`_strain_continuation`): its optimum shears a fixed-cell packing until
hundreds of near contacts close, far from the contact core where a cold working set starts.
HiGHS solves the full LP when the working set gives up, in the dual, force formulation
(Eq. 4.12, sec. 4.3.2.2) with the box turned into penalised slack loads:

    min h^T f + box 1^T (z+ + z-)  s.t.  -A f [+ p Tr] + z+ - z- = (B, b_eps),  f, p, z >= 0,

which the dual simplex does 2-4 times faster than the primal for these LPs (measured on LS
packings, N = 250-1000). ``f`` are the contact forces resisting the load (A f = -B wherever the
box is not active), ``p`` the pressure multiplier of the trace constraint, and the motion dR is
the dual of the equality rows (``res.eqlin.marginals``; LP duality: the optimum's derivative
with respect to the load).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from hardpack.errors import InvalidInputError
from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.highs import HIGHS_OPTIONS, LPFailure, note_fallback, solve_lp
from hardpack.jamming.rigidity import (
    gauge_dofs,
    n_strain,
    rigidity_transpose,
    strain_pairs,
    strain_tensor,
)
from hardpack.jamming.workingset import WarmStart, solve_working_set

#: a strain with 0 < Tr eps <= TRACE_TOLERANCE times the LP box violates the volume constraint
#: (Eq. 4.17) only within the accuracy every row of the LP is solved to -- HiGHS's feasibility
#: tolerance and the working set's pricing tolerance, 1e-10 of the box -- and is made traceless;
#: a larger Tr eps means a solver outside that accuracy (e.g. HiGHS at its default tolerances,
#: 1e-7) and is an error (:class:`VolumeIncrease`). Measured: the working set's basis solves
#: leave Tr eps up to 3.5e-14 at box 0.05 (HCP supercells, 2e-12 of the strain bound box / L,
#: beyond a few hundred ulps of it: the round-off of the LU solve, not of eps)
TRACE_TOLERANCE = HIGHS_OPTIONS["primal_feasibility_tolerance"]


class VolumeIncrease(LPFailure):
    """The strain of a strict LP's solution increases the volume (Tr eps > 0) beyond the LP's
    accuracy: the solution violates the volume constraint (Eq. 4.17), so it is no unjamming
    motion and no certificate of jamming either. The tests report such a verdict as
    undetermined."""


@dataclass(frozen=True)
class Motion:
    """Solution of the displacement LP.

    Attributes
    ----------
    displacement : numpy.ndarray of float, shape (N, d)
        Displacements dr; zero for particles without variables.
    strain : numpy.ndarray of float, shape (d, d), or None
        Symmetric strain of the cell (strict test), None in the collective test.
    forces : numpy.ndarray of float, shape (M,)
        Duals of the impenetrability rows (0 for unused contacts).
    objective : float
        Optimal value of the LP.
    seconds : float
        Wall time of the solve.
    warm : WarmStart or None
        Basis of this LP, to warm-start the next one (working set).
    solver : str
        "working-set" or "highs".
    """

    displacement: np.ndarray  # (N, d); zero for particles without variables
    strain: np.ndarray | None  # (d, d) symmetric, or None (collective test)
    forces: np.ndarray  # (M,) duals of the impenetrability rows (0 for unused contacts)
    objective: float
    seconds: float
    warm: WarmStart | None = None  # basis of this LP, to warm-start the next one (working set)
    solver: str = "highs"  # "working-set" or "highs"


def solve_motion(
    net: ContactNetwork,
    moving: np.ndarray,
    load: np.ndarray,
    *,
    fixed: np.ndarray | None = None,
    strain_load: np.ndarray | None = None,
    box: float,
    cell_length: float,
    working_set: bool = True,
    warm: WarmStart | None = None,
) -> Motion:
    """Solve the LP in the module docstring.

    ``moving``: boolean (N,) mask of particles with displacement variables. ``fixed``: boolean
    mask of particles that are present but do not move (default: none). Contacts with any end
    outside ``moving | fixed`` are ignored. ``load``: (N, d) forces on the particles (rows of
    non-moving particles are ignored). ``strain_load``: (d(d+1)/2,) load conjugate to the strain
    components; giving it turns on the strain variables and the trace constraint (strict
    test). ``box`` bounds each displacement component and ``box / cell_length`` each strain
    component. ``warm``: the basis of a similar LP (``Motion.warm``) to start from; a strict LP
    without one goes through the strain continuation, from the smallest gaps.

    Parameters
    ----------
    net : ContactNetwork
        The contact network (M contacts).
    moving : numpy.ndarray of bool, shape (N,)
        Particles with displacement variables.
    load : numpy.ndarray of float, shape (N, d)
        Forces b on the particles.
    fixed : numpy.ndarray of bool, shape (N,), optional
        Particles present but held fixed.
    strain_load : numpy.ndarray of float, shape (d(d+1)/2,), optional
        Load on the strain components (strict test).
    box : float
        Bound on every displacement component (lengths of the packing).
    cell_length : float
        Scale L of the strain bounds box / L (:func:`hardpack.jamming.ideal.cell_length`).
    working_set : bool, optional
        Solve by the working-set method (:mod:`hardpack.jamming.workingset`) before HiGHS.
    warm : WarmStart, optional
        Basis to start from.

    Returns
    -------
    Motion
        The optimal displacement, strain and contact forces.

    Raises
    ------
    InvalidInputError
        For a strict LP outside a periodic cell.
    """
    t0 = time.perf_counter()
    n, d = net.n_particles, net.dim
    strict = strain_load is not None
    if strict and not net.is_periodic:
        raise InvalidInputError("the strict LP deforms a periodic cell; with hard walls or a container "
                                "the walls stay fixed and only the collective LP applies")
    fixed = np.zeros(n, dtype=bool) if fixed is None else fixed & ~moving
    gauge = np.zeros(n * d, dtype=bool)
    if moving.any() and net.is_periodic:  # anchor: fix one particle against translations
        anchor = int(np.flatnonzero(moving)[0])
        moving, fixed = moving.copy(), fixed.copy()
        moving[anchor], fixed[anchor] = False, True
    elif moving.any():  # walls: fix the coordinates the trivial motions act on (rigidity.gauge_dofs)
        gauge = gauge_dofs(net, moving)
    present = moving | fixed
    use = net.among(present) & (moving[net.i] | moving[net.j])
    if strict:  # self-image and fixed-fixed contacts constrain the strain only
        use |= net.among(present) & np.any(net.shift != 0, axis=1)
    at = rigidity_transpose(net, strain=strict)[use]
    h = net.gap[use]

    dof_moving = np.repeat(moving, d) & ~gauge
    ns = n_strain(d) if strict else 0
    keep_cols = np.flatnonzero(np.concatenate([dof_moving, np.ones(ns, bool)]))
    g = at[:, keep_cols].T.tocsc()  # columns a_c: constraint a_c^T x >= -h_c
    n_pos = int(dof_moving.sum())
    nvar = n_pos + ns
    if nvar == 0:  # nothing can move (a single particle in the collective test)
        return Motion(np.zeros((n, d)), None, np.zeros(net.n_contacts), 0.0, time.perf_counter() - t0)
    c = np.asarray(load, dtype=float).reshape(-1)[dof_moving]
    upper = np.full(nvar, float(box))
    if strict:
        c = np.concatenate([c, np.asarray(strain_load, dtype=float)])
        upper[n_pos:] = box / cell_length
        trace = np.zeros((nvar, 1))
        trace[n_pos:n_pos + d] = -1.0  # -Tr eps >= 0; diagonal components come first (strain_pairs)
        g = sp.hstack([g, sp.csc_matrix(trace)], format="csc")
        h = np.append(h, 0.0)
    # a wall contact's key has j = -(wall + 2): a particle may touch several walls
    keys = np.column_stack([net.i[use], np.where(net.is_wall, -(net.wall + 2), net.j)[use], net.shift[use]])
    if strict:
        keys = np.vstack([keys, np.full((1, keys.shape[1]), -1)])  # the trace column
    sol = None
    if working_set and (warm is not None or not strict):
        sol = solve_working_set(g, h, c, upper, start=None if warm is None else warm.locate(keys, nvar),
                                boxed=np.arange(n_pos, nvar))
    elif working_set:
        sol = _strain_continuation(g, h, c, upper, n_pos)
    solver = "working-set" if sol is not None else "highs"
    if working_set and sol is None:
        note_fallback("lp_working_set_to_highs")
    eps = None
    if sol is not None:
        x, f, objective, warm = sol.x, sol.forces, sol.objective, WarmStart.of(sol, keys)
        if strict and np.trace(strain_tensor(x[n_pos:], d)) > TRACE_TOLERANCE * box:
            note_fallback("lp_volume_to_highs")  # the working set's accuracy, not the LP's answer
            sol, solver = None, "highs"
    if sol is None:
        x, f, objective, basis = _highs_motion(g, h, c, upper)
        warm = WarmStart.from_columns(basis, np.zeros(0, dtype=np.int64), keys, nvar)
    disp = np.zeros(n * d)
    disp[dof_moving] = x[:n_pos]
    disp = disp.reshape(n, d)
    if strict:
        eps = _volume_checked(strain_tensor(x[n_pos:], d), box, solver)
    forces = np.zeros(net.n_contacts)
    forces[use] = f[: int(use.sum())]
    return Motion(disp, eps, forces, objective, time.perf_counter() - t0, warm, solver)


def _volume_checked(eps: np.ndarray, box: float, solver: str) -> np.ndarray:
    """``eps`` with a violation of Tr eps <= 0 within the LP's accuracy (TRACE_TOLERANCE times
    the ``box``) removed: its isotropic part taken off, so that det(I + t eps) <= 1 for small t,
    as the sequential test's step needs. Raises :class:`VolumeIncrease` beyond."""
    trace = float(np.trace(eps))
    if trace > TRACE_TOLERANCE * box:
        raise VolumeIncrease(
            f"the {solver} solution of a strict LP has Tr eps = {trace:.3g}, {trace / box:.3g} of the "
            f"LP box: beyond the LP's accuracy ({TRACE_TOLERANCE:g} of the box), the volume "
            "constraint Tr eps <= 0 (Eq. 4.17) is violated")
    if trace > 0:
        eps = eps - trace / eps.shape[0] * np.eye(eps.shape[0])
    return eps


def _strain_continuation(g, h, c, upper, n_pos, factor: float = 10.0, stages: int = 5):
    """A strict LP without a warm start: the working set is solved for strain bounds
    ``factor**-stages`` times the final one, then ``factor`` times larger each stage, each
    warm-started from the previous optimum. Small strains close few near contacts, so every
    stage starts close to its optimum; the last one is the LP itself. Returns the solution, or
    None if a stage fails.

    The first stage starts from the smallest gaps. A start from the first stage of another
    LP (e.g. of the previous loading sequence of a strict test) is a gamble: at N = 1e4 in 3D
    it once took 170 s where the smallest gaps took > 6 min, but the first LPs of the fourth
    and fifth sequences of the full study's test took 39 min and > 2 h from it, and 9 min
    cold for the fifth (the packing moved 4-6e-4 D per sequence, so another sequence's basis
    carries tens of thousands of negative loads).

    A stage whose optimal strain lies strictly inside its bound ends the continuation: the
    stages differ only in the strain bound, so that optimum satisfies the optimality (KKT)
    conditions of every larger bound with the same multipliers (an inactive bound has none).
    At N = 1e4 in 3D the optimal strain is ~0.07 of the final bound, which saves the last
    stage (15 s: a factorisation of the same basis)."""
    sol = None
    for stage in range(stages, -1, -1):
        bound = upper.copy()
        bound[n_pos:] /= factor**stage
        # after the first stage: the previous basis, but not its working set, whose columns
        # (N = 1e4 in 3D: ~800, 5 ms of LU solves each) the larger bound rarely needs
        start = None if sol is None else (sol.basis, np.zeros(0, dtype=np.int64))
        sol = solve_working_set(g, h, c, bound, start=start, boxed=np.arange(n_pos, upper.size))
        if sol is None:
            return None
        if np.all(np.abs(sol.x[n_pos:]) < (1.0 - 1e-6) * bound[n_pos:]):
            break
    return sol


def _highs_motion(g: sp.csc_matrix, h: np.ndarray, c: np.ndarray, upper: np.ndarray):
    """The LP by HiGHS in its dual (force) form, module docstring. Returns (x, f, objective,
    the loaded columns in the numbering of :mod:`hardpack.jamming.workingset`)."""
    nvar = g.shape[0]
    # dual of  max c^T x  s.t.  -g^T x <= h,  |x| <= upper:
    #     min h^T y + upper^T (z+ + z-)  s.t.  -g y + z+ - z- = c,  y, z >= 0
    eye = sp.identity(nvar, format="csr")
    a_eq = sp.hstack([-g, eye, -eye], format="csr")
    cost = np.concatenate([h, upper, upper])
    res = solve_lp(cost, A_eq=a_eq, b_eq=c, bounds=(0, None))
    # the loaded columns (contacts, then the box columns z+, z-) start the next LP's basis
    basis = np.flatnonzero(res.x > 1e-12 * np.abs(res.x).max(initial=1.0))[:nvar]
    return res.eqlin.marginals, res.x[: g.shape[1]], float(res.fun), basis  # x = d(optimum)/d c


def random_load(rng: np.random.Generator, mask: np.ndarray, d: int) -> np.ndarray:
    """Gaussian load on the particles in ``mask`` with zero net force (as Donev 2006, sec. 4.3.2, suggests).

    Parameters
    ----------
    rng : numpy.random.Generator
        Random source.
    mask : numpy.ndarray of bool, shape (N,)
        Loaded particles.
    d : int
        Dimension.

    Returns
    -------
    numpy.ndarray of float, shape (N, d)
        Standard normal forces less their mean on ``mask``, zeros elsewhere.
    """
    load = np.zeros((mask.size, d))
    k = int(mask.sum())
    if k:
        b = rng.standard_normal((k, d))
        load[mask] = b - b.mean(axis=0)
    return load


def random_strain_load(rng: np.random.Generator, d: int, cell_length: float) -> np.ndarray:
    """Gaussian load on the strain components, scaled by the cell length so that its virtual
    work for a strain eps is comparable to a unit force times the boundary displacement
    eps * L. Off-diagonal components count twice in eps : sigma, hence the factor 2.

    Parameters
    ----------
    rng : numpy.random.Generator
        Random source.
    d : int
        Dimension.
    cell_length : float
        Cell length L (lengths of the packing).

    Returns
    -------
    numpy.ndarray of float, shape (d(d+1)/2,)
        Load on the strain components, ordered by :func:`hardpack.jamming.rigidity.strain_pairs`.
    """
    scale = np.array([1.0 if p == q else 2.0 for p, q in strain_pairs(d)])
    return rng.standard_normal(n_strain(d)) * scale * cell_length


__all__ = [
    "HIGHS_OPTIONS",
    "LPFailure",
    "Motion",
    "TRACE_TOLERANCE",
    "VolumeIncrease",
    "random_load",
    "random_strain_load",
    "solve_lp",
    "solve_motion",
]
