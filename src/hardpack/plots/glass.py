"""Figures of the binary hard-disk glass study (Donev 2006, ch. 13)."""

from __future__ import annotations

import numpy as np

from hardpack.glass import fits
from hardpack.plots.style import figure


def plot_glass_eos(binary, mono):
    """phi~_J(phi) = phi / (1 - 2/Z) of every compression branch (and the crystal decompression),
    with the published Eq. 13.3 cubic, our fit of it, and the glassy branches of Eq. 13.4 (after
    Donev 2006, Figs. 13.1 and 13.6)."""
    fig, axes = figure(1, 2, figsize=(9.0, 3.6))
    for ax, ds, title in ((axes[0], mono, "monodisperse disks"), (axes[1], binary, "binary disks, kappa = 1.4")):
        for b in ds["branch"].values:
            row = ds.sel(branch=b)
            label = "decompression" if b == "decompression" else f"Gamma = {b}"
            ax.errorbar(row["phi_mean"], row["phij"], yerr=row["phij_err"], fmt=".", ms=3, label=label)
            if np.isfinite(float(row["alpha"])):
                x = np.linspace(*ds.attrs["glass_fit_range"], 20)
                ax.plot(x, fits.glass_phij(x, float(row["glass_phi_j"]), float(row["alpha"])), "k:", lw=0.8)
        ax.set_title(title)
        ax.set_xlabel("phi")
        ax.set_ylabel("phi~_J = phi / (1 - 2/p)")
        ax.set_xlim(0.6, 0.9)
        ax.set_ylim(0.8, 0.92)
    x = np.linspace(0.70, 0.80, 50)
    axes[1].plot(x, fits.cubic_phij(x), "k-", label="Eq. 13.3 (published)")
    if np.all(np.isfinite(binary["cubic"].values)):
        axes[1].plot(x, fits.cubic_phij(x, binary["cubic"].values), "r--", label="Eq. 13.3 refitted")
    for ax in axes:
        ax.legend(loc="lower left")
    return fig


def plot_glass_entropy(binary, mono):
    """Left: excess free energies of the liquid (EOS integral) and the SOC glasses (BCMD) vs phi
    (after Fig. 13.11); right: s_c - s_mix vs phi for the binary and monodisperse systems (after
    Fig. 13.12)."""
    fig, axes = figure(1, 2, figsize=(9.0, 3.6))
    for ds, name, mark in ((binary, "binary", "o"), (mono, "mono", "s")):
        phi = ds["phi"].values
        axes[0].plot(phi, ds["glass_excess"], mark, ms=4, label=f"{name}: SOC glass (BCMD)")
        axes[0].errorbar(phi, ds["liquid_excess"], yerr=ds["liquid_excess_err"], fmt=mark, mfc="none", ms=4,
                         label=f"{name}: liquid (EOS integral)")
        axes[1].errorbar(phi, ds["sc_minus_smix"], yerr=ds["sc_minus_smix_err"], fmt=mark, ms=4,
                         label=f"{name} (s_mix = {ds.attrs['s_mix']:.4f})")
    axes[0].set_xlabel("phi")
    axes[0].set_ylabel("excess free energy per disk (kT)")
    axes[1].axhline(0.0, color="k", lw=0.8)
    axes[1].set_xlabel("phi")
    axes[1].set_ylabel("s_c - s_mix")
    for ax in axes:
        ax.legend()
    return fig


def plot_microsegregated(summary):
    """s_c against phi_J of each label ensemble, with phi_J's standard error, the uncorrelated
    ("random") labels marked and s_mix dashed (after Donev 2006, Fig. 13.16)."""
    fig, ax = figure(1, 1, figsize=(4.8, 3.6))
    names = summary["ensemble"].values
    random = names == "random"
    clustered = ~random
    points = ax.scatter(summary["phi_J"].values[clustered], summary["s_c"].values[clustered],
                        c=summary["R"].values[clustered], cmap="viridis", s=18, zorder=3, label="Matérn labels")
    ax.errorbar(summary["phi_J"].values, summary["s_c"].values, xerr=summary["phi_J_err"].values, fmt="none",
                ecolor="0.6", lw=0.8, zorder=2)
    if random.any():
        ax.plot(summary["phi_J"].values[random], summary["s_c"].values[random], "o", mfc="none", mec="k", ms=8,
                label="uncorrelated labels")
    ax.axhline(float(summary["s_mix"].values[0]), color="k", ls="--", lw=0.8, label="s_mix")
    fig.colorbar(points, ax=ax, label="R")
    ax.set_xlabel("phi_J")
    ax.set_ylabel(f"s_c (Markov estimate, {summary.attrs['s_c_window']} windows)")
    ax.set_title(f"micro-segregated packings, N = {summary.attrs['N']}")
    ax.legend(loc="lower left", fontsize="small")
    return fig
