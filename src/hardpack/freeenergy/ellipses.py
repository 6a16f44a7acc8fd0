"""Exact free energy of an isostatic (first-order rigid) ellipse packing.

Donev 2006, dissertation secs. 6.2.2, 6.3.4.2 and 6.4.3; Donev, Stillinger & Torquato 2007,
Sec. 2.2, Sec. 4.4 and Appendix C.

Degrees of freedom. An ellipse has the centroid r and the angle phi (d_f = 3). The rigidity
matrix gets, per particle and contact, the block [n ; r_C x n] (r_C the contact point relative to
the centroid; :func:`hardpack.jamming.ellipsoids.rigidity_transpose_full`). A particle can have its
centroid fixed (its two translation rows removed) and/or its orientation fixed (its rotation row
removed). Donev 2006, sec. 6.4.3: a frozen particle that only removes the trivial translations has
its centroid fixed but not its orientation, since the periodic cell fixes the frame's orientation.

Jamming polytope. The packing is shrunk by (1 - delta) about the centroids. Contact c keeps the
Perram-Wertheim scale factor mu_c (mu = 1 at tangency), which shrinking raises to mu_c / (1 - delta).
Linearising mu_c(Q) >= 1 with grad mu = grad zeta / (2 mu) = (s_c / 2 mu_c) a_c, a_c the
unit-normal gap-rate row of A^T and s_c = 2 lam (1 - lam) |n| (:mod:`hardpack.jamming.ellipsoids`),
gives the polytope

    P = {dQ : -a_c . dQ <= h_c},   h_c = 2 mu_c (mu_c - 1) / s_c,

(for disks h_c is the surface gap). With M = N_f + 1 it is a simplex, whose volume is Eq. 6.5
(:func:`hardpack.freeenergy.simplex.log_simplex_volume`). In the PW normalisation of Donev 2006,
sec. 6.2.1 (footnote 2), the rows grad mu all have the right-hand side delta as delta -> 0, so
P = delta^{N_f} P_x and f_J = ln|P_x| / N_eff (Eq. 6.2).

Bounding cell (Appendix C, Eq. C1). The cell of an ellipse is the ellipse itself scaled by
mu = 1 + Delta mu about its initial centroid, at its initial orientation. For small Delta mu the
allowed displacements dq = (dr, dphi) are

    n . (dr + dphi x r_C) <= Delta mu n . r_C   for every boundary point r_C with unit normal n,

a convex body of volume Delta mu^3 b^2 V_alpha (b the minor semiaxis, alpha = a / b), whose log is
:func:`cell_log_volume` (b = 1): f_c = -3 ln Delta mu - f_c^J with f_c^J = ln V_alpha. We compute
V_alpha as the volume of the polytope cut by K equally spaced normals (it converges from above as
K^-2) with a Richardson step; alpha = 2 gives f_c^J = 2.26940, the 2.269 of Donev 2006,
sec. 6.3.4 (the 2.268 of its sec. 6.3.4.2 / Appendix C is 0.0014 lower). The largest rotation at
dr = 0 is Delta mu 2 alpha / (alpha^2 - 1) (4/3 for alpha = 2, as printed). Particles with a fixed
centroid and a free orientation have the 1D cell |dphi| <= Delta mu 2 alpha / (alpha^2 - 1); fixed
orientation and free centroid, the ellipse scaled by Delta mu (area pi a b Delta mu^2).

Exact Delta f. BCMD runs from large cells to the disjoint-cell point Delta mu_min (no two cells of
the shrunk packing overlap: 1 + Delta mu_min = min_ij mu_ij of the shrunk packing). Its Delta f is

    Delta f_exact = [ln|P| - sum_i ln|cell_i(Delta mu_min)|] / N_eff,

with N_eff the number of particles whose centroid moves (Donev 2006, Fig. 6.5: "96 free and four
frozen"). For exact contacts (mu_c = 1) and Delta mu_min = delta this is f_J - f_c^J (Eq. 6.18).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, HalfspaceIntersection

from hardpack.errors import InvalidInputError
from hardpack.freeenergy.isostatic import check_shrink_gap
from hardpack.freeenergy.simplex import jamming_simplex, log_simplex_volume
from hardpack.geometry.ellipsoid_pairs import potential_pairs
from hardpack.geometry.packing import Packing
from hardpack.jamming.ellipsoids import (
    check_ellipsoid_packing,
    contacts_of_pairs,
    ellipsoid_contacts,
    rigidity_transpose_full,
)

ROUND_TOL = 1e-9  # |alpha - 1| below this is a disk


def max_rotation(alpha: float) -> float:
    """Largest rotation of an ellipse of aspect ratio ``alpha`` > 1 at fixed centroid in its cell
    of size Delta mu = 1: min over the boundary of n.r_C / |r_C x n| = 2 alpha / (alpha^2 - 1)
    (Donev 2006, sec. 6.3.4.2: 4/3 for alpha = 2).

    Parameters
    ----------
    alpha : float
        Aspect ratio, > 1.

    Returns
    -------
    float
        The largest rotation angle in radians at Delta mu = 1 (it scales with Delta mu).

    Raises
    ------
    InvalidInputError
        For alpha <= 1 (a disk).
    """
    alpha = float(alpha)
    if not alpha > 1.0 + ROUND_TOL:
        raise InvalidInputError(f"a disk (alpha = {alpha}) rotates freely in its cell; alpha must be > 1")
    return 2.0 * alpha / (alpha * alpha - 1.0)


def _polytope_volume(alpha: float, k: int) -> float:
    """Volume of the cell body of Eq. C1 (Delta mu = 1, semiaxes alpha and 1) cut by k normals."""
    th = (np.arange(k) + 0.5) * (2.0 * np.pi / k)
    n = np.stack([np.cos(th), np.sin(th)], axis=1)
    xinv = np.array([alpha * alpha, 1.0])  # X^-1 of the ellipse with semiaxes (alpha, 1)
    r = n * xinv / np.sqrt((n * n * xinv).sum(axis=1))[:, None]  # r_C = X^-1 n / sqrt(n X^-1 n)
    lever = r[:, 0] * n[:, 1] - r[:, 1] * n[:, 0]  # r_C x n
    halfspaces = np.column_stack([n, lever, -(n * r).sum(axis=1)])
    hull = ConvexHull(HalfspaceIntersection(halfspaces, np.zeros(3)).intersections)
    return float(hull.volume)


@functools.lru_cache(maxsize=64)
def cell_log_volume(alpha: float, n_normals: int = 4000) -> float:
    """f_c^J = ln V_alpha, the log-volume of the displacements (dr, dphi) of an ellipse with
    semiaxes (alpha, 1) in its cell of size Delta mu = 1 (Eq. C1; module docstring).

    Parameters
    ----------
    alpha : float
        Aspect ratio, > 1.
    n_normals : int, default 4000
        K, the boundary normals of the polytope approximation; the result is the Richardson
        extrapolation 4/3 V(K) - 1/3 V(K/2) (error ~ K^-4; 1e-7 in ln V at K = 4000, alpha = 2).

    Returns
    -------
    float
        ln V_alpha (2.26940 for alpha = 2), so that f_c = -3 ln Delta mu - ln V_alpha.
    """
    alpha = float(alpha)
    if not alpha > 1.0 + ROUND_TOL or not np.isfinite(alpha):
        raise InvalidInputError(
            f"alpha = {alpha} must be a finite aspect ratio > 1 (a disk rotates freely: fix its "
            "orientation)"
        )
    if int(n_normals) < 64:
        raise InvalidInputError(f"n_normals = {n_normals} is too coarse; use >= 64")
    k = int(n_normals)
    v = (4.0 * _polytope_volume(alpha, k) - _polytope_volume(alpha, k // 2)) / 3.0
    return float(np.log(v))


def _cell_log_volumes(packing: Packing, free_translation, free_rotation, dmu: float) -> np.ndarray:
    """ln|cell_i(dmu)| of every particle (0 for a particle with no free degree of freedom)."""
    ax = np.sort(packing.shape.semiaxes, axis=1)
    b, a = ax[:, 0], ax[:, 1]
    out = np.zeros(packing.n_particles)
    for i in range(packing.n_particles):
        alpha = a[i] / b[i]
        if free_translation[i] and free_rotation[i]:
            out[i] = 2.0 * np.log(b[i]) + cell_log_volume(round(alpha, 12)) + 3.0 * np.log(dmu)
        elif free_translation[i]:
            out[i] = np.log(np.pi * a[i] * b[i] * dmu * dmu)
        elif free_rotation[i]:
            out[i] = np.log(2.0 * max_rotation(alpha) * dmu)
    return out


@dataclass(frozen=True)
class EllipseSimplexReference:
    """Exact jamming-simplex numbers of an ellipse packing shrunk by (1 - delta) (module docstring).

    Attributes
    ----------
    n_particles, n_contacts, n_dof : int
        N, M (contacts touching a free degree of freedom) and N_f.
    n_eff : int
        Particles whose centroid moves (the per-particle divisor).
    isostaticity_gap : int
        M - (N_f + 1); when != 0 the volumes are NaN.
    delta_f : float
        Delta f_exact of the module docstring (what BCMD measures from large cells down to
        ``dmu_min``).
    log_volume : float
        ln|P|, the actual-gap simplex.
    f_j : float
        ln|P_x| / n_eff in the PW normalisation (unit right-hand sides).
    f_j_minus_fcj : float
        [ln|P_x| - sum_i ln|cell_i(1)|] / n_eff, the delta -> 0 limit of ``delta_f``.
    min_force : float
        Smallest contact force of the unit-sum self-stress A f = 0 (unit-normal rows: forces
        in the physical sense).
    dmu_min : float
        Disjoint-cell point of the linear model (:func:`linear_model`).
    max_contact_gap, next_gap : float
        Largest mu - 1 of a contact and smallest mu - 1 of a non-contact (unshrunk packing).
    """

    n_particles: int
    n_contacts: int
    n_dof: int
    n_eff: int
    isostaticity_gap: int
    delta_f: float
    log_volume: float
    f_j: float
    f_j_minus_fcj: float
    min_force: float
    dmu_min: float
    max_contact_gap: float
    next_gap: float


def _free_masks(n: int, fixed_translation, fixed_rotation) -> tuple[np.ndarray, np.ndarray]:
    masks = []
    for name, idx in (("fixed_translation", fixed_translation), ("fixed_rotation", fixed_rotation)):
        idx = np.unique(np.asarray([] if idx is None else idx, dtype=np.int64).ravel())
        if idx.size and (idx.min() < 0 or idx.max() >= n):
            raise InvalidInputError(f"{name} holds particle indices outside 0..{n - 1}: {idx}")
        free = np.ones(n, dtype=bool)
        free[idx] = False
        masks.append(free)
    return masks[0], masks[1]


def _check_round_rotations(packing: Packing, free_rotation: np.ndarray) -> None:
    ax = packing.shape.semiaxes
    round_ = ax.max(axis=1) / ax.min(axis=1) < 1.0 + ROUND_TOL
    if np.any(round_ & free_rotation):
        bad = np.flatnonzero(round_ & free_rotation)
        raise InvalidInputError(
            f"particles {bad[:10].tolist()} are disks: their rotation is not constrained and the "
            "free volume is unbounded; list them in fixed_rotation"
        )


@dataclass(frozen=True)
class LinearModel:
    """The linearised jamming problem of an ellipse packing shrunk by (1 - delta).

    Attributes
    ----------
    shrunk : Packing
        The packing with every semiaxis times (1 - delta).
    contacts : EllipsoidContacts
        Its contacts (pairs with mu - 1 <= contact_tol before shrinking) with the lever arms
        r_C = (PW contact point - centroid) / mu_c: the boundary point of each ellipse itself with
        normal +-u, so that the rows [u; r_C x u] are the face normals of the cells (Eq. C1).
    gaps : numpy.ndarray
        h_c = 2 mu_c (mu_c - 1) / s_c, the first-order surface gap of each contact.
    supports : numpy.ndarray
        u . r_iC - u . r_jC: the cells of size Delta mu reach the plane of contact c at
        Delta mu = h_c / supports_c.
    dmu_min : float
        The disjoint-cell point of the linear model, min_c h_c / supports_c (= the PW
        min mu_ij - 1 of the shrunk packing to first order in delta).
    dmu_min_pw : float
        min_ij mu_ij - 1 over every pair of the shrunk packing (nonlinear check).
    max_contact_gap, next_gap : float
        Largest mu - 1 of a contact and smallest mu - 1 of a non-contact (unshrunk packing).
    """

    shrunk: Packing
    contacts: object
    gaps: np.ndarray
    supports: np.ndarray
    dmu_min: float
    dmu_min_pw: float
    max_contact_gap: float
    next_gap: float


def linear_model(packing: Packing, delta: float, contact_tol: float) -> LinearModel:
    """Contacts, gaps and the disjoint-cell point of ``packing`` shrunk by (1 - delta)
    (module docstring); the arguments are those of :func:`ellipse_simplex_reference`.

    Parameters
    ----------
    packing : Packing
        A jammed ellipse packing.
    delta : float
        Relative shrink of the semiaxes.
    contact_tol : float
        Contact tolerance on mu - 1.

    Returns
    -------
    LinearModel
        The linearised contacts of the shrunk packing.

    Raises
    ------
    InvalidInputError
        If an ellipse touches its own periodic image.
    """
    net0 = ellipsoid_contacts(packing, contact_tol)
    if np.any(net0.i == net0.j):
        raise InvalidInputError("an ellipse touches its own periodic image: use a larger cell")
    near = potential_pairs(packing, rel_gap=1e-2)
    others = near.mu - 1.0
    next_gap = float(np.min(others[others > contact_tol], initial=np.inf))
    max_contact_gap = float(np.max(net0.gap, initial=-np.inf))
    shrunk = packing.replace(shape=type(packing.shape)(packing.shape.semiaxes * (1.0 - delta),
                                                       packing.shape.orientations))
    net = contacts_of_pairs(shrunk, net0.i, net0.j, net0.shift, positions=net0.positions)
    mu = np.sqrt(net.zeta + 1.0)
    net = dataclasses.replace(net, lever_i=net.lever_i / mu[:, None], lever_j=net.lever_j / mu[:, None])
    gaps = 2.0 * mu * (mu - 1.0) / net.scale
    supports = np.einsum("cd,cd->c", net.normal, net.lever_i - net.lever_j)
    dmu_min = float(np.min(gaps / supports, initial=np.inf))
    pw = potential_pairs(shrunk, rel_gap=2.0 * delta + 2.0 * contact_tol)
    dmu_min_pw = float(np.min(pw.mu, initial=np.inf)) - 1.0
    return LinearModel(shrunk, net, gaps, supports, dmu_min, dmu_min_pw, max_contact_gap, next_gap)


def ellipse_simplex_reference(
    packing: Packing,
    delta: float,
    contact_tol: float,
    fixed_translation=(0,),
    fixed_rotation=(),
) -> EllipseSimplexReference:
    """Exact free energy of ``packing`` shrunk by (1 - delta), from its jamming simplex.

    Donev 2006, secs. 6.2.2 and 6.4.3; Donev et al. 2007, Sec. 2.2 and Appendix C (module
    docstring).

    Parameters
    ----------
    packing : Packing
        A periodic 2D packing of ellipses (``Ellipsoids``); disks must have their rotation fixed.
    delta : float
        Relative shrink of the particles, in (0, 0.01).
    contact_tol : float
        Pairs of the unshrunk packing with mu - 1 <= contact_tol are contacts; in (0, delta).
    fixed_translation : sequence of int, default (0,)
        Particles whose centroid is frozen (at least one: the trivial translations).
    fixed_rotation : sequence of int, default ()
        Particles whose orientation is frozen.

    Returns
    -------
    EllipseSimplexReference
        Counts, the exact Delta f, f_J, f_J - f_c^J, the smallest force and the gaps; NaN values
        when the packing is not isostatic (M != N_f + 1).

    Raises
    ------
    InvalidInputError
        If the packing is not periodic 2D ellipses, delta or contact_tol are out of range, no
        centroid is fixed, a disk's rotation is free, or the simplex is degenerate (a singular
        augmented matrix or a contact force <= 0).
    """
    check_ellipsoid_packing(packing)
    if packing.dim != 2:
        raise InvalidInputError("the exact ellipse free energy is implemented in 2D only")
    delta = check_shrink_gap(delta, contact_tol)
    n = packing.n_particles
    free_t, free_r = _free_masks(n, fixed_translation, fixed_rotation)
    if free_t.all():
        raise InvalidInputError("fix at least one centroid (fixed_translation) to remove the trivial translations")
    _check_round_rotations(packing, free_r)
    model = linear_model(packing, delta, contact_tol)
    shrunk, net = model.shrunk, model.contacts
    dmu_min = model.dmu_min
    free_dof = np.stack([free_t, free_t, free_r], axis=1).ravel()
    at = rigidity_transpose_full(net).tocsc()[:, free_dof].tocsr()
    touches = np.diff(at.indptr) > 0
    at = at[touches]
    n_dof = int(free_dof.sum())
    m = at.shape[0]
    n_eff = int(free_t.sum())
    gap = m - (n_dof + 1)
    nan = float("nan")
    if gap != 0:
        return EllipseSimplexReference(n, m, n_dof, n_eff, gap, nan, nan, nan, nan, nan, dmu_min,
                                       model.max_contact_gap, model.next_gap)
    mu = np.sqrt(net.zeta + 1.0)[touches]
    s = net.scale[touches]
    h = model.gaps[touches]
    log_v = log_simplex_volume(-at, h)
    grad_mu = at.multiply((s / (2.0 * mu))[:, None]).tocsr()
    js = jamming_simplex(grad_mu.T, n_eff=n_eff)  # checks M = N_f + 1 and forces > 0
    forces = jamming_simplex(at.T, n_eff=n_eff).forces  # in the unit-normal rows
    log_cells = _cell_log_volumes(shrunk, free_t, free_r, dmu_min).sum()
    log_cells_unit = _cell_log_volumes(packing, free_t, free_r, 1.0).sum()
    return EllipseSimplexReference(
        n, m, n_dof, n_eff, 0, (log_v - log_cells) / n_eff, log_v, js.f_j,
        (js.log_volume - log_cells_unit) / n_eff, float(forces.min()), dmu_min,
        model.max_contact_gap, model.next_gap,
    )


def _frozen_set(ci, cj, n: int, size: int, internal: int, rng) -> np.ndarray:
    """A random set of ``size`` particles grown along ``internal`` random contacts (a walk on the
    contact graph), filled up with random particles; the caller checks its contact count."""
    chosen = [int(rng.integers(n))]
    for _ in range(min(internal, size - 1)):
        at = chosen[-1]
        partners = np.r_[cj[ci == at], ci[cj == at]]
        partners = partners[~np.isin(partners, chosen)]
        if partners.size == 0:
            break
        chosen.append(int(rng.choice(partners)))
    rest = np.setdiff1d(np.arange(n), chosen)
    chosen += rng.choice(rest, size=size - len(chosen), replace=False).tolist()
    return np.sort(np.array(chosen, dtype=np.int64))


def freeze_to_isostatic(
    packing: Packing,
    delta: float,
    contact_tol: float,
    seed: int = 0,
    max_tries: int = 400,
    mode: str = "centroid",
    n_frozen: int | None = None,
) -> tuple[np.ndarray, np.ndarray, EllipseSimplexReference]:
    """Choose frozen particles that make ``packing`` isostatic with positive forces.

    Donev 2006, sec. 6.4.3: jammed packings of alpha = 2 ellipses grown from a triangular lattice
    have M < 3N - 1 contacts, and "by freezing 4 of the particles" the numbers of degrees of
    freedom and contacts were matched (Fig. 6.5: "96 free and four frozen ellipses"). The text
    does not say whether those four kept their orientation free (as it prescribes for the one
    particle frozen to remove the translations), so both readings are offered:

    - ``mode="centroid"``: F centroids fixed, orientations free: N_f = 3N - 2F, so
      F = (3N + 1 - M) / 2 (one orientation is fixed too when 3N + 1 - M is odd);
    - ``mode="full"``: ``n_frozen`` particles fixed entirely: N_f = 3(N - n_frozen), and the
      contacts among frozen particles drop out, so the set must hold exactly
      M - 3(N - n_frozen) - 1 of them.

    Random subsets (in the order of ``seed``; in ``"full"`` mode grown along random contacts) are
    tried until the augmented matrix is regular with all forces > 0.

    Parameters
    ----------
    packing : Packing
        A jammed periodic packing of ellipses.
    delta, contact_tol : float
        As in :func:`ellipse_simplex_reference`.
    seed : int, default 0
        Seed of the order of the tried subsets.
    max_tries : int, default 400
        Subsets tried before giving up.
    mode : {"centroid", "full"}, default "centroid"
        What a frozen particle loses (above).
    n_frozen : int, optional
        Particles frozen entirely in ``mode="full"``; default the fewest that can match,
        ceil((3N + 1 - M) / 3) (four for Donev's packing and for ours).

    Returns
    -------
    fixed_translation, fixed_rotation : numpy.ndarray of int
        The frozen centroids and orientations.
    reference : EllipseSimplexReference
        The exact numbers of that choice.

    Raises
    ------
    InvalidInputError
        If ``mode`` is unknown, no set of that kind can match the counts, or no tried subset
        gives a regular simplex with positive forces.
    """
    if mode not in ("centroid", "full"):
        raise InvalidInputError(f"mode must be 'centroid' or 'full', got {mode!r}")
    net = ellipsoid_contacts(packing, contact_tol)
    n, m = packing.n_particles, net.n_contacts
    rng = np.random.default_rng(seed)
    if mode == "centroid":
        excess = 3 * n + 1 - m
        if excess < 2:
            raise InvalidInputError(
                f"the packing has M = {m} contacts for N = {n} ellipses: M >= 3N, so freezing "
                "centroids cannot make it isostatic (it is hyperstatic)"
            )
        n_t, n_r = excess // 2, excess % 2
    else:
        if n_frozen is None:
            n_frozen = max(1, -(-(3 * n + 1 - m) // 3))
        internal = m - 3 * (n - int(n_frozen)) - 1
        if not 0 <= internal <= m:
            raise InvalidInputError(
                f"M = {m} contacts cannot match N_f + 1 = {3 * (n - int(n_frozen)) + 1} with "
                f"{n_frozen} fully frozen particles; choose another n_frozen"
            )
    last = "no subset tried"
    for _ in range(int(max_tries)):
        if mode == "centroid":
            pick = rng.choice(n, size=n_t + n_r, replace=False)
            fixed_t, fixed_r = np.sort(pick[:n_t]), np.sort(pick[n_t:])
        else:
            fixed_t = _frozen_set(net.i, net.j, n, int(n_frozen), internal, rng)
            inside = np.isin(net.i, fixed_t) & np.isin(net.j, fixed_t)
            if int(inside.sum()) != internal:
                last = f"{int(inside.sum())} contacts among the frozen, {internal} needed"
                continue
            fixed_r = fixed_t
        try:
            ref = ellipse_simplex_reference(packing, delta, contact_tol, fixed_t, fixed_r)
        except InvalidInputError as exc:
            last = str(exc)
            continue
        if ref.isostaticity_gap == 0:
            return fixed_t, fixed_r, ref
        last = f"isostaticity gap {ref.isostaticity_gap}"
    raise InvalidInputError(
        f"no tried set of frozen particles (mode {mode!r}, {max_tries} tries) makes the packing "
        f"isostatic with positive forces (last: {last})"
    )


def lattice_ellipses(nx: int = 10, ny: int = 10, alpha: float = 2.0, spread: float = 0.6,
                     seed: int = 0) -> Packing:
    """The start of Donev 2006, sec. 6.4.3: a triangular lattice of nx * ny unit-spaced disks
    (ny even, in its rectangular periodic cell nx by ny sqrt(3)/2) with each disk replaced by an
    ellipse of aspect ratio ``alpha`` inscribed in it (semiaxes 0.49 and 0.49 / alpha), its
    orientation uniform in +-spread/2 about the x axis. Compressing it to jamming
    (:func:`hardpack.md.ellipsoid.compress_ellipsoids`) gives a partially disordered packing.

    Parameters
    ----------
    nx, ny : int, default 10
        Lattice sites per row and rows (ny even, so the cell is periodic).
    alpha : float, default 2.0
        Aspect ratio, >= 1.
    spread : float, default 0.6
        Width of the uniform orientation distribution in radians, in [0, pi].
    seed : int, default 0
        Seed of the orientations.

    Returns
    -------
    Packing
        The periodic packing of ellipses (no overlaps: each ellipse lies inside its disk).
    """
    if int(nx) < 2 or int(ny) < 2 or int(ny) % 2:
        raise InvalidInputError(f"need nx >= 2 and an even ny >= 2 for a periodic triangular lattice, got {nx}, {ny}")
    if not (np.isfinite(alpha) and alpha >= 1.0):
        raise InvalidInputError(f"alpha must be >= 1, got {alpha}")
    if not 0.0 <= spread <= np.pi:
        raise InvalidInputError(f"spread must be in [0, pi], got {spread}")
    from hardpack.geometry.shapes import Ellipsoids

    nx, ny = int(nx), int(ny)
    row = np.sqrt(3.0) / 2.0
    pos = np.array([[i + 0.5 * (j % 2), j * row] for j in range(ny) for i in range(nx)]) + 0.25
    rng = np.random.default_rng(seed)
    axes = np.tile([0.49, 0.49 / alpha], (nx * ny, 1))
    angles = rng.uniform(-spread / 2.0, spread / 2.0, nx * ny)
    return Packing(pos, lattice=np.diag([float(nx), ny * row]), shape=Ellipsoids(axes, angles))
