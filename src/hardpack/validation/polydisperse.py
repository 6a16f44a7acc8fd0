"""Validation rows of the EOS-vs-moments study (Ogarko, dissertation, ch. 3): fluid Z against
BMCSL, jamming densities of the bi-/tridisperse equivalents against the polydisperse ones, the
jamming densities against the published fits, and crystallisation of the slow runs. Each claim
covers the families and widths of its target's ``domain``; other (family, width) pairs get no row.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from hardpack.eos import theory
from hardpack.eos.study import seed_statistics
from hardpack.errors import InvalidInputError
from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import load_targets

#: system -> the target of its equivalence with the polydisperse phi_J
EQUIVALENCE = {"tri": "ogarko-tri-equivalence", "bi": "ogarko-bi-equivalence"}
#: family -> the target of its published phi_J fit
FITS = {"uniform_size": "ogarko-eq3.15-fit", "uniform_volume": "ogarko-eq3.16-fit",
        "lognormal": "ogarko-eq3.52-fit"}
#: large-particle q6 crystallinity counted as partial crystallisation (crystallisation_rows):
#: random jammed packings give 0.000-0.004 in every fast run of the study, and the published
#: breakdown is a partial crystallisation of the large species, not a full crystal
CRYSTALLISED = 0.05


def _published_fit(target, width: float) -> float:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(getattr(theory, target.published_from)(width))


def fluid_rows(summary) -> list[Row]:
    """One row per (distribution, system): the largest |Z/Z_BMCSL - 1| over phi < 0.5.

    Parameters
    ----------
    summary : xarray.Dataset
        The eos_fluid_summary.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    t = load_targets()["ogarko-fluid-bmcsl"]
    out = []
    for case in summary["case"].values:
        c = summary.sel(case=case)
        for system in c["system"].values:
            s = c.sel(system=system)
            s = s.where((s["phi"] < 0.5) & np.isfinite(s["Z"]), drop=True)
            if s.sizes["phi"] == 0:
                continue
            worst = int(np.argmax(np.abs(s["rel_dev"].values)))
            err = float(s["Z_err"].values[worst] / s["Z_bmcsl"].values[worst])
            phis = ", ".join(f"{p:.2f}: {100 * d:+.2f} %" for p, d in zip(s["phi"].values, s["rel_dev"].values))
            out.append(evaluate(t, float(s["rel_dev"].values[worst]), err, n=int(c["N"]), seeds=1,
                                label=f"{case} {system}", detail=f"N = {int(c['N'])}; by phi: {phis}"))
    return out


