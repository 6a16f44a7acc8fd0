"""Pair correlation g2(r), cumulative coordination Z(l) and its near-contact power law.

**g2 normalisation (any d, polydisperse, finite N).** Unordered pairs of distinct particles are
counted over all periodic images (pair (i, j) with separation x_j + L n - x_i for every lattice
image n). For N points placed independently and uniformly in the cell (ideal gas), each of the
N(N-1)/2 distinct pairs has exactly v_shell / V expected images in any shell, so

    g2(r) = n(r) / [ N(N-1)/2 * v_d ((r + dr)^d - r^d) / V ],      v_d = unit-ball volume,

has expectation exactly 1 for the ideal gas at every r (also beyond L/2), and the counts are
Poisson-like with relative noise 1/sqrt(expected count) per bin. This is freud's RDF with
``normalization_mode='finite_size'``. Scaled distances x = r / (r_i + r_j) use the ideal count
sum_{i<j} (r_i + r_j)^d * v_d ((x + dx)^d - x^d) / V, so g2(x) = 1 for the ideal gas of any size
distribution. With ``self_images=True`` a particle's own images are counted too (the infinite
periodic system, needed for cells smaller than the range, e.g. N = 1 lattices) and the pair
count in the normalisation becomes N^2/2 (self terms added to the scaled sum likewise).

**Contact delta peak** (Donev 2006, sec. 9.3.1 and Eq. 9.4, Fig. 9.4): pairs
with |r / (r_i + r_j) - 1| <= contact_tol are contacts; they are counted separately
(``n_contacts``, Z_c = 2 n_contacts / N) and left out of both histograms, so g2 holds only the
continuous part; the full g2 adds Z_c delta(r - D) / (rho s_1(D)) (Donev 2006, Eq. 11.5).

**Cumulative coordination** (Donev 2006, sec. 9.3.1, Fig. 9.4): Z(l) = 2 #{pairs with gap <= l} / N with the
relative gap l = r / (r_i + r_j) - 1 (= (r - D)/D for equal spheres), estimated without binning
from the sorted gaps. With a rattler mask, the backbone version counts only pairs of two
non-rattlers and divides by the number of non-rattlers N_b (as Donev 2006 does: secs. 9.3.1
and 9.3.1.2).

**Near-contact power law** Z(l) = Z_c + a l^alpha (Donev 2006, Eq. 9.7 with alpha = 1 - alpha_Donev;
published alpha ~ 0.6, a ~ 11 for rattler-free jammed spheres, sec. 9.3.1.2, Fig. 9.6). Fitted by maximum
likelihood: gaps inside a window [l_lo, l_hi] above the contact part are samples of the density
alpha l^(alpha-1) / (l_hi^alpha - l_lo^alpha); the standard error comes from the Fisher
information. Pairs sharing particles are not independent, so this error is a lower bound;
compare windows (and packings) to see the systematic part.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import unit_ball_volume
from hardpack.geometry.neighbours import build_grid, pairs_within
from hardpack.geometry.neighbours.grid import pair_histograms, stencil

DEFAULT_CONTACT_TOL = 1e-9


#: default fit window of the near-contact power law: above the contact delta peak (LS packings at
#: Z = 1e12 have contact gaps ~1e-12, far below 1e-5 / 100, Donev 2006, sec. 9.3.1.2) and below the
#: first minimum of g2 (l ~ 0.25), where Donev sees 11 l^0.6 hold
NEAR_CONTACT_FIT = (1e-5, 1e-1)


def _positive(name, value):
    if value is None or not np.isfinite(value) or value <= 0:
        raise InvalidInputError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def _sum_contact_power(radii: np.ndarray, d: int, self_images: bool) -> float:
    """sum over unordered pairs i < j of (r_i + r_j)^d, plus (2 r_i)^d / 2 per particle if
    self-images count; exact via the binomial expansion sum_k C(d,k) S_k S_(d-k), S_k = sum r^k."""
    s = [float(np.sum(radii ** k)) for k in range(d + 1)]
    all_ordered = sum(math.comb(d, k) * s[k] * s[d - k] for k in range(d + 1))
    diagonal = float(np.sum((2.0 * radii) ** d))
    return 0.5 * (all_ordered - diagonal) + (0.5 * diagonal if self_images else 0.0)


def pair_correlation(packing, r_max: float | None = None, dr: float | None = None,
                     x_max: float = 3.0, dx: float = 0.005,
                     contact_tol: float = DEFAULT_CONTACT_TOL,
                     self_images: bool = False) -> xr.Dataset:
    """g2 in absolute distance r and in scaled distance x = r / (r_i + r_j) (module docstring).

    The pair search reaches max(r_max, x_max times the largest contact distance): lower x_max for
    wide size distributions.

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell.
    r_max : float, optional
        Range of the histogram in r; default 5 mean diameters.
    dr : float, optional
        Bin width in r; default mean diameter / 200, fine enough for the split second peak
        (Donev 2006, sec. 9.3.1.3, Fig. 9.7; the dissertation does not print its bin width).
    x_max : float, default 3.0
        Range of the histogram in the scaled distance x.
    dx : float, default 0.005
        Bin width in x.
    contact_tol : float, default 1e-9
        Pairs with |x - 1| <= contact_tol are contacts: counted in ``n_contacts`` and left out of
        both histograms.
    self_images : bool, default False
        Count a particle's own periodic images too (the infinite periodic system; needed for cells
        smaller than the range, e.g. N = 1 lattices).

    Returns
    -------
    xarray.Dataset
        Coordinates ``r`` and ``x`` (bin centres); variables ``g2``, ``pair_count``,
        ``ideal_count`` on r, the same with suffix ``_scaled`` on x, and scalars ``n_contacts``
        and ``z_contacts`` (the delta-peak weight Z_c = 2 n_contacts / N).

    Raises
    ------
    InvalidInputError
        If the packing is not hard spheres in a periodic cell, r_max, dr, x_max or dx is not a
        positive finite number, contact_tol is negative or not finite, or more than 10^7 bins are
        requested.
    """
    packing.require_periodic_spheres("the structure analysis")
    diameter = 2.0 * float(np.mean(packing.radii))
    r_max = _positive("r_max", 5.0 * diameter if r_max is None else r_max)
    dr = _positive("dr", diameter / 200.0 if dr is None else dr)
    x_max, dx = _positive("x_max", x_max), _positive("dx", dx)
    if not (np.isfinite(contact_tol) and contact_tol >= 0):
        raise InvalidInputError(f"contact_tol must be a finite number >= 0, got {contact_tol!r}")
    n_r, n_x = math.ceil(r_max / dr), math.ceil(x_max / dx)
    if max(n_r, n_x) > 10**7:
        raise InvalidInputError(f"{max(n_r, n_x)} bins requested; increase dr/dx or lower r_max/x_max")
    radii = np.ascontiguousarray(packing.radii, dtype=float)
    cutoff = max(n_r * dr, n_x * dx * 2.0 * radii.max())
    grid = build_grid(packing.fractional(), packing.lattice, np.full(radii.size, 0.5 * cutoff), per_cell=2)
    hist_r, hist_x, n_contacts = pair_histograms(
        grid.x, radii, grid.lattice, grid.n_cells[0], grid.strides[0], grid.cell_start, grid.order,
        stencil(grid, cutoff), cutoff, dr, n_r, dx, n_x, float(contact_tol), bool(self_images),
    )
    n, d, volume = packing.n_particles, packing.dim, packing.volume
    vd = unit_ball_volume(d)
    pairs = n * n / 2.0 if self_images else n * (n - 1) / 2.0
    r_edges = dr * np.arange(n_r + 1)
    x_edges = dx * np.arange(n_x + 1)
    ideal_r = pairs * vd * np.diff(r_edges ** d) / volume
    ideal_x = _sum_contact_power(radii, d, self_images) * vd * np.diff(x_edges ** d) / volume
    with np.errstate(invalid="ignore", divide="ignore"):
        g_r, g_x = hist_r / ideal_r, hist_x / ideal_x
    note = ("g2 = pair count / ideal count; ideal count = P * v_d (r_hi^d - r_lo^d) / V with "
            f"P = {'N^2/2 (self-images counted)' if self_images else 'N(N-1)/2'}; all periodic "
            "images; contacts (|r/(r_i+r_j) - 1| <= contact_tol) excluded and reported as z_contacts")
    return xr.Dataset(
        data_vars=dict(
            g2=("r", g_r), pair_count=("r", hist_r), ideal_count=("r", ideal_r),
            g2_scaled=("x", g_x), pair_count_scaled=("x", hist_x), ideal_count_scaled=("x", ideal_x),
            n_contacts=((), float(n_contacts)), z_contacts=((), 2.0 * n_contacts / n),
        ),
        coords=dict(r=0.5 * (r_edges[1:] + r_edges[:-1]), x=0.5 * (x_edges[1:] + x_edges[:-1])),
        attrs=dict(normalisation=note, dr=dr, dx=dx, contact_tol=float(contact_tol),
                   n_particles=n, dim=d, volume=volume, phi=packing.phi,
                   self_images=int(bool(self_images))),
    )


def _check_mask(rattlers, n):
    if rattlers is None:
        return None
    mask = np.asarray(rattlers)
    if mask.shape != (n,) or mask.dtype != bool:
        raise InvalidInputError(
            f"rattlers must be a boolean array of shape ({n},) (True = rattler), got dtype "
            f"{mask.dtype} and shape {mask.shape}")
    if mask.all():
        raise InvalidInputError("every particle is flagged as a rattler; no backbone is left")
    return mask


def cumulative_coordination(packing, gap_max: float = 0.5, rattlers=None,
                            contact_tol: float = DEFAULT_CONTACT_TOL, gap_min: float = 1e-16,
                            n_grid: int = 321) -> xr.Dataset:
    """Z(l) from the sorted relative gaps of all pairs with gap <= gap_max (module docstring).

    Self-image contacts count twice for their particle, as they should.

    Parameters
    ----------
    packing : Packing
        Hard spheres in a periodic cell.
    gap_max : float, default 0.5
        Largest relative gap l = r / (r_i + r_j) - 1 searched.
    rattlers : numpy.ndarray of bool, shape (N,), optional
        True for rattlers; if given, the backbone version (pairs of two non-rattlers, divided by
        the number of non-rattlers) is computed too.
    contact_tol : float, default 1e-9
        Pairs with |l| <= contact_tol count as contacts in ``z_contacts_*``.
    gap_min : float, default 1e-16
        Smallest gap of the logarithmic grid on which Z is tabulated.
    n_grid : int, default 321
        Number of points of that grid.

    Returns
    -------
    xarray.Dataset
        The sorted gaps (``gap_all`` on dim ``pair_all``; with a rattler mask also
        ``gap_backbone`` on ``pair_backbone``), Z on the log grid ``gap`` (``Z_all``, and
        ``Z_backbone``), scalars ``z_contacts_all`` / ``z_contacts_backbone`` (pairs with
        |gap| <= contact_tol) and ``n_particles_all`` / ``n_particles_backbone``.

    Raises
    ------
    InvalidInputError
        If the packing is not hard spheres in a periodic cell, gap_max or gap_min is not a positive
        finite number or gap_min >= gap_max, or rattlers is not a boolean array of shape (N,) or
        flags every particle.
    """
    packing.require_periodic_spheres("the structure analysis")
    gap_max = _positive("gap_max", gap_max)
    gap_min = _positive("gap_min", gap_min)
    if gap_min >= gap_max:
        raise InvalidInputError(f"gap_min ({gap_min}) must be below gap_max ({gap_max})")
    n = packing.n_particles
    mask = _check_mask(rattlers, n)
    pairs = pairs_within(packing, rel_gap=gap_max)
    gaps = pairs.gap
    grid = np.geomspace(gap_min, gap_max, int(n_grid))
    sets = {"all": (np.ones(len(gaps), bool), n)}
    if mask is not None:
        keep = ~mask[pairs.i] & ~mask[pairs.j]
        sets["backbone"] = (keep, int((~mask).sum()))
    data_vars, coords = {}, {"gap": grid}
    for name, (sel, n_set) in sets.items():
        g = np.sort(gaps[sel])
        data_vars[f"gap_{name}"] = (f"pair_{name}", g)
        data_vars[f"Z_{name}"] = ("gap", 2.0 * np.searchsorted(g, grid, side="right") / n_set)
        data_vars[f"z_contacts_{name}"] = ((), 2.0 * np.count_nonzero(np.abs(g) <= contact_tol) / n_set)
        data_vars[f"n_particles_{name}"] = ((), n_set)
    return xr.Dataset(data_vars, coords=coords, attrs=dict(
        gap_definition="l = r / (r_i + r_j) - 1", contact_tol=float(contact_tol),
        rattlers_given=int(mask is not None),
    ))


@dataclass(frozen=True)
class PowerLawFit:
    """Z(l) = z_contact + amplitude * l^alpha fitted on gaps in (gap_lo, gap_hi]
    (:func:`fit_power_law`; Donev 2006, Eq. 9.7 with alpha = 1 - alpha_Donev).

    Attributes
    ----------
    alpha, alpha_err : float
        Maximum-likelihood exponent and its standard error (Fisher information; a lower bound,
        since pairs sharing particles are not independent).
    amplitude, amplitude_err : float
        Amplitude a and its standard error.
    z_contact : float
        Z_c = Z(gap_lo) - a gap_lo^alpha.
    n_pairs : int
        Number of pair gaps in the window.
    gap_lo, gap_hi : float
        The fit window.
    """

    alpha: float
    alpha_err: float
    amplitude: float
    amplitude_err: float
    z_contact: float
    n_pairs: int
    gap_lo: float
    gap_hi: float


def fit_power_law(gaps, n_particles: int, gap_lo: float, gap_hi: float) -> PowerLawFit:
    """Maximum-likelihood fit of Z(l) - Z_c = a l^alpha from pair gaps (module docstring).

    Parameters
    ----------
    gaps : array_like
        Relative gaps of all pairs (any order) of a set of ``n_particles`` particles.
    n_particles : int
        Number of particles of that set (Z = 2 #pairs / n_particles).
    gap_lo, gap_hi : float
        The fit window (gap_lo, gap_hi]; it must lie above the contact part.

    Returns
    -------
    PowerLawFit
        alpha and amplitude a with their standard errors (from the Fisher information; a lower
        bound, since pairs sharing particles are not independent), Z_c = Z(gap_lo) - a gap_lo^alpha,
        the number of gaps in the window and the window.

    Raises
    ------
    InvalidInputError
        If gap_lo or gap_hi is not a positive finite number or gap_lo >= gap_hi, fewer than 10
        gaps lie in the window, or no alpha in (0, 20) fits them.
    """
    gap_lo, gap_hi = _positive("gap_lo", gap_lo), _positive("gap_hi", gap_hi)
    if gap_lo >= gap_hi:
        raise InvalidInputError(f"the fit window needs gap_lo < gap_hi, got [{gap_lo}, {gap_hi}]")
    g = np.asarray(gaps, dtype=float)
    inside = g[(g > gap_lo) & (g <= gap_hi)]
    k = inside.size
    if k < 10:
        raise InvalidInputError(
            f"only {k} pair gaps in the window [{gap_lo:g}, {gap_hi:g}]; widen it or pool packings")
    mean_log = float(np.mean(np.log(inside)))
    la, lb = math.log(gap_lo), math.log(gap_hi)

    def dlog_norm(alpha):  # d/d alpha of log(gap_hi^alpha - gap_lo^alpha)
        t = math.exp(alpha * (la - lb))
        return (lb - t * la) / (1.0 - t)

    def score(alpha):  # per-sample derivative of the log-likelihood
        return 1.0 / alpha + mean_log - dlog_norm(alpha)

    lo, hi = 1e-6, 20.0
    if score(lo) * score(hi) > 0:
        raise InvalidInputError("no power law with 0 < alpha < 20 fits the gaps in this window")
    alpha = brentq(score, lo, hi, xtol=1e-12)
    # Fisher information per sample: 1/alpha^2 + d^2/d alpha^2 log(gap_hi^alpha - gap_lo^alpha)
    # = 1/alpha^2 - c^2 e^(alpha c) / (e^(alpha c) - 1)^2 with c = log(gap_hi / gap_lo)
    c = lb - la
    info = 1.0 / alpha**2 - c * c / (4.0 * math.sinh(0.5 * alpha * c) ** 2)
    alpha_err = 1.0 / math.sqrt(k * info)
    norm = gap_hi**alpha - gap_lo**alpha
    amplitude = 2.0 * k / (n_particles * norm)
    amplitude_err = amplitude * math.sqrt(1.0 / k + (dlog_norm(alpha) * alpha_err) ** 2)
    z_lo = 2.0 * np.count_nonzero(g <= gap_lo) / n_particles
    return PowerLawFit(alpha, alpha_err, amplitude, amplitude_err,
                       z_lo - amplitude * gap_lo**alpha, k, gap_lo, gap_hi)


def fit_coordination_power_law(z: xr.Dataset, gap_lo: float, gap_hi: float,
                               backbone: bool = True) -> PowerLawFit:
    """:func:`fit_power_law` on a :func:`cumulative_coordination` Dataset (backbone if present).

    Parameters
    ----------
    z : xarray.Dataset
        The result of :func:`cumulative_coordination`.
    gap_lo, gap_hi : float
        The fit window (gap_lo, gap_hi]; gap_hi must not exceed the dataset's gap_max.
    backbone : bool, default True
        Fit the backbone gaps if the dataset has them; otherwise (or if False) all gaps.

    Returns
    -------
    PowerLawFit
        As :func:`fit_power_law`.

    Raises
    ------
    InvalidInputError
        If gap_hi exceeds the gap range of the dataset, or as :func:`fit_power_law`.
    """
    name = "backbone" if backbone and "gap_backbone" in z else "all"
    if gap_hi > float(z["gap"].max()):
        raise InvalidInputError(
            f"gap_hi = {gap_hi} exceeds the gap range {float(z['gap'].max())} of the dataset")
    return fit_power_law(z[f"gap_{name}"].values, int(z[f"n_particles_{name}"]), gap_lo, gap_hi)
