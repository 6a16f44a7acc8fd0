"""Figures of the EOS-vs-moments study (Ogarko ch. 3): jamming density vs width for polydisperse
systems and their bi-/tridisperse equivalents, and the fluid Z(phi) against BMCSL."""

from __future__ import annotations

import warnings

import numpy as np
from matplotlib.ticker import NullFormatter, ScalarFormatter

from hardpack.eos import theory
from hardpack.eos.study import seed_statistics
from hardpack.plots.style import figure

SYSTEM_STYLE = {"poly": ("o", "C0", "polydisperse"), "bi": ("s", "C3", "bidisperse equivalent"),
                "tri": ("^", "C2", "tridisperse equivalent")}
FAMILY_LABEL = {"uniform_size": "uniform size (US)", "uniform_volume": "uniform volume (UV)",
                "lognormal": "log-normal (LN)"}
#: the published empirical fits and the rates they were fitted at (Ogarko Eqs. 3.15, 3.16, 3.52)
FITS = {"uniform_size": (theory.phij_fit_uniform_size, r"Eq. 3.15 ($\Gamma_O = 8\times10^{-6}$)"),
        "uniform_volume": (theory.phij_fit_uniform_volume, r"Eq. 3.16 ($\Gamma_O = 16\times10^{-6}$)"),
        "lognormal": (theory.phij_fit_lognormal, r"Eq. 3.52 ($\Gamma_O = 16\times10^{-3}$)")}


def _errorbar(ax, widths, system, mean, sem):
    """One system's seed means +- standard errors in its house style."""
    marker, color, label = SYSTEM_STYLE[str(system)]
    ax.errorbar(widths, mean, yerr=sem.fillna(0), fmt=marker + "-", color=color, mfc="none", ms=4, capsize=2,
                label=label)


def _plot_fit(ax, family, widths):
    """Ogarko's published phi_J fit of the family over the plotted widths."""
    fit, fit_label = FITS[family]
    grid = np.linspace(widths.min(), widths.max(), 200)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ax.plot(grid, fit(grid), "--", color="0.4", lw=1, label="Ogarko fit, " + fit_label)


def plot_phij_vs_width(summaries):
    """Top row: phi_J (mean +- standard error over seeds) vs omega (sigma) per family, with the published
    fit; bottom row: phi_J(equivalent)/phi_J(poly) - 1 in percent with the +-1 % band.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        The eos_jam_summary of each family.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    summaries = sorted(summaries, key=lambda s: list(FAMILY_LABEL).index(s.attrs["family"]))
    fig, axes = figure(2, len(summaries), figsize=(3.3 * len(summaries), 5.2), sharex="col", squeeze=False,
                       gridspec_kw={"height_ratios": [2, 1]})
    for col, summary in enumerate(summaries):
        family = summary.attrs["family"]
        stats = seed_statistics(summary)
        widths = stats["width"].values
        top, bottom = axes[0, col], axes[1, col]
        for system in stats["system"].values:
            s = stats.sel(system=system)
            _errorbar(top, widths, system, s["phi_J_mean"], s["phi_J_sem"])
            if system != "poly":
                _errorbar(bottom, widths, system, 100 * s["dev"], 100 * s["dev_sem"])
        _plot_fit(top, family, widths)
        bottom.axhspan(-1, 1, color="0.85", zorder=0)
        bottom.axhline(0, color="k", lw=0.6)
        name = summary.attrs["width_name"]
        if name == "omega":
            top.set_xscale("log")
            top.xaxis.set_major_formatter(ScalarFormatter())
            top.xaxis.set_minor_formatter(NullFormatter())
            ticks = (1, 1.2, 1.5, 2, 3, 4, 5, 8, 10, 20, 50, 100)
            top.set_xticks([t for t in ticks if widths.min() <= t <= widths.max()])
            bottom.set_xlabel(r"$\omega = a_{\max}/a_{\min}$")
        else:
            bottom.set_xlabel(r"$\sigma$ (log-normal)")
        seeds = summary.sizes["seed"]
        top.set_title(f"{FAMILY_LABEL[family]}, N = {summary.attrs['N']}, {seeds} seed{'s' if seeds > 1 else ''}")
        bottom.set_ylabel(r"$\phi_J/\phi_J^{\rm poly} - 1$ (%)")
        top.set_ylabel(r"$\phi_J$")
        top.legend(loc="upper left", fontsize=6)
    return fig


def plot_crystallisation(summary, threshold: float):
    """Slow runs (Ogarko 2014, sec. 3.1.3): left, phi_J vs omega of poly / bi / tri with the published fit;
    right, the q6 crystallinity of the large particles (mean over seeds, each seed a small marker)
    with the ``threshold`` the validation counts as partial crystallisation.

    Parameters
    ----------
    summary : xarray.Dataset
        The eos_jam_summary of the slow runs.
    threshold : float
        Crystallinity counted as partial crystallisation.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    stats = seed_statistics(summary)
    family = summary.attrs["family"]
    widths = stats["width"].values
    fig, (left, right) = figure(1, 2, figsize=(8.0, 3.4), layout="constrained")
    for system in stats["system"].values:
        marker, color, label = SYSTEM_STYLE[str(system)]
        s = stats.sel(system=system)
        _errorbar(left, widths, system, s["phi_J_mean"], s["phi_J_sem"])
        right.plot(widths, s["crystallinity_large"], marker + "-", color=color, mfc="none", ms=5, label=label)
        per_seed = summary["crystallinity_large"].sel(system=system).values
        right.plot(np.repeat(widths, per_seed.shape[1]), per_seed.ravel(), marker, color=color, ms=2, alpha=0.5)
    _plot_fit(left, family, widths)
    right.axhline(threshold, color="0.4", ls=":", lw=1, label=f"partial crystallisation ({threshold:g})")
    for ax in (left, right):
        ax.set_xlabel(r"$\omega = a_{\max}/a_{\min}$")
    left.set_ylabel(r"$\phi_J$")
    right.set_ylabel("large-particle crystallinity")
    right.set_ylim(0.0, max(2.0 * threshold, 1.15 * float(np.nanmax(summary["crystallinity_large"].values))))
    seeds = summary.sizes["seed"]
    left.set_title(f"{FAMILY_LABEL[family]}, slow compression, N = {summary.attrs['N']}, {seeds} seed"
                   f"{'s' if seeds > 1 else ''}", fontsize=8)
    left.legend(loc="lower right", fontsize=6)
    right.legend(loc="upper left", fontsize=6)
    return fig


