"""Thermodynamics of hard-disk fluids and glasses from their equation of state (kT = 1, free
energies per particle).

- Excess free energy over the ideal gas by integrating the EOS from the ideal-gas limit,
  Delta f(phi) = int_0^phi (Z(phi') - 1) / phi' dphi' (Donev 2006, sec. 13.3; Donev et al. 2007,
  Eq. 12 context), for a tabulated EOS (:func:`excess_free_energy`, with the exact propagation of
  the errors of Z) and for an EOS given as a function (:func:`integrate_eos`).
- The low-density end: (Z - 1) / phi -> 2^(d-1) (1 + <D>^2 / <D^2>) / 2 for additive disks
  (:func:`second_virial_slope`; the second virial coefficient, derived here), so the integrand is
  known at phi = 0 and tables need not start at phi = 0.
- Configurational entropy s_c = s_L - s_g (Donev 2006, Eq. 13.5) and the mixing entropy
  s_mix = -x ln x - (1 - x) ln(1 - x) (Donev 2006, sec. 13.4: printed as
  "x_A ln x_A + x_B ln x_B ~ 0.6365", without the minus sign; for x = 1/3 it is 0.63651).

Conventions of the excess (both relative to the ideal gas of *distinguishable* particles,
f_ideal = ln(rho) - 1 in the same length unit): the liquid's excess Delta f_L is the EOS integral
above; the SOC glass's excess is the BCMD ``excess`` (:func:`hardpack.freeenergy.run_bcmd`).
The liquid's full free energy has the extra -s_mix of identical particles within each species,
f_L = f_ideal - s_mix + Delta f_L, while the glass's cells label every particle,
f_g = f_ideal + Delta f_g. Hence (derived here)

    s_c - s_mix = (f_g - f_L) - s_mix = Delta f_g - Delta f_L,

the quantity of Donev 2006, Fig. 13.12 (s_mix = 0 for a monodisperse system).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

from hardpack.errors import InvalidInputError


def mixing_entropy(x) -> float:
    """Ideal mixing entropy per particle of a binary mixture with number fraction ``x`` of one
    species: -x ln x - (1 - x) ln(1 - x) (Donev 2006, sec. 13.4; 0.63651 at x = 1/3).

    Parameters
    ----------
    x : float
        Number fraction in [0, 1] (0 and 1 give 0: a pure system).

    Returns
    -------
    float
        The entropy per particle, units of k.

    Raises
    ------
    InvalidInputError
        For x outside [0, 1].
    """
    x = float(x)
    if not 0.0 <= x <= 1.0:
        raise InvalidInputError(f"the number fraction x must be in [0, 1], got {x}")
    return 0.0 - sum(p * math.log(p) for p in (x, 1.0 - x) if p > 0)  # +0.0, not -0.0, for a pure system


def second_virial_slope(d: int = 2, size_ratio: float = 1.0, large_fraction: float = 0.0) -> float:
    """lim_{phi -> 0} (Z - 1) / phi of additive hard spheres in ``d`` dimensions, one size or a
    binary mixture (diameter ratio ``size_ratio``, number fraction ``large_fraction`` of the
    large ones).

    Z = 1 + B_2 rho with B_2 = (|B_d| / 2) sum_ij x_i x_j D_ij^d, D_ij = (D_i + D_j) / 2, and
    phi = rho |B_d| <D^d> / 2^d, so (Z - 1) / phi -> 2^(d-1) <D_ij^d> / <D^d> (derived here;
    2 for monodisperse disks, 4 for spheres; for disks 1 + <D>^2 / <D^2>).

    Parameters
    ----------
    d : int, optional
        Dimension, >= 1.
    size_ratio : float, optional
        Diameter ratio large / small, > 0.
    large_fraction : float, optional
        Number fraction of the large particles, in [0, 1].

    Returns
    -------
    float
        The slope.
    """
    if d < 1:
        raise InvalidInputError(f"dimension d must be >= 1, got {d}")
    if not size_ratio > 0:
        raise InvalidInputError(f"size_ratio must be > 0, got {size_ratio}")
    if not 0.0 <= large_fraction <= 1.0:
        raise InvalidInputError(f"large_fraction must be in [0, 1], got {large_fraction}")
    sizes = np.array([1.0, float(size_ratio)])
    x = np.array([1.0 - large_fraction, large_fraction])
    pair = ((sizes[:, None] + sizes[None, :]) / 2) ** d
    return 2.0 ** (d - 1) * float(x @ pair @ x) / float(x @ sizes**d)


def _tabulated(phi, z, z_err):
    phi = np.asarray(phi, float)
    z = np.asarray(z, float)
    if phi.ndim != 1 or phi.shape != z.shape or phi.size < 1:
        raise InvalidInputError(f"phi and Z must be 1-D arrays of the same length, got shapes "
                                f"{phi.shape} and {z.shape}")
    if z_err is None:
        z_err = np.zeros_like(z)
    z_err = np.asarray(z_err, float)
    if z_err.shape != z.shape:
        raise InvalidInputError(f"Z_err must have the shape of Z {z.shape}, got {z_err.shape}")
    if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(z))):
        raise InvalidInputError("phi and Z must be finite (drop empty bins first)")
    if np.any(phi <= 0) or np.any(phi >= 1) or np.any(np.diff(phi) <= 0):
        raise InvalidInputError("phi must increase strictly and lie in (0, 1)")
    return phi, z, np.where(np.isfinite(z_err), z_err, 0.0)


def excess_free_energy(phi, z, z_err=None, *, slope0: float = 2.0):
    """Excess free energy over the ideal gas, Delta f(phi_i) = int_0^phi_i (Z - 1)/phi dphi, of a
    tabulated EOS, and its standard error.

    The integrand y = (Z - 1) / phi is interpolated linearly between the points, starting from
    its exact value ``slope0`` at phi = 0 (:func:`second_virial_slope`), and the interpolant is
    integrated exactly (the trapezoid rule, error O(h^2)). The result is linear in the Z_i, so
    their independent errors propagate exactly: var Delta f(phi_k) = sum_i (w_ki / phi_i)^2
    err_i^2 with w_ki the trapezoid weights.

    Parameters
    ----------
    phi : array_like, shape (n,)
        Strictly increasing volume fractions in (0, 1).
    z : array_like, shape (n,)
        Reduced pressures Z = pV/(NkT) at ``phi``.
    z_err : array_like, shape (n,), optional
        Standard errors of Z (independent); NaN counts as 0.
    slope0 : float, default 2.0
        (Z - 1) / phi at phi = 0 (2 for monodisperse disks).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Delta f and its standard error at each ``phi``.
    """
    phi, z, err = _tabulated(phi, z, z_err)
    x = np.concatenate([[0.0], phi])
    y = np.concatenate([[float(slope0)], (z - 1.0) / phi])
    h = np.diff(x)
    f = np.concatenate([[0.0], np.cumsum(0.5 * h * (y[1:] + y[:-1]))])[1:]
    # d f_k / d y_i: h_{i-1}/2 + h_i/2 for interior points i < k, h_{k-1}/2 for i = k
    n = phi.size
    weights = np.zeros((n, n))
    for k in range(n):
        weights[k, : k + 1] = 0.5 * h[: k + 1]
        weights[k, :k] += 0.5 * h[1 : k + 1]
    f_err = np.sqrt((weights / phi) ** 2 @ err**2)
    return f, f_err


def binned_excess_difference(centres, width: float, phi_mean, z, z_err, lo: float, hi: float) -> tuple[float, float]:
    """Delta f(hi) - Delta f(lo) = int_lo^hi (Z - 1)/phi dphi of a binned EOS (a run's samples
    averaged in bins of phi) and its standard error, as the sum over the bins between the limits
    of width (Z_k - 1) / phi_k.

    The bins tile [lo, hi], so the sum is the integral of the bin averages, exact but for the
    difference between (<Z> - 1)/<phi> and <(Z - 1)/phi> within a bin, of order width^2 Z'/phi^2
    (derived here; ~2e-5 per 0.05 of phi for the hard-disk crystal at 0.75-0.80 in bins of
    0.005). The trapezoid rule through the bin means instead errs by width^2 y''/12 per unit
    phi with y = (Z - 1)/phi, ten times more there (2e-4: y is convex near close packing).

    Parameters
    ----------
    centres : array_like, shape (n,)
        Bin centres (evenly spaced by ``width``).
    width : float
        Bin width.
    phi_mean, z, z_err : array_like, shape (n,)
        Mean phi, mean Z and its standard error per bin (NaN: an empty bin).
    lo, hi : float
        The limits, bin edges with lo < hi.

    Returns
    -------
    (float, float)
        The integral and its standard error (bins independent).

    Raises
    ------
    InvalidInputError
        If a limit is not a bin edge, the bins do not cover the range, or one of them is empty.
    """
    centres, phi_mean, z, z_err = (np.asarray(a, float) for a in (centres, phi_mean, z, z_err))
    if not (width > 0 and lo < hi):
        raise InvalidInputError(f"need width > 0 and lo < hi, got width {width}, limits {lo} .. {hi}")
    for limit in (lo, hi):
        if abs(limit / width - round(limit / width)) > 1e-6 * max(1.0, abs(limit / width)):
            raise InvalidInputError(f"{limit} is not an edge of the EOS bins (width {width}): choose densities "
                                    f"on multiples of the bin width")
    inside = (centres > lo) & (centres < hi)
    expected = int(round((hi - lo) / width))
    if inside.sum() != expected:
        raise InvalidInputError(f"the EOS bins cover {int(inside.sum())} of the {expected} bins between {lo} and {hi}")
    if not (np.isfinite(z[inside]).all() and np.isfinite(phi_mean[inside]).all()):
        raise InvalidInputError(f"an EOS bin between {lo} and {hi} is empty")
    terms = width * (z[inside] - 1.0) / phi_mean[inside]
    errors = width * np.nan_to_num(z_err[inside]) / phi_mean[inside]
    return float(terms.sum()), float(np.sqrt(np.sum(errors**2)))


def integrate_eos(z_of_phi, phi, *, phi0: float = 0.0, f0: float = 0.0, slope0: float = 2.0):
    """Delta f(phi) = f0 + int_phi0^phi (Z(phi') - 1)/phi' dphi' for an EOS given as a function,
    by adaptive quadrature (the integrand at phi' = 0 is ``slope0``).

    Parameters
    ----------
    z_of_phi : callable
        Z(phi) for scalar phi (finite on [phi0, max(phi)]).
    phi : float or array_like
        Upper limits, each >= phi0.
    phi0, f0 : float, default 0
        Lower limit and the value there (0, 0: from the ideal gas).
    slope0 : float, default 2.0
        (Z - 1)/phi at phi = 0, used only if phi0 = 0.

    Returns
    -------
    numpy.ndarray
        Delta f at each ``phi`` (shape of ``phi``).
    """
    targets = np.atleast_1d(np.asarray(phi, float))
    if np.any(targets < phi0):
        raise InvalidInputError(f"every phi must be >= phi0 = {phi0}")

    def integrand(p):
        return float(slope0) if p == 0.0 else (float(z_of_phi(p)) - 1.0) / p

    out = np.array([f0 + quad(integrand, phi0, p, limit=200, epsabs=1e-12, epsrel=1e-11)[0]
                    for p in targets])
    return out.reshape(np.shape(phi))


def henderson_excess(phi):
    """Exact EOS integral of Henderson's hard-disk EOS Z = (1 + phi^2/8)/(1 - phi)^2:
    Delta f = (9/8) phi / (1 - phi) - (7/8) ln(1 - phi) (derived here; a closed-form check).

    Henderson (1975) equation of state.

    Parameters
    ----------
    phi : array_like of float
        Volume fractions, < 1.

    Returns
    -------
    numpy.ndarray of float
        Delta f per disk, units of kT.
    """
    phi = np.asarray(phi, float)
    return 9.0 / 8.0 * phi / (1.0 - phi) - 7.0 / 8.0 * np.log1p(-phi)


def configurational_entropy_excess(glass_excess, liquid_excess, glass_err=0.0, liquid_err=0.0):
    """s_c - s_mix = Delta f_g - Delta f_L (module docstring; Donev 2006, Eq. 13.5, Fig. 13.12),
    with the two errors added in quadrature.

    Parameters
    ----------
    glass_excess : float or array_like
        Excess free energy of the SOC glass over the ideal gas (BCMD ``excess``).
    liquid_excess : float or array_like
        Excess free energy of the liquid at the same phi (EOS integral).
    glass_err, liquid_err : float or array_like, default 0
        Their standard errors.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        s_c - s_mix and its standard error.
    """
    g, lq = np.asarray(glass_excess, float), np.asarray(liquid_excess, float)
    err = np.hypot(np.asarray(glass_err, float), np.asarray(liquid_err, float))
    return g - lq, err
