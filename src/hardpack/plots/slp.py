"""Figures of the SLP study (Torquato & Jiao 2010)."""

from __future__ import annotations

import json

import numpy as np

from hardpack.plots.style import figure
from hardpack.slp.published import TABLE_II
from hardpack.validation.targets import load_targets


def plot_densest(summary, ls=None):
    """phi / phi_densest-known per dimension: every seed, the best, and the paper's SLP and LS values.

    Parameters
    ----------
    summary : xarray.Dataset
        SLP summary over seeds (variables d and phi).
    ls : xarray.Dataset, optional
        LS summary over (d, seed) (variables d, phi and growth_rate): each seed and the best,
        labelled with its growth rate.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
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
    lowest = float(np.min(phi / exact))
    if ls is not None:
        d_ls = ls["d"].values.astype(int)
        phi_ls = ls["phi"].values / np.array([TABLE_II[k][3] for k in d_ls])
        rate = ls["growth_rate"].values
        ax.scatter(d_ls + 0.15 + 0.05 * rng.standard_normal(d_ls.size), phi_ls, s=14, marker="D", color="C1",
                   alpha=0.6, label="hardpack LS, each seed")
        dims_ls = np.unique(d_ls)
        ax.plot(dims_ls + 0.15, [phi_ls[d_ls == k].max() for k in dims_ls], "D-", color="C1", mfc="none",
                label="hardpack LS, best seed")
        for k in dims_ls:
            ax.annotate(f"{rate[d_ls == k][0]:.0e}", (k + 0.15, phi_ls[d_ls == k].min()), xytext=(0, -11),
                        textcoords="offset points", ha="center", fontsize=7, color="C1")
        dims = np.union1d(dims, dims_ls)
        lowest = min(lowest, float(phi_ls.min()))
    ax.axhline(1.0, color="k", lw=0.8)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_ylim(min(0.85, lowest - 0.04), 1.02)
    ax.set_xticks(dims)
    ax.set_xticklabels([f"{k}\n{TABLE_II[k][4]}, N={TABLE_II[k][0]}" for k in dims])
    ax.set_xlabel("dimension d (densest known packing, N = 3^d)")
    ax.set_ylabel(r"$\phi$ / $\phi_{\rm densest\ known}$")
    ax.legend(loc="lower left")
    return fig


def plot_slp_vs_ls(pairs: dict):
    """Mean +- standard error of phi per ensemble for SLP and LS, with Table I where it applies.

    ``pairs`` maps an ensemble name to (SLP summary, LS jammed summary or None for an SLP-only
    system) Datasets. Each name is labelled with its d and N.

    Parameters
    ----------
    pairs : dict of str to (xarray.Dataset, xarray.Dataset or None)
        As above.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure()
    names = list(pairs)
    x = np.arange(len(names))
    for offset, which, color, label in ((-0.1, 0, "C0", "hardpack SLP"), (0.1, 1, "C1", "hardpack LS")):
        keep = [k for k, n in enumerate(names) if pairs[n][which] is not None]
        phi = [pairs[names[k]][which]["phi"].values for k in keep]
        mean = np.array([p.mean() for p in phi])
        sem = np.array([p.std(ddof=1) / np.sqrt(p.size) if p.size > 1 else 0.0 for p in phi])
        ax.errorbar(x[keep] + offset, mean, yerr=sem, fmt="o", color=color, capsize=3, label=label)
    labelled = False
    for k, n in enumerate(names):
        d = int(pairs[n][0]["d"].values[0]) if "d" in pairs[n][0] else None
        spec = json.loads(pairs[n][0].attrs.get("distribution", "{}"))
        targets = load_targets()
        if d == 2 and spec.get("kind") == "uniform_size" and spec.get("omega") == 2:
            ax.plot(k - 0.25, targets["tj-sec5-poly2d-phi"].published, "D", mfc="none", color="C0",
                    label="Torquato & Jiao SLP, 2D disks in [D, 2D] (Sec. V.A)")
        elif f"tj-t1-slp-phi-d{d}" in targets and spec.get("kind", "monodisperse") == "monodisperse":
            slp_pub, ls_pub = targets[f"tj-t1-slp-phi-d{d}"], targets[f"tj-t1-ls-phi-d{d}"]
            ax.errorbar(k - 0.25, slp_pub.published, yerr=slp_pub.tolerance, fmt="s", mfc="none", color="C0",
                        capsize=3, label="Torquato & Jiao SLP (Table I)" if not labelled else None)
            ax.errorbar(k + 0.25, ls_pub.published, yerr=ls_pub.tolerance, fmt="^", mfc="none", color="C1",
                        capsize=3, label="Torquato & Jiao LS (Table I)" if not labelled else None)
            labelled = True
    ax.set_xticks(x)
    ax.set_xticklabels([f"{n}\nd={int(pairs[n][0]['d'].values[0])}, N={int(pairs[n][0]['N'].values[0])}"
                        for n in names])
    ax.set_ylabel(r"jamming density $\phi_J$")
    ax.set_xlabel("ensemble")
    ax.legend(fontsize=6, loc="center")
    return fig


