"""First- and second-order jamming tests of packings of ellipses and ellipsoids.

Donev 2006, dissertation Secs. 5.5.1-5.5.3 (first-order flexes, self-stresses, the stress matrix
and the test for ideal packings) and Sec. 5.6 (packings near their jamming point). Contacts,
rigidity and stress matrices are those of :mod:`hardpack.jamming.ellipsoids`.

Degrees of freedom. The columns are the particles' translations and rotations, reduced by:

- frozen particles (argument ``frozen``): all their columns are removed; they are fixed obstacles
  (Donev 2006, Fig. 5.5 and Sec. 5.5.4: fixed ellipses);
- trivial spins: a particle symmetric about an axis (a spheroid: two equal semiaxes; an ellipse
  with equal semiaxes, i.e. a disk; a sphere: all three rotations) does not change its shape under
  a rotation about that axis, so that column of A^T and of the stress matrix vanishes identically.
  We remove it from the basis (exact, decided from the semiaxes to a relative 1e-12, not from
  the numbers of A): the rotational basis of a spheroid is the two directions orthogonal to its
  symmetry axis (Donev 2006, Sec. 5.6 penalises the same spin with k u u^T instead). The dof per
  particle are then 3 (ellipses), 2 (disks), 6 (general ellipsoids), 5 (spheroids), 3 (spheres);
- global translations: with no frozen particle in a periodic cell the d uniform translations of
  the backbone are trivial floppy modes; they are projected out of the floppy space. Between flat
  hard walls (wall contacts: :mod:`hardpack.jamming.ellipsoids`) only the translations along the
  periodic axes are trivial (they keep every wall gap; none in a closed box, Donev 2006,
  Sec. 4.4.2). In a spherical container the trivial motions are instead the d(d-1)/2 rigid
  rotations of the backbone about the container's centre (each particle's centre moves by
  omega x (x_i - c) and the particle turns by omega), which keep every pair and wall gap; the
  walls stay fixed, so no translation is trivial.

Procedure (Donev 2006, Sec. 5.5.3, on the rattler-free backbone; dense linear algebra). A
first-order flex is Qdot != 0 (nontrivial) with A^T Qdot >= 0; first-order rigid = none exists,
which holds iff a strict self-stress exists (every flex is then a null flex, Eqs. 5.6-5.11) and
null(A^T) holds only trivial motions:

1. rank r of A^T (SVD, relative tolerance ``rank_tol``): N_stresses = M - r,
   N_floppy = n - r - t (n reduced dof, t trivial motions);
2. self-stress LP (Eq. 5.9): max eps s.t. A F = 0, F >= eps, sum F = M. No self-stress
   (infeasible or eps < 0): *not jammed*, decided at first order (a strict first-order flex
   exists, Eqs. 5.6-5.7). eps = 0 (a self-stress, but none strict): *undetermined* (Donev: the
   test is inconclusive); the packing is not first-order rigid;
3. strict self-stress and N_floppy = 0: *jammed* at first order (first-order rigid). Hypostatic
   packings (M < n - t) always have N_floppy > 0 and go on;
4. the projected stiffness K_V = V^T K V, V an orthonormal basis of the nontrivial floppy space
   (null(A^T) orthogonal to the trivial motions) and K = -sum_c (F_c / s_c) Hess zeta_c the
   negative of Donev's stress matrix (Eq. 5.16; sign convention in
   :mod:`hardpack.jamming.ellipsoids`). lambda_min(K_V) > tol: *jammed* at second order
   (pre-stress stable with the LP's self-stress F, Eq. 5.17); lambda_min < -tol with a unique
   self-stress: *not jammed* (second-order flexible: V x_min extends to an unjamming motion,
   Eq. 5.14). With several self-stresses (Donev: a semidefinite program would be needed) we
   maximise lambda_min(K_V(F)), a concave function, over the self-stresses F >= 0 by Kelley's
   cutting planes (one LP per iteration, :func:`_best_stress`): a positive maximum is *jammed*
   (pre-stress stable); a floppy mode x with max_F x^T K_V(F) x < -tol (the dual LP 5.15 of a
   strict second-order flex) is *not jammed*; else, or when |lambda_min| <= tol,
   *undetermined*. tol = ``eig_tol`` times the largest |K| entry.

Packings near, not at, their jamming point (LS packings at a high pressure; Donev 2006, Sec. 5.6).
Their A f = 0 holds only approximately, so the exact LP 5.9 finds no self-stress. When A has no
exact self-stress and its smallest singular value (balance equations scaled to unit norm, so that
the O(alpha - 1) torque rows near the sphere point count at their own scale) lies at least
10^1.5 below the next (Donev: the smallest eigenvalue of A^T A 3-6 orders below the next), its
singular vector f is taken as the self-stress (:func:`approximate_stress`, recorded as
``approx_stress`` with its residual) and A^T is replaced by (I - f f^T) A^T, the nearest matrix
with A f = 0, for everything that follows. With ``delta="gaps"`` the contact tolerance is read off
the gap distribution (:func:`contact_delta_from_gaps`); when more than AMBIGUOUS_FRACTION of the
contacts have a pair within a decade of it, the contacts are not resolved and the verdict is
*undetermined*.

Cross-check of the first-order verdict on the backbone by the randomised displacement LP of the
sphere code (:func:`first_order_lp`; in the sparse path only when the backbone is not hypostatic,
since M < N_f leaves a nontrivial flex by counting): ``lp_flex`` says whether it found a
first-order flex; it must equal ``not first_order_rigid``.

Local test: each particle among its neighbours, which are fixed (its own columns only, no
trivial motion); the same procedure, so a particle held only at second order (Fig. 5.5) is
locally jammed. Particles that are not locally jammed are rattlers and are removed iteratively
(their contacts dropped), as in the sphere code (Donev 2006, Sec. 4.2.4.1). One case is decided
before the procedure (:func:`_slides_along_walls`): a particle whose every contact is with a
flat hard wall, and whose walls' normals do not span R^d (an ellipse between the two walls of a
slit), keeps every gap exactly when it translates parallel to those walls; the procedure would
see that exact unjamming motion only as a floppy mode of zero stiffness (undetermined), so it is
decided as not locally jammed at first order, as a sphere with the same contacts is
(Donev 2006, Sec. 4.4.3.1: d vectors cannot positively span R^d).

Large packings (``method="sparse"``, default above ``DENSE_LIMIT`` dof): the same procedure with
sparse linear algebra (:func:`decide_sparse`). N_stresses and N_floppy come from the inertia of
LDL^T factorisations of A^T A and A A^T shifted by ``rank_tol`` (relative; Sylvester's law; Donev
used a Cholesky factorisation as a certificate, Sec. 5.6), the floppy space from eigsh in
shift-invert mode, and the second order from the projected stiffness K_V, formed from that basis
(n_floppy columns, at most a few percent of the dof). Donev's shifted form k A A^T + K (Sec. 5.6)
needs k s^2 >> |K| for the smallest nonzero singular value s of A^T, which LS packings of
spheroids do not give at moderate k (:func:`decide_sparse`). The search over several
self-stresses is dense-only, so there a negative eigenvalue gives *undetermined*.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import xarray as xr

from hardpack.errors import InvalidInputError, check_seed
from hardpack.geometry.packing import Packing
from hardpack.jamming.ellipsoids import (
    EllipsoidContacts,
    check_ellipsoid_packing,
    contact_hessians,
    dof_per_particle,
    ellipsoid_contacts,
    generators,
    rigidity_transpose_full,
    stiffness_matrix_full,
    wall_name,
)
from hardpack.jamming.highs import LPFailure, recording_fallbacks, solve_lp
from hardpack.jamming.result import Verdict

__all__ = ["EllipsoidJammingResult", "Decision", "verify_ellipsoids", "first_order_lp", "self_stress_lp",
           "approximate_stress", "contact_delta_from_gaps", "DEFAULT_DELTA", "DENSE_LIMIT"]

#: contact tolerance mu - 1 of exact (ideal) packings
DEFAULT_DELTA = 1e-9
#: reduced dof above which method="auto" uses the sparse path (measured on this 2-core
#: machine: the dense SVD takes ~8 s at 750 dof, the sparse path 1 s)
DENSE_LIMIT = 600
#: sparse path: matrices up to this size get a dense eigh instead of eigsh
SMALL_EIGH = 50
#: symmetric semiaxes: equal to this relative tolerance
SYMMETRY_RTOL = 1e-12
#: largest ratio s_1 / s_2 of the two smallest singular values of A (no exact self-stress) at which
#: the singular vector of s_1 is taken as an approximate self-stress: Donev 2006, Sec. 5.6 finds the
#: smallest eigenvalue of A^T A 3-6 orders of magnitude below the next (s_1 / s_2 = 10^-1.5..10^-3)
APPROX_STRESS_GAP = 10**-1.5
#: contact tolerance from the gap distribution: contacts count as resolved when at most this
#: fraction of them has a pair within a decade of the tolerance
AMBIGUOUS_FRACTION = 0.01
#: pairs within this mu - 1 are searched for the jump of the gap distribution
GAPS_SEARCH = 1e-2
#: gaps below this count as round-off when the contact tolerance is read off the gap distribution
GAP_FLOOR = 1e-16
#: codes of the order that decided a test, as stored in datasets
ORDER_CODES = {"undetermined": 0, "first": 1, "second": 2}
#: numerical fallbacks recorded in the result
FALLBACKS = {
    "sparse_eigsh_dense": ("the floppy space's eigsh did not converge or its inertia count failed; a "
                           "dense eigh was used"),
}


# ------------------------------------------------------------------------------------- dof basis
def rotation_basis(semiaxes: np.ndarray, shape_inv: np.ndarray) -> list[np.ndarray]:
    """Per particle, an orthonormal basis (k, r_i) of its nontrivial rotations (module docstring).

    Parameters
    ----------
    semiaxes : numpy.ndarray of float, shape (N, d)
        Semiaxes of every particle.
    shape_inv : numpy.ndarray of float, shape (N, d, d)
        X^-1 of every particle (eigenvalues a_k^2).

    Returns
    -------
    list of numpy.ndarray
        Per particle a (k, r_i) array, k = d(d-1)/2 rotation components and r_i the nontrivial
        rotations (0 for a sphere or circle, 2 for a spheroid, k otherwise).
    """
    d = semiaxes.shape[1]
    s = np.sort(semiaxes, axis=1)
    close = np.isclose(s[:, 1:], s[:, :-1], rtol=SYMMETRY_RTOL, atol=0.0)
    if d == 2:
        return [np.zeros((1, 0)) if c else np.ones((1, 1)) for c in close[:, 0]]
    out = [np.zeros((3, 0)) if c.all() else np.eye(3) for c in close]
    # spheroids: the rotations about the two axes normal to the distinct semiaxis, all at once
    # (the same LAPACK calls per particle as one at a time)
    spheroids = np.flatnonzero(close.any(axis=1) & ~close.all(axis=1))
    if spheroids.size:
        _, vecs = np.linalg.eigh(shape_inv[spheroids])  # eigenvalues a_k^2, ascending
        axis = np.where(close[spheroids, 0][:, None], vecs[:, :, 2], vecs[:, :, 0])  # the distinct semiaxis
        q, _ = np.linalg.qr(np.concatenate([axis[:, :, None], np.broadcast_to(np.eye(3), (spheroids.size, 3, 3))],
                                           axis=2))
        for k, p in enumerate(spheroids):
            out[p] = q[k, :, 1:3]
    return out


def dof_basis(net: EllipsoidContacts, moving: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
    """(T, dof per particle): T maps the reduced dof of the ``moving`` particles to all N d_f
    columns (frozen particles and trivial spins removed).

    Parameters
    ----------
    net : EllipsoidContacts
        The contact network.
    moving : numpy.ndarray of bool, shape (N,)
        Particles with degrees of freedom.

    Returns
    -------
    t : scipy.sparse.csr_matrix, shape (N d_f, n_red)
        The map from reduced to full dof.
    counts : numpy.ndarray of int64, shape (N,)
        Reduced dof of each particle (0 for frozen ones).
    """
    d, n = net.dim, net.n_particles
    f = dof_per_particle(d)
    rot = rotation_basis(net.semiaxes, net.shape_inv)
    rows, cols, vals = [], [], []
    counts = np.zeros(n, dtype=np.int64)
    col = 0
    for p in np.flatnonzero(moving):
        for k in range(d):
            rows.append(p * f + k), cols.append(col), vals.append(1.0)
            col += 1
        basis = rot[p]
        for b in range(basis.shape[1]):
            for a in range(basis.shape[0]):
                rows.append(p * f + d + a), cols.append(col), vals.append(basis[a, b])
            col += 1
        counts[p] = d + basis.shape[1]
    t = sp.csr_matrix((vals, (rows, cols)), shape=(n * f, col))
    return t, counts


def trivial_translations(t: sp.csr_matrix, net: EllipsoidContacts, moving: np.ndarray) -> np.ndarray:
    """Orthonormal (n_red, d) uniform translations of the ``moving`` particles in reduced dof.

    Parameters
    ----------
    t : scipy.sparse.csr_matrix, shape (N d_f, n_red)
        Map from reduced to full dof (:func:`dof_basis`).
    net : EllipsoidContacts
        The contact network.
    moving : numpy.ndarray of bool, shape (N,)
        Particles with degrees of freedom.

    Returns
    -------
    numpy.ndarray of float, shape (n_red, d)
        Unit columns, one per axis.
    """
    d, n = net.dim, net.n_particles
    f = dof_per_particle(d)
    full = np.zeros((n * f, d))
    for k in range(d):
        full[np.flatnonzero(moving) * f + k, k] = 1.0
    red = t.T @ full
    return red / np.linalg.norm(red, axis=0)


def trivial_motions(t: sp.csr_matrix, net: EllipsoidContacts, moving: np.ndarray) -> np.ndarray:
    """Orthonormal trivial motions of the ``moving`` particles in reduced dof (module docstring):
    the uniform translations along the periodic axes (all d in a periodic cell, those without
    walls between flat hard walls), the rigid rotations about the centre in a container (those
    that vanish in the reduced dof, e.g. spins of spheres at the centre, are dropped: (n_red, t)
    with t <= d(d-1)/2).

    Parameters
    ----------
    t : scipy.sparse.csr_matrix, shape (N d_f, n_red)
        Map from reduced to full dof (:func:`dof_basis`).
    net : EllipsoidContacts
        The contact network.
    moving : numpy.ndarray of bool, shape (N,)
        Particles with degrees of freedom.

    Returns
    -------
    numpy.ndarray of float, shape (n_red, t)
        Orthonormal columns.
    """
    if net.centre is None:
        return trivial_translations(t, net, moving)[:, net.periodic]
    d, n = net.dim, net.n_particles
    f = dof_per_particle(d)
    gens = generators(d)
    idx = np.flatnonzero(moving)
    full = np.zeros((n * f, gens.shape[0]))
    rel = net.positions[idx] - net.centre
    for a in range(gens.shape[0]):
        full[(idx[:, None] * f + np.arange(d)).ravel(), a] = (rel @ gens[a].T).ravel()
        full[idx * f + d + a, a] = 1.0
    red = t.T @ full
    if red.size == 0:
        return np.zeros((red.shape[0], 0))
    u, s, _ = np.linalg.svd(red, full_matrices=False)
    keep = s > 1e-12 * max(s.max(initial=0.0), 1e-300)
    return u[:, keep]


# ------------------------------------------------------------------------------------- decisions
@dataclass
class Decision:
    """Outcome of the procedure of the module docstring on one (sub)packing.

    Attributes
    ----------
    verdict : Verdict
        The verdict code (:class:`hardpack.jamming.result.Verdict`).
    order : str
        "first", "second" or "undetermined".
    first_order_rigid : bool
        No nontrivial first-order flex.
    reason : str
        Why, in words.
    forces : numpy.ndarray of float, shape (M,)
        The LP self-stress (Donev 2006, Eq. 5.9; zeros when none).
    n_stresses : int
        Number of independent self-stresses (-1: not computed).
    n_floppy : int
        Number of nontrivial floppy modes (-1: not computed).
    n_dof : int
        Reduced degrees of freedom less the trivial motions.
    n_constraints : int
        Number of contacts M.
    stress_margin : float
        Optimum eps* of LP 5.9, the smallest force of the self-stress with mean 1.
    lambda_min : float
        Smallest eigenvalue of the projected stiffness K_V (NaN when not computed), in the units
        of K.
    stiffness_scale : float
        Largest |entry| of K.
    motion : numpy.ndarray of float, shape (n,), or None
        A second-order flex in reduced dof, when one was found.
    lp_flex : bool or None
        The randomised LP's answer (:func:`first_order_lp`), collective test only.
    fallbacks : int
        Dense eigh after eigsh failed (sparse path).
    approx_stress : numpy.ndarray of float, shape (M,), or None
        The unit approximate self-stress of a packing near (not at) its jamming point, when one
        was accepted (:func:`approximate_stress`).
    stress_residual : float
        s_1 / s_max of that stress (0: the self-stresses are exact).
    stress_gap : float
        s_1 / s_2 of that stress (NaN: the self-stresses are exact).
    jamming_distance : float
        Newton distance to the jamming point along the floppy modes (:func:`_jamming_distance`).
    """

    verdict: Verdict
    order: str
    first_order_rigid: bool
    reason: str
    forces: np.ndarray
    n_stresses: int
    n_floppy: int
    n_dof: int
    n_constraints: int
    stress_margin: float = float("nan")
    lambda_min: float = float("nan")
    stiffness_scale: float = float("nan")
    motion: np.ndarray | None = None
    lp_flex: bool | None = None  # the randomised LP's answer (first_order_lp), collective test only
    fallbacks: int = 0  # dense eigh after eigsh failed (sparse path)
    approx_stress: np.ndarray | None = None  # unit approximate self-stress (see approximate_stress)
    stress_residual: float = 0.0  # s_1 / s_max of that stress (0: the self-stresses are exact)
    stress_gap: float = float("nan")  # s_1 / s_2 of that stress (NaN: the self-stresses are exact)
    jamming_distance: float = 0.0  # Newton distance to the jamming point along the floppy modes (_jamming_distance)


def self_stress_lp(a: sp.spmatrix) -> tuple[float, np.ndarray]:
    """Donev 2006, Eq. 5.9: max eps s.t. A F = 0, F >= eps, sum F = M. Returns (eps*, F); eps* is
    -inf (and F zeros) when no F with A F = 0 and sum F = M exists.

    Parameters
    ----------
    a : scipy.sparse matrix, shape (n, M)
        The equilibrium matrix A (reduced dof by contacts).

    Returns
    -------
    eps : float
        The optimum eps*, the smallest force of the best self-stress of mean 1.
    forces : numpy.ndarray of float, shape (M,)
        Its forces F.
    """
    nrow, m = a.shape
    if m == 0:
        return float("-inf"), np.zeros(0)
    a = sp.csr_matrix(a)
    a_eq = sp.vstack([sp.hstack([a, sp.csr_matrix((nrow, 1))]),
                      sp.csr_matrix(np.concatenate([np.ones(m), [0.0]])[None, :])], format="csr")
    b_eq = np.concatenate([np.zeros(nrow), [float(m)]])
    a_ub = sp.hstack([-sp.identity(m, format="csr"), sp.csr_matrix(np.ones((m, 1)))], format="csr")
    cost = np.zeros(m + 1)
    cost[-1] = -1.0
    bounds = [(None, None)] * m + [(None, 1.0)]
    try:
        res = solve_lp(cost, A_ub=a_ub, b_ub=np.zeros(m), A_eq=a_eq, b_eq=b_eq, bounds=bounds)
    except LPFailure:
        return float("-inf"), np.zeros(m)
    return float(res.x[-1]), np.asarray(res.x[:m])


#: simplex iterations of :func:`first_order_lp` per row and column before the next solver is tried
LP_ITERATIONS = 20


def first_order_lp(at: sp.spmatrix, trivial: np.ndarray, rng: np.random.Generator,
                   tol: float = 1e-9, stress: np.ndarray | None = None) -> tuple[bool, float, float]:
    """Randomised LP test for a first-order flex (Donev 2006, Eqs. 5.6 and 5.10, in the displacement
    form of the sphere code, Eq. 4.10 with h = 0), independent of the self-stress procedure:

        max B^T Qdot  s.t.  A^T Qdot >= 0,  |Qdot_k| <= 1,

    once with B = A e (the flexes strict on some contact: exact, by LP duality Eq. 5.7) and once
    with a Gaussian B orthogonal to the trivial motions (null flexes: found with probability 1).
    Returns (a nontrivial first-order flex exists, the two optima) with optima relative to |B|_1.
    With an approximate self-stress f (``stress``, :func:`approximate_stress`) the flexes must also
    keep f^T A^T Qdot = 0, i.e. A is taken at the nearby jamming point where f is exact: the flex
    strict on the contacts by |A f| alone is not counted.

    Parameters
    ----------
    at : scipy.sparse matrix, shape (M, n)
        A^T in reduced dof.
    trivial : numpy.ndarray of float, shape (n, t)
        Orthonormal trivial motions.
    rng : numpy.random.Generator
        Source of the Gaussian load.
    tol : float, optional
        Optimum above which a flex counts.
    stress : numpy.ndarray of float, shape (M,), optional
        Approximate self-stress f.

    Returns
    -------
    flexible : bool
        A nontrivial first-order flex exists.
    strict_optimum, random_optimum : float
        The two optima over |B|_1.
    """
    m, n = at.shape
    at = sp.csr_matrix(at)
    eq = {} if stress is None else dict(A_eq=sp.csr_matrix((at.T @ stress)[None, :]), b_eq=np.zeros(1))
    load_random = rng.standard_normal(n)
    if trivial.shape[1]:
        load_random -= trivial @ (trivial.T @ load_random)
    optima = []
    for load in (np.asarray(at.sum(axis=0)).ravel(), load_random):
        norm = np.abs(load).sum()
        if norm == 0:
            optima.append(0.0)
            continue
        # an iteration limit: the dual simplex can stall on this degenerate LP (measured: > 7 min on the
        # refined near-sphere packing, N = 100); solve_lp then tries the interior-point method
        res = solve_lp(-load, A_ub=-at, b_ub=np.zeros(m), bounds=(-1.0, 1.0),
                       options=dict(maxiter=LP_ITERATIONS * (m + n)), **eq)
        optima.append(float(-res.fun) / norm)
    return bool(max(optima) > tol), optima[0], optima[1]


def _first_order(at: sp.spmatrix, stress_tol: float) -> tuple[float, np.ndarray, str | None]:
    """Self-stress step (2. of the module docstring): (eps*, F, reason if not strict)."""
    eps, forces = self_stress_lp(at.T)
    return _self_stress_outcome(eps, forces, stress_tol, "; LP 5.9 optimum")


def _self_stress_outcome(eps: float, forces: np.ndarray, stress_tol: float,
                         why_none: str) -> tuple[float, np.ndarray, str | None]:
    """(eps*, F, reason if not strict) of the self-stress step from the LP 5.9 optimum ``eps`` and its
    forces: no self-stress below -stress_tol (``why_none`` says why, before the optimum's value),
    a non-strict one within +-stress_tol (negative forces clipped), a strict one above."""
    if eps < -stress_tol:
        return eps, np.zeros(forces.size), (
            f"no self-stress (force and torque balance with F >= 0 fails{why_none} "
            f"{eps:.3g}): a strict first-order flex exists")
    if eps <= stress_tol:
        return eps, np.clip(forces, 0.0, None), (
            "a self-stress exists but none is strict (LP 5.9 optimum 0): some contact carries no "
            "force, the first-order test is inconclusive (Donev 2006, Sec. 5.5.3)")
    return eps, forces, None


def contact_delta_from_gaps(gaps: np.ndarray, n_particles: int, dim: int,
                            search: float = GAPS_SEARCH) -> tuple[float, int]:
    """Contact tolerance of a packing near its jamming point from its gap distribution.

    An LS packing compressed to a high pressure p has its true contacts at gaps mu - 1 ~ 1/p and
    its near contacts orders of magnitude further (Donev 2006, Sec. 5.2 and ch. 9: Z is flat over a
    wide range of tolerances). The tolerance is where Z(delta) is flattest: the delta (on a grid of
    0.05 decades) with the fewest pairs within a decade of it, delta / 10 < mu - 1 <= 10 delta, among
    those with enough contacts below delta / 10 for Z >= d + 1 over all particles (the fewest a
    jammed particle can have) and 10 delta <= ``search``; the middle of the longest run of such
    deltas. Gaps below GAP_FLOOR count as GAP_FLOOR.

    Parameters
    ----------
    gaps : ndarray
        mu - 1 of the candidate pairs: every pair with mu - 1 <= ``search``.
    n_particles, dim : int
    search : float
        The tolerance the candidates were searched with (default GAPS_SEARCH).

    Returns
    -------
    (delta, ambiguous) : (float, int)
        The tolerance and the number of pairs within a decade of it (NaN, -1 when no delta
        qualifies).
    """
    lg = np.sort(np.log10(np.maximum(np.asarray(gaps, float), GAP_FLOOR)))
    lg = lg[lg <= np.log10(search)]
    needed = int(np.ceil((dim + 1) * n_particles / 2))
    if lg.size < needed:
        return float("nan"), -1
    grid = np.arange(lg[needed - 1] + 1.0, np.log10(search) - 1.0 + 1e-9, 0.05)
    if grid.size == 0:
        return float("nan"), -1
    counts = np.searchsorted(lg, grid + 1.0, side="right") - np.searchsorted(lg, grid - 1.0, side="right")
    best = counts == counts.min()
    runs = np.split(np.flatnonzero(best), np.flatnonzero(np.diff(np.flatnonzero(best)) > 1) + 1)
    run = max(runs, key=len)
    return float(10 ** grid[run[len(run) // 2]]), int(counts.min())


def _unique_stress(stress: np.ndarray, stress_tol: float) -> tuple[float, np.ndarray, str | None]:
    """The self-stress step for a one-dimensional space of self-stresses spanned by ``stress``: LP
    5.9 has the optimum min(F) with F = stress scaled to sum M and the sign that makes the sum
    positive (a stress of mixed signs has no non-negative multiple)."""
    m = stress.size
    total = stress.sum()
    forces = stress * (m / total) if total != 0 else stress
    eps = float(forces.min()) if total != 0 else float("-inf")
    return _self_stress_outcome(eps, forces, stress_tol, ": the unique self-stress has mixed signs, LP 5.9 optimum")


def decide_dense(at: sp.spmatrix, stiffness, quadratic, trivial: np.ndarray, *, rank_tol: float = 1e-9,
                 stress_tol: float = 1e-9, eig_tol: float = 1e-9, lengths: np.ndarray | None = None) -> Decision:
    """The procedure of the module docstring with dense linear algebra.

    Parameters
    ----------
    at : sparse matrix, shape (M, n)
        A^T in reduced dof.
    stiffness : callable
        forces (M,) -> dense (n, n) stiffness K in reduced dof.
    quadratic : callable
        y (n, k) -> (M, k): y_k^T K_c y_k per contact (K = sum_c F_c K_c), for several stresses.
    trivial : ndarray, shape (n, t)
        Orthonormal trivial motions (translations), t may be 0.
    rank_tol, stress_tol, eig_tol : float
        Relative tolerances of the rank, of the LP's eps*, of lambda_min.
    lengths : ndarray, shape (n,), optional
        Length unit of each column (a particle size for a translation, 1 for a rotation): with
        it, the distance of a packing near its jamming point from that point along the floppy
        modes is recorded (:func:`_jamming_distance`).

    Returns
    -------
    Decision
    """
    m, n = at.shape
    t = trivial.shape[1]
    dense = at.toarray()
    measured = dense
    approx, residual, gap = None, 0.0, float("nan")
    if m:
        u, s, vh = np.linalg.svd(dense, full_matrices=True)
        rank = int((s > rank_tol * s.max()).sum()) if s.size and s.max() > 0 else 0
        near = approximate_stress(at) if rank == m else None
        if near is not None:
            # no exact self-stress but a near one f (a packing near its jamming point, Sec. 5.6):
            # A at the jamming point is taken as (I - f f^T) applied to A^T, so that A f = 0
            approx, gap, residual = near
            dense = dense - np.outer(approx, approx @ dense)
            at = sp.csr_matrix(dense)
            u, s, vh = np.linalg.svd(dense, full_matrices=True)
            rank = min(m - 1, int((s > rank_tol * s.max()).sum()))
    else:
        vh, rank = np.eye(n), 0
    n_stresses, n_floppy = m - rank, n - rank - t
    common = dict(n_stresses=n_stresses, n_floppy=n_floppy, n_dof=n - t, n_constraints=m,
                  approx_stress=approx, stress_residual=residual, stress_gap=gap)
    if n - t == 0:
        return Decision(Verdict.JAMMED, "first", True, "no nontrivial degree of freedom",
                        np.zeros(m), **common)
    if m == 0:
        return Decision(Verdict.NOT_JAMMED, "first", False, "no contacts", np.zeros(0), **common)
    eps, forces, why = _unique_stress(u[:, m - 1], stress_tol) if n_stresses == 1 else _first_order(at, stress_tol)
    if why is not None:
        verdict = Verdict.NOT_JAMMED if eps < -stress_tol else Verdict.UNDETERMINED
        return Decision(verdict, "first" if verdict == Verdict.NOT_JAMMED else "undetermined",
                        False, why, forces, stress_margin=eps, **common)
    if n_floppy <= 0:
        return Decision(Verdict.JAMMED, "first", True,
                        "strict self-stress and no nontrivial floppy mode: first-order rigid",
                        forces, stress_margin=eps, **common)
    null = vh[rank:].T  # (n, n - rank)
    if t:
        null = null - trivial @ (trivial.T @ null)  # spans the nontrivial floppy space, rank n_floppy
        q, r, piv = sla.qr(null, mode="economic", pivoting=True)
        null = q[:, :n_floppy]
    k = stiffness(forces)
    scale = max(np.abs(k).max(), 1e-300)
    w, x = _projected_eigh(k, null)
    note = ""
    if w[0] <= eig_tol * scale and n_stresses > 1:
        forces, w, x, flex = _best_stress(at, stiffness, quadratic, null, forces, w, x, eig_tol * scale)
        k = stiffness(forces)
        scale = max(np.abs(k).max(), 1e-300)
        note = (" (the self-stress that maximises lambda_min(K_V) among the "
                f"{n_stresses}-dimensional space of self-stresses)")
    else:
        flex = None
    lam = float(w[0])
    distance = _jamming_distance(k, null, measured.T @ forces, lengths)
    margin = eig_tol * scale
    common.update(stress_margin=eps, lambda_min=lam, stiffness_scale=scale, jamming_distance=distance)
    if lam > margin:
        return Decision(Verdict.JAMMED, "second", False,
                        f"{n_floppy} floppy mode(s), all blocked by the stress matrix "
                        f"(lambda_min(K_V) = {lam / scale:.3g} of max |K|){note}: second-order jammed",
                        forces, **common)
    motion = null @ x[:, 0]
    if lam < -margin and n_stresses == 1:
        return Decision(Verdict.NOT_JAMMED, "second", False,
                        "a floppy mode with negative stiffness and a unique self-stress: "
                        "second-order flexible", forces, motion=motion, **common)
    if flex is not None:
        return Decision(Verdict.NOT_JAMMED, "second", False,
                        f"a floppy mode on which every self-stress has negative stiffness (LP 5.15 "
                        f"optimum {flex[0]:.3g}): second-order flexible", forces, motion=null @ flex[1],
                        **common)
    why = ("several self-stresses and none blocks every floppy mode, while each mode tried is "
           "blocked by some self-stress (Donev 2006, Sec. 5.5.2.1: the general case)" if lam < -margin else
           "lambda_min(K_V) is zero within the tolerance: higher orders would decide")
    return Decision(Verdict.UNDETERMINED, "undetermined", False, why, forces, motion=motion, **common)


def _projected_eigh(k: np.ndarray, null: np.ndarray):
    kv = null.T @ k @ null
    return np.linalg.eigh(0.5 * (kv + kv.T))


def _jamming_distance(k, null: np.ndarray, residual: np.ndarray, lengths: np.ndarray | None) -> float:
    """Distance of the packing from its jamming point along the floppy modes, in particle sizes.

    A packing near its jamming point balances its near self-stress F only approximately: the
    residual R = A F (Sec. 5.6) lies mostly along the floppy modes, where the only restoring term
    is the stiffness. The Newton step of the equilibrium K y = R restricted to the floppy space,
    y = V K_V^-1 V^T R, estimates how far the jamming point lies. It is reported, not used in the
    verdict: how much lambda_min(K_V) changes over that distance depends on the shape (about |K|
    |y| / a for the M&M spheroids, a the radius of curvature, but much less for rotations of
    near-spheres, whose contacts change at O(alpha - 1)). Returns max_k |y_k| / lengths_k
    (``lengths``: a for a translation column, 1 for a rotation angle), 0 without ``lengths`` or
    residual, inf when K_V is singular."""
    if lengths is None or not null.shape[1] or not np.any(residual):
        return 0.0
    kv = null.T @ (k @ null)
    kv = 0.5 * (kv + kv.T)
    try:
        y = null @ np.linalg.solve(kv, null.T @ residual)
    except np.linalg.LinAlgError:
        return float("inf")
    return float(np.max(np.abs(y) / lengths))


#: iterations of the cutting-plane search of :func:`_best_stress`
MAX_CUTS = 100


def _best_stress(at, stiffness, quadratic, null, forces, w, x, tol):
    """Maximise lambda_min(K_V(F)) over the self-stresses F >= 0, sum F = M (concave in F) by
    Kelley's cutting planes: each eigenvector x of K_V(F) gives the linear cut
    t <= sum_c F_c x^T V^T K_c V x. Stops when lambda_min > tol (pre-stress stable), when the
    LP's bound t <= tol (no self-stress blocks all floppy modes), or after MAX_CUTS LPs.

    Returns (F, eigenvalues, eigenvectors, flex) with flex = (optimum, x) when a floppy mode x
    was found on which every self-stress has negative stiffness (max_F x^T K_V(F) x < -tol, the
    dual LP 5.15 of a strict second-order flex), else None."""
    m = at.shape[0]
    a = sp.csr_matrix(at.T)
    nrow = a.shape[0]
    a_eq = sp.vstack([sp.hstack([a, sp.csr_matrix((nrow, 1))]),
                      sp.csr_matrix(np.concatenate([np.ones(m), [0.0]])[None, :])], format="csr")
    b_eq = np.concatenate([np.zeros(nrow), [float(m)]])
    cost = np.zeros(m + 1)
    cost[-1] = -1.0
    bounds = [(0.0, None)] * m + [(None, None)]
    cuts = []
    best = (w, x, forces)
    for _ in range(MAX_CUTS):
        use = x[:, : max(1, int((w <= w[0] + abs(w[0]) + tol).sum()))]
        q = quadratic(null @ use)  # (M, k)
        for col in range(q.shape[1]):
            if q[:, col] @ forces <= tol:
                # a mode this stress does not block: is it blocked by any self-stress?
                res = solve_lp(-np.concatenate([q[:, col], [0.0]]), A_eq=a_eq, b_eq=b_eq,
                               bounds=bounds[:m] + [(0.0, 0.0)])
                if -res.fun < -tol:
                    return best[2], best[0], best[1], (float(-res.fun), use[:, col])
            cuts.append(q[:, col])
        a_ub = np.column_stack([-np.array(cuts), np.ones(len(cuts))])
        res = solve_lp(cost, A_ub=a_ub, b_ub=np.zeros(len(cuts)), A_eq=a_eq, b_eq=b_eq, bounds=bounds)
        forces, bound = np.clip(res.x[:m], 0.0, None), float(res.x[-1])
        w, x = _projected_eigh(stiffness(forces), null)
        if w[0] > best[0][0]:
            best = (w, x, forces)
        if best[0][0] > tol or bound <= tol or bound - best[0][0] <= tol:
            break
    return best[2], best[0], best[1], None


def approximate_stress(at: sp.spmatrix) -> tuple[np.ndarray, float, float] | None:
    """Donev 2006, Sec. 5.6: the self-stress of a packing near (not at) its jamming point as the
    eigenvector of the smallest eigenvalue of A^T A, when that eigenvalue is well below the next
    (s_1 <= APPROX_STRESS_GAP s_2 for the singular values of A).

    Each balance equation (row of A: a force or torque component on one particle) is first scaled
    to unit norm, which leaves the exact self-stresses as they are but measures the residual of
    each equation against its own scale: near the sphere point the torque rows are O(alpha - 1),
    and a torque imbalance of the same order must not pass for a near self-stress.

    Returns (unit stress with a positive sum, s_1 / s_2, s_1 / s_max) of the scaled A, or None when
    A has fewer rows than columns (M > n: exact self-stresses exist) or s_1 is not separated.

    Parameters
    ----------
    at : scipy.sparse matrix, shape (M, n)
        A^T in reduced dof.

    Returns
    -------
    tuple of (numpy.ndarray of float, shape (M,), float, float) or None
        As above.
    """
    m, n = at.shape
    if m < 2 or m > n:
        return None
    at = sp.csr_matrix(at)
    norms = np.sqrt(np.asarray(at.multiply(at).sum(axis=0)).ravel())
    scaled = at @ sp.diags(np.where(norms > 0, 1.0 / np.maximum(norms, 1e-300), 0.0))
    gram = (scaled @ scaled.T).tocsc()
    if m <= DENSE_LIMIT:
        w, v = np.linalg.eigh(gram.toarray())
        top = float(w[-1])
    else:
        top = float(spla.eigsh(gram, k=1, which="LA", return_eigenvectors=False)[0])
        w, v = spla.eigsh(gram, k=2, sigma=-1e-6 * top, which="LM")
        order = np.argsort(w)
        w, v = w[order], v[:, order]
    s1, s2 = np.sqrt(np.maximum(w[:2], 0.0))
    if not (s2 > 0 and s1 <= APPROX_STRESS_GAP * s2):  # s2 = 0: several exact self-stresses
        return None
    f = v[:, 0] * np.sign(v[:, 0].sum())
    return f, float(s1 / s2), float(s1 / np.sqrt(top))


def decide_sparse(at: sp.spmatrix, stiffness, trivial: np.ndarray, *, rank_tol: float = 1e-9,
                  stress_tol: float = 1e-9, eig_tol: float = 1e-9, lengths: np.ndarray | None = None) -> Decision:
    """The procedure of the module docstring with sparse linear algebra (large packings).

    The counts come from the inertia of LDL^T factorisations (N_stresses: the eigenvalues of
    A^T A below ``rank_tol``, relative); the floppy space is the span of the eigenvectors of
    A A^T below that tolerance (shift-invert eigsh), orthogonalised against the trivial motions,
    and the second order is decided by the smallest eigenvalue of the projected stiffness
    K_V = V^T K V, as in :func:`decide_dense`. Donev 2006, Sec. 5.6 instead takes the smallest
    eigenvalue of the shifted form k A A^T + K (k = 1e6), which has the sign of lambda_min(K_V)
    only when k s^2 >> |K| for the smallest nonzero singular value s of A^T. In LS packings of
    spheroids s / s_max reaches 5e-3 (measured: an N = 80 M&M packing, Z = 9.93), where the
    shifted form with k = 1e3 |K| / |A A^T| is off by a factor of 12 in lambda; the projection
    needs no k. Parameters and result as :func:`decide_dense` (``stiffness``: forces -> sparse K).

    Parameters
    ----------
    at : scipy.sparse matrix, shape (M, n)
        A^T in reduced dof.
    stiffness : callable
        forces (M,) -> sparse (n, n) stiffness K in reduced dof.
    trivial : numpy.ndarray of float, shape (n, t)
        Orthonormal trivial motions, t may be 0.
    rank_tol, stress_tol, eig_tol : float, optional
        Relative tolerances of the rank, of the LP's eps*, of lambda_min.
    lengths : numpy.ndarray of float, shape (n,), optional
        Length unit of each column, as in :func:`decide_dense`.

    Returns
    -------
    Decision
        The outcome.
    """
    m, n = at.shape
    t = trivial.shape[1]
    common = dict(n_stresses=-1, n_floppy=-1, n_dof=n - t, n_constraints=m)
    gram = (at.T @ at).tocsc()
    gscale = max(abs(gram).max(), 1e-300)
    stresses = (at @ at.T).tocsc()
    n_stresses = _count_below(stresses / max(abs(stresses).max(), 1e-300), rank_tol)[0]
    common.update(n_stresses=-1 if n_stresses is None else n_stresses)
    near = approximate_stress(at) if n_stresses is not None and n_stresses <= 1 else None
    w = np.zeros(n)
    if near is not None:
        # a self-stress within rank_tol, or a near one (Sec. 5.6): the packing is near its jamming
        # point, where A f = 0; A there is A - w f^T
        approx, gap, residual = near
        w = np.asarray(at.T @ approx).ravel()
        common.update(approx_stress=approx, stress_residual=residual, stress_gap=gap)
    if near is not None and n_stresses == 1:
        # the one self-stress: LP 5.9 is its minimum
        eps, forces, why = _unique_stress(approx, stress_tol)
    elif near is not None:
        forces = approx * (m / approx.sum())
        eps = float(forces.min())
        n_stresses = 1
        common.update(n_stresses=1)
        why = None if eps > stress_tol else (
            "the near self-stress (smallest singular vector of A) is not strictly positive: a strict "
            "first-order flex exists" if eps < -stress_tol else
            "the near self-stress (smallest singular vector of A) is not strict: inconclusive")
    elif n_stresses == 0:
        eps, forces = float("-inf"), np.zeros(m)
        why = ("no self-stress (A has full column rank and no near self-stress: LP 5.9 infeasible): a "
               "strict first-order flex exists")
    else:
        eps, forces, why = _first_order(at, stress_tol)
    if why is not None:
        verdict = Verdict.NOT_JAMMED if eps < -stress_tol else Verdict.UNDETERMINED
        return Decision(verdict, "first" if verdict == Verdict.NOT_JAMMED else "undetermined",
                        False, why, forces, stress_margin=eps, **common)
    null, fell = _floppy_space(gram / gscale, w / np.sqrt(gscale), trivial, rank_tol)
    n_floppy = null.shape[1]
    common.update(n_floppy=n_floppy, stress_margin=eps, fallbacks=fell)
    if not n_floppy:
        return Decision(Verdict.JAMMED, "first", True,
                        "strict self-stress and no nontrivial floppy mode: first-order rigid",
                        forces, **common)
    k = stiffness(forces)
    kscale = max(abs(k).max(), 1e-300)
    lams, x = _projected_eigh(k, null)
    lam = float(lams[0])
    distance = _jamming_distance(k, null, np.asarray(at.T @ forces).ravel(), lengths)
    margin = eig_tol * kscale
    common.update(lambda_min=lam, stiffness_scale=kscale, jamming_distance=distance)
    if lam > margin:
        return Decision(Verdict.JAMMED, "second", False,
                        f"{n_floppy} floppy mode(s), all blocked by the stress matrix "
                        f"(lambda_min(K_V) = {lam / kscale:.3g} of max |K|): second-order jammed",
                        forces, **common)
    motion = null @ x[:, 0]
    if lam < -margin and n_stresses == 1:
        return Decision(Verdict.NOT_JAMMED, "second", False,
                        f"a floppy mode with negative stiffness (lambda_min(K_V) = {lam / kscale:.3g} of "
                        "max |K|) and a unique self-stress: second-order flexible", forces, motion=motion, **common)
    return Decision(Verdict.UNDETERMINED, "undetermined", False,
                    "a floppy mode with negative stiffness and several self-stresses (or their count "
                    "failed); the search over several self-stresses is in the dense method" if lam < -margin else
                    "lambda_min(K_V) is zero within the tolerance: higher orders would decide",
                    forces, motion=motion, **common)


#: floppy space of the sparse path: eigenpairs beyond the floppy ones computed, to see the gap
FLOPPY_MARGIN = 4


def _floppy_space(gram: sp.csc_matrix, w: np.ndarray, trivial: np.ndarray, rank_tol: float):
    """(V, fell): an orthonormal basis V (n, n_floppy) of the nontrivial floppy space, the null
    space of A^T at the jamming point, and whether a dense eigh replaced eigsh.

    ``gram`` = A A^T of scale 1 (as n x n), ``w`` = A f of a near self-stress f on the same scale
    (zeros without one): A at the jamming point is A - w f^T, whose A A^T is gram - w w^T. The
    floppy eigenvalues are those below tau = max(rank_tol, 2 |w|^2); their number (trivial
    motions included) comes from the inertia of gram - tau I, their eigenvectors, with
    FLOPPY_MARGIN more, from eigsh in shift-invert mode at tau (the same factorisation), then a Rayleigh-Ritz
    step with gram - w w^T in that subspace, and the trivial motions are projected out."""
    n = gram.shape[0]
    t = trivial.shape[1]
    tau = max(rank_tol, 2.0 * float(w @ w))
    count, lu = _count_below(gram, tau)
    want = (n if count is None else count) + FLOPPY_MARGIN
    fell = count is None and n > SMALL_EIGH
    vals = None
    if not fell and SMALL_EIGH < n and want < n // 2:
        try:  # shift-invert at tau with the factorisation of the count: the floppy eigenvalues are nearest
            inverse = spla.LinearOperator(gram.shape, matvec=lu.solve, dtype=float)
            vals, vecs = spla.eigsh(gram, k=want, sigma=tau, which="LM", OPinv=inverse)
        except (spla.ArpackNoConvergence, RuntimeError):
            fell = True
    if vals is None:
        vals, vecs = np.linalg.eigh(gram.toarray())
    yw = vecs.T @ w
    vals, rot = np.linalg.eigh(np.diag(vals) - np.outer(yw, yw))
    floppy = vecs @ rot[:, vals <= tau]
    if t:
        floppy = floppy - trivial @ (trivial.T @ floppy)
    if not floppy.shape[1]:
        return floppy, fell
    q, r, _ = sla.qr(floppy, mode="economic", pivoting=True)
    keep = np.abs(np.diag(r)) > 1e-6 * max(abs(r[0, 0]), 1e-300)
    return q[:, : int(keep.sum())], fell


def _count_below(mat: sp.csc_matrix, tau: float):
    """(number of eigenvalues of a symmetric sparse matrix below ``tau``, the factorisation of
    mat - tau I) by Sylvester's law of inertia: the negative pivots of the LU factorisation of
    mat - tau I with a symmetric permutation and no pivoting, P M P^T = L D L^T, U = D L^T.
    (None, None) when the factorisation failed or pivoted."""
    shifted = (mat - tau * sp.identity(mat.shape[0], format="csc")).tocsc()
    try:
        lu = spla.splu(shifted, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular
        return None, None
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None, None
    return int((lu.U.diagonal() < 0).sum()), lu


# ------------------------------------------------------------------------------------- result
@dataclass
class EllipsoidJammingResult:
    """What :func:`verify_ellipsoids` found (see the module docstring).

    Attributes
    ----------
    params : dict
        The test's options and the contact tolerance used (``delta``, ``method``, tolerances).
    network : EllipsoidContacts
        Every contact within the tolerance.
    frozen : ndarray of bool, shape (N,)
        Fixed particles (obstacles).
    local : ndarray of int, shape (N,)
        :class:`Verdict` code of each particle's local test (NOT_RUN for frozen particles).
    local_order : ndarray of int, shape (N,)
        The order that decided it (:data:`ORDER_CODES`: 1 first, 2 second, 0 undetermined or not run).
    rattler : ndarray of bool, shape (N,)
        Particles removed by the iterated local test.
    collective : Decision
        The test of the backbone.
    contacts_used : ndarray of bool, shape (M,)
        The contacts of the backbone (among ``network``).
    dof : ndarray of int, shape (N,)
        Reduced dof per particle (0 for frozen ones).
    seconds : dict
        Wall-clock seconds per stage.
    fallbacks : dict
        Counts of the numerical fallbacks (:data:`FALLBACKS`).
    """

    params: dict
    network: EllipsoidContacts
    frozen: np.ndarray
    local: np.ndarray
    local_order: np.ndarray
    rattler: np.ndarray
    collective: Decision
    contacts_used: np.ndarray
    dof: np.ndarray
    seconds: dict = field(default_factory=dict)
    fallbacks: dict = field(default_factory=dict)

    @property
    def verdict(self) -> Verdict:
        return self.collective.verdict

    @property
    def order(self) -> str:
        """"first", "second" or "undetermined": the order of the test that decided."""
        return self.collective.order

    @property
    def backbone(self) -> np.ndarray:
        return ~self.frozen & ~self.rattler

    @property
    def z_mean(self) -> float:
        """Mean contacts per backbone particle (contacts with frozen particles included)."""
        nb = int(self.backbone.sum())
        if not nb:
            return float("nan")
        used = self.network.subset(self.contacts_used)
        return float(used.counts()[self.backbone].sum() / nb)

    @property
    def contact_forces(self) -> np.ndarray:
        """(M,) the self-stress on every contact of ``network`` (zero on the unused ones)."""
        forces = np.zeros(self.network.n_contacts)
        forces[self.contacts_used] = self.collective.forces
        return forces

    @property
    def n_backbone_wall_contacts(self) -> int:
        """Wall contacts of the backbone (among the M_b)."""
        return int((self.contacts_used & self.network.is_wall).sum())

    @property
    def wall_force(self) -> float:
        """Sum of the wall reactions (the self-stress has mean 1 over the backbone contacts)."""
        return float(self.contact_forces[self.network.is_wall].sum())

    def unjamming_motion(self) -> np.ndarray | None:
        """The collective test's floppy mode of negative (or zero) stiffness as a motion of every
        particle: translations (in length units) and lab-frame rotation vectors, unit Euclidean
        norm over the backbone's reduced degrees of freedom.

        Returns
        -------
        numpy.ndarray of float, shape (N, d_f), or None
            Columns 0..d-1 translate, the others turn (one angle in 2D, a rotation vector in 3D);
            rattlers and frozen particles do not move. None when the test found no such mode (a
            jammed verdict, or one decided at first order).
        """
        motion = self.collective.motion
        if motion is None:
            return None
        t_full, dof = dof_basis(self.network, ~self.frozen)
        owner = np.repeat(np.flatnonzero(~self.frozen), dof[~self.frozen])
        tm = t_full[:, np.flatnonzero(self.backbone[owner])]
        return np.asarray(tm @ motion).reshape(self.network.n_particles, dof_per_particle(self.network.dim))

    @property
    def isostaticity_gap(self) -> int:
        """M_b - N_f: constraints minus nontrivial dof of the backbone (0 or 1: isostatic,
        Donev 2006, Sec. 5.4.1; negative: hypostatic)."""
        return self.collective.n_constraints - self.collective.n_dof

    def summary(self) -> str:
        """A few human-readable lines: the verdict and the order that decided it, counts, degrees of
        freedom, self-stresses and floppy modes, wall contacts, the near self-stress and fallbacks.

        Returns
        -------
        str
            The lines, joined by newlines.
        """
        c = self.collective
        nb = int(self.backbone.sum())
        lines = [
            f"verdict: {self.verdict.name.lower().replace('_', ' ')} (decided at order: {self.order}); {c.reason}",
            (f"N={self.network.n_particles}, frozen={int(self.frozen.sum())}, rattlers="
             f"{int(self.rattler.sum())}, backbone={nb}, contacts M_b={c.n_constraints}, Z={self.z_mean:.4f}"),
            (f"dof N_f={c.n_dof} (per particle: {np.unique(self.dof[self.backbone]).tolist()}), "
             f"M_b - N_f = {self.isostaticity_gap}, self-stresses {c.n_stresses}, nontrivial floppy "
             f"modes {c.n_floppy}, lambda_min(K_V) = {c.lambda_min:.4g}; first-order LP found a flex: "
             f"{'-' if c.lp_flex is None else 'yes' if c.lp_flex else 'no'}"),
        ]
        if self.network.n_wall_contacts:
            lines.append(f"{self.params.get('boundary', 'walls')}: {self.network.n_wall_contacts} wall contacts, "
                         f"{self.n_backbone_wall_contacts} of them in the backbone, total reaction "
                         f"{self.wall_force:.4g} (forces of mean 1)")
        if c.approx_stress is not None:
            lines.append(f"near self-stress (smallest singular vector of A, Donev 2006 Sec. 5.6): |A f| / "
                         f"(|A| |f|) = {c.stress_residual:.3g}; distance from the jamming point along the "
                         f"floppy modes {c.jamming_distance:.3g} particle sizes")
        for name, count in self.fallbacks.items():
            if count:
                lines.append(f"numerical fallback {name}: {count}")
        return "\n".join(lines)

    def to_dataset(self) -> xr.Dataset:
        """Per-particle and per-contact arrays and scalar attributes (verdict codes of
        :class:`Verdict`: 1 jammed, 0 not jammed, -1 not run, -2 undetermined). Wall contacts
        have ``contact_wall`` 0 (container) or 2 k / 2 k + 1 (the flat walls x_k = 0 / x_k = L_k;
        -1 for a pair), j = i, ``contact_gap`` h / a_max and their ``force`` is the wall's
        reaction; attributes ``n_wall_contacts``, ``n_backbone_wall_contacts``, ``wall_force`` (sum
        of the reactions) and ``boundary``, as for spheres
        (:meth:`hardpack.jamming.result.JammingResult.to_dataset`)."""
        net, c = self.network, self.collective
        forces = self.contact_forces
        data = {
            "contact_i": (("contact",), net.i),
            "contact_j": (("contact",), net.j),
            "contact_shift": (("contact", "dim"), net.shift),
            "contact_gap": (("contact",), net.gap),
            "contact_normal": (("contact", "dim"), net.normal),
            "contact_used": (("contact",), self.contacts_used.astype(np.int8)),
            "contact_wall": (("contact",), net.wall),
            "force": (("contact",), forces),
            "frozen": (("particle",), self.frozen.astype(np.int8)),
            "rattler": (("particle",), self.rattler.astype(np.int8)),
            "local": (("particle",), self.local.astype(np.int8)),
            "local_order": (("particle",), self.local_order.astype(np.int8)),
            "dof": (("particle",), self.dof),
        }
        attrs = dict(
            hardpack_kind="ellipsoid_jamming", verdict=int(self.verdict), order=self.order,
            reason=c.reason, first_order_rigid=int(c.first_order_rigid),
            first_order_lp_flex=-1 if c.lp_flex is None else int(c.lp_flex),
            N=net.n_particles, d=net.dim, n_contacts=net.n_contacts, n_frozen=int(self.frozen.sum()),
            n_rattlers=int(self.rattler.sum()), n_backbone=int(self.backbone.sum()),
            n_backbone_contacts=c.n_constraints, n_dof=c.n_dof, z_mean=self.z_mean,
            isostaticity_gap=self.isostaticity_gap, n_stresses=c.n_stresses, n_floppy=c.n_floppy,
            lambda_min=c.lambda_min, stiffness_scale=c.stiffness_scale, stress_margin=c.stress_margin,
            n_local_undetermined=int((self.local == Verdict.UNDETERMINED).sum()),
            approximate_stress=int(c.approx_stress is not None), stress_residual=c.stress_residual,
            stress_gap=c.stress_gap,
            jamming_distance=c.jamming_distance,
            order_code=ORDER_CODES[self.order], rattler_fraction=float(self.rattler.sum() / max(net.n_particles, 1)),
            hypostatic=int(self.isostaticity_gap < 0), jammed=int(self.verdict == Verdict.JAMMED),
            n_wall_contacts=net.n_wall_contacts, n_backbone_wall_contacts=self.n_backbone_wall_contacts,
            wall_force=self.wall_force,
            **{k: v for k, v in self.params.items() if v is not None},
            **{f"fallback_{k}": int(v) for k, v in self.fallbacks.items()},
            **{f"seconds_{k}": v for k, v in self.seconds.items()},
        )
        return xr.Dataset(data, attrs=attrs)


# ------------------------------------------------------------------------------------- verify
def _submatrices(net, at_full, hess, t_full, owner, contacts, moving, near=None):
    """(A^T, dense stiffness(forces), sparse stiffness(forces), T) restricted to ``contacts`` and
    the reduced dof of the ``moving`` particles (``owner``: the particle of each reduced column).
    ``near`` = (f, A f) of a near self-stress over all contacts: A^T is then taken at the jamming
    point, (I - f f^T) A^T (module docstring)."""
    tm = t_full[:, np.flatnonzero(moving[owner])]
    at = (at_full[contacts] @ tm).tocsr()
    if near is not None:
        at = sp.csr_matrix(at.toarray() - np.outer(near[0][contacts], near[1] @ tm))
    sub = net.subset(contacts)
    sub_hess = hess[contacts]

    def stiffness_sparse(forces):
        return (tm.T @ stiffness_matrix_full(sub, forces, sub_hess) @ tm).tocsc()

    def stiffness(forces):
        return stiffness_sparse(forces).toarray()

    f = dof_per_particle(net.dim)
    idx = np.concatenate([sub.i[:, None] * f + np.arange(f), sub.j[:, None] * f + np.arange(f)], axis=1)

    def quadratic(y):
        """(M, k): y_k^T K_c y_k of every contact c for the columns y_k of y (n_red, k)."""
        yc = (tm @ y)[idx]  # (M, 2 d_f, k)
        return -np.einsum("cak,cab,cbk->ck", yc, sub_hess, yc) / sub.scale[:, None]

    return at, stiffness, stiffness_sparse, quadratic, tm


def _column_lengths(tm: sp.spmatrix, net: EllipsoidContacts) -> np.ndarray:
    """Length unit of each reduced column (``tm``: reduced -> full dof): the smallest semiaxis of
    the packing for a translation, 1 for a rotation angle (:func:`_jamming_distance`)."""
    f, d = dof_per_particle(net.dim), net.dim
    csc = sp.csc_matrix(tm)
    csc.sort_indices()
    first = csc.indices[csc.indptr[:-1]] if csc.shape[1] else np.zeros(0, dtype=np.int64)
    return np.where(first % f < d, float(np.min(net.semiaxes)), 1.0)


def _global_near_stress(net, at_full, t_full, owner, frozen):
    """(f, A f) over all contacts (zeros on those between frozen particles) of the near self-stress
    of the whole packing (:func:`approximate_stress`), or None when it has none. The local tests
    use A at the jamming point it defines: a particle's own balance equations alone can be far
    more sensitive to the distance from jamming than the whole packing's (near the sphere point,
    where the torque rows are small, an exact local balance of a packing at a finite pressure may
    need negative forces while the whole packing has a strictly positive near self-stress)."""
    moving = ~frozen
    base = np.flatnonzero(moving[net.i] | moving[net.j])
    tm = t_full[:, np.flatnonzero(moving[owner])]
    found = approximate_stress(at_full[base] @ tm)
    if found is None:
        return None
    f = np.zeros(net.n_contacts)
    f[base] = found[0]
    return f, np.asarray(at_full.T @ f).ravel()


def _slides_along_walls(net: EllipsoidContacts, contacts: np.ndarray, n_dof: int) -> Decision | None:
    """The local test's decision for a particle all of whose ``contacts`` (a nonempty set) are with
    flat hard walls whose normals n do not span R^d, None otherwise (module docstring).

    Each gap h = b - n . x - s depends on the centre only through n . x (module docstring of
    :mod:`hardpack.jamming.ellipsoids`), so a translation t with n . t = 0 for every touched wall
    (one exists iff the normals do not span R^d) leaves every gap unchanged exactly: an
    unjamming motion, which the second-order test would see only as a floppy mode of zero
    stiffness. ``n_dof`` is the particle's reduced dof."""
    if not contacts.size or not net.is_plane_wall[contacts].all():
        return None
    normals = net.normal[contacts]
    if np.linalg.matrix_rank(normals) == net.dim:
        return None
    walls = ", ".join(sorted({wall_name(net, c) for c in contacts}))
    return Decision(Verdict.NOT_JAMMED, "first", False,
                    f"its only contacts are with flat walls ({walls}) whose normals do not span R^{net.dim}: "
                    "translating parallel to them keeps every gap, an exact unjamming motion",
                    np.zeros(contacts.size), -1, -1, n_dof, int(contacts.size))


