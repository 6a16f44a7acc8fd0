"""Figures of the finite-container study of spheres and ellipsoids (Donev 2006, Sec. 7.3): the
radial density profile near the wall (after Fig. 7.5; ellipsoids one panel per shape), the average
density against a/R with the Eq. 7.2 linear extrapolation (after Fig. 7.6) and the window
fluctuations sigma_phi(2R/D) of periodic packings (after Fig. 7.3)."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.structure.containers import fit_window_power_law
from hardpack.validation.rows import seed_statistics

#: Donev 2006, Sec. 7.3.2.1: the extrapolated bulk density of jammed spheres, 0.642 +- 0.002
DONEV_PHI0 = (0.642, 0.002)
#: Donev 2006, Sec. 7.3.2.1: simulated bulk densities of the named ellipsoid shapes
DONEV_ELLIPSOID_PHI0 = {"mm": ("M&M", 0.700, 0.002), "ollipsoid": ("ollipsoid", 0.741, 0.002)}
#: Donev 2006, Fig. 7.5: the core density far from the wall, about 0.64
DONEV_CORE = 0.64


def plot_radial_profile(profiles):
    """phi(r) against the distance from the wall (R - r) / a of packings in spherical containers,
    with the core density 0.64 of Donev 2006, Fig. 7.5 (dashed) and each packing's core density
    (dotted, the covered fraction of the ball r <= R - core_margin a).

    Parameters
    ----------
    profiles : sequence of xarray.Dataset
        Radial profiles (:func:`hardpack.structure.containers.radial_density_profile`) with the
        attributes ``N``, ``seed``, ``a``, ``radius``, ``phi_core`` and ``core_margin``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure(figsize=(6.0, 3.2))
    _draw_profiles(ax, profiles)
    ax.axhline(DONEV_CORE, color="k", ls="--", lw=1, label=r"Donev 2006: $\phi_0 \approx 0.64$")
    ax.legend(fontsize=7, loc="lower right")
    return fig