def jam_rows(summary, fits: bool = True) -> list[Row]:
    """Equivalence rows of the systems and widths the claims cover, and, if ``fits``, the
    published fits of phi_J(omega) / phi_J(sigma) at this summary's protocol.

    Parameters
    ----------
    summary : xarray.Dataset
        An eos_jam_summary.
    fits : bool, optional
        Add the rows of the published fits.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    stats = seed_statistics(summary)
    family, n = summary.attrs["family"], int(stats.attrs["N"])
    out = []
    for width in stats["width"].values:
        for system, tid in EQUIVALENCE.items():
            t = targets[tid]
            if system not in stats["system"].values or not t.covers(family, float(width)):
                continue
            s = stats.sel(width=width, system=system)
            out.append(evaluate(
                t, float(s["dev"]), float(s["dev_sem"]), n=n, seeds=int(s["n_seeds"]),
                label=f"{family} {stats.attrs['width_name']} = {width:g}",
                detail=f"phi_J poly {float(stats['phi_J_mean'].sel(width=width, system='poly')):.4f}, {system} "
                       f"{float(s['phi_J_mean']):.4f}; N = {n}, {int(s['n_seeds'])} seeds; large-particle "
                       f"crystallinity {float(s['crystallinity_large']):.3f}"))
    return out + (_fit_rows(stats, family, summary.attrs.get("study_protocol", "")) if fits else [])


def _fit_rows(stats, family, protocol) -> list[Row]:
    """phi_J of the polydisperse system against the published fit, one row per covered width."""
    t = load_targets()[FITS[family]]
    poly = stats.sel(system="poly")
    n = int(stats.attrs["N"])
    out = []
    for width in stats["width"].values:
        if not t.covers(family, float(width)):
            continue
        out.append(evaluate(
            t, float(poly["phi_J_mean"].sel(width=width)), float(poly["phi_J_sem"].sel(width=width)),
            n=n, seeds=int(poly["n_seeds"].sel(width=width)), published=_published_fit(t, float(width)),
            label=f"{family} {stats.attrs['width_name']} = {width:g}", detail=f"N = {n}; protocol {protocol}"))
    return out


def crystallisation_rows(summary) -> list[Row]:
    """Slow runs: the large species of the bidisperse equivalent of a uniform-size distribution
    partly crystallises for omega > 5 and not for omega <= 4; the maximal tridisperse equivalent and
    the polydisperse system do not crystallise; and phi_J against the published fit, which was
    measured at such slow rates.

    The text puts the onset at "omega >= 5 (R_bi >= 2.25)" once and at "omega > 5" twice; its
    equimolar bidisperse regimes are amorphous up to R_bi = 2.06 and a crystal of large particles
    from R_bi = 2.40 (Ogarko, Sec. 3.1.4). The US equivalents have R_bi = 2.06, 2.25, 2.40, 2.79 at
    omega = 4, 5, 6, 10, so 4 < omega <= 5 is the crossover: no target covers it.

    Crystallised = large-particle q6 crystallinity (:func:`hardpack.eos.study.large_species_crystallinity`)
    of at least :data:`CRYSTALLISED`, averaged over seeds.

    Parameters
    ----------
    summary : xarray.Dataset
        The eos_jam_summary of the slow runs.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    stats = seed_statistics(summary)
    family, n = summary.attrs["family"], int(stats.attrs["N"])
    protocol = summary.attrs.get("study_protocol", "")
    ids = {"bi": ("ogarko-crystallisation-bi-above5", "ogarko-crystallisation-bi-upto4"),
           "tri": ("ogarko-crystallisation-tri",), "poly": ("ogarko-crystallisation-poly",)}
    out = []
    for width in stats["width"].values:
        for system in stats["system"].values:
            s = stats.sel(width=width, system=system)
            value = float(s["crystallinity_large"])
            for tid in ids[str(system)]:
                t = targets[tid]
                if not t.covers(family, float(width)):
                    continue
                out.append(evaluate(
                    t, float(value >= CRYSTALLISED) if math.isfinite(value) else math.nan, n=n,
                    seeds=int(s["n_seeds"]), label=f"{family} {stats.attrs['width_name']} = {width:g} {system}",
                    detail=f"large-particle crystallinity {value:.3f} (threshold {CRYSTALLISED}); phi_J "
                           f"{float(s['phi_J_mean']):.4f}, {100 * float(s['dev']):+.2f} % from poly; N = {n}, "
                           f"{int(s['n_seeds'])} seeds; protocol {protocol}"))
    return out + _fit_rows(stats, family, protocol)


def polydisperse_rows(datasets) -> list[Row]:
    """Rows from the study's summaries: ``eos_jam_summary`` (per family and study: equivalence or
    crystallisation runs) and ``eos_fluid_summary``. A family with slow (crystallisation) runs is
    compared with its published fit there only: the fits were measured at such rates.

    Parameters
    ----------
    datasets : iterable of xarray.Dataset
        The summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).

    Raises
    ------
    InvalidInputError
        For a dataset of another kind.
    """
    datasets = list(datasets)
    slow = {ds.attrs["family"] for ds in datasets if ds.attrs.get("study") == "crystallisation"}
    out = []
    for ds in datasets:
        kind = ds.attrs.get("hardpack_kind")
        if kind == "eos_jam_summary" and ds.attrs.get("study") == "crystallisation":
            out += crystallisation_rows(ds)
        elif kind == "eos_jam_summary":
            out += jam_rows(ds, fits=ds.attrs["family"] not in slow)
        elif kind == "eos_fluid_summary":
            out += fluid_rows(ds)
        else:
            raise InvalidInputError(f"polydisperse validation input has hardpack_kind {kind!r}; expected "
                                    "eos_jam_summary or eos_fluid_summary")
    return out
