"""Equations of state of hard-sphere (and hard-disk) fluids and empirical jamming densities.

Compressibility factor Z = PV/(N k_B T) as a function of the volume fraction phi (Ogarko 2014,
secs. 3.1.2-3.1.3, 3.2 and 3.3.2). All functions are vectorised over phi and refuse
phi outside [0, 1) (or outside [0, phi_J) for the free-volume form) and unrealisable moments.

Polydisperse theories depend on the size distribution only through O1 = <a><a^2>/<a^3> and
O2 = <a^2>^3/<a^3>^2 (Eq. 3.6; :func:`hardpack.eos.moments.dimensionless_moments`), with
0 < O1 <= 1 and O1^2 <= O2 <= O1 (Ogarko 2014, sec. 3.1.2). O1 = O2 = 1 is the monodisperse case, where
BMCSL = SCS = CS and SCSK = BCSK = CSK.

Fluid theories (CS, CSK, BMCSL, SCS, SCSK, BCSK, Z_OL, PY, Henderson) describe the equilibrium
fluid: for monodisperse spheres up to freezing/melting (phi ~ 0.49-0.55), for polydisperse spheres
to phi ~ 0.56-0.60 (tested to phi <= 0.60, Ogarko 2014, Fig. 3.1). They stay finite up to phi = 1
and do not know about jamming; beyond their range compare with :func:`free_volume`.
"""

from __future__ import annotations

import warnings

import numpy as np

from hardpack.errors import InvalidInputError


def _phi(phi, upper: float = 1.0, name: str = "phi") -> np.ndarray:
    x = np.asarray(phi, dtype=float)
    if not np.isfinite(x).all():
        raise InvalidInputError(f"{name} must be finite")
    if (x < 0).any() or (x >= upper).any():
        raise InvalidInputError(f"{name} must lie in [0, {upper}); got values in [{x.min()}, {x.max()}]")
    return x


def _omoments(O1, O2) -> tuple[np.ndarray, np.ndarray]:
    o1, o2 = np.asarray(O1, dtype=float), np.asarray(O2, dtype=float)
    tol = 1e-12
    ok = (o1 > 0) & (o1 <= 1 + tol) & (o2 >= o1**2 * (1 - tol)) & (o2 <= o1 * (1 + tol))
    if not np.all(ok):
        raise InvalidInputError(
            f"(O1, O2) = ({O1}, {O2}) is not a size distribution: need 0 < O1 <= 1 and O1^2 <= O2 <= O1 "
            "(Ogarko 2014, sec. 3.1.2); compute them with hardpack.eos.moments.dimensionless_moments"
        )
    return o1, o2


def carnahan_starling(phi):
    """Carnahan-Starling Z_CS = (1 + phi + phi^2 - phi^3)/(1 - phi)^3 = 1 + 4 phi g_CS, with
    g_CS = (1 - phi/2)/(1 - phi)^3 (Ogarko 2014, below Eq. 3.8). Monodisperse 3D fluid, phi <~ 0.55.

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1).
    """
    x = _phi(phi)
    return (1 + x + x**2 - x**3) / (1 - x) ** 3


def csk(phi):
    """Carnahan-Starling-Kolafa Z_CSK = [1 + phi + phi^2 - 2 phi^3 (1 + phi)/3]/(1 - phi)^3 (sec. 3.1.2).
    Monodisperse 3D fluid, slightly more accurate than CS near freezing (phi <~ 0.55).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1).
    """
    x = _phi(phi)
    return (1 + x + x**2 - 2 * x**3 * (1 + x) / 3) / (1 - x) ** 3


def percus_yevick(phi):
    """Percus-Yevick (compressibility route) Z = (1 + phi + phi^2)/(1 - phi)^3, monodisperse 3D fluid.
    Overestimates Z; use CS/CSK for accuracy. Not in Ogarko 2014 (standard liquid-state theory).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1).
    """
    x = _phi(phi)
    return (1 + x + x**2) / (1 - x) ** 3


def henderson(phi):
    """Henderson's hard-disk EOS Z = (1 + phi^2/8)/(1 - phi)^2 (Mol. Phys. 30, 971 (1975)).
    Monodisperse 2D fluid only, below the liquid-hexatic transition (phi ~ 0.70).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1).
    """
    x = _phi(phi)
    return (1 + x**2 / 8) / (1 - x) ** 2


