"""Jamming density phi_J from compressibility data Z(phi) near jamming (Ogarko 2014, sec. 3.1.3).

Near jamming the pressure follows the free-volume law Z = d/(1 - phi/phi_J) (Eq. 3.14), so every
point gives a running estimate phi_J^est = phi/(1 - d/Z) (:func:`hardpack.eos.theory.phij_estimate`,
Ogarko 2014, Eq. 3.14). Where the free-volume law holds these estimates are constant; :func:`fit_free_volume`
takes their weighted mean over the last decades of Z (a one-parameter weighted least-squares fit of
the linearised law) and tests for the plateau with a weighted linear trend in ln Z. A fluid EOS such
as BMCSL gives a drifting estimate (no plateau) and is flagged.

Error model: each Z_i has standard error sigma_Z,i (given), or, by default, a common *relative*
error (windowed virial pressures), whose size is then estimated from the scatter (reduced chi^2),
as in scipy.optimize.curve_fit with absolute_sigma=False. By the delta method the estimate from
point i has error phi_i d sigma_Z,i/(Z_i - d)^2, so the highest pressures dominate.

Caveat (Ogarko 2014, sec. 3.1.3 and Fig. 3.8): the law holds for phi_J - phi <~ 1e-8, i.e. Z >~ 3e8;
fits at moderate Z are biased high, which the plateau test detects when the data are precise enough.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hardpack.eos.theory import phij_estimate
from hardpack.errors import InvalidInputError

#: a drift below this multiple of its standard error counts as a plateau
PLATEAU_SIGMAS = 3.0


@dataclass(frozen=True)
class FreeVolumeFit:
    """Result of :func:`fit_free_volume`.

    Attributes
    ----------
    phi_j, stderr : float
        Fitted jamming density and its standard error.
    phi_range, z_range : tuple of (float, float)
        Ranges of phi and Z of the points used.
    n_points : int
        Number of points used.
    chi2_red : float
        Reduced chi^2 of the constant model (about 1 if sigma_z was right).
    drift, drift_err : float
        Change of the linear trend of phi_J^est(ln Z) across the fit range, and its error.
    """

    phi_j: float
    stderr: float
    phi_range: tuple[float, float]
    z_range: tuple[float, float]
    n_points: int
    chi2_red: float
    drift: float
    drift_err: float

    @property
    def plateau(self) -> bool:
        """True if the running estimate is constant within PLATEAU_SIGMAS errors over the fit range."""
        floor = 16 * np.finfo(float).eps * self.phi_j  # exact data: drift and its error are round-off
        return abs(self.drift) <= max(PLATEAU_SIGMAS * self.drift_err, floor)


def _weighted_line(t, y, w, absolute):
    """Weighted least squares y = a + b t; returns b and its standard error."""
    design = np.column_stack([np.ones_like(t), t]) * np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(design, y * np.sqrt(w), rcond=None)
    cov = np.linalg.inv(design.T @ design)
    if not absolute:
        resid = (y - coef[0] - coef[1] * t) * np.sqrt(w)
        cov = cov * (resid @ resid) / (len(t) - 2)
    return coef[1], np.sqrt(cov[1, 1])


def fit_free_volume(phi, Z, d: int = 3, decades: float = 2.0, z_min: float | None = None, sigma_z=None):
    """Fit phi_J of Z = d/(1 - phi/phi_J) (Eq. 3.14) to the points with Z >= max(Z)/10^decades.

    phi, Z: 1-d arrays of equal length (one compression run; any order); d: dimension;
    z_min: additional lower bound on Z; sigma_z: standard errors of Z (scalar or per point; default:
    equal relative errors, scaled by the scatter). Needs at least 3 points with Z > d in range.
    Returns a :class:`FreeVolumeFit`.

    Parameters
    ----------
    phi : array_like of float, shape (n,)
        Volume fractions of one compression run.
    Z : array_like of float, shape (n,)
        Reduced pressures Z = pV/(NkT).
    d : int, optional
        Dimension.
    decades : float, optional
        Decades of Z below its maximum that are fitted.
    z_min : float, optional
        Additional lower bound on Z.
    sigma_z : float or array_like of float, optional
        Standard errors of Z.

    Returns
    -------
    FreeVolumeFit
        The fit.

    Raises
    ------
    InvalidInputError
        For bad arrays or fewer than 3 usable points.
    """
    x, z = np.asarray(phi, dtype=float), np.asarray(Z, dtype=float)
    if x.ndim != 1 or x.shape != z.shape:
        raise InvalidInputError(f"phi and Z must be 1-d arrays of equal length, got {x.shape} and {z.shape}")
    if not (np.isfinite(x).all() and np.isfinite(z).all()):
        raise InvalidInputError("phi and Z must be finite; drop NaN windows before fitting")
    if not (decades > 0):
        raise InvalidInputError(f"decades must be positive, got {decades}")
    absolute = sigma_z is not None
    sz = np.broadcast_to(np.asarray(sigma_z if absolute else z, dtype=float), z.shape)
    if absolute and not (np.isfinite(sz).all() and (sz > 0).all()):
        raise InvalidInputError("sigma_z must be positive and finite")
    lower = max(z.max() / 10.0**decades, d if z_min is None else max(z_min, d))
    sel = (z >= lower) & (z > d)
    if sel.sum() < 3:
        raise InvalidInputError(
            f"only {sel.sum()} points with Z >= {lower:.3g} (and Z > d = {d}); need at least 3. "
            "Compress further or widen `decades`."
        )
    x, z, sz = x[sel], z[sel], sz[sel]
    est = phij_estimate(x, z, d)
    w = ((z - d) ** 2 / (x * d * sz)) ** 2
    phi_j = float(np.sum(w * est) / np.sum(w))
    chi2_red = float(np.sum(w * (est - phi_j) ** 2) / (len(est) - 1))
    stderr = float(np.sqrt((1.0 if absolute else chi2_red) / np.sum(w)))
    t = np.log(z)
    if np.ptp(t) == 0:
        raise InvalidInputError("all selected Z values are equal; the free-volume law cannot be tested")
    slope, slope_err = _weighted_line(t - t.mean(), est, w, absolute)
    span = t.max() - t.min()
    return FreeVolumeFit(
        phi_j=phi_j,
        stderr=stderr,
        phi_range=(float(x.min()), float(x.max())),
        z_range=(float(z.min()), float(z.max())),
        n_points=len(x),
        chi2_red=chi2_red,
        drift=float(slope * span),
        drift_err=float(slope_err * span),
    )
