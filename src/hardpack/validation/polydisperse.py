"""Validation rows of the EOS-vs-moments study (issue 6; Ogarko ch. 3): fluid Z against BMCSL, jamming
densities of the bi-/tridisperse equivalents against the polydisperse ones, and the jamming densities
against the published fits."""

from __future__ import annotations

import math
import warnings

import numpy as np

from hardpack.eos import theory
from hardpack.eos.study import seed_statistics
from hardpack.errors import InvalidInputError
from hardpack.validation.rows import Row, within

OGARKO = "Ogarko dissertation (seed 002)"
FLUID_STUDY = "EOS vs moments: fluid Z against BMCSL"
JAM_STUDY = "EOS vs moments: jamming density of equivalent mixtures"
#: published fits (function, source lines, fit accuracy, rate of the fit)
FITS = {
    "uniform_size": (theory.phij_fit_uniform_size, "Eq. 3.15, L4886-4902", 0.005, "Gamma_O = 8e-6"),
    "uniform_volume": (theory.phij_fit_uniform_volume, "Eq. 3.16, L4906-4925", 0.01, "Gamma_O = 16e-6"),
    "lognormal": (theory.phij_fit_lognormal, "Eq. 3.52, L6656-6705", 0.007, "Gamma_O = 16e-3"),
}
RATE_EFFECT = 0.01  # nu_max rises by up to 1 % as Gamma decreases (L4961-4970)
#: large-particle crystallinity counted as partial crystallisation (crystallisation_rows)
CRYSTALLISED = 0.05


def fluid_rows(summary) -> list[Row]:
    """One row per (distribution, system): the largest |Z/Z_BMCSL - 1| over phi < 0.5."""
    out = []
    for case in summary["case"].values:
        c = summary.sel(case=case)
        for system in c["system"].values:
            s = c.sel(system=system)
            s = s.where((s["phi"] < 0.5) & np.isfinite(s["Z"]), drop=True)
            if s.sizes["phi"] == 0:
                continue
            worst = int(np.argmax(np.abs(s["rel_dev"].values)))
            dev = float(s["rel_dev"].values[worst])
            err = float(s["Z_err"].values[worst] / s["Z_bmcsl"].values[worst])
            phis = ", ".join(f"{p:.2f}: {100 * d:+.2f} %" for p, d in zip(s["phi"].values, s["rel_dev"].values))
            out.append(Row(
                FLUID_STUDY, f"{case} {system}: worst Z/Z_BMCSL - 1 for phi < 0.5", f"{OGARKO} L4494-4502, L5707-5710",
                0.0, dev, err, 0.01, "simulations within 1 % of BMCSL (Eq. 3.9) for phi < 0.54 in ch. 3.1-3.2",
                within(dev, 0.0, 0.01, err), f"N = {int(c['N'])}; by phi: {phis}"))
    return out


def _dev_row(stats, family, width, system, tolerance, source, why):
    s = stats.sel(width=width, system=system)
    dev, err = float(s["dev"]), float(s["dev_sem"])
    return Row(JAM_STUDY, f"{family} {stats.attrs['width_name']}={width:g}: phi_J({system})/phi_J(poly) - 1",
               f"{OGARKO} {source}", 0.0, dev, err, tolerance, why, within(dev, 0.0, tolerance, err),
               f"phi_J poly {float(stats['phi_J_mean'].sel(width=width, system='poly')):.4f}, {system} "
               f"{float(s['phi_J_mean']):.4f}; N = {stats.attrs['N']}, {int(s['n_seeds'])} seeds; "
               f"large-particle crystallinity {float(s['crystallinity_large']):.3f}")


def jam_rows(summary, fits: bool = True) -> list[Row]:
    """Equivalence rows (tri: all widths up to omega = 10; bi: omega <= 4) and, if ``fits``, the
    published fits of phi_J(omega) / phi_J(sigma) at this summary's protocol."""
    stats = seed_statistics(summary)
    family = summary.attrs["family"]
    systems = list(stats["system"].values)
    out = []
    for width in stats["width"].values:
        if "tri" in systems and (family == "lognormal" or width <= 10):
            out.append(_dev_row(stats, family, width, "tri", 0.01, "L5753-5757, Fig. 3.12",
                                "tridisperse maximal equivalents within 1 % of the polydisperse phi_J up to "
                                "omega = 100 (perfect for omega <= 3); same protocol and N"))
        if "bi" in systems and (family == "lognormal" or width <= 4):
            out.append(_dev_row(stats, family, width, "bi", 0.01, "L4747-4752, L4851-4856",
                                "bidisperse equivalents within 1 % for 1.2 <= omega <= 4 (slightly below)"))
    return out + (_fit_rows(stats, family, summary.attrs.get("study_protocol", "")) if fits else [])


