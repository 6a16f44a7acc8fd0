"""Finite-container and window analysis of sphere packings (Donev 2006, Ch. 7, Sec. 7.3).

- :func:`radial_density_profile`: phi(r), the fraction of the spherical shell [r, r + dr] about the
  container centre covered by the spheres (Fig. 7.5), exact: each sphere contributes its
  intersection volume with the ball of radius r + dr minus that with the ball of radius r
  (:func:`ball_intersection_volume`).
- :func:`extrapolate_bulk_density`: the linear fit of the average density against delta = a / R
  and its value at delta -> 0 with a standard error (Eq. 7.2, Fig. 7.6).
- :func:`window_fluctuations`: sigma_phi(R), the standard deviation of the volume fraction inside
  spherical windows of radius R placed uniformly at random in a periodic packing (Fig. 7.3).

Eq. 7.2 (derived again here from phi_avg = 3 R^-3 int_0^R r^2 phi(r) dr with Eq. 7.1,
phi(r) = phi_0 - Dphi((R - r) / a)): phi_avg(delta) = phi_0 - 3 m_0 delta + 6 m_1 delta^2
- 3 m_2 delta^3 with m_n = int_0^inf x^n Dphi(x) dx. The printed equation labels the moments
<Dphi>_1, <Dphi>_2, <Dphi>_3 while defining <Dphi>_n = int x^n Dphi: its indices are one too high.
Only the linear term matters for the extrapolation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.geometry.balls import ball_volume


def ball_intersection_volume(big, small, dist, d: int = 3) -> np.ndarray:
    """Volume (d = 3) or area (d = 2) of the intersection of two balls of radii ``big`` and
    ``small`` whose centres are ``dist`` apart (arrays broadcast).

    d = 3: the lens V = pi (R + a - s)^2 (s^2 + 2 s a - 3 a^2 + 2 s R + 6 a R - 3 R^2) / (12 s)
    for |R - a| < s < R + a; d = 2: the sum of the two circular segments cut by the common chord.
    Disjoint balls give 0, a ball inside the other the smaller ball's volume.

    Parameters
    ----------
    big, small : array_like
        The radii of the two balls.
    dist : array_like
        The distance between their centres.
    d : int, default 3
        Dimension, 2 or 3.

    Returns
    -------
    numpy.ndarray
        The intersection volumes (areas in 2D), broadcast over the inputs.

    Raises
    ------
    InvalidInputError
        If d is not 2 or 3.
    """
    if d not in (2, 3):
        raise InvalidInputError(f"ball intersections are implemented for d = 2 and 3, got d = {d}")
    R, a, s = np.broadcast_arrays(np.asarray(big, float), np.asarray(small, float), np.asarray(dist, float))
    out = np.zeros(R.shape)
    lo, hi = np.minimum(R, a), np.maximum(R, a)
    inside = s <= hi - lo
    out[inside] = ball_volume(lo[inside], d)
    part = (~inside) & (s < R + a)
    R, a, s = R[part], a[part], s[part]
    if d == 3:
        out[part] = np.pi * (R + a - s) ** 2 * (s * s + 2 * s * a - 3 * a * a + 2 * s * R + 6 * a * R
                                                 - 3 * R * R) / (12 * s)
    else:
        ca = np.clip((s * s + R * R - a * a) / (2 * s * R), -1.0, 1.0)
        cb = np.clip((s * s + a * a - R * R) / (2 * s * a), -1.0, 1.0)
        ta, tb = np.arccos(ca), np.arccos(cb)  # half-angles of the chord seen from each centre
        out[part] = R * R * (ta - np.sin(2 * ta) / 2) + a * a * (tb - np.sin(2 * tb) / 2)
    return out


def _sphere_check(packing, user: str) -> None:
    if packing.shape.kind != "sphere" or packing.dim not in (2, 3):
        raise InvalidInputError(f"{user} handles sphere packings in d = 2 or 3, got {packing.shape.name} "
                                f"in d = {packing.dim}")


def radial_density_profile(packing, n_shells: int = 200, centre=None) -> xr.Dataset:
    """phi(r) of a packing about the centre of its spherical container (Donev 2006, Fig. 7.5).

    Parameters
    ----------
    packing : Packing
        Spheres (d = 2 or 3) in a spherical container, or any sphere packing with ``centre`` given
        (periodic images are not used: the shells must lie in the cell).
    n_shells : int, default 200
        Equal-width shells from r = 0 to the container radius (or to the largest centre distance
        plus radius when ``centre`` is given).
    centre : sequence of float, optional
        Centre of the shells; default the container's.

    Returns
    -------
    xarray.Dataset
        ``phi`` on dimension ``r`` (shell mid-radii), with ``r_inner`` / ``r_outer``, and
        ``phi_core_average`` = 3 int_0^r x^2 phi(x) dx / r^3 at the shell's outer radius
        (Donev 2006, Ch. 7, the core average) at the shell's outer radius; attrs ``radius`` and the
        length unit ``a`` (the mean radius; Donev's a = D/2 for equal spheres).
    """
    _sphere_check(packing, "the radial density profile")
    if int(n_shells) != n_shells or n_shells < 1:
        raise InvalidInputError(f"n_shells must be a positive integer, got {n_shells!r}")
    d = packing.dim
    x, a = packing.positions, packing.radii
    if centre is None:
        if packing.boundary.kind != "spherical_container":
            raise InvalidInputError("pass centre= for a packing without a spherical container")
        centre, radius = np.array(packing.boundary.centre), packing.boundary.radius
    else:
        centre = np.asarray(centre, float)
        radius = float(np.max(np.linalg.norm(x - centre, axis=1) + a))
    dist = np.linalg.norm(x - centre, axis=1)
    edges = np.linspace(0.0, radius, int(n_shells) + 1)
    # covered volume inside each ball of radius edges[k], summed over spheres (only the spheres that
    # reach the shell's edge contribute a partial lens; others are all in or all out)
    inside = np.array([ball_intersection_volume(r, a, dist, d).sum() for r in edges])
    shell = np.diff(ball_volume(edges, d))
    phi = np.diff(inside) / shell
    core = inside[1:] / ball_volume(edges[1:], d)
    mid = 0.5 * (edges[1:] + edges[:-1])
    return xr.Dataset(
        {"phi": ("r", phi, {"description": "fraction of the shell covered by spheres"}),
         "phi_core_average": ("r", core, {"description": "fraction of the ball of radius r_outer covered"}),
         "r_inner": ("r", edges[:-1]), "r_outer": ("r", edges[1:])},
        coords={"r": mid},
        attrs={"hardpack_kind": "radial_density_profile", "radius": float(radius), "a": float(a.mean()),
               "centre": centre.tolist(), "N": packing.n_particles, "d": d,
               "source": "Donev 2006, Ch. 7, Fig. 7.5 (phi(r)); exact sphere-ball intersections"},
    )


@dataclass(frozen=True)
class BulkExtrapolation:
    """Linear fit phi_avg = phi_0 - s delta over delta = a / R (Donev 2006, Eq. 7.2).

    ``phi0`` is the extrapolation to delta -> 0 with standard error ``phi0_err`` (ordinary least
    squares; the residual variance estimates the scatter, so at least 3 points are needed);
    ``slope`` = -3 m_0 with its error, ``n`` points.
    """

    phi0: float
    phi0_err: float
    slope: float
    slope_err: float
    n: int


def extrapolate_bulk_density(delta, phi_avg) -> BulkExtrapolation:
    """Extrapolate average container densities to the bulk (Donev 2006, Eq. 7.2 and Fig. 7.6).

    Parameters
    ----------
    delta : array_like
        a / R of each packing (a the particle length scale, R the container radius).
    phi_avg : array_like
        Its average volume fraction (N V_particle / V_container).

    Returns
    -------
    BulkExtrapolation
        Intercept phi_0 and slope of the least-squares line, with standard errors.
    """
    x = np.asarray(delta, float)
    y = np.asarray(phi_avg, float)
    if x.shape != y.shape or x.ndim != 1:
        raise InvalidInputError(f"delta and phi_avg must be 1-d arrays of one length, got {x.shape} and {y.shape}")
    if len(x) < 3 or not (np.isfinite(x).all() and np.isfinite(y).all()) or np.ptp(x) == 0:
        raise InvalidInputError("the extrapolation needs at least 3 finite points with different a/R "
                                "(the scatter about the line gives the error)")
    design = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    resid = y - design @ coef
    s2 = float(resid @ resid) / (len(x) - 2)
    cov = s2 * np.linalg.inv(design.T @ design)
    return BulkExtrapolation(float(coef[0]), float(np.sqrt(cov[0, 0])), float(coef[1]),
                             float(np.sqrt(cov[1, 1])), len(x))


def window_fluctuations(packing, window_radii, n_windows: int = 1000, seed: int = 0) -> xr.Dataset:
    """Volume fraction inside random spherical windows of a periodic packing (Donev 2006, Fig. 7.3).

    For each window radius R, ``n_windows`` centres are drawn uniformly in the cell
    (``numpy.random.default_rng(seed)``); phi(R) = sum_i V(window ∩ sphere_i) / V(window) with
    exact intersection volumes (:func:`ball_intersection_volume`) of the nearest image of each
    sphere (the only one that can reach the window, R + a_max <= L_min / 2).

    Parameters
    ----------
    packing : Packing
        A sphere packing in a periodic orthorhombic cell.
    window_radii : array_like
        Window radii R, each positive and at most L_min / 2 - a_max.
    n_windows : int, default 1000
        Random windows per radius.
    seed : int, default 0
        Seed of the window centres.

    Returns
    -------
    xarray.Dataset
        On dimension ``R``: ``phi_mean``, ``sigma_phi`` (standard deviation over windows) and
        ``sigma_phi_err`` (its standard error, sigma / sqrt(2 (n - 1)) for near-Gaussian
        scatter); the fit of the text for comparison is sigma_phi ~ 0.1 (2R/D)^-2.

    Raises
    ------
    InvalidInputError
        If the packing is not of spheres in a periodic orthorhombic cell, or a window radius is
        out of range.
    """
    _sphere_check(packing, "the window fluctuations")
    if packing.boundary.kind != "periodic" or not packing.is_orthorhombic:
        raise InvalidInputError("window fluctuations need a periodic orthorhombic cell")
    from scipy.spatial import cKDTree

    d = packing.dim
    box = np.diag(packing.lattice).copy()
    radii_w = np.atleast_1d(np.asarray(window_radii, float))
    a = packing.radii
    if (radii_w <= 0).any() or (radii_w + a.max() > box.min() / 2).any():
        raise InvalidInputError(f"window radii must be positive and at most L/2 - a_max = "
                                f"{box.min() / 2 - a.max():.4g} (one periodic image per sphere)")
    if int(n_windows) != n_windows or n_windows < 2:
        raise InvalidInputError(f"n_windows must be an integer >= 2, got {n_windows!r}")
    x = packing.wrapped().positions % box
    tree = cKDTree(x, boxsize=box)
    rng = np.random.default_rng(seed)
    mean, sd = [], []
    for R in radii_w:
        centres = rng.random((int(n_windows), d)) * box
        vals = np.empty(int(n_windows))
        for w, c in enumerate(centres):
            idx = np.asarray(tree.query_ball_point(c, R + a.max()), dtype=np.int64)
            dx = x[idx] - c
            dx -= box * np.rint(dx / box)
            dist = np.sqrt(np.einsum("ij,ij->i", dx, dx))
            vals[w] = ball_intersection_volume(R, a[idx], dist, d).sum() / ball_volume(R, d)
        mean.append(vals.mean())
        sd.append(vals.std(ddof=1))
    sd = np.array(sd)
    return xr.Dataset(
        {"phi_mean": ("R", np.array(mean)), "sigma_phi": ("R", sd),
         "sigma_phi_err": ("R", sd / np.sqrt(2.0 * (int(n_windows) - 1)))},
        coords={"R": radii_w},
        attrs={"hardpack_kind": "window_fluctuations", "n_windows": int(n_windows), "seed": int(seed),
               "N": packing.n_particles, "d": d, "phi": float(packing.phi),
               "source": "Donev 2006, Ch. 7, Fig. 7.3 (fit sigma_phi ~ 0.1 (2R/D)^-2)"},
    )
