"""Figures of the structure study: g2 near contact, Z(l), S(k) at small k (Donev ch. 9-10)."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.plots.style import figure
from hardpack.structure.pair import NEAR_CONTACT_FIT, fit_coordination_power_law


def plot_g2_near_contact(ensembles: dict):
    """Seed-averaged g2 against r / (r_i + r_j), contacts excluded; sqrt(3) and 2 marked (split second peak).

    Parameters
    ----------
    ensembles : dict of str to list of xarray.Dataset
        Ensemble name -> structure datasets of its seeds.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (name, members) in enumerate(ensembles.items()):
        x = members[0]["x"].values
        g2 = np.mean([m["g2_scaled"].values for m in members], axis=0)
        ax.plot(x, g2, color=f"C{k}", label=f"{name} ({len(members)} seeds, N = {members[0].attrs['n_particles']})")
    for xv, label in ((math.sqrt(3), r"$\sqrt{3}$"), (2.0, "2")):
        ax.axvline(xv, color="k", ls=":", lw=0.8)
        ax.text(xv, ax.get_ylim()[1] * 0.95, label, ha="center", va="top")
    ax.set_xlim(0.9, 2.6)
    ax.set_xlabel(r"$r / (r_i + r_j)$ (pair distance over contact distance)")
    ax.set_ylabel(r"$g_2$ (contacts excluded)")
    ax.legend()
    return fig


def plot_coordination(ensembles: dict, gap_lo: float = NEAR_CONTACT_FIT[0], gap_hi: float = NEAR_CONTACT_FIT[1]):
    """log-log Z(l) - Z(0) of the rattler-free backbone with the fitted power law (Donev ch. 9: Z - 6 ~ 11 l^0.6).

    Parameters
    ----------
    ensembles : dict of str to list of xarray.Dataset
        Ensemble name -> structure datasets of its seeds.
    gap_lo, gap_hi : float, optional
        Gap range of the power-law fit.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (name, members) in enumerate(ensembles.items()):
        for j, m in enumerate(members):
            part = "backbone" if "Z_backbone" in m else "all"  # "all": the verdict left no backbone
            gap, z = m["gap"].values, m[f"Z_{part}"].values
            z0 = float(m[f"z_contacts_{part}"])
            keep = (gap > 0) & (z > z0)
            ax.loglog(gap[keep], z[keep] - z0, color=f"C{k}", alpha=0.5, lw=0.9,
                      label=name if j == 0 else None)
            try:
                fit = fit_coordination_power_law(m, gap_lo, gap_hi)
            except InvalidInputError:
                continue
            if j == 0 and math.isfinite(fit.alpha):
                ll = np.logspace(math.log10(gap_lo), math.log10(gap_hi), 20)
                ax.loglog(ll, fit.amplitude * ll**fit.alpha, "--", color=f"C{k}",
                          label=rf"fit: {fit.amplitude:.3g} $l^{{{fit.alpha:.2f}\pm{fit.alpha_err:.2f}}}$")
    ll = np.logspace(-6, -1, 10)
    ax.loglog(ll, 11 * ll**0.6, "k:", label=r"Donev: $11\,l^{0.6}$ (3D)")
    ax.set_xlabel(r"gap $l = r/(r_i + r_j) - 1$")
    ax.set_ylabel(r"$Z(l) - Z(0)$ (rattlers removed)")
    ax.legend()
    return fig


def plot_structure_factor(ensembles: dict, k_max_d: float = 12.0):
    """S(k) at small k (k in units of 1 / mean diameter) with the extrapolated S(0) of each seed.

    Parameters
    ----------
    ensembles : dict of str to list of xarray.Dataset
        Ensemble name -> structure datasets of its seeds.
    k_max_d : float, optional
        Largest k D shown.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (name, members) in enumerate(ensembles.items()):
        for j, m in enumerate(members):
            diameter = float(m.attrs["mean_diameter"])
            kd = m["k"].values * diameter
            keep = kd <= k_max_d
            ax.semilogy(kd[keep], m["S"].values[keep], "o-", ms=3, color=f"C{k}", alpha=0.7,
                        label=name if j == 0 else None)
            s0 = float(m["S0"])
            if math.isfinite(s0) and s0 > 0:
                ax.plot([0], [s0], "s", color=f"C{k}", mfc="none")
    ax.set_xlabel(r"$k D$")
    ax.set_ylabel(r"$S(k)$ (open squares: extrapolated $S(0)$)")
    ax.legend()
    return fig


def plot_channels(ensembles: dict, ratio_max: float = 1.5):
    """Seed-averaged histogram of channel radii over central radius R / r (Ogarko ch. 4, bin 0.01);
    the exact channels of touching equal spheres (triangle 2/sqrt(3) - 1, square sqrt(2) - 1) marked.

    Parameters
    ----------
    ensembles : dict of str to list of xarray.Dataset
        Ensemble name -> structure datasets of its seeds.
    ratio_max : float, optional
        Largest R / r shown.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (name, members) in enumerate(ensembles.items()):
        hists = [m["channel_density"] for m in members if "channel_density" in m]
        if not hists:
            continue
        mean = xr.concat(xr.align(*hists, join="outer", fill_value=0.0), dim="seed").mean("seed")
        keep = mean["ratio_bin"].values <= ratio_max
        ax.plot(mean["ratio_bin"].values[keep], mean.values[keep], color=f"C{k}",
                label=f"{name} ({len(hists)} seeds)")
    for xv, label in ((2 / math.sqrt(3) - 1, "triangle"), (math.sqrt(2) - 1, "square")):
        ax.axvline(xv, color="k", ls=":", lw=0.8)
        ax.text(xv, ax.get_ylim()[1] * 0.95, label, ha="left", va="top", rotation=90, fontsize=7)
    ax.set_xlabel(r"channel radius / central radius $R/r$")
    ax.set_ylabel("probability density")
    ax.legend()
    return fig
