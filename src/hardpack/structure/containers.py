"""Finite-container and window analysis of sphere packings (Donev 2006, Ch. 7, Sec. 7.3).

- :func:`radial_density_profile`: phi(r), the fraction of the spherical shell [r, r + dr] about the
  container centre covered by the spheres (Fig. 7.5), exact: each sphere contributes its
  intersection volume with the ball of radius r + dr minus that with the ball of radius r
  (:func:`ball_intersection_volume`).
- :func:`extrapolate_bulk_density`: the linear fit of the average density against delta = a / R
  and its value at delta -> 0 with a standard error (Eq. 7.2, Fig. 7.6).
- :func:`window_fluctuations`: sigma_phi(R), the standard deviation of the volume fraction inside
  spherical windows of radius R placed uniformly at random in a periodic packing (Fig. 7.3).
- :func:`core_density`, :func:`container_summary`: the per-packing numbers of a container study
  (average density, delta = a / R, the density of the core away from the wall) over (N, seed),
  with the Eq. 7.2 extrapolation.
- :func:`ellipsoid_radial_density_profile`: phi(r) of ellipsoids (ellipses), exact to a stated
  tolerance: each particle contributes its intersection volume with the ball of radius r
  (:func:`hardpack.geometry.ellipsoid_ball.ellipsoid_ball_volume`); :func:`core_density` uses it
  for ellipsoids.
- :func:`ellipsoid_container_summary`: the same extrapolation for ellipsoids in containers (the
  M&M-shaped spheroids of Sec. 7.3.2.1), from the packings' average densities, with their core
  densities when given their profiles.
- :func:`window_study`, :func:`fit_window_power_law`: sigma_phi against the window diameter 2R/D
  over several periodic packings and the log-log fit of the text, sigma_phi ~ 0.1 (2R/D)^-2.

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
from hardpack.geometry.ellipsoid_ball import TOLERANCE, covered_volumes
from hardpack.geometry.neighbours import build_grid
from hardpack.geometry.neighbours.grid import points_within


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

    Attributes
    ----------
    phi0, phi0_err : float
        Extrapolated bulk density and its standard error.
    slope, slope_err : float
        Slope s and its standard error.
    n : int
        Points fitted.
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
    return BulkExtrapolation(*_line_fit(x, y), len(x))


def _line_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """Ordinary least-squares line y = c0 + c1 x: c0, its standard error, c1, its standard error
    (the residual variance estimates the scatter; at least 3 points)."""
    design = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    resid = y - design @ coef
    s2 = float(resid @ resid) / (len(x) - 2)
    cov = s2 * np.linalg.inv(design.T @ design)
    return float(coef[0]), float(np.sqrt(cov[0, 0])), float(coef[1]), float(np.sqrt(cov[1, 1]))


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
    d = packing.dim
    box = np.diag(packing.lattice).copy()
    radii_w = np.atleast_1d(np.asarray(window_radii, float))
    a = packing.radii
    if (radii_w <= 0).any() or (radii_w + a.max() > box.min() / 2).any():
        raise InvalidInputError(f"window radii must be positive and at most L/2 - a_max = "
                                f"{box.min() / 2 - a.max():.4g} (one periodic image per sphere)")
    if int(n_windows) != n_windows or n_windows < 2:
        raise InvalidInputError(f"n_windows must be an integer >= 2, got {n_windows!r}")
    reach = 0.5 * (radii_w.max() + a.max())
    grid = build_grid(packing.fractional(), packing.lattice, np.full(packing.n_particles, reach), per_cell=2)
    rng = np.random.default_rng(seed)
    mean, sd = [], []
    for R in radii_w:
        centres = rng.random((int(n_windows), d))
        start, member, dist = points_within(centres, grid.x, grid.lattice, 1.0 / grid.heights, grid.n_cells,
                                            grid.strides, grid.cell_offset, grid.cell_start, grid.order,
                                            R + a.max())
        window = np.repeat(np.arange(int(n_windows)), np.diff(start))
        covered = ball_intersection_volume(R, a[member], dist, d)
        vals = np.bincount(window, weights=covered, minlength=int(n_windows)) / ball_volume(R, d)
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


def length_unit(packing) -> float:
    """Donev's particle length scale a of a container study (Donev 2006, Sec. 7.3.1.2): the mean
    radius of spheres (a = D/2), the geometric mean semiaxis (O_1 O_2 ... O_d)^(1/d) of ellipsoids
    averaged over the particles.

    Parameters
    ----------
    packing : Packing
        A packing of spheres or ellipsoids.

    Returns
    -------
    float
        a.
    """
    if packing.shape.kind == "ellipsoid":
        return float(np.mean(np.prod(packing.shape.semiaxes, axis=1) ** (1.0 / packing.dim)))
    return float(packing.radii.mean())


def core_density(packing, margin: float) -> float:
    """Fraction of the ball of radius R - margin a about the container centre covered by the particles.

    Donev 2006, Sec. 7.3.1.2 (Fig. 7.5): the density profile reaches the core density "of about
    0.64" only after several layers near the wall are removed; ``margin`` is that distance from
    the wall in units of a (spheres: the mean radius, Donev's a = D/2; ellipsoids: the geometric
    mean semiaxis (O_1 O_2 O_3)^(1/3) averaged over the particles).

    Parameters
    ----------
    packing : Packing
        Spheres or ellipsoids (d = 2 or 3) in a spherical container.
    margin : float
        Distance of the core from the wall in units of a, 0 <= margin < R / a.

    Returns
    -------
    float
        The covered fraction of the core ball: exact sphere-ball intersections for spheres, the
        ellipsoid-ball intersection volumes of :func:`ellipsoid_radial_density_profile` for
        ellipsoids (each to 1e-10 of its particle's volume).

    Raises
    ------
    InvalidInputError
        Without a spherical container, or when the margin leaves no core.
    """
    if packing.shape.kind == "ellipsoid":
        _ellipsoid_container_check(packing, "the core density")
    else:
        _sphere_check(packing, "the core density")
        if packing.boundary.kind != "spherical_container":
            raise InvalidInputError("the core density needs a packing in a spherical container")
    a = length_unit(packing)
    radius = packing.boundary.radius - float(margin) * a
    if not (np.isfinite(margin) and margin >= 0 and radius > 0):
        raise InvalidInputError(f"core margin {margin!r} (in units of a = {a:.4g}) must be >= 0 and leave a "
                                f"core inside the container of radius {packing.boundary.radius:.4g}")
    if packing.shape.kind == "ellipsoid":
        return float(_covered(packing, [radius])[0] / ball_volume(radius, packing.dim))
    dist = np.linalg.norm(packing.positions - np.asarray(packing.boundary.centre), axis=1)
    covered = ball_intersection_volume(radius, packing.radii, dist, packing.dim).sum()
    return float(covered / ball_volume(radius, packing.dim))


def container_summary(profiles, fit_min_n: int = 1, bulk=()) -> xr.Dataset:
    """The packings of a container study over (N, seed), the Eq. 7.2 bulk extrapolation and the
    density of periodic packings made with the same protocol.

    Parameters
    ----------
    profiles : sequence of xarray.Dataset
        Radial profiles (:func:`radial_density_profile`) with the attributes ``N``, ``seed``,
        ``phi`` (the average density N V_particle / V_container), ``a_over_R`` and ``phi_core``
        (:func:`core_density`) and ``core_margin``.
    fit_min_n : int, default 1
        The extrapolation uses the packings with N >= fit_min_n (Donev: "a range of (sufficiently
        large) container sizes").
    bulk : sequence of xarray.Dataset, optional
        Jammed periodic packings of the containers' compression protocol (attributes ``N``,
        ``seed``, ``phi``): the bulk density phi_0 that the extrapolation estimates (Donev 2006,
        Sec. 7.3.2.1: "the core density phi_0 will approach the bulk packing density").

    Returns
    -------
    xarray.Dataset
        Dimension ``sample`` with coordinates ``N`` and ``seed`` and variables ``a_over_R``,
        ``phi_avg``, ``phi_core``; attributes ``phi0``, ``phi0_err``, ``slope``, ``slope_err``
        (:func:`extrapolate_bulk_density` over every packing with N >= fit_min_n, NaN when fewer
        than 3 such packings or only one a/R), ``n_fit``, ``n_sizes_fit``, ``fit_min_n``,
        ``core_margin``. ``phi_wall_layer`` is the density of the layer within one a of the wall,
        the part of Eq. 7.1's wall correction that wall curvature changes most;
        ``phi0_fixed_layer`` +- ``phi0_fixed_layer_err`` is the same fit after
        :func:`fixed_wall_layer_density` (every wall layer at the largest container's density). With ``bulk``:
        dimension ``bulk_sample`` (``bulk_seed``, ``phi_bulk``) and attributes ``phi_bulk``, its
        standard error ``phi_bulk_err`` (NaN for one packing), ``n_bulk``, ``bulk_N``.

    Raises
    ------
    InvalidInputError
        If there are no profiles, a profile lacks an attribute, (N, seed) repeats, or the
        profiles have different core margins.
    """
    profiles = list(profiles)
    if not profiles:
        raise InvalidInputError("a container summary needs at least one radial profile")
    keys = ("N", "seed", "phi", "a_over_R", "phi_core", "core_margin")
    for p in profiles:
        missing = [k for k in keys if k not in p.attrs]
        if missing:
            raise InvalidInputError(f"radial profile {p.attrs.get('source', '?')} lacks the attributes {missing}")
    rows = sorted((int(p.attrs["N"]), int(p.attrs["seed"]), float(p.attrs["a_over_R"]), float(p.attrs["phi"]),
                   float(p.attrs["phi_core"])) for p in profiles)
    pairs = [r[:2] for r in rows]
    if len(set(pairs)) != len(pairs):
        raise InvalidInputError(f"a (N, seed) pair repeats among the profiles: {pairs}")
    margins = {float(p.attrs["core_margin"]) for p in profiles}
    if len(margins) != 1:
        raise InvalidInputError(f"the profiles have different core margins {sorted(margins)}")
    layer = {(int(p.attrs["N"]), int(p.attrs["seed"])): wall_layer_density(p) for p in profiles}
    n, seed, delta, phi, core = (np.array(c) for c in zip(*rows))
    wall = np.array([layer[(int(a), int(b))] for a, b in zip(n, seed)])
    use = n >= fit_min_n
    fit = {"phi0": np.nan, "phi0_err": np.nan, "slope": np.nan, "slope_err": np.nan,
           "phi0_fixed_layer": np.nan, "phi0_fixed_layer_err": np.nan}
    if use.sum() >= 3 and np.ptp(delta[use]) > 0:
        f = extrapolate_bulk_density(delta[use], phi[use])
        fixed = extrapolate_bulk_density(delta[use], fixed_wall_layer_density(delta, phi, wall, n)[use])
        fit = {"phi0": f.phi0, "phi0_err": f.phi0_err, "slope": f.slope, "slope_err": f.slope_err,
               "phi0_fixed_layer": fixed.phi0, "phi0_fixed_layer_err": fixed.phi0_err}
    data = {"a_over_R": ("sample", delta), "phi_avg": ("sample", phi), "phi_core": ("sample", core),
            "phi_wall_layer": ("sample", wall)}
    coords = {"N": ("sample", n), "seed": ("sample", seed)}
    extra = _bulk_density(bulk, data, coords)
    return xr.Dataset(
        data, coords=coords,
        attrs={"hardpack_kind": "container_summary", **fit, **extra, "n_fit": int(use.sum()),
               "n_sizes_fit": len(set(n[use].tolist())), "fit_min_n": int(fit_min_n),
               "core_margin": margins.pop(), "index": '["N", "seed"]',
               "source": "Donev 2006, Sec. 7.3.2.1, Eq. 7.2 and Fig. 7.6 (linear fit in a/R)"},
    )


def window_study(packings, n_radii: int = 12, min_diameter: float = 1.0, n_windows: int = 1000,
                 seed: int = 0) -> xr.Dataset:
    """sigma_phi against the window diameter 2R/D over periodic sphere packings (Donev 2006, Fig. 7.3).

    The window diameters 2R/D are ``n_radii`` values spaced evenly in log from ``min_diameter``
    to the largest that every packing allows (2R/D <= L_min / D - 1, one image per sphere);
    D is each packing's mean diameter. Each packing gets :func:`window_fluctuations` with
    ``n_windows`` windows per radius.

    Parameters
    ----------
    packings : sequence of Packing
        Sphere packings in periodic orthorhombic cells.
    n_radii : int, default 12
        Window sizes, >= 2.
    min_diameter : float, default 1.0
        Smallest 2R/D, positive and below the largest allowed.
    n_windows : int, default 1000
        Windows per radius and packing.
    seed : int, default 0
        Seed of the window centres (the same for every packing).

    Returns
    -------
    xarray.Dataset
        ``sigma_phi``, ``sigma_phi_err`` and ``phi_mean`` on (``sample``, ``x``) with x = 2R/D,
        ``N`` and ``phi`` per sample.

    Raises
    ------
    InvalidInputError
        Without packings, for bad counts, or when ``min_diameter`` is not below the largest
        allowed window.
    """
    packings = list(packings)
    if not packings:
        raise InvalidInputError("the window study needs at least one packing")
    if int(n_radii) != n_radii or n_radii < 2:
        raise InvalidInputError(f"n_radii must be an integer >= 2, got {n_radii!r}")
    for p in packings:
        _sphere_check(p, "the window study")
        if p.boundary.kind != "periodic" or not p.is_orthorhombic:
            raise InvalidInputError("the window study needs packings in periodic orthorhombic cells")
    diameters = [2.0 * float(p.radii.mean()) for p in packings]
    largest = min((np.diag(p.lattice).min() / 2 - p.radii.max()) * 2 / dia for p, dia in zip(packings, diameters))
    if not (np.isfinite(min_diameter) and 0 < min_diameter < largest):
        raise InvalidInputError(f"min_diameter must be in (0, {largest:.4g}) (the largest window 2R/D the "
                                f"cells allow), got {min_diameter!r}")
    x = np.geomspace(min_diameter, largest, int(n_radii))
    runs = [window_fluctuations(p, x * dia / 2 * (1 - 1e-12), n_windows, seed) for p, dia in zip(packings, diameters)]
    stack = {name: (("sample", "x"), np.array([r[name].values for r in runs]))
             for name in ("sigma_phi", "sigma_phi_err", "phi_mean")}
    return xr.Dataset(
        {**stack, "N": ("sample", np.array([p.n_particles for p in packings])),
         "phi": ("sample", np.array([p.phi for p in packings]))},
        coords={"x": x},
        attrs={"hardpack_kind": "window_study", "n_windows": int(n_windows), "seed": int(seed),
               "x_description": "window diameter over sphere diameter, 2R/D",
               "source": "Donev 2006, Sec. 7.3.1.1 and Fig. 7.3 (fit sigma_phi ~ 0.1 (2R/D)^-2)"},
    )


@dataclass(frozen=True)
class PowerLaw:
    """sigma_phi = prefactor (2R/D)^exponent fitted in log-log (ordinary least squares, standard
    errors from the scatter about the line), and the prefactor with the exponent fixed at -2 of
    Donev 2006, Fig. 7.3 (mean of sigma_phi (2R/D)^2 with its standard error); ``n`` points.

    Attributes
    ----------
    exponent, exponent_err : float
        Fitted exponent and its standard error.
    prefactor, prefactor_err : float
        Fitted prefactor and its standard error.
    prefactor_fixed, prefactor_fixed_err : float
        Prefactor with the exponent fixed at -2, and its standard error.
    n : int
        Points fitted.
    """

    exponent: float
    exponent_err: float
    prefactor: float
    prefactor_err: float
    prefactor_fixed: float
    prefactor_fixed_err: float
    n: int


def fit_window_power_law(x, sigma, x_min: float = 0.0) -> PowerLaw:
    """Fit sigma_phi(2R/D) by a power law over 2R/D >= ``x_min`` (Donev 2006, Fig. 7.3).

    Parameters
    ----------
    x : array_like
        Window diameters 2R/D.
    sigma : array_like
        sigma_phi at each (one value per x: average the packings first).
    x_min : float, default 0
        Smallest window of the fit (small windows see single spheres, not the R^-2 regime).

    Returns
    -------
    PowerLaw
        Exponent and prefactor with standard errors.

    Raises
    ------
    InvalidInputError
        With fewer than 3 finite positive points in the range.
    """
    x = np.asarray(x, float)
    y = np.asarray(sigma, float)
    if x.shape != y.shape or x.ndim != 1:
        raise InvalidInputError(f"x and sigma must be 1-d arrays of one length, got {x.shape} and {y.shape}")
    use = (x >= x_min) & np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if use.sum() < 3:
        raise InvalidInputError(f"the power-law fit needs at least 3 positive points with 2R/D >= {x_min:g}, "
                                f"got {int(use.sum())}")
    log_a, log_a_err, exponent, exponent_err = _line_fit(np.log(x[use]), np.log(y[use]))
    scaled = y[use] * x[use] ** 2
    return PowerLaw(exponent, exponent_err, float(np.exp(log_a)), float(np.exp(log_a) * log_a_err),
                    float(scaled.mean()), float(scaled.std(ddof=1) / np.sqrt(scaled.size)), int(use.sum()))


def wall_layer_density(profile: xr.Dataset) -> float:
    """Volume fraction of the shell R - a < r <= R next to the wall, from a radial profile
    (:func:`radial_density_profile`; shells cut by the layer's edge count by their overlap).

    Parameters
    ----------
    profile : xarray.Dataset
        Radial profile with attributes radius and a.

    Returns
    -------
    float
        The volume fraction.

    Raises
    ------
    InvalidInputError
        If an attribute is missing.
    """
    for k in ("radius", "a"):
        if k not in profile.attrs:
            raise InvalidInputError(f"radial profile {profile.attrs.get('source', '?')} lacks the attribute {k!r}")
    radius, a = float(profile.attrs["radius"]), float(profile.attrs["a"])
    inner = np.clip(profile["r_inner"].values, radius - a, radius)
    outer = np.clip(profile["r_outer"].values, radius - a, radius)
    vol = outer**3 - inner**3
    return float(np.sum(profile["phi"].values * vol) / (radius**3 - (radius - a) ** 3))


def fixed_wall_layer_density(delta, phi_avg, phi_layer, n) -> np.ndarray:
    """Average densities with every container's wall layer at the density of the largest
    container's (mean over its seeds): the test of Eq. 7.1's assumption that the wall
    correction does not depend on R (Donev 2006, Sec. 7.3.2.1).

    The layer R - a < r <= R holds the fraction 1 - (1 - a/R)^3 of a container's volume, so

        phi_avg' = phi_avg + (1 - (1 - a/R)^3) (phi_layer(N_max) - phi_layer(N)).

    A linear fit of phi_avg' in a/R then extrapolates without the curvature dependence of the
    first layer (its density rises with R); what Eq. 7.2 leaves in the slope is the wall
    correction of the largest container.

    Parameters
    ----------
    delta, phi_avg, phi_layer : array_like
        a / R, the average density and the wall-layer density (:func:`wall_layer_density`) of
        each packing.
    n : array_like of int
        Its number of particles; the reference layer is the mean over the largest N.

    Returns
    -------
    numpy.ndarray
        phi_avg' of each packing.
    """
    delta, phi_avg, phi_layer, n = (np.asarray(v) for v in (delta, phi_avg, phi_layer, n))
    if not (delta.shape == phi_avg.shape == phi_layer.shape == n.shape) or delta.ndim != 1:
        raise InvalidInputError("delta, phi_avg, phi_layer and n must be 1-d arrays of one length, got shapes "
                                f"{delta.shape}, {phi_avg.shape}, {phi_layer.shape}, {n.shape}")
    reference = float(np.mean(phi_layer[n == n.max()]))
    return phi_avg + (1.0 - (1.0 - delta) ** 3) * (reference - phi_layer)


def _bulk_density(bulk, data: dict, coords: dict) -> dict:
    """Add the periodic packings of the protocol to ``data`` / ``coords``; their attributes."""
    bulk = list(bulk)
    if not bulk:
        return {}
    for p in bulk:
        missing = [k for k in ("N", "seed", "phi") if k not in p.attrs]
        if missing:
            raise InvalidInputError(f"bulk packing {p.attrs.get('source', '?')} lacks the attributes {missing}")
    sizes = {int(p.attrs["N"]) for p in bulk}
    if len(sizes) != 1:
        raise InvalidInputError(f"the bulk packings have different N {sorted(sizes)}: give one ensemble")
    seeds = [int(p.attrs["seed"]) for p in bulk]
    if len(set(seeds)) != len(seeds):
        raise InvalidInputError(f"a seed repeats among the bulk packings: {seeds}")
    values = np.array([float(p.attrs["phi"]) for p in bulk])
    data["phi_bulk"] = ("bulk_sample", values)
    coords["bulk_seed"] = ("bulk_sample", np.array(seeds))
    err = float(values.std(ddof=1) / np.sqrt(len(values))) if len(values) > 1 else float("nan")
    return {"phi_bulk": float(values.mean()), "phi_bulk_err": err, "n_bulk": len(values), "bulk_N": sizes.pop()}


def ellipsoid_container_summary(packings, seeds, fit_min_n: int = 1, profiles=()) -> xr.Dataset:
    """Jammed ellipsoids in spherical containers over (N, seed) and the Eq. 7.2 bulk extrapolation
    (Donev 2006, Sec. 7.3.2.1 and Fig. 7.6: M&M-shaped oblate spheroids, phi_0 = 0.700 +- 0.002).

    The average density is the packing's phi (particle volume over the container's), the length
    unit the geometric mean semiaxis a = (O_1 O_2 O_3)^(1/3) (Donev 2006, Sec. 7.3.1.2: a = D/2 for
    spheres), averaged over the particles (:func:`length_unit`), and the line
    phi_avg = phi_0 - s a/R is fitted over the packings with N >= fit_min_n
    (:func:`extrapolate_bulk_density`). With the packings' radial profiles
    (:func:`ellipsoid_radial_density_profile`) the summary also has the core density and the wall
    layer's density of each packing, as :func:`container_summary` has for spheres.

    Parameters
    ----------
    packings : sequence of Packing
        Ellipsoids in spherical containers.
    seeds : sequence of int
        The seed of each packing.
    fit_min_n : int, default 1
        Smallest N in the fit.
    profiles : sequence of xarray.Dataset, optional
        One radial profile per packing, in the same order, with the attributes ``N``, ``seed``,
        ``phi_core`` (:func:`core_density`) and ``core_margin`` (one margin for all).

    Returns
    -------
    xarray.Dataset
        Dimension ``sample`` (coordinates ``N``, ``seed``) with ``a_over_R`` and ``phi_avg``, and
        with profiles ``phi_core`` and ``phi_wall_layer`` (:func:`wall_layer_density`) and the
        attribute ``core_margin``; attributes ``phi0``, ``phi0_err``, ``slope``, ``slope_err`` (NaN
        with fewer than 3 packings or one a/R in the fit), ``n_fit``, ``n_sizes_fit``,
        ``fit_min_n``, ``semiaxes`` (of the first particle of the first packing) and
        ``hardpack_kind`` "ellipsoid_container_summary".

    Raises
    ------
    InvalidInputError
        No packings, a packing that is not ellipsoids in a spherical container, seeds of another
        length, a repeated (N, seed), or profiles that do not match the packings one to one (or
        lack an attribute, or differ in core margin).
    """
    packings, seeds, profiles = list(packings), [int(s) for s in seeds], list(profiles)
    if not packings or len(packings) != len(seeds):
        raise InvalidInputError(f"an ellipsoid container summary needs packings and one seed each, got "
                                f"{len(packings)} packings and {len(seeds)} seeds")
    if profiles and len(profiles) != len(packings):
        raise InvalidInputError(f"give one radial profile per packing, got {len(profiles)} for "
                                f"{len(packings)} packings")
    rows = []
    for k, (p, seed) in enumerate(zip(packings, seeds)):
        if p.shape.kind != "ellipsoid" or p.boundary.kind != "spherical_container":
            raise InvalidInputError(f"expected ellipsoids in a spherical container, got {p!r}")
        core = (_profile_core(profiles[k], p.n_particles, seed),) if profiles else ()
        rows.append((p.n_particles, seed, length_unit(p) / p.boundary.radius, float(p.phi), *core))
    rows.sort(key=lambda row: row[:2])
    pairs = [r[:2] for r in rows]
    if len(set(pairs)) != len(pairs):
        raise InvalidInputError(f"a (N, seed) pair repeats among the packings: {pairs}")
    n, seed, delta, phi = (np.array(c) for c in list(zip(*rows))[:4])
    use = n >= fit_min_n
    fit = {"phi0": np.nan, "phi0_err": np.nan, "slope": np.nan, "slope_err": np.nan}
    if use.sum() >= 3 and np.ptp(delta[use]) > 0:
        f = extrapolate_bulk_density(delta[use], phi[use])
        fit = {"phi0": f.phi0, "phi0_err": f.phi0_err, "slope": f.slope, "slope_err": f.slope_err}
    data = {"a_over_R": ("sample", delta), "phi_avg": ("sample", phi)}
    extra = {}
    if profiles:
        margins = {float(q.attrs["core_margin"]) for q in profiles}
        if len(margins) != 1:
            raise InvalidInputError(f"the profiles have different core margins {sorted(margins)}")
        data["phi_core"] = ("sample", np.array([r[4][0] for r in rows]))
        data["phi_wall_layer"] = ("sample", np.array([r[4][1] for r in rows]))
        extra["core_margin"] = margins.pop()
    return xr.Dataset(
        data,
        coords={"N": ("sample", n), "seed": ("sample", seed)},
        attrs={"hardpack_kind": "ellipsoid_container_summary", **fit, **extra, "n_fit": int(use.sum()),
               "n_sizes_fit": len(set(n[use].tolist())), "fit_min_n": int(fit_min_n),
               "semiaxes": [float(v) for v in packings[0].shape.semiaxes[0]], "index": '["N", "seed"]',
               "source": "Donev 2006, Sec. 7.3.2.1, Eq. 7.2 and Fig. 7.6 (linear fit in a/R, a the "
                         "geometric mean semiaxis)"},
    )


def _profile_core(profile: xr.Dataset, n: int, seed: int) -> tuple[float, float]:
    """The core density and the wall layer's density of one packing's radial profile, checked
    against the packing's (N, seed)."""
    missing = [k for k in ("N", "seed", "phi_core", "core_margin") if k not in profile.attrs]
    if missing:
        raise InvalidInputError(f"radial profile {profile.attrs.get('source', '?')} lacks the attributes {missing}")
    if (int(profile.attrs["N"]), int(profile.attrs["seed"])) != (n, seed):
        raise InvalidInputError(f"radial profile of (N, seed) = ({profile.attrs['N']}, {profile.attrs['seed']}) "
                                f"given for the packing ({n}, {seed}): give the profiles in the packings' order")
    return float(profile.attrs["phi_core"]), wall_layer_density(profile)


def _ellipsoid_container_check(packing, user: str) -> None:
    if packing.shape.kind != "ellipsoid" or packing.boundary.kind != "spherical_container":
        raise InvalidInputError(f"{user} handles ellipsoids (d = 2 or 3) in a spherical container, got "
                                f"{packing.shape.name} with {packing.boundary.name}; sphere packings have the exact "
                                "radial_density_profile and core_density")
    if not (np.isfinite(packing.positions).all() and np.isfinite(packing.shape.semiaxes).all()):
        raise InvalidInputError(f"{user}: the packing has non-finite positions or semiaxes")


def _covered(packing, radii) -> np.ndarray:
    """Volume of the particles inside each ball of ``radii`` about the container centre."""
    shape = packing.shape
    covered, _ = covered_volumes(np.ascontiguousarray(packing.positions, dtype=float),
                                 np.ascontiguousarray(shape.semiaxes, dtype=float),
                                 np.ascontiguousarray(shape.rotations(), dtype=float),
                                 np.asarray(packing.boundary.centre, dtype=float),
                                 np.ascontiguousarray(radii, dtype=float), TOLERANCE)
    return covered


def ellipsoid_radial_density_profile(packing, n_shells: int = 200) -> xr.Dataset:
    """phi(r) of ellipsoids (or ellipses) about the centre of their spherical container (Donev 2006,
    Sec. 7.3.1.2, Fig. 7.5), from exact intersection volumes.

    The covered volume inside the ball of radius r is the sum over particles of each particle's
    intersection volume with the ball (:func:`hardpack.geometry.ellipsoid_ball.ellipsoid_ball_volume`:
    closed form in 2D, adaptive quadrature of closed-form slice areas in 3D, to 1e-10 of the
    particle's volume; particles wholly inside or outside the ball, or holding it, are classified
    exactly without quadrature); phi of the shell [r_k, r_k+1] is the difference of the covered
    volumes over the shell's volume. Donev evaluated phi(r) with the plane tangent to the ball in
    place of the ball (the footnote to Fig. 7.5), which overcounts by about (3/5) phi (a/r)^2 in a
    uniform core of radius r; the exact volumes have no such bias, also near the centre.

    Parameters
    ----------
    packing : Packing
        Ellipsoids (d = 3) or ellipses (d = 2) in a spherical container.
    n_shells : int, default 200
        Equal-width shells from r = 0 to the container radius.

    Returns
    -------
    xarray.Dataset
        The variables of :func:`radial_density_profile`: ``phi`` on dimension ``r`` (shell
        mid-radii), ``r_inner`` / ``r_outer``, and ``phi_core_average`` = d int_0^r x^(d-1) phi(x) dx / r^d
        at the shell's outer radius (Donev 2006, Sec. 7.3.2.3, the core average). Attributes
        ``radius``, the length unit ``a`` (the geometric mean semiaxis (O_1 O_2 O_3)^(1/3), averaged
        over the particles; Donev 2006, Sec. 7.3.1.2), ``centre``, ``N``, ``d``, ``method``
        "exact" and ``tolerance`` (of each particle's volume).

    Raises
    ------
    InvalidInputError
        If the packing is not ellipsoids in a spherical container, has non-finite coordinates, or
        ``n_shells`` is not a positive integer.
    """
    _ellipsoid_container_check(packing, "the ellipsoid radial density profile")
    if not (np.isfinite(n_shells) and int(n_shells) == n_shells and n_shells >= 1):
        raise InvalidInputError(f"n_shells must be a positive integer, got {n_shells!r}")
    d = packing.dim
    radius = packing.boundary.radius
    edges = np.linspace(0.0, radius, int(n_shells) + 1)
    covered = _covered(packing, edges)
    ball = ball_volume(edges, d)
    mid = 0.5 * (edges[1:] + edges[:-1])
    a = length_unit(packing)
    return xr.Dataset(
        {"phi": ("r", np.diff(covered) / np.diff(ball), {"description": "fraction of the shell covered by particles"}),
         "phi_core_average": ("r", covered[1:] / ball[1:],
                              {"description": "fraction of the ball of radius r_outer covered"}),
         "r_inner": ("r", edges[:-1]), "r_outer": ("r", edges[1:])},
        coords={"r": mid},
        attrs={"hardpack_kind": "radial_density_profile", "radius": float(radius), "a": a,
               "centre": list(packing.boundary.centre), "N": packing.n_particles, "d": d,
               "method": "exact", "tolerance": TOLERANCE,
               "source": "Donev 2006, Ch. 7, Fig. 7.5 (phi(r)); exact ellipsoid-ball intersection volumes"},
    )
