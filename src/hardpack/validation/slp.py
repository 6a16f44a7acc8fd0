"""Validation rows of the SLP study (Torquato & Jiao 2010) from the pipeline's summaries."""

from __future__ import annotations

import numpy as np

from hardpack.jamming.result import Verdict
from hardpack.validation.jamming import (
    fraction_statistics,
    fraction_uncertainty_note,
    verdict_fraction,
    verdict_notes,
)
from hardpack.validation.packings import n_particles, system_key
from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import load_targets


def densest_rows(summary) -> list[Row]:
    """Table II: the best density over seeds from N = 3^d random starts against the densest known
    lattice that the paper's SLP reaches (n/a where our N is not the paper's 3^d).

    Parameters
    ----------
    summary : xarray.Dataset
        SLP summary over seeds (variables d, phi, N).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    return _best_over_seeds(summary, "tj-t2-densest")


def ls_densest_rows(summary) -> list[Row]:
    """Table II, LS column: the best LS density over seeds from N = 3^d random starts (a deforming
    cell in d = 2, 3, the fixed cubic cell in d >= 4, as in the paper) against the paper's LS
    values; each row names our growth rate (the paper's is 10^-(3+d)).

    Parameters
    ----------
    summary : xarray.Dataset
        LS summary over (d, seed) (variables d, phi, N, growth_rate).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    return _best_over_seeds(summary, "tj-t2-ls")


def _best_over_seeds(summary, prefix: str) -> list[Row]:
    """One row per dimension: the best phi over seeds against the target ``{prefix}-d{d}``, with
    the number of seeds within its tolerance and the median."""
    targets = load_targets()
    out = []
    d_all = summary["d"].values.astype(int)
    phi_all = summary["phi"].values
    n_all = summary["N"].values.astype(int)
    rate_all = summary["growth_rate"].values if "growth_rate" in summary else None
    for d in np.unique(d_all):
        t = targets.get(f"{prefix}-d{d}")
        if t is None:
            continue
        phi, n = phi_all[d_all == d], n_all[d_all == d]
        hits = int(np.sum(np.abs(phi - t.published) <= t.tolerance))
        rates = [] if rate_all is None else np.unique(rate_all[d_all == d])
        rate = f"growth rate {', '.join(f'{g:g}' for g in rates)}; " if len(rates) else ""
        out.append(evaluate(t, float(np.max(phi)), n=int(n.min()), seeds=phi.size, label=f"d = {d}",
                            detail=f"{rate}N = {', '.join(str(m) for m in np.unique(n))}: {hits} of {phi.size} "
                                   f"seeds reach it; median phi {np.median(phi):.5f}"))
    return out


def mrj_jamming_rows(summaries) -> list[Row]:
    """Table I rattler fractions, the 3D backbone contact number and the strict-jamming rate of
    SLP MRJ packings (``slp_jamming`` summaries of ``hardpack verify`` verdicts over seeds).

    The rattler fraction's uncertainty is the larger of the standard error over seeds and the
    binomial error of the pooled count. Strict jamming is a published claim in d = 2 and 3 only
    (the paper's LP tests): other dimensions get no row.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        The slp_jamming summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for s in summaries:
        key = system_key(s)
        if key is None:
            continue
        label, d = s.attrs.get("ensemble", ""), key[1]
        n, seeds = n_particles(s), s.sizes["sample"]
        notes = verdict_notes(s)
        size = f"N = {n}, {seeds} seeds" + (f"; {notes}" if notes else "")
        rattler_target = (f"tj-t1-slp-rattlers-d{d}" if key[0] == "monodisperse" else
                          "tj-sec5-poly2d-rattlers" if key == ("us_omega2", 2) else None)
        if rattler_target in targets:
            target = targets[rattler_target]
            f, unc = fraction_statistics(s["rattler_fraction"].values, n, target.single_sample)
            out.append(evaluate(target, f, unc, n=n, seeds=seeds, label=label,
                                detail=f"{size}; {fraction_uncertainty_note(target.single_sample)}"))
        if key == ("monodisperse", 3):
            out.append(evaluate(targets["tj-sec6-slp-z-d3"], samples=s["z_mean"].values, n=n, label=label,
                                detail=f"{size}; backbone (rattlers removed)"))
        if f"tj-sec3-strict-d{d}" in targets:
            out.append(evaluate(targets[f"tj-sec3-strict-d{d}"], verdict_fraction(s["strict"].values),
                                n=n, seeds=seeds, label=label, detail=size))
    return out


def order_map_rows(summary) -> list[Row]:
    """Fig. 6: the densest packing of the SLP order map (a Barlow packing), the least dense from
    random dilute starts (the paper's 0.64; its lower densities come from the Sec. VI protocol,
    :func:`diluted_rows`), and the strict-jamming rate.

    Parameters
    ----------
    summary : xarray.Dataset
        The order-map summary.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    phi, t = summary["phi"].values, summary["T"].values
    n = summary["N"].values.astype(int)
    sizes = ", ".join(str(m) for m in np.unique(n))
    size = f"{phi.size} packings, N = {sizes}"
    k_max, k_min = int(np.argmax(phi)), int(np.argmin(phi))
    return [
        evaluate(targets["tj-fig6-densest"], float(phi[k_max]), n=int(n[k_max]), seeds=phi.size,
                 detail=f"{size}; its T = {t[k_max]:.3f}"),
        evaluate(targets["tj-fig6-least-dense-random"], float(phi[k_min]), n=int(n[k_min]), seeds=phi.size,
                 detail=f"{size}; its T = {t[k_min]:.3f}"),
        evaluate(targets["tj-fig6-strict"], verdict_fraction(summary["strict"].values), n=int(n.min()),
                 seeds=phi.size, detail=size),
    ]


def diluted_rows(summary) -> list[Row]:
    """Sec. VI of the paper: re-jammed diluted MRJ packings (rounds >= 1 of the ``slp_diluted``
    summary over (seed, round)). The least dense strictly jammed one (the least dense of all when
    none is) against the paper's lower end 0.6, its
    density without rattlers against 0.595, its backbone contact number against Z = 6.3 at
    phi = 0.6, and the fraction of them that are strictly jammed.

    Parameters
    ----------
    summary : xarray.Dataset
        The slp_diluted summary over (seed, round).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    diluted = summary.sel(round=[r for r in summary["round"].values if r >= 1])
    phi = diluted["phi"].values.ravel()
    if phi.size == 0:
        return []
    jammed = np.where(diluted["strict"].values.ravel() == Verdict.JAMMED, phi, np.nan)  # the paper's are jammed
    k = int(np.nanargmin(jammed)) if np.any(np.isfinite(jammed)) else int(np.nanargmin(phi))
    flat = {name: diluted[name].values.ravel() for name in ("phi_no_rattlers", "z_mean", "N", "strict")}
    seeds, rounds = diluted.sizes["seed"], diluted.sizes["round"]
    n = int(flat["N"][k])
    where = (f"{phi.size} re-jammed packings ({seeds} seeds x {rounds} rounds), N = "
             f"{int(flat['N'].min())}-{int(flat['N'].max())}; the least dense: seed "
             f"{int(diluted['seed'].values[k // rounds])}, round {int(diluted['round'].values[k % rounds])}")
    return [
        evaluate(targets["tj-sec6-diluted-phi"], float(phi[k]), n=n, seeds=seeds, detail=where),
        evaluate(targets["tj-sec6-diluted-phi-backbone"], float(flat["phi_no_rattlers"][k]), n=n, seeds=seeds,
                 detail=where),
        evaluate(targets["tj-sec6-diluted-z"], float(flat["z_mean"][k]), n=n, seeds=seeds,
                 detail=f"{where}; its phi = {phi[k]:.4f}"),
        evaluate(targets["tj-sec6-diluted-strict"], verdict_fraction(flat["strict"]), n=int(flat["N"].min()),
                 seeds=seeds, detail=where),
    ]