def plot_order_map(summary, diluted=None):
    """Left: translational order T against phi (Fig. 6 of Torquato & Jiao), one marker per
    packing. Right: phi against the influence radius gamma / D (the SLP densities vs influence
    radius of the paper's sec. V), one marker per packing with the mean per radius.

    One colour and marker per SLP setting (alpha = gamma / D, bounds strain / shear / displacement,
    LP solver); filled when the packing passed the strict jamming test. Coinciding packings (e.g.
    several seeds ending in the same crystal) are labelled with their count. FCC (phi = 0.74048,
    T = 1) and the paper's MRJ density 0.64 (Torquato & Jiao 2010, Sec. VI) are marked for reference.

    ``diluted`` (:func:`hardpack.slp.diluted.diluted_summary`, optional) adds the diluted-MRJ
    packings of the paper's Sec. VI on the left as red squares (its Fig. 6 symbol), each seed's
    rounds joined from its MRJ start, with the paper's low end phi = 0.60 (0.595 without
    rattlers) marked. Either summary may be None, not both.

    Parameters
    ----------
    summary : xarray.Dataset or None
        The order-map summary.
    diluted : xarray.Dataset, optional
        The diluted-MRJ summary.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    if summary is None and diluted is None:
        raise ValueError("plot_order_map needs an order-map or a diluted-MRJ summary")
    fig, (ax, ax_r) = figure(1, 2, figsize=(9.0, 3.8))
    if diluted is not None:
        _plot_diluted(ax, diluted)
    ax.plot([np.pi / np.sqrt(18)], [1.0], "k*", ms=10, label="FCC")
    ax.axvline(0.64, color="0.5", ls=":", lw=1, label=r"MRJ $\phi$ = 0.64 (paper)")
    ax.set_xlabel(r"packing density $\phi$")
    ax.set_ylabel("translational order T")
    ax_r.set_xlabel(r"influence radius $\gamma$ / D")
    ax_r.set_ylabel(r"packing density $\phi$")
    if summary is not None:
        _plot_settings(ax, ax_r, summary)
        ax_r.legend(fontsize=6, loc="best")
    ax.legend(fontsize=5.5, loc="upper left")
    return fig


def _plot_diluted(ax, diluted):
    """Red squares: the rounds of each seed of the diluted-MRJ study, filled when strictly jammed."""
    colour = "darkred"
    phi, t, strict = (diluted[k].transpose("seed", "round").values for k in ("phi", "T", "strict"))
    for k in range(phi.shape[0]):
        ax.plot(phi[k], t[k], "-", color=colour, lw=0.6, alpha=0.5)
    later = np.asarray(diluted["round"].values) > 0
    for jammed in (True, False):
        sel = (strict == 1) == jammed
        sel[:, ~later] = False
        if sel.any():
            ax.scatter(phi[sel], t[sel], s=22, marker="s", edgecolors=colour, facecolors=colour if jammed else "none",
                       label=f"diluted MRJ (Sec. VI), f = {diluted.attrs.get('fraction', '?')}, "
                             f"rounds 1-{int(diluted['round'].max())}" + ("" if jammed else " (not strictly jammed)"))
    ax.axvline(0.60, color=colour, ls=":", lw=1, label=r"diluted MRJ $\phi$ = 0.60 (paper)")
    ax.set_title(f"SLP jammed packings, d = 3; diluted from N = {int(diluted['N'].max())}")


def _plot_settings(ax, ax_r, summary):
    """The order-map packings, one colour and marker per SLP setting (plot_order_map)."""
    keys = ("alpha", "strain_bound", "shear_bound", "displacement_bound", "lp_method", "N")
    settings = list(zip(*(summary[k].values.tolist() for k in keys)))
    strict = summary["strict"].values == 1
    phi, t, alpha = summary["phi"].values, summary["T"].values, summary["alpha"].values
    for n, setting in enumerate(dict.fromkeys(settings)):
        radius, strain, shear, disp, method, size = setting
        pick = np.array([s == setting for s in settings])
        colour, marker = f"C{n % 10}", "os^Dv<>ph*"[n % 10]
        label = (rf"N = {size}, $\gamma$ = {radius:g} D, bounds {strain:g}/{shear:g}/{disp:g} D, "
                 f"{method.removeprefix('highs-')}")
        offset = 0.04 * (n - 0.5 * (len(set(settings)) - 1))  # side by side on the right panel
        for jammed in (True, False):
            sel = pick & (strict == jammed)
            if sel.any():
                face = colour if jammed else "none"
                ax.scatter(phi[sel], t[sel], s=24, marker=marker, edgecolors=colour, facecolors=face,
                           label=label + ("" if jammed else " (not strictly jammed)"))
                ax_r.scatter(alpha[sel] + offset, phi[sel], s=18, marker=marker, edgecolors=colour,
                             facecolors=face)
    points, counts = np.unique(np.round(np.column_stack([phi, t]), 4), axis=0, return_counts=True)
    for (x, y), count in zip(points, counts):
        if count > 1:
            ax.annotate(f"x{count}", (x, y), textcoords="offset points", xytext=(5, -9), fontsize=6)
    radii = np.unique(alpha)
    ax_r.plot(radii, [phi[alpha == r].mean() for r in radii], "k_", ms=16, mew=1.5, label="mean")
    ax_r.axhline(np.pi / np.sqrt(18), color="k", ls="--", lw=1, label="FCC / HCP")
    ax_r.axhline(0.64, color="0.5", ls=":", lw=1, label="MRJ 0.64 (paper)")
    sizes = ", ".join(str(n) for n in np.unique(summary["N"].values))
    ax.set_title(f"SLP jammed packings, d = 3, N = {sizes}: {summary.sizes['packing']} packings")
