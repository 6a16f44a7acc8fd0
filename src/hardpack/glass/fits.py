"""Fits of the estimated jamming density phi~_J(phi) = phi / (1 - d/Z) of compressed binary disks
(Donev 2006, sec. 13.3; Donev, Stillinger & Torquato 2006).

- Liquid-branch extension, Eq. 13.3: phi~_J(phi) = c0 + c1 phi + c2 phi^2 + c3 phi^3, fitted to the
  slowest compressions below the kinetic glass transition; published c = (3.136, -8.4826, 10.277,
  -4.0356) (:data:`PUBLISHED_CUBIC`), "just a fit", not meant beyond phi ~ 0.8.
- Glassy branch, Eq. 13.4: phi~_J(phi) = (1 + alpha) phi_J - alpha phi above phi_g ~ 0.8, with
  alpha ~ 0.133 (:data:`PUBLISHED_ALPHA`); equivalently the pressure p = d / (1 - phi / phi~_J).

Both are weighted linear least squares in phi (weights 1/err^2 of phi~_J, propagated from the
errors of Z). The covariance is (A^T W A)^-1 scaled by max(1, chi^2 / dof) (errors that
understate the scatter widen the coefficient errors; errors that overstate it are kept).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.errors import InvalidInputError

#: Donev 2006, Eq. 13.3 (c0, c1, c2, c3)
PUBLISHED_CUBIC = (3.136, -8.4826, 10.277, -4.0356)
#: Donev 2006, Eq. 13.4
PUBLISHED_ALPHA = 0.133


def estimated_jamming_density(phi, z, z_err=None, d: int = 2):
    """phi~_J = phi / (1 - d/Z) (Donev 2006, Eq. 1.2, the free-volume EOS inverted) and its error
    |d phi~_J / dZ| z_err = phi d / (Z - d)^2 z_err. Z <= d gives NaN (no finite estimate).

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    z : array_like of float
        Reduced pressures Z = pV/(NkT), same shape.
    z_err : array_like of float, optional
        Standard errors of Z (default 0).
    d : int, optional
        Dimension.

    Returns
    -------
    estimate : numpy.ndarray of float
        phi~_J.
    error : numpy.ndarray of float
        Its standard error.
    """
    phi, z = np.asarray(phi, float), np.asarray(z, float)
    z_err = np.zeros_like(z) if z_err is None else np.asarray(z_err, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        ok = z > d
        est = np.where(ok, phi / (1.0 - d / z), np.nan)
        err = np.where(ok, phi * d / (z - d) ** 2 * z_err, np.nan)
    return est, err


def cubic_phij(phi, coefficients=PUBLISHED_CUBIC):
    """Eq. 13.3 evaluated at ``phi`` (default: the published coefficients).

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    coefficients : sequence of 4 float, optional
        c0..c3, lowest power first.

    Returns
    -------
    numpy.ndarray of float
        phi~_J(phi).
    """
    c = np.asarray(coefficients, float)
    phi = np.asarray(phi, float)
    return c[0] + c[1] * phi + c[2] * phi**2 + c[3] * phi**3


def glass_phij(phi, phi_j, alpha=PUBLISHED_ALPHA):
    """Eq. 13.4: phi~_J = (1 + alpha) phi_J - alpha phi.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    phi_j : float
        Jamming density phi_J of the glass.
    alpha : float, optional
        Slope parameter.

    Returns
    -------
    numpy.ndarray of float
        phi~_J(phi).
    """
    return (1.0 + alpha) * phi_j - alpha * np.asarray(phi, float)


def pressure_from_phij(phi, phij, d: int = 2):
    """Z = d / (1 - phi / phi~_J), the free-volume form behind both fits.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    phij : array_like of float
        Estimated jamming densities phi~_J.
    d : int, optional
        Dimension.

    Returns
    -------
    numpy.ndarray of float
        Z.
    """
    phi = np.asarray(phi, float)
    return d / (1.0 - phi / np.asarray(phij, float))


@dataclass(frozen=True)
class LinearFit:
    """Weighted least-squares coefficients (lowest power first) with their covariance.

    Attributes
    ----------
    coefficients : numpy.ndarray of float, shape (degree + 1,)
        Coefficients, lowest power first.
    covariance : numpy.ndarray of float, shape (degree + 1, degree + 1)
        Their covariance (module docstring).
    chi2 : float
        Weighted sum of squared residuals.
    dof : int
        Points less coefficients.
    """

    coefficients: np.ndarray
    covariance: np.ndarray
    chi2: float
    dof: int

    @property
    def errors(self) -> np.ndarray:
        """Standard errors of the coefficients."""
        return np.sqrt(np.diag(self.covariance))

    def __call__(self, x):
        return np.polynomial.polynomial.polyval(np.asarray(x, float), self.coefficients)


def weighted_polyfit(x, y, y_err, degree: int) -> LinearFit:
    """Weighted least-squares polynomial of ``degree`` (module docstring for the covariance).

    Parameters
    ----------
    x, y : array_like
        Points (finite entries only are used).
    y_err : array_like or None
        Standard errors of y; None or non-positive entries give unit weights to all points.
    degree : int
        Polynomial degree (>= 0); needs more points than coefficients.

    Returns
    -------
    LinearFit
        The fit.

    Raises
    ------
    InvalidInputError
        With too few finite points.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    err = np.ones_like(y) if y_err is None else np.asarray(y_err, float)
    keep = np.isfinite(x) & np.isfinite(y) & np.isfinite(err)
    x, y, err = x[keep], y[keep], err[keep]
    if not np.all(err > 0):
        err = np.ones_like(y)
    n_coef = degree + 1
    if x.size <= n_coef:
        raise InvalidInputError(f"a degree-{degree} fit needs more than {n_coef} points, got {x.size}")
    design = np.vander(x, n_coef, increasing=True) / err[:, None]
    rhs = y / err
    coef, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    resid = rhs - design @ coef
    chi2 = float(resid @ resid)
    dof = x.size - n_coef
    cov = np.linalg.inv(design.T @ design) * max(1.0, chi2 / dof)
    return LinearFit(coef, cov, chi2, dof)


