"""Figures of the SLP study (Torquato & Jiao 2010)."""

from __future__ import annotations

import numpy as np

from hardpack.plots.style import figure
from hardpack.slp.published import TABLE_I, TABLE_II


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


def plot_slp_vs_ls(pairs: dict):
    """Mean +- standard error of phi per ensemble for SLP and LS, with Table I where it applies.

    ``pairs`` maps an ensemble name to (SLP summary, LS jammed summary) Datasets.
    """
    fig, ax = figure()
    names = list(pairs)
    x = np.arange(len(names))
    for offset, which, color, label in ((-0.1, 0, "C0", "hardpack SLP"), (0.1, 1, "C1", "hardpack LS")):
        phi = [pairs[n][which]["phi"].values for n in names]
        mean = np.array([p.mean() for p in phi])
        sem = np.array([p.std(ddof=1) / np.sqrt(p.size) if p.size > 1 else 0.0 for p in phi])
        ax.errorbar(x + offset, mean, yerr=sem, fmt="o", color=color, capsize=3, label=label)
    for k, n in enumerate(names):
        d = int(pairs[n][0]["d"].values[0]) if "d" in pairs[n][0] else None
        if d in TABLE_I:
            _, ls_pub, _, slp_pub, _ = TABLE_I[d]
            ax.errorbar(k - 0.25, slp_pub[0], yerr=slp_pub[1], fmt="s", mfc="none", color="C0", capsize=3,
                        label="Torquato & Jiao SLP (Table I)" if k == 0 else None)
            ax.errorbar(k + 0.25, ls_pub[0], yerr=ls_pub[1], fmt="^", mfc="none", color="C1", capsize=3,
                        label="Torquato & Jiao LS (Table I)" if k == 0 else None)
    ax.set_xticks(x)
    ax.set_xticklabels(names)
    ax.set_ylabel(r"jamming density $\phi_J$")
    ax.set_xlabel("ensemble")
    ax.legend()
    return fig