#: Reduced virial coefficients B_k / B_2^(k-1) of hard disks, k = 2..10. B_3 = 4/3 - sqrt(3)/pi and
#: B_4 = 2 - 9 sqrt(3)/(2 pi) + 10/pi^2 are exact; B_5..B_10 are the Monte Carlo values of Clisby &
#: McCoy, J. Stat. Phys. 122, 15 (2006), Table for D = 2 (last-digit errors 1e-8 .. 8e-9).
HARD_DISK_VIRIAL = (1.0, 4 / 3 - np.sqrt(3) / np.pi, 2 - 9 * np.sqrt(3) / (2 * np.pi) + 10 / np.pi**2,
                    0.33355604, 0.1988425, 0.1148728, 0.0649930, 0.0362193, 0.0199537)


def hard_disk_virial(phi):
    """The hard-disk virial series to B_10, Z = 1 + sum_{k=2}^{10} (B_k / B_2^(k-1)) (2 phi)^(k-1)
    (B_2 rho = 2 phi; coefficients :data:`HARD_DISK_VIRIAL`, Clisby & McCoy 2006).

    The omitted terms are positive and their ratios B_{k+1}/B_k fall from 0.78 to 0.55 by k = 10, so
    the truncation error is at most B_10 x^9 r x/(1 - r x) with x = 2 phi and r = B_10/B_9 = 0.551:
    1.5e-6 at phi = 0.2, 1.0e-4 at phi = 0.3 and 2.1e-3 at phi = 0.4 (:func:`hard_disk_virial_truncation`).
    Use it in the dilute and moderately dense fluid, phi <~ 0.35.

    Parameters
    ----------
    phi : array_like
        Area fraction(s), in [0, 0.5) (the bound above diverges at 2 r phi = 1).

    Returns
    -------
    numpy.ndarray or float
        Z = PA/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 0.5).
    """
    x = 2 * _phi(phi, upper=0.5)
    return 1 + sum(c * x ** (k + 1) for k, c in enumerate(HARD_DISK_VIRIAL))


def hard_disk_virial_truncation(phi):
    """Bound on the terms :func:`hard_disk_virial` omits, B_10 x^9 r x/(1 - r x), x = 2 phi,
    r = B_10/B_9 (the ratios of successive coefficients decrease through k = 10).

    Parameters
    ----------
    phi : array_like
        Area fraction(s), in [0, 0.5).

    Returns
    -------
    numpy.ndarray or float
        The bound on |Z - Z_virial| at each phi.
    """
    x = 2 * _phi(phi, upper=0.5)
    r = HARD_DISK_VIRIAL[-1] / HARD_DISK_VIRIAL[-2]
    return HARD_DISK_VIRIAL[-1] * x**9 * r * x / (1 - r * x)


#: (C_0, error, C_1, error) of the hard-disk solid EOS of Alder, Hoover & Young 1968, Eq. 1
AHY_DISK_SOLID = (1.90, 0.01, 0.67, 0.07)


def hard_disk_solid(phi):
    """The high-density hard-disk crystal EOS of Alder, Hoover & Young, J. Chem. Phys. 49, 3688
    (1968), Eq. 1: Z = 2/a + C_0 + C_1 a with a = V/V_0 - 1 = phi_cp/phi - 1, phi_cp = pi/sqrt(12),
    C_0 = 1.90 +- 0.01, C_1 = 0.67 +- 0.07 (:data:`AHY_DISK_SOLID`). 2/a is the free-volume
    divergence; the fit describes the triangular crystal from close packing down to its melting.

    Parameters
    ----------
    phi : array_like
        Area fraction(s), in (0, pi/sqrt(12)).

    Returns
    -------
    z : numpy.ndarray or float
        Z = PA/(N k_B T) at each phi.
    error : numpy.ndarray or float
        The stated errors of C_0 and C_1 at each phi, dC_0 + dC_1 a (added linearly).

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside (0, pi/sqrt(12)).
    """
    cp = np.pi / np.sqrt(12)
    x = _phi(phi, upper=cp)
    if np.any(x <= 0):
        raise InvalidInputError("phi must be positive for the crystal EOS")
    a = cp / x - 1
    c0, e0, c1, e1 = AHY_DISK_SOLID
    return 2 / a + c0 + c1 * a, e0 + e1 * a