def verify_ellipsoids(packing: Packing, delta: float | None = None, *, frozen=None,
                      method: str = "auto", local: bool = True, rank_tol: float = 1e-9,
                      stress_tol: float = 1e-9, eig_tol: float = 1e-9, seed: int = 0) -> EllipsoidJammingResult:
    """Jamming test of a packing of ellipses or ellipsoids, periodic, between flat hard walls or in a
    spherical container (module docstring; wall contacts: :mod:`hardpack.jamming.ellipsoids`).

    Parameters
    ----------
    packing : Packing
        Ellipses or ellipsoids in a periodic cell, between flat hard walls or in a spherical
        container (the contacts must be exact to ``delta``; a wall contact's gap counts relative
        to the particle's a_max).
    delta : float or "gaps", optional
        Contact tolerance mu - 1 (default DEFAULT_DELTA, 1e-9), or "gaps": read off the gap
        distribution (:func:`contact_delta_from_gaps`; packings from a compression to high
        pressure, whose contacts are not exact).
    frozen : array_like of bool, shape (N,), optional
        Fixed particles (obstacles): no dof, no balance equations.
    method : {"auto", "dense", "sparse"}
        Linear algebra of the collective test ("auto": dense up to DENSE_LIMIT reduced dof).
    local : bool, default True
        Run the iterated local test (rattler removal) before the collective test.
    rank_tol, stress_tol, eig_tol : float
        Relative tolerances of the rank of A, of the self-stress LP's margin, of lambda_min.
    seed : int, default 0
        Seed of the random load of the first-order LP cross-check (:func:`first_order_lp`).

    Returns
    -------
    EllipsoidJammingResult

    Raises
    ------
    InvalidInputError
        For a packing that is not an ellipsoid packing, a particle touching the container along a
        continuum, overlaps (pairs: mu - 1 below -packing.overlap_tol, by the Perram-Wertheim
        function; a wall, flat or the container's: h / a_max below it), a
        bad ``delta``, ``frozen`` of
        the wrong shape, an unknown ``method`` or non-positive tolerances.
    """
    check_ellipsoid_packing(packing)
    n = packing.n_particles
    if method not in ("auto", "dense", "sparse"):
        raise InvalidInputError(f"method must be 'auto', 'dense' or 'sparse', got {method!r}")
    for name, value in (("rank_tol", rank_tol), ("stress_tol", stress_tol), ("eig_tol", eig_tol)):
        if not (np.isfinite(value) and 0 < value < 1):
            raise InvalidInputError(f"{name} must be in (0, 1), got {value!r}")
    check_seed(seed)
    frozen = np.zeros(n, dtype=bool) if frozen is None else np.asarray(frozen)
    if frozen.shape != (n,) or frozen.dtype != bool:
        raise InvalidInputError(f"frozen must be a boolean array of shape ({n},), got {frozen.dtype} {frozen.shape}")
    delta = DEFAULT_DELTA if delta is None else delta
    seconds = {}
    t0 = time.perf_counter()
    ambiguous = -1
    if isinstance(delta, str):
        if delta != "gaps":
            raise InvalidInputError(f"delta must be a number in (0, 1) or 'gaps', got {delta!r}")
        wide = ellipsoid_contacts(packing, GAPS_SEARCH)
        delta, ambiguous = contact_delta_from_gaps(wide.gap, n, packing.dim)
        if not np.isfinite(delta):
            raise InvalidInputError(
                f"fewer pairs within mu - 1 <= {GAPS_SEARCH:g} than a jammed packing needs "
                f"(Z >= d + 1): no contact tolerance can be read off the gaps; pass a number")
    net = ellipsoid_contacts(packing, delta)
    overlap = net.gap < -packing.overlap_tol
    if overlap.any():
        worst = int(np.argmin(net.gap))
        what = (f"particle {net.i[worst]} and {wall_name(net, worst)}, h / a_max" if net.wall[worst] >= 0
                else f"particles {net.i[worst]} and {net.j[worst]}, mu - 1")
        raise InvalidInputError(
            f"{int(overlap.sum())} contacts overlap beyond the tolerance {packing.overlap_tol:g} (worst: "
            f"{what} = {net.gap[worst]:.3g}); jamming tests need a packing of hard particles: finish or "
            "repair it first")
    at_full = rigidity_transpose_full(net)
    hess = contact_hessians(net)
    t_full, dof = dof_basis(net, ~frozen)
    owner = np.repeat(np.flatnonzero(~frozen), dof[~frozen])
    seconds["contacts"] = time.perf_counter() - t0
    tols = dict(stress_tol=stress_tol, eig_tol=eig_tol)
    with recording_fallbacks() as fallbacks:
        t0 = time.perf_counter()
        near = _global_near_stress(net, at_full, t_full, owner, frozen) if local else None
        local_verdict = np.full(n, int(Verdict.NOT_RUN), dtype=np.int64)
        local_order = np.zeros(n, dtype=np.int64)
        active = ~frozen
        if local:
            # removing a particle can unjam only its neighbours: they are tested again
            pending = list(np.flatnonzero(active))
            queued = active.copy()
            while pending:
                p = pending.pop(0)
                queued[p] = False
                present = active | frozen
                mine = (net.i == p) | (net.j == p)
                contacts = np.flatnonzero(mine & present[net.i] & present[net.j])
                only = np.zeros(n, dtype=bool)
                only[p] = True
                dec = _slides_along_walls(net, contacts, int(dof[p]))
                if dec is None:
                    at, stiff, _, quad, _ = _submatrices(net, at_full, hess, t_full, owner, contacts, only, near)
                    dec = decide_dense(at, stiff, quad, np.zeros((at.shape[1], 0)), rank_tol=rank_tol, **tols)
                local_verdict[p] = int(dec.verdict)
                local_order[p] = ORDER_CODES[dec.order]
                if dec.verdict == Verdict.NOT_JAMMED:
                    active[p] = False
                    for q in np.unique(np.concatenate([net.i[mine], net.j[mine]])):
                        if active[q] and not queued[q]:
                            pending.append(q)
                            queued[q] = True
        seconds["local"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        present = active | frozen
        used = present[net.i] & present[net.j] & (active[net.i] | active[net.j])
        contacts = np.flatnonzero(used)
        at, stiff, stiff_sparse, quad, tm = _submatrices(net, at_full, hess, t_full, owner, contacts, active)
        trivial = (trivial_motions(tm, net, active) if not frozen.any() and active.any()
                   else np.zeros((at.shape[1], 0)))
        dense = method == "dense" or (method == "auto" and at.shape[1] <= DENSE_LIMIT)
        lengths = _column_lengths(tm, net)
        if not active.any():
            second = (local_order == ORDER_CODES["second"]).any()
            dec = Decision(Verdict.NOT_JAMMED, "second" if second else "first", False,
                           "every particle is a rattler (the local test"
                           + (", at second order for some," if second else "")
                           + " found an unjamming motion of each): nothing is jammed",
                           np.zeros(len(contacts)), 0, 0, 0, len(contacts))
        elif dense:
            dec = decide_dense(at, stiff, quad, trivial, rank_tol=rank_tol, lengths=lengths, **tols)
        else:
            dec = decide_sparse(at, stiff_sparse, trivial, rank_tol=rank_tol, lengths=lengths, **tols)
        if active.any() and (dense or dec.n_constraints >= dec.n_dof):
            # (sparse path: a hypostatic backbone has a nontrivial flex by counting; its two large LPs
            # took 370 of 580 s at N = 1000 and would check nothing)
            dec.lp_flex = first_order_lp(at, trivial, np.random.default_rng(seed), stress=dec.approx_stress)[0]
        seconds["collective"] = time.perf_counter() - t0
    if ambiguous > AMBIGUOUS_FRACTION * net.n_contacts:
        dec.reason = (f"contacts not resolved: {ambiguous} pairs lie within a decade of the tolerance, more than "
                      f"{AMBIGUOUS_FRACTION:g} of the {net.n_contacts} contacts, so no tolerance separates contacts "
                      "from near contacts; "
                      f"compress to a higher pressure (the test alone said: {dec.verdict.name.lower()} at "
                      f"order {dec.order}; {dec.reason})")
        dec.verdict, dec.order = Verdict.UNDETERMINED, "undetermined"
    params = dict(boundary=str(packing.boundary),
                  delta=float(delta), delta_ambiguous=ambiguous, method="dense" if dense else "sparse", seed=int(seed),
                  rank_tol=rank_tol, stress_tol=stress_tol, eig_tol=eig_tol)
    rattler = ~frozen & ~active
    return EllipsoidJammingResult(
        params=params, network=net, frozen=frozen, local=local_verdict, local_order=local_order,
        rattler=rattler,
        collective=dec, contacts_used=used, dof=np.where(frozen, 0, dof), seconds=seconds,
        fallbacks={**{k: int(v) for k, v in fallbacks.items()},
                   "sparse_eigsh_dense": dec.fallbacks},
    )
