"""Figures of the binary hard-disk glass study (Donev 2006, ch. 13)."""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib import rc_context

from hardpack.eos.theory import hard_disk_solid
from hardpack.glass import fits
from hardpack.plots.style import RC, figure


def plot_glass_eos(binary, mono):
    """phi~_J(phi) = phi / (1 - 2/Z) of every compression branch (and the crystal decompression; a
    branch continued from another from where it starts), with the published Eq. 13.3 cubic, our
    fit of it, the glassy branches of Eq. 13.4 and the hard-disk crystal EOS of Alder, Hoover &
    Young 1968 (after Donev 2006, Figs. 13.1 and 13.6).

    Parameters
    ----------
    binary, mono : xarray.Dataset
        The glass_eos summaries of the binary and monodisperse systems.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, axes = figure(1, 2, figsize=(9.0, 3.6))
    for ax, ds, title in ((axes[0], mono, "monodisperse disks"), (axes[1], binary, "binary disks, kappa = 1.4")):
        for b in ds["branch"].values:
            row = ds.sel(branch=b)
            phi, phij, err = (row[k].values for k in ("phi_mean", "phij", "phij_err"))
            if "start_phi" in row.coords and np.isfinite(float(row["start_phi"])):
                # a compression continued from another: its points below the start are the parent's
                own = phi >= float(row["start_phi"])
                phi, phij, err = phi[own], phij[own], err[own]
            label = "decompression" if b == "decompression" else f"Gamma = {b}"
            ax.errorbar(phi, phij, yerr=err, fmt=".", ms=3, label=label)
            if np.isfinite(float(row["alpha"])):
                x = np.linspace(*ds.attrs["glass_fit_range"], 20)
                ax.plot(x, fits.glass_phij(x, float(row["glass_phi_j"]), float(row["alpha"])), "k:", lw=0.8)
        ax.set_title(title)
        ax.set_xlabel("phi")
        ax.set_ylabel("phi~_J = phi / (1 - 2/p)")
        ax.set_xlim(0.6, 0.9)
    axes[0].set_ylim(0.8, 0.92)
    axes[1].set_ylim(0.84, 0.875)  # the binary branches differ by ~1e-3: zoom in
    x = np.linspace(0.74, 0.89, 60)
    axes[0].plot(x, x / (1 - 2 / hard_disk_solid(x)[0]), "k-", lw=0.8, label="crystal, Alder-Hoover-Young 1968")
    x = np.linspace(0.70, 0.80, 50)
    axes[1].plot(x, fits.cubic_phij(x), "k-", label="Eq. 13.3 (published)")
    if np.all(np.isfinite(binary["cubic"].values)):
        # solid over the fitted range (up to where a ten times faster compression separates), dashed beyond
        top = min(float(binary.attrs.get("liquid_fit_max", 0.80)), 0.80)
        inside = x <= top
        axes[1].plot(x[inside], fits.cubic_phij(x[inside], binary["cubic"].values), "r-",
                     label=f"Eq. 13.3 refitted (to phi = {top:.3f})")
        axes[1].plot(x[~inside], fits.cubic_phij(x[~inside], binary["cubic"].values), "r--")
    axes[0].legend(loc="lower right", fontsize=8)
    axes[1].legend(loc="upper left", fontsize=8)
    return fig


def plot_glass_entropy(binary, mono):
    """Left: excess free energies of the liquid (EOS integral) and the SOC glasses (BCMD) vs phi
    (after Fig. 13.11); right: s_c - s_mix vs phi for the binary and monodisperse systems (after
    Fig. 13.12).

    Parameters
    ----------
    binary, mono : xarray.Dataset
        The entropy datasets of the binary and monodisperse systems
        (:func:`hardpack.glass.study.entropy_dataset`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
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


def plot_glass_jamming(eos, relaxed):
    """Jamming densities of the mixture vs growth rate (after Donev 2006, Fig. 13.8): the glassy
    branch's phi_J (Eq. 13.4 fit) of every compression, and the fast glasses before and after
    relaxation and recompression, per run, with the printed ~0.85 (slowest runs) and ~0.847 (relaxed
    fast glasses).

    Parameters
    ----------
    eos : xarray.Dataset
        The glass_eos summary of the mixture.
    relaxed : xarray.Dataset
        The relaxed-glass summary (:func:`hardpack.glass.study.relaxed_dataset`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = figure(1, 1, figsize=(5.0, 3.6))
    rates = eos["growth_rate"].values
    comp = np.isfinite(rates) & (rates > 0)
    ax.errorbar(rates[comp], eos["glass_phi_j"].values[comp], yerr=eos["glass_phi_j_err"].values[comp], fmt="o",
                label="compression: glassy branch (Eq. 13.4 fit)")
    ax.plot(relaxed["rate"], relaxed["phi_J_fast"], "v", mfc="none", label="fast compression (not truly jammed)")
    ax.plot(relaxed["rate"], relaxed["phi_J"], "^",
            label=f"relaxed ({relaxed.attrs['relax_collisions']:g} coll./disk), recompressed")
    ax.axhline(0.85, color="k", lw=0.8, ls="--", label="Donev: slowest runs ~0.85")
    ax.axhline(0.847, color="k", lw=0.8, ls=":", label="Donev: relaxed fast glasses ~0.847")
    ax.set_xscale("log")
    ax.set_xlabel("growth rate Gamma")
    ax.set_ylabel("jamming density phi_J")
    ax.set_title(f"binary disks, N = {relaxed.attrs['N']}")
    ax.legend(loc="lower left", fontsize="small")
    return fig


def plot_glass_crystal(eos, crystal_bcmd):
    """Free energy of monodisperse disks by EOS integration and by BCMD (after Donev 2006, Fig.
    13.2). Left: Delta f(phi) integrated from the ideal gas along the slowest compression, and the
    BCMD points of the defect-free crystal. Right: the differences from that integral: the BCMD
    points, and the decompression EOS integrated bin by bin from the lowest BCMD point (the
    crystal's own EOS; where it meets the higher BCMD points, BCMD and EOS integration agree).

    Parameters
    ----------
    eos : xarray.Dataset
        The monodisperse EOS summary (:func:`hardpack.glass.study.eos_dataset`) with a
        ``decompression`` branch.
    crystal_bcmd : xarray.Dataset
        BCMD of the crystal over (phi, seed) with ``excess``.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    from hardpack.glass.study import liquid_excess_at

    fig, axes = figure(1, 2, figsize=(9.0, 3.6))
    slow = eos.sel(branch=eos.attrs["cubic_branch"])
    ok = np.isfinite(slow["excess"].values)
    p, f = slow["phi_mean"].values[ok], slow["excess"].values[ok]
    axes[0].plot(p, f, "-", color="C0", label=f"EOS integral, compression at {slow['growth_rate'].item():g}")
    phi = np.round(crystal_bcmd["phi"].values.astype(float), 6)
    excess = crystal_bcmd["excess"].values.astype(float)
    levels = np.unique(phi)
    mean = np.array([excess[phi == x].mean() for x in levels])
    err = np.array([excess[phi == x].std(ddof=1) / np.sqrt((phi == x).sum()) if (phi == x).sum() > 1 else np.nan
                    for x in levels])
    n = int(np.asarray(crystal_bcmd["n_particles"].values).max())
    axes[0].errorbar(levels, mean, yerr=err, fmt="s", color="C3", ms=5, label="defect-free crystal, BCMD")
    base = np.array([liquid_excess_at(eos, x)[0] for x in levels])
    axes[1].errorbar(levels, mean - base, yerr=err, fmt="s", color="C3", ms=5, label="crystal, BCMD")
    dec = eos.sel(branch="decompression")
    width = float(eos.attrs["bin_width"])
    after = eos["phi"].values > levels[0]
    steps = width * (dec["Z"].values[after] - 1.0) / dec["phi_mean"].values[after]
    empty = ~np.isfinite(steps)
    steps = steps[: int(np.argmax(empty)) if empty.any() else steps.size]   # up to the first empty bin
    grid = levels[0] + width * np.arange(steps.size + 1)
    grid, curve = grid[grid <= p.max()], (mean[0] + np.concatenate([[0.0], np.cumsum(steps)]))[grid <= p.max()]
    ref = np.array([liquid_excess_at(eos, x)[0] for x in grid])
    axes[1].plot(grid, curve - ref, "-", color="C2", label=f"crystal: BCMD at {levels[0]:g} + decompression EOS")
    axes[1].axhline(0.0, color="C0", lw=0.8)
    axes[0].set_xlabel("phi")
    axes[0].set_ylabel("excess free energy per disk (kT)")
    axes[1].set_xlabel("phi")
    axes[1].set_ylabel("Delta f - Delta f(compression) (kT)")
    axes[0].set_title(f"monodisperse disks, N = {n}")
    for ax in axes:
        ax.legend(fontsize="small")
    return fig


def plot_glass_separated(freezing, decompressions=()):
    """The fully phase-separated crystal of the mixture. Left (after Donev 2006, Fig. 13.4): the
    densities of the small-disk phase A and the large-disk phase B against the overall density,
    with the monodisperse transition region 0.70-0.72 and the overall densities at which each
    phase reaches its middle (printed: A at ~0.75, B at ~0.65). Right, given decompressions (after
    Fig. 13.5): the reduced pressure of the decompressed slab crystal per rate (windows averaged in
    bins of 0.005) against the separated crystal's equilibrium Z from the monodisperse EOS.

    Parameters
    ----------
    freezing : xarray.Dataset
        The freezing summary (:func:`hardpack.glass.study.freezing_dataset`) with ``phi_a``,
        ``phi_b``, ``z_separated`` and ``phi_a_melts``, ``phi_b_melts``.
    decompressions : sequence of xarray.Dataset, optional
        Time series of decompressions of the phase-separated crystal (``phi``, ``Z`` per window;
        attribute ``growth_rate``).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    panels = 2 if len(decompressions) else 1
    fig, axes = figure(1, panels, figsize=(5.0 * panels, 3.8))
    ax = axes[0] if panels == 2 else axes
    phi = freezing["phi"].values
    ax.axhspan(0.70, 0.72, color="0.85", label="monodisperse transition 0.70-0.72")
    ax.plot(phi, phi, color="0.5", lw=0.8, ls=":")
    ax.plot(phi, freezing["phi_a"], color="C0", label="phase A (small disks)")
    ax.plot(phi, freezing["phi_b"], color="C3", label="phase B (large disks)")
    t = float(freezing.attrs.get("phi_transition", 0.71))
    for name, colour, printed in (("phi_a_melts", "C0", 0.75), ("phi_b_melts", "C3", 0.65)):
        ax.plot([float(freezing[name])], [t], "o", color=colour, ms=6)
        ax.axvline(printed, color=colour, lw=0.8, ls="--")
    ax.plot([], [], "k--", lw=0.8, label="Donev: A melts at ~0.75, B at ~0.65")
    ax.set_xlabel("overall phi")
    ax.set_ylabel("density of the phase")
    ax.set_title(f"fully phase-separated crystal, kappa = {freezing.attrs['kappa']:g}")
    ax.legend(loc="lower right", fontsize="small")
    if panels == 2:
        right = axes[1]
        right.plot(phi, freezing["z_separated"], "k-", lw=1.2,
                   label="separated crystal, equilibrium (monodisperse EOS)")
        edges = np.arange(0.5, 0.9, 0.005)
        for k, ts in enumerate(sorted(decompressions, key=lambda t: -abs(float(t.attrs["growth_rate"])))):
            p, z = ts["phi"].values, ts["Z"].values
            which = np.digitize(p, edges)
            bins = np.unique(which)
            right.plot([p[which == b].mean() for b in bins], [z[which == b].mean() for b in bins], "-", color=f"C{k}",
                       lw=1.0, label=f"decompression at Gamma = {abs(float(ts.attrs['growth_rate'])):g}")
        right.set_yscale("log")
        right.set_xlabel("phi")
        right.set_ylabel("Z = PV / NkT")
        right.set_title(f"N = {int(decompressions[0].attrs['N'])}")
        right.legend(loc="upper left", fontsize="small")
    return fig


def plot_glass_relaxation(runs):
    """Pressure relaxation of the mixture's glasses at fixed phi (after Donev 2006, Fig. 13.7):
    Z per block of NVE MD from each compression rate's snapshot against the collisions per disk
    since the start (the block ends).

    Parameters
    ----------
    runs : list of xarray.Dataset
        ``hardpack eos --equilibration 0`` results (``Z_block`` over ``block``; attributes
        ``collisions``, ``equilibration``, ``N``, ``phi`` and ``init``, the snapshot's path, which
        names the rate as ``g<rate>``).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    import re

    fig, ax = figure(1, 1, figsize=(5.2, 3.8))

    def rate_of(ds):
        match = re.search(r"/g([0-9.e+-]+)/", str(ds.attrs.get("init", "")))
        return float(match.group(1)) if match else float("nan")

    rates = sorted({rate_of(ds) for ds in runs}, reverse=True)
    labelled = set()
    for ds in sorted(runs, key=rate_of, reverse=True):
        rate = rate_of(ds)
        z = ds["Z_block"].values
        n_disks = float(ds.attrs["N"])
        per_block = float(ds.attrs["collisions"]) / z.size / n_disks
        start = float(ds.attrs.get("equilibration", 0)) / n_disks
        colour = f"C{rates.index(rate) % 10}"
        ax.plot(start + per_block * np.arange(1, z.size + 1), z, "-", lw=1.0, color=colour,
                label=None if rate in labelled else f"compressed at Gamma = {rate:g}")
        labelled.add(rate)
    ax.set_xscale("log")
    ax.set_xlabel("collisions per disk since the snapshot")
    ax.set_ylabel("Z = PV / NkT (block)")
    phi = float(runs[0].attrs["phi"]) if runs else float("nan")
    n = int(runs[0].attrs["N"]) if runs else 0
    ax.set_title(f"binary disks at phi = {phi:.3f}, N = {n}")
    ax.legend(fontsize="small")
    return fig


def plot_glass_soc(eos, runs, summary):
    """SOC solids of the mixture (after Donev 2006, Fig. 13.9): left, Z(phi) of each compression in
    cells (coloured by its start density phi_0) over the slowest unconstrained compression; right,
    phi_J in the cells and after relaxation without them vs phi_0, with the printed ~0.83 and ~0.85.

    Parameters
    ----------
    eos : xarray.Dataset
        The mixture's glass_eos summary (its slowest branch is drawn).
    runs : list of xarray.Dataset
        SOC compression time series (:func:`hardpack.glass.soc.compress_in_cells`).
    summary : xarray.Dataset
        Their summary (:func:`hardpack.glass.soc.soc_summary`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    from matplotlib import colormaps

    fig, (ax, bx) = figure(1, 2, figsize=(10.0, 4.0), layout="constrained")
    slowest = eos["branch"].values[int(np.argmin(eos["growth_rate"].values))]
    row = eos.sel(branch=slowest)
    ok = np.isfinite(row["Z"].values) & (row["phi_mean"].values >= 0.65)
    ax.plot(row["phi_mean"].values[ok], row["Z"].values[ok], "k-", lw=1.6,
            label=f"no cells, Gamma = {float(row['growth_rate']):g}")
    phi0s = sorted({round(float(ds.attrs["phi0"]), 4) for ds in runs})
    cmap = colormaps["viridis"]
    first_seed = min((int(ds.attrs["seed"]) for ds in runs), default=0)
    for ds in runs:
        phi0 = round(float(ds.attrs["phi0"]), 4)
        colour = cmap(phi0s.index(phi0) / max(1, len(phi0s) - 1))
        labelled = int(ds.attrs["seed"]) == first_seed and phi0 in (phi0s[0], phi0s[-1])
        ax.plot(ds["phi_mid"].values, ds["Z"].values, "-", lw=0.8, color=colour,
                label=f"in cells from phi_0 = {phi0:g}" if labelled else None)
    ax.set_yscale("log")
    ax.set_xlim(min(phi0s) - 0.01, 0.86)
    ax.set_xlabel("phi")
    ax.set_ylabel("Z = PV / NkT (pair collisions)")
    a = runs[0].attrs if runs else {}
    ax.set_title(f"N = {a.get('n_particles', 0)}, cells of Delta mu = {a.get('dmu', float('nan')):g}, "
                 f"Gamma = {a.get('growth_rate', float('nan')):g}", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    x = summary["phi0"].values
    for name, marker, label in (("phi_J_soc", "o", "in cells"), ("phi_J_relaxed", "s", "cells removed, relaxed")):
        values = summary[name].values
        mean = np.nanmean(values, axis=1)
        count = np.sum(np.isfinite(values), axis=1)
        err = np.where(count > 1, np.nanstd(values, axis=1, ddof=min(1, values.shape[1] - 1)) / np.sqrt(count), 0.0)
        bx.errorbar(x, mean, yerr=err, fmt=marker + "-", ms=4, capsize=2, label=label)
    bx.axhline(0.83, color="C0", ls=":", lw=0.8, label="Donev: ~0.83 from liquid snapshots")
    bx.axhline(0.85, color="C1", ls=":", lw=0.8, label="Donev: ~0.85 after relaxation")
    bx.set_xlabel("phi_0 of the snapshot")
    bx.set_ylabel("phi_J = phi / (1 - 2/Z)")
    bx.set_title(f"jamming densities ({summary.sizes['seed']} seed(s))", fontsize=9)
    bx.legend(fontsize=7)
    return fig


def _snapshot_phi(ds) -> float:
    """The snapshot's density: BCMD shrinks the radii by (1 - delta) (attribute ``delta``)."""
    shrink = (1.0 - float(ds.attrs.get("delta", 0.0))) ** int(ds.attrs.get("dim", 2))
    return round(float(ds.attrs["phi"]) / shrink, 3)


def plot_glass_cell_pressure(binary, mono):
    """Cell-wall pressure p_c of the SOC glasses as their cells shrink at fixed phi (after Donev
    2006, Fig. 13.10): in glasses p_c vanishes at large cells (the disks never reach the walls);
    in the liquid it stays positive, so the liquid's BCMD free energy depends on the cell size.

    Parameters
    ----------
    binary, mono : list of xarray.Dataset
        BCMD results (:func:`hardpack.freeenergy.run_bcmd`) of the snapshots of each system, with
        ``dmu_mid`` and ``p_c`` per segment and the attributes ``phi``, ``delta`` and ``dim``.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, axes = figure(1, 2, figsize=(9.0, 3.6))
    for ax, runs, name in ((axes[0], binary, "binary (1/3 large, 1.4 : 1)"), (axes[1], mono, "monodisperse")):
        levels = sorted({_snapshot_phi(ds) for ds in runs})
        colours = {phi: f"C{k % 10}" for k, phi in enumerate(levels)}
        labelled = set()
        for ds in sorted(runs, key=lambda r: float(r.attrs["phi"])):
            phi = _snapshot_phi(ds)
            p_c = ds["p_c"].values
            keep = p_c > 0
            ax.plot(ds["dmu_mid"].values[keep], p_c[keep], "-", lw=0.8, color=colours[phi],
                    label=None if phi in labelled else f"phi_0 = {phi:.3f}")
            labelled.add(phi)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cell size Delta mu (disk radii)")
        ax.set_ylabel("cell pressure p_c")
        ax.set_title(name)
        ax.legend(fontsize="small")
    return fig


def _value_error(value: float, error: float) -> str:
    """value +- error in mathtext, the error to two significant digits and the value to its decimals."""
    if not (np.isfinite(error) and error > 0):
        return rf"{value:.4g} \pm {error:g}"
    decimals = max(0, 1 - int(np.floor(np.log10(error))))
    return rf"{value:.{decimals}f} \pm {error:.{decimals}f}"


def _fit_label(fit) -> str:
    return (rf"fit $s_c = s_{{\rm ref}}\,e^{{-b(\phi_J - {fit.phi_ref:g})}}$ ({fit.n_points} ensembles):" "\n"
            rf"$s_{{\rm ref}} = {_value_error(fit.s_ref, fit.s_ref_err)}$, "
            rf"$b = {_value_error(fit.decay, fit.decay_err)}$")


def plot_microsegregated(summary):
    """s_c against phi_J of each label ensemble, with phi_J's standard error, the uncorrelated
    ("random") labels marked, s_mix dashed and the exponential fit of the summary with its
    parameters and standard errors in the legend (after Donev 2006, Fig. 13.16).

    Parameters
    ----------
    summary : xarray.Dataset
        The micro-segregated summary over ensembles.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    from hardpack.glass.microsegregated import ExponentialFit

    fig, ax = figure(1, 1, figsize=(5.2, 4.6), layout="constrained")
    names = summary["ensemble"].values
    phi_j, s_c = summary["phi_J"].values, summary["s_c"].values
    random = names == "random"
    clustered = ~random
    points = ax.scatter(phi_j[clustered], s_c[clustered], c=summary["R"].values[clustered], cmap="viridis", s=18,
                        zorder=3, label="Matérn labels")
    ax.errorbar(phi_j, s_c, xerr=summary["phi_J_err"].values, fmt="none", ecolor="0.6", lw=0.8, zorder=2)
    if random.any():
        ax.plot(phi_j[random], s_c[random], "o", mfc="none", mec="k", ms=8, label="uncorrelated labels")
    ax.axhline(float(summary["s_mix"].values[0]), color="k", ls="--", lw=0.8, label=r"$s_{\rm mix}$")
    fit = ExponentialFit.from_attrs(summary.attrs)
    if fit is not None:
        lo, hi = float(np.min(phi_j)), float(np.max(phi_j))
        x = np.linspace(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo), 100)
        ax.plot(x, fit(x), "r-", lw=1.0, label=_fit_label(fit))
    else:
        status = str(summary.attrs.get("sc_fit_status", "no fit in the summary"))
        ax.plot([], [], " ", label=textwrap.fill(status, 60))
    with rc_context(RC):
        fig.colorbar(points, ax=ax, label=r"$R$ (Matérn correlation length)")
        ax.set_xlabel(r"$\phi_J$")
        ax.set_ylabel(rf"$s_c$ (Markov estimate, {summary.attrs['s_c_window']} windows)")
        ax.set_title(f"micro-segregated packings, N = {summary.attrs['N']}")
        fig.legend(loc="outside lower center", ncols=2)
    return fig


def _map_panel(fig, ax, maps, key, label, fmt):
    import matplotlib
    import matplotlib.colors as mcolors
    from matplotlib.patches import Rectangle

    values = np.ma.masked_invalid(maps[key].values)
    n_r, n_nu = values.shape
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="none")
    present = values.compressed()
    norm = mcolors.Normalize(*(present.min(), present.max()) if present.size else (0.0, 1.0))
    mesh = ax.pcolormesh(np.arange(n_nu + 1) - 0.5, np.arange(n_r + 1) - 0.5, values, cmap=cmap, norm=norm)
    for i in range(n_r):
        for j in range(n_nu):
            if values.mask[i, j]:
                ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///", edgecolor="0.6", lw=0))
                ax.text(j, i, "missing", ha="center", va="center", fontsize=7, color="0.3")
            else:
                shade = cmap(norm(values[i, j]))
                dark = 0.299 * shade[0] + 0.587 * shade[1] + 0.114 * shade[2] < 0.5
                ax.text(j, i, fmt.format(values[i, j]), ha="center", va="center", fontsize=7,
                        color="w" if dark else "k")
    ax.set_xticks(range(n_nu), [f"{v:g}" for v in maps["nu"].values])
    ax.set_yticks(range(n_r), [f"{v:g}" for v in maps["R"].values])
    ax.set_xlabel(r"$\nu$ (Matérn smoothness)")
    ax.set_ylabel(r"$R$ (Matérn correlation length)")
    ax.grid(False)
    if present.size:
        fig.colorbar(mesh, ax=ax, label=label)


def plot_microsegregated_maps(maps):
    """Colour maps of phi_J(R, nu) (left) and s_c(R, nu) (right) over the grid of Matérn
    parameters, the values written in the cells and cells without an ensemble hatched as missing
    (after Donev 2006, Fig. 13.17: nu on the x axis, R on the y axis).

    Parameters
    ----------
    maps : xarray.Dataset
        phi_J and s_c over the (R, nu) grid (:func:`hardpack.glass.microsegregated.grid_maps`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, axes = figure(1, 2, figsize=(9.5, 3.8), layout="constrained")
    with rc_context(RC):
        _map_panel(fig, axes[0], maps, "phi_J", r"$\phi_J$ (mean over packings)", "{:.4f}")
        _map_panel(fig, axes[1], maps, "s_c", rf"$s_c$ (Markov estimate, {maps.attrs['s_c_window']} windows)",
                   "{:.3f}")
        fig.suptitle(f"micro-segregated packings, N = {maps.attrs['N']}")
    return fig