def bmcsl(phi, O1=1.0, O2=1.0):
    """Boublik-Mansoori-Carnahan-Starling-Leland, Ogarko 2014, Eq. 3.9:
    Z = 1/(1 - phi) + 3 O1 phi/(1 - phi)^2 + O2 phi^2 (3 - phi)/(1 - phi)^3 = 1 + 4 phi g_eff (Eqs. 3.7-3.8).
    Polydisperse 3D fluid; within 1 % of simulations for phi < 0.54-0.60 (Fig. 3.1, sec. 3.2).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    O1, O2 : float or array_like, default 1.0
        Dimensionless moments O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eq. 3.6),
        with 0 < O1 <= 1 and O1^2 <= O2 <= O1; 1 for monodisperse spheres.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or (O1, O2) are not the moments of a size
        distribution.
    """
    x = _phi(phi)
    o1, o2 = _omoments(O1, O2)
    return 1 / (1 - x) + 3 * o1 * x / (1 - x) ** 2 + o2 * x**2 * (3 - x) / (1 - x) ** 3


def scs(phi, O1=1.0, O2=1.0):
    """Santos et al., CS-based, Eq. 3.10: Z_SCS = Z_BMCSL + (O1 - O2) phi^3/(1 - phi)^3.

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    O1, O2 : float or array_like, default 1.0
        Dimensionless moments O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eq. 3.6),
        with 0 < O1 <= 1 and O1^2 <= O2 <= O1; 1 for monodisperse spheres.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or (O1, O2) are not the moments of a size
        distribution.
    """
    x = _phi(phi)
    o1, o2 = _omoments(O1, O2)
    return bmcsl(x, o1, o2) + (o1 - o2) * x**3 / (1 - x) ** 3


def scsk(phi, O1=1.0, O2=1.0):
    """Santos et al., CSK-based, Eq. 3.11: Z_SCSK = Z_SCS + (O1 + O2) phi^3 (1 - 2 phi)/(6 (1 - phi)^3).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    O1, O2 : float or array_like, default 1.0
        Dimensionless moments O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eq. 3.6),
        with 0 < O1 <= 1 and O1^2 <= O2 <= O1; 1 for monodisperse spheres.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or (O1, O2) are not the moments of a size
        distribution.
    """
    x = _phi(phi)
    o1, o2 = _omoments(O1, O2)
    return scs(x, o1, o2) + (o1 + o2) * x**3 * (1 - 2 * x) / (6 * (1 - x) ** 3)


def bcsk(phi, O1=1.0, O2=1.0):
    """Boublik's CSK extension, Eq. 3.12: Z_BCSK = Z_BMCSL + O2 phi^3 (1 - 2 phi)/(3 (1 - phi)^3).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    O1, O2 : float or array_like, default 1.0
        Dimensionless moments O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eq. 3.6),
        with 0 < O1 <= 1 and O1^2 <= O2 <= O1; 1 for monodisperse spheres.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or (O1, O2) are not the moments of a size
        distribution.
    """
    x = _phi(phi)
    o1, o2 = _omoments(O1, O2)
    return bmcsl(x, o1, o2) + o2 * x**3 * (1 - 2 * x) / (3 * (1 - x) ** 3)


def z_ol(phi, O1=1.0, O2=1.0):
    """Ogarko-Luding Z_OL = (Z_SCS + Z_BCSK)/2, Ogarko 2014, Eq. 3.13: better than 0.2 % for
    0.20 <= phi <= 0.60 in polydisperse fluids (not monodisperse above phi = 0.54).

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    O1, O2 : float or array_like, default 1.0
        Dimensionless moments O1 = <a><a^2>/<a^3> and O2 = <a^2>^3/<a^3>^2 (Ogarko 2014, Eq. 3.6),
        with 0 < O1 <= 1 and O1^2 <= O2 <= O1; 1 for monodisperse spheres.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or (O1, O2) are not the moments of a size
        distribution.
    """
    return 0.5 * (scs(phi, O1, O2) + bcsk(phi, O1, O2))