def plot_eos_vs_bmcsl(fluid):
    """Left: Z vs phi (simulation markers, BMCSL lines) per distribution; right: Z/Z_BMCSL - 1 in percent
    with the +-1 % band and Ogarko's Z_OL (Eq. 3.13) relative to BMCSL as dashed lines.

    Parameters
    ----------
    fluid : xarray.Dataset
        The eos_fluid_summary.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, (left, right) = figure(1, 2, figsize=(9.0, 3.8))
    grid = np.linspace(0.0, 0.5, 200)
    for k, case in enumerate(fluid["case"].values):
        c = fluid.sel(case=case)
        color = f"C{k}"
        for system in c["system"].values:
            marker, _, label = SYSTEM_STYLE[str(system)]
            s = c.sel(system=system)
            ok = np.isfinite(s["Z"].values)
            left.plot(s["phi"].values[ok], s["Z"].values[ok], marker, color=color, mfc="none", ms=4)
            right.errorbar(s["phi"].values[ok], 100 * s["rel_dev"].values[ok],
                           yerr=100 * (s["Z_err"] / s["Z_bmcsl"]).values[ok], fmt=marker, color=color,
                           mfc="none", ms=4, capsize=2)
        o1, o2 = float(c["O1"].sel(system="poly").mean()), float(c["O2"].sel(system="poly").mean())
        left.plot(grid, theory.bmcsl(grid, o1, o2), color=color, lw=0.8,
                  label=f"{case} (N = {int(c['N'])}), BMCSL")
        right.plot(grid, 100 * (theory.z_ol(grid, o1, o2) / theory.bmcsl(grid, o1, o2) - 1), "--", color=color,
                   lw=0.8)
    for system, (marker, _, label) in SYSTEM_STYLE.items():
        left.plot([], [], marker, color="0.3", mfc="none", label=label)
    right.plot([], [], "--", color="0.3", label=r"$Z_{\rm OL}$ (Eq. 3.13) / BMCSL")
    right.axhspan(-1, 1, color="0.85", zorder=0)
    right.axhline(0, color="k", lw=0.6)
    left.set_yscale("log")
    left.set_xlabel(r"$\phi$")
    left.set_ylabel(r"$Z = pV/(Nk_BT)$")
    right.set_xlabel(r"$\phi$")
    right.set_ylabel(r"$Z/Z_{\rm BMCSL} - 1$ (%)")
    left.legend(fontsize=6)
    right.legend(fontsize=6, loc="upper left")
    return fig
