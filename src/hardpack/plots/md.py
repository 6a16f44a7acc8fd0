"""Figures of the LS engine: the growth-rate scan of Donev's Fig. 1.3 (Donev 2006, secs. 1.2-1.2.1)."""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from hardpack.eos.theory import carnahan_starling
from hardpack.plots.style import figure


def _by_rate(series):
    groups = defaultdict(list)
    for ts in series:
        groups[float(ts.attrs["growth_rate"])].append(ts)
    return dict(sorted(groups.items(), reverse=True))


def plot_rate_phij(series):
    """phi_J estimate phi / (1 - d/Z) (Eq. 1.2) vs phi, one colour per Gamma, with the estimate the
    Carnahan-Starling fluid would give (the gamma -> 0 limit below freezing).

    Parameters
    ----------
    series : iterable of xarray.Dataset
        MD time series of the compressions.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (rate, members) in enumerate(_by_rate(series).items()):
        for j, ts in enumerate(members):
            keep = ts["Z"].values > 2 * int(ts.attrs["d"])  # the estimate is meaningful once Z > d
            ax.plot(ts["phi"].values[keep], ts["phi_J_est"].values[keep], color=f"C{k}", lw=0.9,
                    label=rf"$\Gamma$ = {rate:g} ({len(members)} seeds, N = {ts.attrs['N']})" if j == 0 else None)
    phi = np.linspace(0.35, 0.55, 50)
    z = carnahan_starling(phi)
    ax.plot(phi, phi / (1 - 3 / z), "k--", label="Carnahan-Starling fluid (equilibrium)")
    ax.set_xlabel(r"volume fraction $\phi$")
    ax.set_ylabel(r"jamming-density estimate $\phi / (1 - d/Z)$")
    ax.set_ylim(0.6, 0.76)
    ax.legend()
    return fig


def plot_rate_eos(series):
    """Reduced pressure Z = pV/(NkT) vs phi for each Gamma (log scale) against Carnahan-Starling and
    the free-volume law Z = d / (1 - phi/phi_J) with the final phi_J of each run (Eq. 1.1).

    Parameters
    ----------
    series : iterable of xarray.Dataset
        MD time series of the compressions.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    for k, (rate, members) in enumerate(_by_rate(series).items()):
        for j, ts in enumerate(members):
            phi, z = ts["phi"].values, ts["Z"].values
            ax.semilogy(phi, z, color=f"C{k}", lw=0.9,
                        label=rf"$\Gamma$ = {rate:g} (LS, N = {ts.attrs['N']})" if j == 0 else None)
            phi_j = float(ts["phi_J_est"].values[-1])
            grid = np.linspace(0.55, phi_j, 200, endpoint=False)
            ax.semilogy(grid, 3 / (1 - grid / phi_j), ":", color=f"C{k}", lw=0.8,
                        label=r"free volume $d/(1-\phi/\phi_J)$" if (j == 0 and k == 0) else None)
    phi = np.linspace(0.05, 0.56, 100)
    ax.semilogy(phi, carnahan_starling(phi), "k--", label="Carnahan-Starling")
    ax.set_xlabel(r"volume fraction $\phi$")
    ax.set_ylabel(r"reduced pressure $Z = pV/(NkT)$")
    ax.set_ylim(1, 1e6)
    ax.legend()
    return fig