def plot_ellipsoid_radial_profiles(profiles):
    """phi(r) of ellipsoids in spherical containers against the distance from the wall (R - r) / a,
    one panel per shape (after Donev 2006, Fig. 7.5): each packing's profile (exact
    intersection volumes), its core density (dotted) and core average phi_avg(r) =
    3 int_0^r x^2 phi dx / r^3 (thin dashed, Sec. 7.3.2.3) and Donev's bulk density of the shape
    (Sec. 7.3.2.1: 0.700 for the M&M and 0.741 for the ollipsoid shape, dashed).

    Parameters
    ----------
    profiles : sequence of xarray.Dataset
        Radial profiles (:func:`hardpack.structure.containers.ellipsoid_radial_density_profile`)
        with the attributes ``shape_name``, ``N``, ``seed``, ``a``, ``radius``, ``phi_core`` and
        ``core_margin``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    shapes = list(dict.fromkeys(p.attrs["shape_name"] for p in profiles))
    fig, axes = figure(ncols=max(len(shapes), 1), figsize=(4.2 * max(len(shapes), 1), 3.2), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, name in zip(axes, shapes):
        group = [p for p in profiles if p.attrs["shape_name"] == name]
        _draw_profiles(ax, group, core_average=True)
        label, published, _ = DONEV_ELLIPSOID_PHI0.get(name, (name, np.nan, np.nan))
        if np.isfinite(published):
            ax.axhline(published, color="k", ls="--", lw=1, label=rf"Donev 2006: $\phi_0$ = {published:.3f}")
        ax.set_title(label, fontsize=9)
        ax.legend(fontsize=6, loc="lower right")
    return fig


def _draw_profiles(ax, profiles, core_average=False):
    """Each profile against (R - r) / a with its core density (dotted) and, optionally, its core
    average (thin dashed); the core margin (grey line); axes labels and limits."""
    for k, p in enumerate(profiles):
        a, radius = p.attrs["a"], p.attrs["radius"]
        x = (radius - p["r"].values) / a
        ax.plot(x, p["phi"].values, lw=0.8, color=f"C{k}", label=f"N = {p.attrs['N']}, seed {p.attrs['seed']}")
        ax.axhline(p.attrs["phi_core"], color=f"C{k}", ls=":", lw=0.8)
        if core_average:
            ax.plot((radius - p["r_outer"].values) / a, p["phi_core_average"].values, color=f"C{k}", ls="--",
                    lw=0.6, label=r"core average $\phi_{avg}(r)$" if k == 0 else None)
    margin = profiles[0].attrs["core_margin"] if profiles else 0
    ax.axvline(margin, color="0.5", lw=0.6)
    ax.set_xlabel(r"distance from the wall $(R - r)/a$")
    ax.set_ylabel(r"$\phi(r)$")
    ax.set_ylim(0, 1)


def plot_extrapolation(summary, ellipsoids=()):
    """The average density phi_avg against delta = a/R of every packing, the mean per N, and the
    linear fit of Eq. 7.2 extended to delta = 0 with its intercept phi_0 +- s.e., beside Donev's
    0.642 +- 0.002 (Donev 2006, Sec. 7.3.2.1, Fig. 7.6) and, when the summary has them, the mean
    density of periodic packings made with the same protocol (dashed, band: s.e.); the same for
    each ellipsoid shape, beside Donev's value for the M&M and ollipsoid shapes.

    Parameters
    ----------
    summary : xarray.Dataset
        :func:`hardpack.structure.containers.container_summary` output.
    ellipsoids : sequence of xarray.Dataset, optional
        :func:`hardpack.structure.containers.ellipsoid_container_summary` outputs (attribute
        ``shape_name``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    ellipsoids = list(ellipsoids)
    fig, ax = figure(figsize=(7.6, 3.6) if ellipsoids else (5.0, 3.4))
    n = np.asarray(summary["N"].values)
    delta = np.asarray(summary["a_over_R"].values, float)
    phi = np.asarray(summary["phi_avg"].values, float)
    ax.plot(delta, phi, "o", ms=3, mfc="none", color="C0", label="sphere packings")
    for size in np.unique(n):
        mean, sem, _, _ = seed_statistics(phi[n == size])
        ax.errorbar(delta[n == size].mean(), mean, 0 if not np.isfinite(sem) else sem, fmt="s", ms=4, color="C0")
    phi0, err, slope = (summary.attrs[k] for k in ("phi0", "phi0_err", "slope"))
    if np.isfinite(phi0):
        grid = np.linspace(0, delta.max() * 1.05, 50)
        ax.plot(grid, phi0 + slope * grid, "-", color="C1",
                label=rf"sphere fit (N $\geq$ {summary.attrs['fit_min_n']}): $\phi_0$ = {phi0:.4f} $\pm$ {err:.4f}")
        ax.errorbar([0], [phi0], [err], fmt="o", color="C1", capsize=3)
    if "phi_bulk" in summary.attrs:
        bulk, bulk_err = summary.attrs["phi_bulk"], summary.attrs["phi_bulk_err"]
        ax.axhline(bulk, color="C2", lw=1, ls="--",
                   label=rf"periodic, same protocol (N = {summary.attrs['bulk_N']}): {bulk:.4f}"
                         + (rf" $\pm$ {bulk_err:.4f}" if np.isfinite(bulk_err) else ""))
        if np.isfinite(bulk_err):
            ax.axhspan(bulk - bulk_err, bulk + bulk_err, color="C2", alpha=0.15, lw=0)
    ax.errorbar([0], [DONEV_PHI0[0]], [DONEV_PHI0[1]], fmt="*", ms=8, color="k", capsize=3,
                label=r"Donev 2006: $\phi_0$ = 0.642 $\pm$ 0.002")
    for k, ell in enumerate(ellipsoids):
        _ellipsoid_extrapolation(ax, ell, f"C{k + 3}")
    ax.set_xlim(left=-0.005)
    ax.set_xlabel(r"$\delta = a/R$")
    ax.set_ylabel(r"$\phi_{avg}$")
    if ellipsoids:  # beside the axes: the shapes' points span the plot
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
    else:
        ax.legend(fontsize=7)
    return fig


def _ellipsoid_extrapolation(ax, summary, color):
    """One ellipsoid shape's packings, its Eq. 7.2 line and intercept, and Donev's value."""
    name = summary.attrs.get("shape_name", "ellipsoids")
    label, published, published_err = DONEV_ELLIPSOID_PHI0.get(name, (name, np.nan, np.nan))
    delta = np.asarray(summary["a_over_R"].values, float)
    ax.plot(delta, np.asarray(summary["phi_avg"].values, float), "^", ms=3, mfc="none", color=color,
            label=f"{label} packings")
    phi0, err, slope = (summary.attrs[k] for k in ("phi0", "phi0_err", "slope"))
    if np.isfinite(phi0):
        grid = np.linspace(0, delta.max() * 1.05, 50)
        ax.plot(grid, phi0 + slope * grid, "-", color=color, lw=1,
                label=rf"{label} fit: $\phi_0$ = {phi0:.4f} $\pm$ {err:.4f}")
    if np.isfinite(published):
        ax.errorbar([0], [published], [published_err], fmt="*", ms=8, color=color, mec="k", capsize=3,
                    label=rf"Donev 2006, {label}: {published:.3f} $\pm$ {published_err:.3f}")


def plot_window_fluctuations(windows):
    """sigma_phi of random spherical windows against 2R/D (log-log), per packing and the mean,
    with the fitted power law and Donev's 0.1 (2R/D)^-2 (Donev 2006, Fig. 7.3).

    Parameters
    ----------
    windows : xarray.Dataset
        :func:`hardpack.structure.containers.window_study` output (attribute
        ``fit_min_diameter``: the smallest window of the fit).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure(figsize=(5.0, 3.4))
    x = windows["x"].values
    sigma = windows["sigma_phi"].values
    for row in sigma:
        ax.loglog(x, row, "-", lw=0.6, color="0.6")
    mean = sigma.mean(axis=0)
    ax.loglog(x, mean, "o", ms=4, color="C0", label=f"{sigma.shape[0]} packing(s), N = {int(windows['N'][0])}")
    fit = fit_window_power_law(x, mean, windows.attrs.get("fit_min_diameter", 0.0))
    ax.loglog(x, fit.prefactor * x**fit.exponent, "-", color="C1",
              label=rf"fit: {fit.prefactor:.3f} $(2R/D)^{{{fit.exponent:.2f} \pm {fit.exponent_err:.2f}}}$")
    ax.loglog(x, 0.1 * x**-2.0, "--", color="k", label=r"Donev 2006: $0.1\,(2R/D)^{-2}$")
    ax.set_xlabel(r"window diameter $2R/D$")
    ax.set_ylabel(r"$\sigma_\phi(R)$")
    ax.legend(fontsize=7)
    return fig
