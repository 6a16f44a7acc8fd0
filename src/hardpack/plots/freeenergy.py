"""Figures of the BCMD free-energy study."""

from __future__ import annotations

import numpy as np

from hardpack.freeenergy.crystal import (
    JAMMING_CONSTANT,
    MELTING_EXCESS,
    MELTING_PHI,
    PHI_CP,
    cell_limit_excess,
    cell_offset,
    distance_to_jamming,
    eos_excess,
)
from hardpack.plots.style import figure
from hardpack.validation.freeenergy import TARGETS, finite_size_extrapolation
from hardpack.validation.targets import load_targets


def plot_fcc_finite_size(summaries: dict):
    """BCMD free energies of FCC vs ln N / N (the leading finite-size term), with the fit
    a + b ln N / N and the published values.

    Parameters
    ----------
    summaries : dict of str to xarray.Dataset
        State name -> combined BCMD summary (as :func:`hardpack.validation.freeenergy.bcmd_rows`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, axes = figure(1, len(summaries), figsize=(4.2 * len(summaries), 3.4), squeeze=False)
    for ax, (state, ds) in zip(axes.flat, summaries.items()):
        tid, var = TARGETS[state]
        target = load_targets()[tid]
        value, label = target.published, target.quantity
        n = ds["n_particles"].values.astype(float)
        x = np.log(n) / n
        y = ds[var].values
        ax.plot(x, y, "o", color="C0", label="hardpack BCMD (each seed)")
        if np.unique(n).size >= 3:
            a, err, _ = finite_size_extrapolation(n, y)
            b = np.polyfit(x, y, 1)[0]  # the same least-squares line
            xs = np.linspace(0, x.max(), 50)
            ax.plot(xs, a + b * xs, "-", color="C0", lw=0.8,
                    label=f"fit a + b ln N/N: a = {a:.4f} +- {err:.4f}")
        ax.axhline(value, color="C3", ls="--", label=f"published {value} ({target.citation.split(' (')[0]})")
        ax.set_xlim(left=0)
        ax.set_xlabel(r"$\ln N / N$")
        ax.set_ylabel(label.replace("FCC ", "") + r" [$k_BT$ per particle]")
        ax.set_title(f"FCC, {'phi = 0.545' if state == 'melting' else 'delta = 1e-6'}")
        ax.legend()
    fig.tight_layout()
    return fig


def plot_fcc_density(bcmd, eos):
    """FCC free energy vs density: (a) excess over the ideal gas vs phi, (b) BCMD's Delta f =
    f_c(Delta mu_d) - f vs the distance to jamming delta (log scale; f = -3 ln delta - f_J
    + ..., so Delta f tends to the jamming constant as delta -> 0), with the EOS integration of
    the engine's pressure from the published melting value and the cell limit with the published
    jamming constant (hardpack.freeenergy.crystal).

    Parameters
    ----------
    bcmd : xarray.Dataset
        BCMD summary over (phi, seed).
    eos : xarray.Dataset
        MD equation-of-state summary of the crystal over phi.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, (ax1, ax2) = figure(1, 2, figsize=(9.0, 3.6))
    phi_b, ex_b = bcmd["phi"].values, bcmd["excess"].values
    phi_e, z = eos["phi"].values, eos["Z"].values
    fine = np.linspace(phi_e.min(), phi_e.max(), 200)
    ex_e = eos_excess(phi_e, z, at=fine)
    grid = np.linspace(MELTING_PHI, PHI_CP * (1 - 1e-4), 400)
    n = int(np.asarray(bcmd["n_particles"].values).ravel()[0])
    n_md = int(np.asarray(eos["N"].values).ravel()[0])
    ax1.plot(grid, cell_limit_excess(grid), ":", color="C2",
             label=f"cell limit, published jamming constant {JAMMING_CONSTANT}")
    ax1.plot(fine, ex_e, "-", color="C1",
             label=f"published 5.91916 + EOS integral (MD, N = {n_md})")
    ax1.plot(phi_b, ex_b, "o", color="C0", ms=4, label=f"hardpack BCMD, N = {n}")
    ax1.plot([MELTING_PHI], [MELTING_EXCESS], "*", color="C3", ms=9,
             label="published at melting (Donev 2006, sec. 6.4.1)")
    ax1.set_xlabel(r"$\phi$")
    ax1.set_ylabel(r"excess free energy $f - f_{ideal}$ [$k_BT$]")
    ax1.set_ylim(top=1.1 * max(ex_b.max(), ex_e.max()))
    ax1.legend(loc="upper left", fontsize=6.5)
    ax2.plot(distance_to_jamming(fine), cell_offset(fine) - ex_e, "-", color="C1", label="EOS integral")
    ax2.plot(distance_to_jamming(phi_b), cell_offset(phi_b) - ex_b, "o", color="C0", ms=4, label="hardpack BCMD")
    ax2.plot([distance_to_jamming(MELTING_PHI)], [cell_offset(MELTING_PHI) - MELTING_EXCESS], "*", color="C3", ms=9,
             label="published melting value")
    ax2.axhline(JAMMING_CONSTANT, color="C2", ls=":",
                label=f"published jamming limit {JAMMING_CONSTANT} (Donev 2006, sec. 6.4.1)")
    ax2.set_xscale("log")
    ax2.set_xlabel(r"distance to jamming $\delta = (\phi_{cp}/\phi)^{1/3} - 1$")
    ax2.set_ylabel(r"$\Delta f = f_c(\Delta\mu_d) - f$ [$k_BT$]")
    ax2.legend(loc="lower left", fontsize=6.5)
    fig.tight_layout()
    return fig