def binary_contact_z(phi, n1, R):
    """Z of a binary mixture from the Jenkins-Mancini pressure with BMCSL contact values,
    Ogarko 2014, Eqs. 3.1-3.5: species 1 (radius a1 = R a2, number fraction n1) and 2,
    A_k = n1 + (1 - n1) R^-k, and

    Z = 1 + phi/(2 <a^3>) sum_ij n_i n_j g_ij (a_i + a_j)^3.

    Equal to BMCSL with the mixture's (O1, O2) (Eq. 3.8); written out independently so that the
    equivalence Z_bi = Z_poly of the bidisperse equivalent (Eqs. 3.20-3.21) can be checked.

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    n1 : float
        Number fraction of species 1 (the larger), in [0, 1].
    R : float
        Size ratio a1 / a2 >= 1.

    Returns
    -------
    numpy.ndarray or float
        Z = PV/(N k_B T) at each phi.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), n1 is outside [0, 1] or R < 1.
    """
    x = _phi(phi)
    if not (0 <= n1 <= 1 and R >= 1):
        raise InvalidInputError(f"need 0 <= n1 <= 1 and size ratio R >= 1, got n1 = {n1}, R = {R}")
    A2, A3 = (n1 + (1 - n1) * R**-k for k in (2, 3))
    u = x * A2 / A3

    def g(c):  # contact value for the reduced radius a_i a_j/(a_i + a_j) = c a1
        return 1 / (1 - x) + 3 * c * u / (1 - x) ** 2 + 2 * (c * u) ** 2 / (1 - x) ** 3

    a1, a2 = 1.0, 1.0 / R
    g11, g22, g12 = g(0.5), g(0.5 / R), g(1 / (1 + R))
    mean3 = n1 * a1**3 + (1 - n1) * a2**3
    s = n1**2 * g11 * (2 * a1) ** 3 + 2 * n1 * (1 - n1) * g12 * (a1 + a2) ** 3 + (1 - n1) ** 2 * g22 * (2 * a2) ** 3
    return 1 + x * s / (2 * mean3)


def free_volume(phi, phi_j, d: int = 3):
    """Free-volume (Salsburg-Wood) EOS near jamming, Eq. 3.14: Z_fv = d/(1 - phi/phi_J).

    Valid asymptotically as phi -> phi_J; in ED compressions the data collapse onto it for
    phi_J - phi <~ 1e-8 (Ogarko 2014, sec. 3.1.3 and Fig. 3.8). Refuses phi >= phi_J.

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, phi_J).
    phi_j : float
        Jamming density phi_J, in (0, 1].
    d : int, default 3
        Dimension.

    Returns
    -------
    numpy.ndarray or float
        Z_fv at each phi.

    Raises
    ------
    InvalidInputError
        If phi_J is outside (0, 1], or phi is not finite or outside [0, phi_J).
    """
    if not (0 < phi_j <= 1):
        raise InvalidInputError(f"phi_J must lie in (0, 1], got {phi_j}")
    x = _phi(phi, upper=phi_j)
    return d / (1 - x / phi_j)


def phij_estimate(phi, Z, d: int = 3):
    """Running jamming-density estimate phi_J^est = phi/(1 - d/Z) (Ogarko 2014, Eq. 3.14, sec. 3.1.3; sec. 3.2).

    The inverse of :func:`free_volume` at each point; phi_J^est -> phi as Z -> infinity, and it is
    constant (a plateau) only where Z follows the free-volume law. Undefined (NaN) where Z <= d.

    Parameters
    ----------
    phi : array_like
        Volume fraction(s), in [0, 1).
    Z : array_like
        Reduced pressure(s) at phi, finite.
    d : int, default 3
        Dimension.

    Returns
    -------
    numpy.ndarray
        phi_J^est at each point; NaN where Z <= d.

    Raises
    ------
    InvalidInputError
        If phi is not finite or outside [0, 1), or Z is not finite.
    """
    x = _phi(phi)
    z = np.asarray(Z, dtype=float)
    if not np.isfinite(z).all():
        raise InvalidInputError("Z must be finite")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(z > d, x / (1 - d / z), np.nan)


# --- empirical jamming densities (reference fits of ch. 3) ------------------------------------


def _warn_range(name, value, lo, hi):
    v = np.asarray(value, dtype=float)
    if (v < lo).any() or (v > hi).any():
        warnings.warn(
            f"{name}: argument outside the fitted range [{lo}, {hi}]; the fit is an extrapolation there",
            stacklevel=3,
        )


def _omega(omega):
    w = np.asarray(omega, dtype=float)
    if np.isnan(w).any() or (w < 1).any():
        raise InvalidInputError(f"omega = a_max/a_min must be >= 1, got {omega}")
    return w


def phij_fit_uniform_size(omega, nu_inf: float = 0.6828, phi_rcp: float = 0.65):
    """nu_max(omega) for US, Ogarko 2014, Eq. 3.15: nu_inf - (nu_inf - phi_RCP)(3 omega^-2 - 2 omega^-3).

    Fitted (within +-0.5 %) for omega >~ 1.2 (no crystallisation) at growth rates 8-16e-6; omega = inf
    allowed (nu_inf = 0.6828 +- 0.0004, sec. 3.1.3). Warns for omega < 1.2. Fig. 3.10 uses
    nu_inf = 0.679, phi_RCP = 0.647 instead (Fig. 3.10 caption).

    Parameters
    ----------
    omega : array_like
        Width a_max / a_min >= 1 (inf allowed).
    nu_inf, phi_rcp : float, default 0.6828, 0.65
        The limits omega -> inf and omega = 1 of the fit.

    Returns
    -------
    numpy.ndarray or float
        The jamming density nu_max at each omega.

    Raises
    ------
    InvalidInputError
        If omega is NaN or below 1.

    Warns
    -----
    UserWarning
        If omega lies outside the fitted range [1.2, inf].
    """
    w = _omega(omega)
    _warn_range("phij_fit_uniform_size", w, 1.2, np.inf)
    return nu_inf - (nu_inf - phi_rcp) * (3 / w**2 - 2 / w**3)


