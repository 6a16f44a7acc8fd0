"""One linear program of the Torquato-Jiao sequential-LP packing algorithm (PRE 82, 061302, 2010).

Variables (all continuous, box-bounded by the trust region):

- global displacements u_n = M dx_n of every sphere (N x d; the paper uses lattice-coordinate
  displacements dx_n, Eq. 19; the global form is the same LP in better-conditioned variables,
  our choice); u_0 = 0 removes the free global translation;
- the symmetric strain eps of the cell, M -> (I + eps) M (Eqs. 8-10): d(d+1)/2 entries for a
  deforming cell, or one scalar e (eps = e I) for an isotropically shrinking cell.

Objective (Eq. 18): minimise tr(eps) (the relative volume change to first order).

Constraints (Eq. 19 with R = 0): for every pair (m, n, image k) with centre distance below the
influence radius gamma_mn = alpha D_mn, r = x_n + M k - x_m the current separation and
delta = u_n - u_m,

    r^T eps r + delta . r >= (D_mn^2 - r . r) / 2,

the first-order expansion of |(I + eps)(r + delta)|^2 >= D_mn^2 (exact remainder derived
here; signs derived and tested here). Self-images (m = n, k != 0) constrain the
strain alone, which is the lattice (N = 1) problem.

Redundant pairs (our addition, exact): with |eps_ab| bounded, ||eps||_2 <= e_max = min(strain +
(d - 1) shear, sqrt(d strain^2 + d (d - 1) shear^2)) (Gershgorin / Frobenius), and with |u_n,a| <= t,
|delta| <= delta_max = 2 sqrt(d) t. The left side is then >= -(e_max r^2 + delta_max r), so the row
of a pair with (1/2 - e_max) r^2 - delta_max r - D_mn^2 / 2 >= 0, i.e. r >= r_safe(D_mn) =
(delta_max + sqrt(delta_max^2 + (1 - 2 e_max) D_mn^2)) / (1 - 2 e_max), can never bind inside the
trust region. Leaving those rows out does not change the LP's feasible set or optimal value (the
solver may pick another point of the degenerate optimal face); it only shortens the LP. With the
Table II bounds (0.01 / 0.01 / 0.05 D) r_safe is 1.2-1.4 D in d = 2..6, so for the LP an
influence radius gamma = 3.5 D is the same as gamma = r_safe: beyond r_safe the influence sphere
is irrelevant (an observation of our prototype, here as a bound). With d = 6, N = 729 this is
~60 thousand rows instead of ~16 million (at phi = 0.37). With the Table I
bounds (0.1 / 0.1 / 0.5 D) r_safe ~ 9 D and gamma = 1.5 D does drop binding pairs.

Solver: HiGHS interior point with crossover (``method="highs-ipm"``) by default. The LP's
displacements do not enter the objective, so its optimal face is huge and degenerate; the dual
simplex needs thousands of pivots on it (3000 for N = 250 in 3D, ~3x slower than the interior
point there), and the interior point also gave fewer rejected steps in our runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from hardpack.errors import InvalidInputError
from hardpack.geometry.neighbours import pairs_within


@dataclass(frozen=True)
class Bounds:
    """Trust-region widths: |eps_aa| <= strain, |eps_ab| <= shear (a != b), |u_n,a| <= displacement * <D>.

    Parameters
    ----------
    strain : float
        Bound on the diagonal strain entries (on e for an isotropically shrinking cell); > 0.
    shear : float
        Bound on the off-diagonal strain entries; >= 0.
    displacement : float
        Bound on each displacement component, in units of the mean diameter <D>; >= 0.

    Raises
    ------
    InvalidInputError
        If a bound is negative or not finite, or the strain bound is 0 (the cell could not shrink).
    """

    strain: float
    shear: float
    displacement: float

    def __post_init__(self):
        for name in ("strain", "shear", "displacement"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise InvalidInputError(f"bound {name} must be a finite non-negative number, got {value}")
        if self.strain <= 0:
            raise InvalidInputError("the strain bound must be positive, otherwise the cell cannot shrink")

    def scaled(self, s: float) -> "Bounds":
        """The bounds multiplied by ``s``.

        Parameters
        ----------
        s : float
            Factor, > 0.

        Returns
        -------
        Bounds
            strain, shear and displacement times s.

        Raises
        ------
        InvalidInputError
            If the scaled bounds are invalid (s <= 0 or not finite).
        """
        return Bounds(self.strain * s, self.shear * s, self.displacement * s)


@dataclass(frozen=True)
class StepSolution:
    """Optimal step: strain (d x d), displacements (N x d), predicted tr(eps), pair count, LP time.

    Attributes
    ----------
    strain : numpy.ndarray of float, shape (d, d)
        Symmetric strain eps of the cell.
    displacement : numpy.ndarray of float, shape (N, d)
        Displacements of the spheres.
    trace : float
        tr(eps), the predicted relative volume change.
    n_constraints : int
        Pair rows of the LP.
    lp_seconds : float
        Time of the LP solve.
    duals : numpy.ndarray of float, shape (n_constraints,)
        Duals of the pair rows (>= 0).
    pairs : PairList
        The pairs behind the rows.
    """

    strain: np.ndarray
    displacement: np.ndarray
    trace: float
    n_constraints: int
    lp_seconds: float
    duals: np.ndarray
    pairs: object


def strain_index(d: int, deforming: bool):
    """(rows, cols) of the independent strain entries: upper triangle, or the single isotropic one.

    Parameters
    ----------
    d : int
        Dimension.
    deforming : bool
        Whether the cell deforms (else it shrinks isotropically).

    Returns
    -------
    rows, cols : numpy.ndarray of int
        Index arrays of the strain variables.
    """
    if not deforming:
        return np.array([0]), np.array([0])
    return np.triu_indices(d)


def redundancy_radius(bounds: Bounds, d: int, mean_diameter: float, contact: np.ndarray | float,
                      deforming: bool = True) -> np.ndarray | float:
    """r_safe(D_mn) beyond which a pair's row cannot bind inside the trust region (module docstring).

    Returns inf when the strain bound is too large (e_max >= 1/2) for the estimate to hold.

    Parameters
    ----------
    bounds : Bounds
        Trust-region widths.
    d : int
        Dimension.
    mean_diameter : float
        Mean diameter <D>.
    contact : float or numpy.ndarray of float
        Contact distances D_mn.
    deforming : bool, optional
        Whether the cell deforms.

    Returns
    -------
    float or numpy.ndarray of float
        r_safe for every contact distance.
    """
    if deforming:
        e_max = min(bounds.strain + (d - 1) * bounds.shear,
                    np.sqrt(d * bounds.strain**2 + d * (d - 1) * bounds.shear**2))
    else:
        e_max = bounds.strain
    if e_max >= 0.5:
        return np.full_like(np.asarray(contact, float), np.inf)
    delta_max = 2.0 * np.sqrt(d) * bounds.displacement * mean_diameter
    return (delta_max + np.sqrt(delta_max**2 + (1 - 2 * e_max) * np.asarray(contact, float) ** 2)) / (1 - 2 * e_max)


def influence_pairs(packing, alpha: float, bounds: Bounds, deforming: bool = True):
    """Pairs (all images) with centre distance < alpha D_mn whose row can bind (``redundancy_radius``).

    Parameters
    ----------
    packing : Packing
        A periodic sphere packing.
    alpha : float
        Influence radius over the contact distance.
    bounds : Bounds
        Trust-region widths.
    deforming : bool, optional
        Whether the cell deforms.

    Returns
    -------
    PairList
        The pairs.

    Raises
    ------
    InvalidInputError
        Unless the packing holds spheres in a periodic cell.
    """
    packing.require_periodic_spheres("SLP")
    d = packing.dim
    mean_diameter = 2.0 * packing.radii.mean()
    d_max = 2.0 * packing.radii.max()
    cutoff = min(alpha * d_max, float(redundancy_radius(bounds, d, mean_diameter, d_max, deforming)))
    pairs = pairs_within(packing, cutoff=cutoff)
    limit = np.minimum(alpha * pairs.contact, redundancy_radius(bounds, d, mean_diameter, pairs.contact, deforming))
    keep = pairs.distance < limit
    if keep.all():
        return pairs
    return pairs.subset(keep)


METHODS = ("highs-ipm", "highs-ds", "highs")


def solve_step(packing, alpha: float, bounds: Bounds, deforming: bool = True,
               feasibility_tol: float = 1e-10, method: str = "highs-ipm") -> StepSolution:
    """Build and solve one SLP linear program for ``packing`` (see the module docstring).

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell (the start configuration of the step).
    alpha : float
        Influence-sphere factor gamma_mn / D_mn, >= 1: pairs closer than alpha D_mn get a row,
        unless the row cannot bind inside the trust region (:func:`redundancy_radius`).
    bounds : Bounds
        The trust region.
    deforming : bool, default True
        Symmetric strain of a deforming cell; if False, one isotropic strain eps = e I.
    feasibility_tol : float, default 1e-10
        Primal and dual feasibility tolerance of HiGHS.
    method : {"highs-ipm", "highs-ds", "highs"}, default "highs-ipm"
        The scipy ``linprog`` method.

    Returns
    -------
    StepSolution
        The optimal strain (d x d) and displacements (N x d), the predicted tr(eps), the number
        of rows, the LP time, the duals of the rows and the pairs behind them.

    Raises
    ------
    InvalidInputError
        If alpha is not finite or below 1, method is not one of the above, the packing is not hard
        spheres in a periodic cell, or the linear program fails (e.g. an overlapping start
        configuration or degenerate bounds).
    """
    if not (np.isfinite(alpha) and alpha >= 1):
        raise InvalidInputError(f"influence-sphere factor alpha = gamma / D must be >= 1, got {alpha}")
    if method not in METHODS:
        raise InvalidInputError(f"LP method must be one of {METHODS}, got {method!r}")
    n, d = packing.n_particles, packing.dim
    pairs = influence_pairs(packing, alpha, bounds, deforming)
    rows_a, cols_a = strain_index(d, deforming)
    n_strain = len(rows_a)
    m = len(pairs)
    r = pairs.separation
    # strain coefficients: r^T eps r = sum_a eps_aa r_a^2 + sum_{a<b} 2 eps_ab r_a r_b
    if deforming:
        factor = np.where(rows_a == cols_a, 1.0, 2.0)
        strain_coef = r[:, rows_a] * r[:, cols_a] * factor
    else:
        strain_coef = np.einsum("ij,ij->i", r, r)[:, None]
    # displacement coefficients: +r for u_n (j), -r for u_m (i); self-images cancel
    ii, jj = pairs.i, pairs.j
    row_idx = np.repeat(np.arange(m), d)
    disp_cols_j = (n_strain + jj[:, None] * d + np.arange(d)).ravel()
    disp_cols_i = (n_strain + ii[:, None] * d + np.arange(d)).ravel()
    not_self = np.repeat(ii != jj, d)
    data = np.concatenate([
        -strain_coef.ravel(),
        -r.ravel()[not_self],
        r.ravel()[not_self],
    ])
    rows = np.concatenate([np.repeat(np.arange(m), n_strain), row_idx[not_self], row_idx[not_self]])
    cols = np.concatenate([np.tile(np.arange(n_strain), m), disp_cols_j[not_self], disp_cols_i[not_self]])
    a_ub = sp.csr_matrix((data, (rows, cols)), shape=(m, n_strain + n * d))
    b_ub = 0.5 * (np.einsum("ij,ij->i", r, r) - pairs.contact**2)

    c = np.zeros(n_strain + n * d)
    if deforming:
        c[:n_strain] = (rows_a == cols_a).astype(float)
    else:
        c[0] = d
    mean_diameter = 2.0 * packing.radii.mean()
    lower = np.empty_like(c)
    upper = np.empty_like(c)
    if deforming:
        diag = rows_a == cols_a
        upper[:n_strain] = np.where(diag, bounds.strain, bounds.shear)
    else:
        upper[:n_strain] = bounds.strain
    upper[n_strain:] = bounds.displacement * mean_diameter
    upper[n_strain:n_strain + d] = 0.0  # pin sphere 0: no free global translation
    lower[:] = -upper
    start = time.perf_counter()
    res = linprog(c, A_ub=a_ub, b_ub=b_ub, bounds=np.column_stack([lower, upper]), method=method,
                  options={"primal_feasibility_tolerance": feasibility_tol,
                           "dual_feasibility_tolerance": feasibility_tol})
    elapsed = time.perf_counter() - start
    if res.status != 0:
        raise InvalidInputError(
            f"the SLP linear program failed ({res.message}); the start configuration may overlap "
            "or the bounds may be degenerate"
        )
    x = res.x
    eps = np.zeros((d, d))
    if deforming:
        eps[rows_a, cols_a] = x[:n_strain]
        eps[cols_a, rows_a] = x[:n_strain]
    else:
        eps = x[0] * np.eye(d)
    return StepSolution(
        strain=eps, displacement=x[n_strain:].reshape(n, d), trace=float(np.trace(eps)),
        n_constraints=m, lp_seconds=elapsed, duals=-res.ineqlin.marginals, pairs=pairs,
    )
