"""Figures of the SLP study (Torquato & Jiao 2010)."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.slp.published import TABLE_II


def plot_densest(summary):
    """phi / phi_densest-known per dimension: every seed, the best, and the paper's SLP and LS values."""
    fig, ax = figure()
    d = summary["d"].values.astype(int)
    phi = summary["phi"].values
    exact = np.array([TABLE_II[k][3] for k in d])
    rng = np.random.default_rng(0)
    ax.scatter(d + 0.08 * rng.standard_normal(d.size), phi / exact, s=14, color="C0", alpha=0.6,
               label="hardpack SLP, each seed")
    dims = np.unique(d)
    best = [phi[d == k].max() / TABLE_II[k][3] for k in dims]
    ax.plot(dims, best, "o-", color="C0", mfc="none", label="hardpack SLP, best seed")
    ax.plot(dims, [TABLE_II[k][2] / TABLE_II[k][3] for k in dims], "s--", color="C3", mfc="none",
            label="Torquato & Jiao SLP (Table II)")
    ax.plot(dims, [TABLE_II[k][1] / TABLE_II[k][3] for k in dims], "^:", color="C2", mfc="none",
            label="Torquato & Jiao LS (Table II)")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_ylim(min(0.85, float(np.min(phi / exact)) - 0.02), 1.02)
    ax.set_xticks(dims)
    ax.set_xticklabels([f"{k}\n{TABLE_II[k][4]}, N={TABLE_II[k][0]}" for k in dims])
    ax.set_xlabel("dimension d (densest known packing, N = 3^d)")
    ax.set_ylabel(r"$\phi$ / $\phi_{\rm densest\ known}$")
    ax.legend(loc="lower left")
    return fig