def _fit_rows(stats, family, protocol) -> list[Row]:
    """phi_J of the polydisperse system against the published fit, one row per width."""
    fit, source, accuracy, rate = FITS[family]
    poly = stats.sel(system="poly")
    out = []
    for width in stats["width"].values:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            published = float(fit(width))
        value, err = float(poly["phi_J_mean"].sel(width=width)), float(poly["phi_J_sem"].sel(width=width))
        tol = (accuracy + RATE_EFFECT) * published
        out.append(Row(
            JAM_STUDY, f"{family} {stats.attrs['width_name']}={width:g}: phi_J (polydisperse) vs published fit",
            f"{OGARKO} {source}", published, value, err, tol,
            f"fit accuracy {100 * accuracy:g} % at {rate} plus up to 1 % rate effect (L4961-4970); a faster "
            "protocol puts phi_J at or below the fit",
            within(value, published, tol, err), f"N = {stats.attrs['N']}; protocol {protocol}"))
    return out


def crystallisation_rows(summary) -> list[Row]:
    """Slow runs (Ogarko L4851-4865, L5074-5088, L5759-5763, L6831-6834): the large species of the
    bidisperse equivalent of a uniform-size distribution partly crystallises for omega > 5 and not for
    omega <= 4; the maximal tridisperse equivalent and the polydisperse system do not crystallise; and
    phi_J against the published fit, which was measured at such slow rates.

    The text puts the onset at "omega >= 5 (R_bi >= 2.25)" once (L4862) and at "omega > 5" twice
    (L5763, L6834); its equimolar bidisperse regimes are amorphous up to R_bi = 2.06 and a crystal of
    large particles from R_bi = 2.40 (L5074-5088). The US equivalents have R_bi = 2.06, 2.25, 2.40,
    2.79 at omega = 4, 5, 6, 10 (equal numbers), so 4 < omega <= 5 is the crossover: no bidisperse
    row there.

    Crystallised = large-particle q6 crystallinity (:func:`hardpack.eos.study.large_species_crystallinity`)
    of at least CRYSTALLISED, averaged over seeds. Random jammed packings give 0.000-0.004 in every
    fast run of the study; the published breakdown is "partial" crystallisation, not a full crystal."""
    stats = seed_statistics(summary)
    family = summary.attrs["family"]
    protocol = summary.attrs.get("study_protocol", "")
    out = []
    for width in stats["width"].values:
        for system in stats["system"].values:
            s = stats.sel(width=width, system=system)
            value = float(s["crystallinity_large"])
            expected = system == "bi" and family == "uniform_size" and width > 5
            if system == "bi":
                if family == "uniform_size" and 4 < width <= 5:
                    continue  # the crossover (docstring)
                why = ("bidisperse equivalents of US distributions: partial crystallisation of the large species "
                       "for omega > 5 (R_bi >= 2.40), none for 1.22 <= omega <= 4 (R_bi <= 2.06)")
            else:
                why = f"no crystallisation of the {system}disperse system for omega >= 1.4"
            out.append(Row(
                JAM_STUDY, f"{family} {stats.attrs['width_name']}={width:g}: {system} large-species crystallised "
                f"(1) or not (0), slow compression", f"{OGARKO} L4851-4865, L5759-5763", float(expected),
                float(value >= CRYSTALLISED), math.nan, 0.0, why, (value >= CRYSTALLISED) == expected,
                f"large-particle crystallinity {value:.3f} (threshold {CRYSTALLISED}); phi_J "
                f"{float(s['phi_J_mean']):.4f}, {100 * float(s['dev']):+.2f} % from poly; N = {stats.attrs['N']}, "
                f"{int(s['n_seeds'])} seeds; protocol {protocol}"))
    return out + _fit_rows(stats, family, protocol)


def polydisperse_rows(datasets) -> list[Row]:
    """Rows from the study's summaries: ``eos_jam_summary`` (per family and study: equivalence or
    crystallisation runs) and ``eos_fluid_summary``. A family with slow (crystallisation) runs is
    compared with its published fit there only: the fits were measured at such rates."""
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