def equilibrium_limit(phi, slow, slow_err, faster, faster_err, phi_max: float) -> float:
    """The density up to which slowing a compression down does not change its pressure (Donev
    2006, sec. 13.3.1: Eq. 13.3 is fitted to the slowest runs "up to the density where slowing
    down the compression by an order of magnitude does not change the observed pressure (within
    statistical variability)").

    The binned phi~_J of the slowest compression and of the next faster one count as different
    in a bin when they differ by more than twice their combined standard error (the convention
    of the validation rows); the limit is the last bin below the first one from which they
    differ in every bin up to ``phi_max`` (a single differing bin followed by agreeing ones is
    noise of the bins' errors, which a few seeds estimate poorly). Bins where either is missing
    are skipped.

    Parameters
    ----------
    phi : array_like of float
        Bin centres, increasing.
    slow, slow_err : array_like of float
        phi~_J of the slowest compression and its standard errors.
    faster, faster_err : array_like of float
        The same for the compression an order of magnitude faster.
    phi_max : float
        Largest density considered.

    Returns
    -------
    float
        The limit (``phi_max`` when they never separate for good).
    """
    phi = np.asarray(phi, float)
    a, ae, b, be = (np.asarray(v, float) for v in (slow, slow_err, faster, faster_err))
    keep = (phi <= phi_max) & np.isfinite(a) & np.isfinite(b)
    phi, a, ae, b, be = phi[keep], a[keep], ae[keep], b[keep], be[keep]
    err = np.hypot(np.nan_to_num(ae), np.nan_to_num(be))
    apart = np.abs(a - b) > 2.0 * err
    limit = phi_max
    for k in range(phi.size - 1, -1, -1):  # walk down while they stay apart
        if not apart[k]:
            break
        limit = float(phi[k - 1]) if k > 0 else -np.inf
    return limit


def fit_liquid_cubic(phi, phij, phij_err=None, phi_max: float = 0.8) -> LinearFit:
    """Eq. 13.3: the cubic phi~_J(phi) fitted to the points with phi <= ``phi_max``.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    phij : array_like of float
        Estimated jamming densities phi~_J.
    phij_err : array_like of float, optional
        Their standard errors.
    phi_max : float, optional
        Largest phi fitted.

    Returns
    -------
    LinearFit
        The cubic.
    """
    phi = np.asarray(phi, float)
    sel = phi <= phi_max
    err = None if phij_err is None else np.asarray(phij_err, float)[sel]
    return weighted_polyfit(phi[sel], np.asarray(phij, float)[sel], err, 3)


@dataclass(frozen=True)
class GlassFit:
    """Eq. 13.4 fitted: alpha and phi_J with standard errors and their correlation.

    Attributes
    ----------
    alpha : float
        Slope parameter alpha.
    alpha_err : float
        Its standard error.
    phi_j : float
        Jamming density phi_J.
    phi_j_err : float
        Its standard error.
    line : LinearFit
        The fitted line phi~_J = a + b phi.
    """

    alpha: float
    alpha_err: float
    phi_j: float
    phi_j_err: float
    line: LinearFit


def fit_glass_branch(phi, phij, phij_err=None, phi_min: float = 0.8) -> GlassFit:
    """Eq. 13.4 fitted to the points with phi >= ``phi_min``: the line phi~_J = a + b phi gives
    alpha = -b and phi_J = a / (1 + alpha), errors by first-order propagation of the line's
    covariance (d phi_J / da = 1/(1+alpha), d phi_J / db = a/(1+alpha)^2).

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    phij : array_like of float
        Estimated jamming densities phi~_J.
    phij_err : array_like of float, optional
        Their standard errors.
    phi_min : float, optional
        Smallest phi fitted.

    Returns
    -------
    GlassFit
        The fit.

    Raises
    ------
    InvalidInputError
        If the slope is >= 1.
    """
    phi = np.asarray(phi, float)
    sel = phi >= phi_min
    err = None if phij_err is None else np.asarray(phij_err, float)[sel]
    line = weighted_polyfit(phi[sel], np.asarray(phij, float)[sel], err, 1)
    a, b = line.coefficients
    alpha = -b
    if not 1.0 + alpha > 0:
        raise InvalidInputError(f"the glass branch has slope {b:.3g} >= 1: no phi_J (not a glass branch)")
    grad = np.array([1.0 / (1.0 + alpha), a / (1.0 + alpha) ** 2])
    phi_j = a / (1.0 + alpha)
    return GlassFit(alpha, float(np.sqrt(line.covariance[1, 1])), phi_j,
                    float(np.sqrt(grad @ line.covariance @ grad)), line)