def phij_fit_uniform_volume(omega, nu_inf: float = 0.859, phi_rcp: float = 0.647):
    """nu_max(omega) for UV, Ogarko 2014, Eq. 3.16:
    nu_inf - (nu_inf - phi_RCP)(omega^-1 - omega^-2 + omega^-3)(1 - ln omega^-2).

    The printed "log" is the natural log: only ln gives d nu/d(1/omega) = 0 at omega = 1 as the text
    requires (derived here). Fitted (+-1 %) for 1.2 <= omega <= 10 (rates 8-16e-6); warns outside.
    Bidisperse equivalents with omega > 10 follow it with phi_RCP and nu_inf swapped (Fig. 3.7(b)).

    Parameters
    ----------
    omega : array_like
        Width a_max / a_min >= 1.
    nu_inf, phi_rcp : float, default 0.859, 0.647
        The fit's parameters nu_inf and phi_RCP (its value at omega = 1).

    Returns
    -------
    numpy.ndarray or float
        The jamming density nu_max at each omega.

    Raises
    ------
    InvalidInputError
        If omega is NaN or below 1.

    Warns
    -----
    UserWarning
        If omega lies outside the fitted range [1.2, 10].
    """
    w = _omega(omega)
    _warn_range("phij_fit_uniform_volume", w, 1.2, 10.0)
    return nu_inf - (nu_inf - phi_rcp) * (1 / w - 1 / w**2 + 1 / w**3) * (1 + 2 * np.log(w))


def _sigma(sigma):
    s = np.asarray(sigma, dtype=float)
    if np.isnan(s).any() or (s < 0).any():
        raise InvalidInputError(f"log-normal sigma must be >= 0, got {sigma}")
    _warn_range("log-normal jamming fit", s, 0.0, 1.0)
    return s


def phij_fit_lognormal(sigma, nu_inf: float = 0.7990, phi_rcp: float = 0.6373):
    """nu_max(sigma) for log-normal radii, Ogarko 2014, Eq. 3.52: nu_inf - (nu_inf - phi_RCP) exp(-2 sigma^2).
    Fitted (+-0.7 %) for 0 <= sigma <= 1 at the fast rate Gamma = 16e-3 (random close packing);
    warns outside. exp(-2 sigma^2) = (D32/D43)^2 (Eq. 3.54).

    Parameters
    ----------
    sigma : array_like
        Standard deviation of ln a, >= 0.
    nu_inf, phi_rcp : float, default 0.7990, 0.6373
        The limits sigma -> inf and sigma = 0 of the fit.

    Returns
    -------
    numpy.ndarray or float
        The jamming density nu_max at each sigma.

    Raises
    ------
    InvalidInputError
        If sigma is NaN or negative.

    Warns
    -----
    UserWarning
        If sigma lies outside the fitted range [0, 1].
    """
    s = _sigma(sigma)
    return nu_inf - (nu_inf - phi_rcp) * np.exp(-2 * s**2)


def phij_fit_lognormal_alt(sigma, nu_inf: float = 0.8583, c1: float = -0.3516, c2: float = 0.1332):
    """Alternative log-normal fit, Ogarko 2014, Eq. 3.55: nu_inf + c1 exp(-sigma^2) + c2 exp(-sigma^3).
    +-0.4 % for 0 <= sigma <= 1 (Gamma = 16e-3); departs from Eq. 3.52 for sigma > 1; warns outside.

    Parameters
    ----------
    sigma : array_like
        Standard deviation of ln a, >= 0.
    nu_inf, c1, c2 : float, default 0.8583, -0.3516, 0.1332
        The fit's coefficients.

    Returns
    -------
    numpy.ndarray or float
        The jamming density nu_max at each sigma.

    Raises
    ------
    InvalidInputError
        If sigma is NaN or negative.

    Warns
    -----
    UserWarning
        If sigma lies outside the fitted range [0, 1].
    """
    s = _sigma(sigma)
    return nu_inf + c1 * np.exp(-(s**2)) + c2 * np.exp(-(s**3))
