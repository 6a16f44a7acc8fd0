"""The randomised displacement LP (Donev Eq. 4.10, with Eq. 4.17 for strict jamming), HiGHS.

    max  B^T dR + b_eps^T eps        (virtual work of a random load)
    s.t. A^T (dR, eps) >= -h          (linearised impenetrability, Eq. 4.7)
         Tr eps <= 0                  (volume non-increasing, Eq. 4.17/4.19; strict test only)
         |dR| <= box, |eps| <= box/L  (keeps the LP bounded; footnote 8, L584-L585)
         dr_a = 0 for one "anchor" particle a   (removes the trivial translation, L562-L569)

(seeds/000_chapters/ch04-05.txt L539-L597, L944-L1037). Only the ``moving`` particles carry
displacement variables; particles in ``fixed`` stay put but still constrain their moving
neighbours (Donev L880-L885). When nothing is fixed, one particle is anchored; the solution then
differs from a mean-pinned one only by a translation, which the callers remove (componentwise
median), and no dense pinning row is needed.

HiGHS solves the dual, the force formulation (Eq. 4.12, L626-L653) with the box turned into
penalised slack loads:

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
from scipy.optimize import linprog

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.rigidity import (
    n_strain,
    rigidity_transpose,
    strain_pairs,
    strain_tensor,
)

#: HiGHS tolerances: tighter than the defaults (1e-7) so that a jammed packing with exact
#: contacts returns displacements at round-off level instead of the feasibility tolerance.
HIGHS_OPTIONS = {
    "primal_feasibility_tolerance": 1e-10,
    "dual_feasibility_tolerance": 1e-10,
}


class LPFailure(RuntimeError):
    """HiGHS did not return an optimal solution (should not happen for a bounded LP)."""


#: solver attempts, in order: the dual simplex, then the interior-point method with crossover,
#: then both with HiGHS's default tolerances (rare numerical trouble on near-degenerate LPs)
ATTEMPTS = (("highs-ds", HIGHS_OPTIONS), ("highs-ipm", HIGHS_OPTIONS), ("highs-ds", {}), ("highs-ipm", {}))


def solve_lp(c, *, method: str = "highs-ds", **kwargs):
    """scipy.optimize.linprog with HiGHS, retried with the other ATTEMPTS when HiGHS reports
    numerical trouble or a limit (status 1 or 4). Returns the optimal result; raises LPFailure
    for an infeasible or unbounded LP (status 2, 3) or after the last attempt."""
    attempts = [(m, o) for m, o in ATTEMPTS if m == method] + [a for a in ATTEMPTS if a[0] != method]
    res = None
    for m, options in attempts:
        res = linprog(c, method=m, options=options, **kwargs)
        if res.status in (0, 2, 3):
            break
    if res.status == 0:
        return res
    raise LPFailure(f"HiGHS returned status {res.status}: {res.message}")


@dataclass(frozen=True)
class Motion:
    """Solution of the displacement LP."""

    displacement: np.ndarray  # (N, d); zero for particles without variables
    strain: np.ndarray | None  # (d, d) symmetric, or None (collective test)
    forces: np.ndarray  # (M,) duals of the impenetrability rows (0 for unused contacts)
    objective: float
    seconds: float


def solve_motion(
    net: ContactNetwork,
    moving: np.ndarray,
    load: np.ndarray,
    *,
    fixed: np.ndarray | None = None,
    strain_load: np.ndarray | None = None,
    box: float,
    cell_length: float,
) -> Motion:
    """Solve the LP in the module docstring.

    ``moving``: boolean (N,) mask of particles with displacement variables. ``fixed``: boolean
    mask of particles that are present but do not move (default: none). Contacts with any end
    outside ``moving | fixed`` are ignored. ``load``: (N, d) forces on the particles (rows of
    non-moving particles are ignored). ``strain_load``: (d(d+1)/2,) load conjugate to the strain
    components; giving it turns on the strain variables and the trace constraint (strict
    test). ``box`` bounds each displacement component and ``box / cell_length`` each strain
    component.
    """
    t0 = time.perf_counter()
    n, d = net.n_particles, net.dim
    fixed = np.zeros(n, dtype=bool) if fixed is None else fixed & ~moving
    if moving.any() and not fixed.any():  # anchor: fix one particle against translations
        anchor = int(np.flatnonzero(moving)[0])
        moving, fixed = moving.copy(), fixed.copy()
        moving[anchor], fixed[anchor] = False, True
    present = moving | fixed
    strict = strain_load is not None
    use = net.among(present) & (moving[net.i] | moving[net.j])
    if strict:  # self-image and fixed-fixed contacts constrain the strain only
        use |= net.among(present) & np.any(net.shift != 0, axis=1)
    at = rigidity_transpose(net, strain=strict)[use]
    h = net.gap[use]

    dof_moving = np.repeat(moving, d)
    ns = n_strain(d) if strict else 0
    keep_cols = np.flatnonzero(np.concatenate([dof_moving, np.ones(ns, bool)]))
    g_t = -at[:, keep_cols].T.tocsr()  # G^T, G = -A^T: (variables x contacts)
    n_pos = int(dof_moving.sum())
    nvar = n_pos + ns
    if nvar == 0:  # nothing can move (a single particle in the collective test)
        return Motion(np.zeros((n, d)), None, np.zeros(net.n_contacts), 0.0, time.perf_counter() - t0)
    c = np.asarray(load, dtype=float).reshape(-1)[dof_moving]
    upper = np.full(nvar, float(box))
    cost = [h]
    if strict:
        c = np.concatenate([c, np.asarray(strain_load, dtype=float)])
        upper[n_pos:] = box / cell_length
        trace = np.zeros((nvar, 1))
        trace[n_pos:n_pos + d] = 1.0  # diagonal components come first (strain_pairs)
        g_t = sp.hstack([g_t, sp.csr_matrix(trace)], format="csr")
        cost.append([0.0])
    # dual of  max c^T x  s.t.  G x <= (h, 0),  |x| <= upper:
    #     min (h, 0)^T y + upper^T (z+ + z-)  s.t.  G^T y + z+ - z- = c,  y, z >= 0
    eye = sp.identity(nvar, format="csr")
    a_eq = sp.hstack([g_t, eye, -eye], format="csr")
    cost = np.concatenate(cost + [upper, upper])
    res = solve_lp(cost, A_eq=a_eq, b_eq=c, bounds=(0, None))
    x = res.eqlin.marginals  # the primal motion: d(optimal value)/d c
    disp = np.zeros((n, d))
    disp[moving] = x[:n_pos].reshape(-1, d)
    eps = strain_tensor(x[n_pos:], d) if strict else None
    if strict and np.trace(eps) > 0:  # Tr eps <= 0 holds only to the solver tolerance (~1e-12);
        eps -= np.trace(eps) / d * np.eye(d)  # make it exact so that det(I + t eps) <= 1 for small t
    forces = np.zeros(net.n_contacts)
    forces[use] = res.x[: int(use.sum())]
    return Motion(disp, eps, forces, float(res.fun), time.perf_counter() - t0)


def random_load(rng: np.random.Generator, mask: np.ndarray, d: int) -> np.ndarray:
    """Gaussian load on the particles in ``mask`` with zero net force (note sec. 2.4 [rec])."""
    load = np.zeros((mask.size, d))
    k = int(mask.sum())
    if k:
        b = rng.standard_normal((k, d))
        load[mask] = b - b.mean(axis=0)
    return load


def random_strain_load(rng: np.random.Generator, d: int, cell_length: float) -> np.ndarray:
    """Gaussian load on the strain components, scaled by the cell length so that its virtual
    work for a strain eps is comparable to a unit force times the boundary displacement
    eps * L. Off-diagonal components count twice in eps : sigma, hence the factor 2."""
    scale = np.array([1.0 if p == q else 2.0 for p, q in strain_pairs(d)])
    return rng.standard_normal(n_strain(d)) * scale * cell_length


__all__ = [
    "HIGHS_OPTIONS",
    "LPFailure",
    "Motion",
    "random_load",
    "random_strain_load",
    "solve_lp",
    "solve_motion",
]
