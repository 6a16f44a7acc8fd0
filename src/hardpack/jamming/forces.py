"""Contact forces, statics and counting of a rattler-free backbone.

Forces: two LPs on the backbone's equilibrium matrix A (particle rows only, fixed cell).

1. Jamming-gap LP: ``mu* = min h^T f  s.t.  A f = 0, f >= 0, D^T f = 1``. It is the dual of
   "grow every diameter by the largest common factor 1 + mu with linearised contacts",
   ``max mu  s.t.  A^T dR >= mu D - h`` (the growth LP behind SLP/CALiPPSO; Donev's estimate
   Eq. 5.19 in Donev 2006, dissertation sec. 5.5.5.2, up to its normalisation), so f is the
   force network the packing would carry at the jamming point it is closest to. Because
   A f = 0, f^T h does not change when particles move inside their cage, so mu* does not depend
   on where the snapshot sits in the cage.
2. Among optimal f (h^T f <= mu* (1 + 1e-6) + 1e-14 D), the most uniform one:
   ``max t  s.t.  f >= t`` -- Donev's self-stress LP (5.9), sec. 5.5.1.1. For an isostatic
   backbone both LPs return the unique self-stress; for crystals (h = 0) step 2 picks uniform
   forces. t > 0 certifies a strict self-stress (sec. 5.5.1.1).

When the backbone is rigid with few self-stresses (K = M - d(N_b - 1) <= 12, one of them
positive), both LPs are solved in the K coordinates of the self-stress basis from one sparse LU
(:class:`hardpack.jamming.isostatic.RigidBackbone`); for K = 1 (isostatic) the self-stress is
unique and no LP is needed. The LP solution balances forces to the solver tolerance; :func:`polish` projects it onto the
null space of A restricted to the loaded contacts (regularised normal equations, SuperLU,
iterative refinement), which brings the imbalance to round-off. Forces are reported with mean 1
over the backbone contacts.

Statics (each checked by the tests):

- virial ``p V = (1/d) sum_c f_c |r_c|``, stress ``sigma = (1/V) sum_c f_c |r_c| u u^T``
  (Eq. 4.24, sec. 4.4.6.2); with balanced forces this equals the boundary form (4.23).
- free-volume reduced pressure ``p = PV/(NkT) = (N_b - 1) / (N mu*)``: for homogeneous gaps the
  basin {A^T dR >= -h} scales like mu*, its volume like mu*^(d (N_b - 1)), and a relative length
  dilation eps raises mu* by eps, so beta P = d(N_b - 1) / (d V mu*) (derived here; to first order
  it is Salsburg-Wood / Donev Eq. 1.1 and 5.24, p = d / (1 - phi/phi_J) with 1 - phi/phi_J = d mu*).
  It is exact for uniformly shrunk jammed packings; for thermal snapshots with very unequal gaps the
  basin is not a scaled copy of itself and the estimate is only indicative.
- isostaticity counts (Eqs. 4.8, 4.9, sec. 4.3.1.1): N_f = d(N_b - 1) in a fixed cell and
  N_f + d(d+1)/2 - 1 with a deformable cell; an isostatic backbone has M_b = N_f + 1, and
  ``gap = M_b - N_f - 1`` is 0 (isostatic), > 0 (hyperstatic) or < 0 (hypostatic).
  Hard walls (sec. 4.3.1.1: "if hard wall boundary conditions are employed then N_f = N d and
  one should also count contacts with the hard walls among the M constraints"): N_f = d N_b
  less the translations along periodic axes (for a spherical container less its d(d-1)/2
  rotations), the wall contacts count in M_b, and the walls stay fixed, so the strict count is
  the collective one.
- walls: a wall contact is a contact with a fixed point of the wall (Donev 2006, sec. 4.4.3), so
  its force is the wall's reaction and enters the force balance A f = 0 of its particle only;
  the virial sum over all contacts, wall contacts with their centre-wall distance, is the
  boundary integral of x . t, i.e. d P V for a uniform wall pressure P (derived here from
  sum_i x_i . F_i = 0).
- free-volume pressure with walls: p = N_f / (d N mu*), which is (N_b - 1) / (N mu*) in a
  periodic cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from hardpack.jamming.contacts import ContactNetwork
from hardpack.jamming.highs import LPFailure, note_fallback, solve_lp
from hardpack.jamming.isostatic import RigidBackbone
from hardpack.jamming.rigidity import anchored_transpose, rigidity_transpose
from hardpack.jamming.workingset import solve_working_set


@dataclass(frozen=True)
class Forces:
    """Self-stress of the backbone: ``forces`` (M,) is 0 off the backbone, mean 1 on it.

    Attributes
    ----------
    forces : numpy.ndarray of float, shape (M,)
        Contact forces, 0 off the backbone, mean 1 on it.
    min_force : float
        Optimum t of LP 5.9 (the smallest force relative to the mean).
    jamming_gap : float
        mu* of the jamming-gap LP.
    imbalance : numpy.ndarray of float, shape (N, d)
        Net contact force on each particle (0 off the backbone).
    exists : bool
        False when the backbone admits no non-negative self-stress.
    """

    forces: np.ndarray
    min_force: float  # optimum t of LP 5.9 (relative to the mean force)
    jamming_gap: float  # mu* of the jamming-gap LP
    imbalance: np.ndarray  # (N, d) net contact force on each particle (0 off the backbone)
    exists: bool  # False when the backbone admits no non-negative self-stress


def backbone_rows(net: ContactNetwork, backbone: np.ndarray, contacts: np.ndarray) -> sp.csr_matrix:
    """A restricted to the backbone particles' rows and the given contact columns, (N_b d, M_b).

    Parameters
    ----------
    net : ContactNetwork
        The contact network (M contacts).
    backbone : numpy.ndarray of bool, shape (N,)
        Backbone particles.
    contacts : numpy.ndarray of bool, shape (M,) or int indices
        The contact columns kept.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (N_b d, M_b)
        The rigidity matrix block.
    """
    at = rigidity_transpose(net)[contacts]
    dofs = np.flatnonzero(np.repeat(backbone, net.dim))
    return at[:, dofs].T.tocsr()


def self_stress(net: ContactNetwork, backbone: np.ndarray) -> Forces:
    """Forces of the backbone from the two LPs of the module docstring, polished to round-off.

    Donev 2006, sec. 5.5.1.1 (LP 5.9) after the jamming-gap LP; a rigid backbone with few
    self-stresses is solved in the self-stress basis.

    Parameters
    ----------
    net : ContactNetwork
        The contacts of the packing.
    backbone : numpy.ndarray of bool, shape (N,)
        The rattler-free backbone; only contacts among its particles carry force.

    Returns
    -------
    Forces
        ``forces`` (M,): 0 off the backbone, mean 1 over the backbone contacts; ``min_force``
        the optimum t of LP 5.9 relative to the mean force (> 0 certifies a strict
        self-stress); ``jamming_gap`` mu*; ``imbalance`` (N, d) the net contact force on each
        particle; ``exists`` False (forces 0, NaN numbers) when the backbone has no contacts or
        admits no non-negative self-stress.
    """
    n, d = net.n_particles, net.dim
    contacts = net.among(backbone)
    m = int(contacts.sum())
    forces = np.zeros(net.n_contacts)
    failed = Forces(forces, np.nan, np.nan, np.zeros((n, d)), False)
    if m == 0:
        return failed
    a = backbone_rows(net, backbone, contacts)
    h, dist = net.gap[contacts], net.contact_distance[contacts]
    rigid = RigidBackbone.build(net, backbone)
    if rigid is not None:  # the same two LPs in the K self-stress coordinates f = N alpha
        f, t, mu = _reduced_lps(rigid.null, h, dist, rigid.f0)
        f = polish(a, f)
        f *= m / f.sum()
        forces[contacts] = f
        imbalance = np.zeros((n, d))
        imbalance[backbone] = (a @ f).reshape(-1, d)
        return Forces(forces, t, mu, imbalance, True)
    zeros = np.zeros(a.shape[0])
    # 1. jamming gap: min h^T f  s.t.  A f = 0, D^T f = 1, f >= 0
    try:
        res = solve_lp(
            h, A_eq=sp.vstack([a, sp.csr_matrix(dist[None, :])], format="csr"),
            b_eq=np.append(zeros, 1.0), bounds=(0, None), method="highs-ipm",
        )
    except LPFailure:  # infeasible: no non-negative self-stress
        return failed
    mu = float(res.fun)
    # 2. most uniform optimal f = g + t:  max t  s.t.  A g + t A 1 = 0,  D^T g + t sum D = 1,
    #    h^T g + t sum h <= mu (1 + 1e-6) + 1e-14 mean(D),  g >= 0
    col_sum = np.asarray(a.sum(axis=1)).ravel()
    a_eq = sp.vstack([
        sp.hstack([a, sp.csr_matrix(col_sum[:, None])]),
        sp.csr_matrix(np.append(dist, dist.sum())[None, :]),
    ], format="csr")
    a_ub = sp.csr_matrix(np.append(h, h.sum())[None, :])
    c = np.zeros(m + 1)
    c[-1] = -1.0
    try:
        res2 = solve_lp(
            c, A_ub=a_ub, b_ub=[mu * (1 + 1e-6) + 1e-14 * dist.mean()], A_eq=a_eq,
            b_eq=np.append(zeros, 1.0), bounds=[(0, None)] * m + [(None, None)], method="highs-ipm",
        )
        f = res2.x[:m] + res2.x[-1]
        t = res2.x[-1] * m / f.sum()  # relative to the mean force
    except LPFailure:  # keep the jamming-gap solution
        note_fallback("uniform_forces_lp_failed")
        f, t = res.x, 0.0
    f = polish(a, np.maximum(f, 0.0))
    f *= m / f.sum()
    forces[contacts] = f
    imbalance = np.zeros((n, d))
    imbalance[backbone] = (a @ f).reshape(-1, d)
    return Forces(forces, float(t), mu, imbalance, True)


def jamming_point_forces(net: ContactNetwork, backbone: np.ndarray, contact_delta: float,
                         box: float) -> tuple[ContactNetwork, Forces] | None:
    """Forces of the jamming point nearest to a backbone that has no self-stress of its own.

    A finite-pressure LS packing can be hypostatic at the contact tolerance (e.g. two contacts
    short at delta = 1e-6 for N = 1000 in 3D: a floppy mode that the MD explores by ~1e-6 D and
    that ends on near contacts at gaps 1e-6-1e-5). Then A f = 0, f >= 0 has no solution on the
    contacts and LP 1 of the module docstring is infeasible. Its dual says why: the linearised
    particles can all grow, ``max mu s.t. A^T dR >= mu D - h``, until near contacts close. On
    the contact list ``net`` of a larger tolerance (the first coordination shell) the same LP
    is bounded; its optimal f is the self-stress of the jamming point the packing is closest
    to, supported on the contacts plus the near contacts that close there (for one floppy mode,
    one at each end of it). As the pressure diverges the packing converges to that point, and
    the time-averaged collision forces of the MD, which balance every particle, converge to
    that self-stress -- which is why it is the one to compare with them
    (:mod:`hardpack.jamming.md_forces`). Solved by :func:`solve_working_set` (the
    variables are dR of the backbone minus an anchor and mu, columns (a_c, -D_c), gaps h_c;
    its dual is LP 1: A f = 0, D^T f = 1, f >= 0, min h^T f).

    Returns the network of the contacts within ``contact_delta`` plus the near contacts that
    carry force, and the forces on it (mean 1 over its backbone contacts), or None if the LP
    fails or no self-stress exists even on ``net`` (the growth reaches the LP box).

    Parameters
    ----------
    net : ContactNetwork
        Contacts within a tolerance larger than ``contact_delta`` (the first coordination shell).
    backbone : numpy.ndarray of bool, shape (N,)
        Backbone particles.
    contact_delta : float
        Relative gap tolerance of the contacts proper.
    box : float
        Bound on every displacement component of the LP.

    Returns
    -------
    tuple of (ContactNetwork, Forces) or None
        As above.
    """
    d = net.dim
    contacts = net.among(backbone)
    nb = int(backbone.sum())
    if nb < 2 or not contacts.any():
        return None
    _, at = anchored_transpose(net, backbone, contacts)
    dist, h = net.contact_distance[contacts], net.gap[contacts]
    g = sp.vstack([at.T, sp.csr_matrix(-dist[None, :])], format="csc")
    nvar = g.shape[0]
    c = np.zeros(nvar)
    c[-1] = 1.0
    upper = np.full(nvar, float(box))
    upper[-1] = 1.0  # mu: relative growth of the diameters
    sol = solve_working_set(g, h, c, upper)
    if sol is None or np.abs(sol.x).max() >= (1.0 - 1e-9) * float(box) or sol.x[-1] >= 1.0 - 1e-9:
        return None
    f_all = np.zeros(net.n_contacts)
    f_all[contacts] = np.maximum(sol.forces, 0.0)
    rel_gap = net.distance / net.contact_distance - 1.0
    keep = (rel_gap <= contact_delta) | (f_all > 1e-12 * f_all.max())
    sub = net.subset(keep)
    f = f_all[keep]
    sub_contacts = sub.among(backbone)
    a = backbone_rows(sub, backbone, sub_contacts)
    loaded = polish(a, f[sub_contacts])
    m = int(sub_contacts.sum())
    loaded *= m / loaded.sum()
    f[sub_contacts] = loaded
    imbalance = np.zeros((net.n_particles, d))
    imbalance[backbone] = (a @ loaded).reshape(-1, d)
    return sub, Forces(f, float(loaded.min() / loaded.mean()), float(sol.x[-1]), imbalance, True)


def _reduced_lps(null: np.ndarray, h: np.ndarray, dist: np.ndarray, uniform: np.ndarray):
    """LPs 1 and 2 of the module docstring with f = null @ alpha (a strictly positive self-stress
    ``uniform`` exists). Returns (f, min force / mean, mu*)."""
    m, k = null.shape
    if k == 1:
        f = uniform
        return f, float(f.min() / f.mean()), float(f @ h / (f @ dist))
    hn, dn = h @ null, dist @ null
    res = solve_lp(hn, A_ub=-null, b_ub=np.zeros(m), A_eq=dn[None, :], b_eq=[1.0],
                   bounds=[(None, None)] * k)
    mu = float(res.fun)
    c = np.r_[np.zeros(k), -1.0]
    a_ub = np.vstack([np.column_stack([-null, np.ones(m)]), np.r_[hn, 0.0][None, :]])
    b_ub = np.r_[np.zeros(m), mu * (1 + 1e-6) + 1e-14 * dist.mean()]
    try:
        res2 = solve_lp(c, A_ub=a_ub, b_ub=b_ub, A_eq=np.r_[dn, 0.0][None, :], b_eq=[1.0],
                        bounds=[(None, None)] * (k + 1))
        f = null @ res2.x[:k]
    except LPFailure:
        note_fallback("uniform_forces_lp_failed")
        f = null @ res.x
    f = np.where(f < 0, 0.0, f)  # round-off negatives (f = N alpha >= t >= 0 up to tolerance)
    return f, float(f.min() / f.mean()), mu


def polish(a: sp.csr_matrix, f: np.ndarray, iterations: int = 4) -> np.ndarray:
    """Project f onto {A f = 0} changing only the loaded contacts (f > 1e-9 max f).

    Solves (A_S A_S^T + lam I) y = A_S f_S and sets f_S -= A_S^T y, repeated (iterative
    refinement); lam = 1e-12 times the mean diagonal only regularises floppy directions (and
    makes the matrix positive definite, so it is factorised without pivoting).

    Parameters
    ----------
    a : scipy.sparse.csr_matrix, shape (n, M)
        The equilibrium matrix A (coordinates by contacts, e.g. :func:`backbone_rows`).
    f : numpy.ndarray of float, shape (M,)
        Non-negative forces.
    iterations : int, optional
        Refinement steps at most.

    Returns
    -------
    numpy.ndarray of float, shape (M,)
        The projected forces, or ``f`` unchanged when the projection does not reduce the
        imbalance |A f| or makes a force negative.
    """
    f = f.copy()
    start = f.copy()
    support = f > 1e-9 * f.max()
    a_s = a[:, support].tocsc()
    solve = None
    for _ in range(iterations):
        r = a_s @ f[support]
        if np.abs(r).max(initial=0.0) <= 1e-15 * f.max():
            break
        if solve is None:
            normal = (a_s @ a_s.T).tocsc()
            lam = 1e-12 * normal.diagonal().mean()
            # symmetric positive definite: diagonal pivots and a symmetric order (SuperLU's
            # symmetric mode); at N = 1e4 in 3D 13 s and 4.6e7 LU entries, against 55 s and 1.1e8
            # with the default partial pivoting and COLAMD
            solve = spla.splu(normal + lam * sp.identity(normal.shape[0], format="csc"),
                              permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                              options={"SymmetricMode": True}).solve
        f[support] -= a_s.T @ solve(r)
    if np.abs(a @ f).max() > np.abs(a @ start).max() or f.min() < 0:
        return start  # a floppy support: the projection did not help
    return f


@dataclass(frozen=True)
class Statics:
    """Counting and pressure of a backbone with forces (see the module docstring).

    Attributes
    ----------
    n_backbone : int
        N_b, particles in the backbone.
    n_contacts : int
        M_b, backbone contacts (self-image contacts once).
    z_mean : float
        Mean coordination (2 M_b - M_w) / N_b (a wall contact counts once).
    n_dof_collective : int
        d (N_b - 1); with walls d N_b less the trivial motions.
    n_dof_strict : int
        d (N_b - 1) + d(d+1)/2 - 1; with walls (fixed) as collective.
    isostaticity_gap : int
        M_b - n_dof_collective - 1 (0: isostatic in a fixed cell).
    isostaticity_gap_strict : int
        M_b - n_dof_strict - 1.
    pressure_virial : float
        sum f |r| / (d V), forces normalised to mean 1.
    stress : numpy.ndarray of float, shape (d, d)
        Virial stress tensor, same units.
    jamming_gap : float
        mu* = sum f h / sum f D.
    pressure_free_volume : float
        Reduced pressure PV/(NkT) = N_f / (d N mu*) ((N_b - 1) / (N mu*) in a periodic cell).
    n_wall_contacts : int
        Backbone contacts with walls, among the M_b.
    wall_force : float
        Sum of the wall reactions.
    """

    n_backbone: int
    n_contacts: int  # M_b, self-image contacts once
    z_mean: float  # (2 M_b - M_w) / N_b: a wall contact counts once
    n_dof_collective: int  # d (N_b - 1); with walls d N_b less the trivial motions
    n_dof_strict: int  # d (N_b - 1) + d(d+1)/2 - 1; with walls (fixed) as collective
    isostaticity_gap: int  # M_b - n_dof_collective - 1  (0 = isostatic in a fixed cell)
    isostaticity_gap_strict: int  # M_b - n_dof_strict - 1
    pressure_virial: float  # sum f |r| / (d V), forces normalised to mean 1
    stress: np.ndarray  # (d, d) virial stress tensor, same units
    jamming_gap: float  # mu* = sum f h / sum f D
    pressure_free_volume: float  # N_f / (d N mu*) = (N_b - 1) / (N mu*) periodic, PV/(NkT)
    n_wall_contacts: int = 0  # backbone contacts with walls, among the M_b
    wall_force: float = 0.0  # sum of the wall reactions (forces of mean 1 over the M_b contacts)


def statics(net: ContactNetwork, backbone: np.ndarray, forces: Forces, volume: float,
            counted: np.ndarray | None = None) -> Statics:
    """Counts over the backbone contacts in ``counted`` (default all; :func:`verify` leaves out
    the near contacts that only carry the forces of the nearest jamming point), pressures over
    every contact with a force.

    Formulas in the module docstring (Donev 2006, Eqs. 4.8, 4.9, 4.24).

    Parameters
    ----------
    net : ContactNetwork
        The contacts of the packing.
    backbone : numpy.ndarray of bool, shape (N,)
        The rattler-free backbone.
    forces : Forces
        Its self-stress (:func:`self_stress`), mean 1 over the backbone contacts.
    volume : float
        Volume V of the cell.
    counted : numpy.ndarray of bool, shape (M,), optional
        The contacts that count for M_b, Z and the isostaticity gaps (default all).

    Returns
    -------
    Statics
        ``n_backbone`` N_b, ``n_contacts`` M_b, ``z_mean`` (2 M_b - M_w) / N_b (M_w of them with
        walls, each a contact of one particle), ``n_dof_collective``
        d (N_b - 1), ``n_dof_strict`` (+ d(d+1)/2 - 1), ``isostaticity_gap`` and
        ``isostaticity_gap_strict`` (M_b - N_f - 1), ``pressure_virial`` and ``stress`` (d, d)
        (forces of mean 1; NaN without forces), ``jamming_gap`` mu* and
        ``pressure_free_volume`` (N_b - 1) / (N mu*) = PV/(NkT) (inf for mu* = 0, NaN without
        forces). An empty backbone gives zero counts and NaN Z.
    """
    d, n = net.dim, net.n_particles
    contacts = net.among(backbone)
    nb = int(backbone.sum())
    mb_mask = contacts if counted is None else contacts & counted
    mb = int(mb_mask.sum())
    nf = max(d * nb - net.n_trivial, 0) if nb else 0
    nf_strict = nf + d * (d + 1) // 2 - 1 if nb and net.is_periodic else nf
    f = forces.forces[contacts]
    r, u = net.distance[contacts], net.normal[contacts]
    stress = np.einsum("k,kp,kq->pq", f * r, u, u) / volume if forces.exists else np.full((d, d), np.nan)
    p_vir = float(np.trace(stress) / d)
    mu = forces.jamming_gap
    p_fv = nf / (d * n * mu) if forces.exists and mu > 0 else np.inf if forces.exists else np.nan
    wall = contacts & net.is_wall
    mw = int((mb_mask & net.is_wall).sum())
    return Statics(
        n_backbone=nb, n_contacts=mb, z_mean=(2.0 * mb - mw) / nb if nb else np.nan,
        n_dof_collective=nf, n_dof_strict=nf_strict,
        isostaticity_gap=mb - nf - 1 if nb else 0, isostaticity_gap_strict=mb - nf_strict - 1 if nb else 0,
        pressure_virial=p_vir, stress=stress, jamming_gap=mu, pressure_free_volume=float(p_fv),
        n_wall_contacts=mw,
        wall_force=float(forces.forces[wall].sum()) if forces.exists else np.nan,
    )
