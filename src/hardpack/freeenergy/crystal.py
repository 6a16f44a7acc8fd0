"""Reference curves for the free energy of the FCC hard-sphere crystal vs density.

Units: the sphere diameter D = 1, kT = 1, per particle. phi_cp = pi / sqrt(18) is close packing.
Two published numbers anchor the curves (Donev 2006, dissertation sec. 6.4.1): the excess free
energy over the ideal gas at melting, 5.91916 at phi = 0.545, and the jamming-limit constant
[f_J - f_c^J]_FCC = 2.160.

- BCMD's quantity. A run from large cells down to the disjoint-cell point Delta mu_d(phi) =
  (phi_cp / phi)^(1/3) - 1 of lattice-centred cells measures Delta f = f_c(Delta mu_d) - f, with
  f_c = -3 ln Delta mu_d - ln(pi/6) (Eq. 6.10) and f_ideal = -ln(pi / (6 phi)) - 1 (Eq. 6.15), so
  excess = f - f_ideal = c(phi) - Delta f with c(phi) = f_c - f_ideal = 1 - ln phi - 3 ln
  Delta mu_d (:func:`cell_offset`). At close packing Delta f -> f_J - f_c^J (Eq. 6.18).
- Cell (free-volume) limit: Delta f = 2.160 for all phi, i.e. excess = c(phi) - 2.160, exact to
  first order in Delta mu_d (:func:`cell_limit_excess`; e.g. -3 ln(1 - phi/phi_cp) + 2.436 as
  phi -> phi_cp, derived here).
- Thermodynamic integration of the crystal's equation of state Z(phi) = pV/(NkT) from the
  melting value (:func:`eos_excess`): excess(phi) = excess(phi_0) + int_{phi_0}^{phi} (Z - 1)
  dphi'/phi'. The free-volume part Z_fv = 1 / (1 - x), x = (phi/phi_cp)^(1/3) (the cell model's
  exact pressure, = 3 / (1 - phi/phi_cp) to leading order, Salsburg-Wood), integrates to
  -3 ln(1 - x) exactly; the smooth rest (Z - Z_fv)/phi is integrated by a cubic spline through
  the measured points.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from hardpack.errors import InvalidInputError

PHI_CP = np.pi / np.sqrt(18.0)
MELTING_PHI = 0.545
MELTING_EXCESS = 5.91916  # Donev 2006, sec. 6.4.1
JAMMING_CONSTANT = 2.160  # Donev 2006, sec. 6.4.1


def disjoint_dmu(phi):
    """Disjoint-cell point of lattice-centred FCC cells, (phi_cp / phi)^(1/3) - 1.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.

    Returns
    -------
    numpy.ndarray of float
        Delta mu_d(phi).
    """
    return (PHI_CP / np.asarray(phi, float)) ** (1.0 / 3.0) - 1.0


def distance_to_jamming(phi):
    """delta = (phi_cp / phi)^(1/3) - 1: the relative growth of the diameters that jams FCC at
    density phi (the crystal's free energy behaves as -3 ln delta - f_J as delta -> 0).

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.

    Returns
    -------
    numpy.ndarray of float
        delta(phi).
    """
    return (PHI_CP / np.asarray(phi, float)) ** (1.0 / 3.0) - 1.0


def cell_offset(phi):
    """c(phi) = f_c(Delta mu_d) - f_ideal = 1 - ln phi - 3 ln Delta mu_d(phi): excess = c - Delta f.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.

    Returns
    -------
    numpy.ndarray of float
        c(phi), per particle in units of kT.
    """
    phi = np.asarray(phi, float)
    return 1.0 - np.log(phi) - 3.0 * np.log(disjoint_dmu(phi))


def cell_limit_excess(phi, constant=JAMMING_CONSTANT):
    """Excess free energy of the cell limit, c(phi) - [f_J - f_c^J].

    Parameters
    ----------
    phi : array_like of float
        Volume fractions.
    constant : float, optional
        f_J - f_c^J (Donev 2006, sec. 6.4.1: 2.160 for FCC).

    Returns
    -------
    numpy.ndarray of float
        Excess free energy per particle, units of kT.
    """
    return cell_offset(phi) - constant


def free_volume_z(phi):
    """Z_fv = 1 / (1 - (phi/phi_cp)^(1/3)), the cell model's pressure.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions, below phi_cp.

    Returns
    -------
    numpy.ndarray of float
        Z_fv.
    """
    return 1.0 / (1.0 - (np.asarray(phi, float) / PHI_CP) ** (1.0 / 3.0))


def eos_excess(phi, z, phi0=MELTING_PHI, excess0=MELTING_EXCESS, at=None):
    """Excess free energy by integrating the measured Z(phi) from phi0 (the smallest of the
    measured densities) with excess(phi0) = excess0 (module docstring); evaluated at the measured
    densities, or at ``at`` (within their range).

    Parameters
    ----------
    phi : array_like of float, shape (k,)
        Distinct measured volume fractions (k >= 3), the smallest equal to ``phi0``.
    z : array_like of float, shape (k,)
        Reduced pressures Z = pV/(NkT) at them.
    phi0 : float, optional
        Start of the integration.
    excess0 : float, optional
        Excess free energy per particle at phi0 (units of kT).
    at : array_like of float, optional
        Where to evaluate (default: the measured densities, in their order).

    Returns
    -------
    numpy.ndarray of float
        Excess free energy per particle, units of kT.

    Raises
    ------
    InvalidInputError
        For fewer than 3 densities, none at phi0, densities at or above close packing or ``at``
        outside the measured range.
    """
    phi = np.asarray(phi, float)
    z = np.asarray(z, float)
    order = np.argsort(phi)
    phi, z = phi[order], z[order]
    if phi.size < 3 or not np.isclose(phi[0], phi0) or np.any(np.diff(phi) <= 0):
        raise InvalidInputError(
            f"need >= 3 distinct densities starting at phi0 = {phi0} (got {phi.tolist()})"
        )
    if np.any(phi >= PHI_CP):
        raise InvalidInputError("densities must be below close packing")
    rest = CubicSpline(phi, (z - free_volume_z(phi)) / phi)
    if at is None:
        x_at = phi[np.argsort(order)]
    else:
        x_at = np.asarray(at, float)
        if np.any(x_at < phi[0] - 1e-12) or np.any(x_at > phi[-1] + 1e-12):
            raise InvalidInputError("evaluation densities must lie within the measured range")
    x, x0 = (x_at / PHI_CP) ** (1 / 3), (phi0 / PHI_CP) ** (1 / 3)
    fv = -3.0 * np.log((1.0 - x) / (1.0 - x0))
    return excess0 + fv + np.array([rest.integrate(phi0, p) for p in np.atleast_1d(x_at)]).reshape(fv.shape)
