"""Validation rows of the jamming verdicts of the LS packings (Donev 2006, ch. 4 and ch. 9) and
of the ellipse density slope from their self-stress (Donev 2006, Sec. 5.9.2.1).

Input: ensemble jamming summaries (``jamming_summary`` rule: per seed z_mean, rattler_fraction,
isostaticity_gap, collective, ...), matched to a published system by
:func:`hardpack.validation.packings.system_key`.
"""

from __future__ import annotations

import math

import numpy as np

from hardpack.jamming.result import Verdict
from hardpack.validation.packings import n_particles, system_key
from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import load_targets


def _system(key) -> str | None:
    """Target suffix of a recognised system: d<d> for monodisperse spheres, binary2d."""
    if key is None:
        return None
    if key[0] == "monodisperse":
        return f"d{key[1]}"
    return "binary2d" if key == ("binary_1.4_equimolar", 2) else None


def fraction_statistics(values, n_particles: int, single_sample: bool = False) -> tuple[float, float]:
    """Mean of per-seed particle fractions and its uncertainty: the larger of the standard error
    over seeds and the binomial error of the pooled count (one packing of N particles still has
    sqrt(f (1 - f) / N)). For a published value from one packing (``single_sample``), the
    uncertainty of its difference from our mean: the spread of one packing (the larger of the
    standard deviation over seeds and the binomial sqrt(f (1 - f) / N)) times sqrt(1 + 1/n), as
    :func:`hardpack.validation.rows.seed_statistics` does for other single-sample targets. NaN
    values make the mean NaN (the row then fails).

    Parameters
    ----------
    values : array_like of float, shape (n_seeds,)
        Per-seed fractions.
    n_particles : int
        Particles per packing.
    single_sample : bool, optional
        The published value is one packing's.

    Returns
    -------
    mean : float
        Mean fraction.
    uncertainty : float
        Its uncertainty.
    """
    values = np.asarray(values, float)
    mean = float(values.mean())
    if not math.isfinite(mean):
        return math.nan, math.nan
    sd = values.std(ddof=1) if values.size > 1 else 0.0
    if single_sample:
        one = max(math.sqrt(max(mean * (1 - mean), 0.0) / n_particles), sd)
        return mean, one * math.sqrt(1 + 1 / values.size)
    binomial = math.sqrt(max(mean * (1 - mean), 0.0) / (n_particles * values.size))
    return mean, max(binomial, sd / math.sqrt(values.size))


def fraction_uncertainty_note(single_sample: bool) -> str:
    """How :func:`fraction_statistics` made a row's uncertainty, for the row's detail.

    Parameters
    ----------
    single_sample : bool
        The published value is one packing's (the ``single_sample`` of the target).

    Returns
    -------
    str
        The explanation.
    """
    if single_sample:
        return ("the published value is one packing: uncertainty of one more packing, max(SD over seeds, "
                "binomial) x sqrt(1 + 1/seeds)")
    return "uncertainty: binomial or over seeds, the larger"


def verdict_fraction(values) -> float:
    """Fraction of seeds with a positive verdict (NaN when any verdict is missing).

    Parameters
    ----------
    values : array_like of float, shape (n_seeds,)
        Verdict codes (1: jammed).

    Returns
    -------
    float
        The fraction.
    """
    values = np.asarray(values, float)
    return float(np.mean(values == 1)) if np.all(np.isfinite(values)) else math.nan


def verdict_notes(summary) -> str:
    """Undetermined verdicts (code -2) and numerical fallbacks of an ensemble's jamming tests, for
    a row's detail (empty when there were none).

    Parameters
    ----------
    summary : xarray.Dataset
        Verdict summary over seeds.

    Returns
    -------
    str
        The notes, "; "-separated.
    """
    notes = []
    for test in ("collective", "strict"):
        if test in summary:
            undetermined = int(np.sum(np.asarray(summary[test].values) == Verdict.UNDETERMINED))
            if undetermined:
                notes.append(f"{undetermined} {test} verdict(s) undetermined (counted as not jammed)")
    for name in summary.data_vars:
        if str(name).startswith("fallback_"):
            count = int(np.nansum(summary[name].values))
            if count:
                notes.append(f"{str(name).removeprefix('fallback_')}: {count}")
    return "; ".join(notes)


def largest_magnitude(values) -> float:
    """The value of largest magnitude (NaN if any is missing): a per-packing claim must hold for
    every seed.

    Parameters
    ----------
    values : array_like of float
        Per-seed values.

    Returns
    -------
    float
        The value.
    """
    values = np.asarray(values, float)
    return float(values[np.argmax(np.abs(values))]) if np.all(np.isfinite(values)) else math.nan


def jamming_rows(summaries) -> list[Row]:
    """Isostaticity, rattler fraction and collective-jamming rate of recognised LS ensembles.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        Verdict summaries of LS ensembles.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for s in summaries:
        system = _system(system_key(s))
        if system is None:
            continue
        n, seeds, label = n_particles(s), s.sizes["sample"], s.attrs.get("ensemble", "")
        size = f"N = {n}, {seeds} seeds"
        if notes := verdict_notes(s):
            size += f"; {notes}"
        gaps = np.asarray(s["isostaticity_gap"].values, float)
        if f"donev-ch9-isostatic-{system}" in targets:
            out.append(evaluate(
                targets[f"donev-ch9-isostatic-{system}"], largest_magnitude(gaps), n=n, seeds=seeds, label=label,
                detail=f"{size}; the claim holds per packing, so the row takes the gap of largest magnitude; "
                       f"gaps per seed {', '.join(f'{g:g}' for g in gaps)}; backbone Z "
                       f"{', '.join(f'{z:.4f}' for z in s['z_mean'].values)}"))
        for tid in (f"donev-ch9-rattlers-{system}", f"tj-t1-ls-rattlers-{system}"):
            if tid in targets:
                one = targets[tid].single_sample
                f, unc = fraction_statistics(s["rattler_fraction"].values, n, one)
                out.append(evaluate(targets[tid], f, unc, n=n, seeds=seeds, label=label,
                                    detail=f"{size}; {fraction_uncertainty_note(one)}"))
        if f"donev-4.7.2-collective-{system}" in targets:
            out.append(evaluate(targets[f"donev-4.7.2-collective-{system}"],
                                verdict_fraction(s["collective"].values), n=n, seeds=seeds, label=label,
                                detail=size))
        if f"donev-eq5.29-slope-{system}" in targets:
            out.append(_slope_row(targets[f"donev-eq5.29-slope-{system}"], s, n, seeds, label, size))
    return out


def _slope_row(target, summary, n: int, seeds: int, label: str, size: str) -> Row:
    """s_phi of Eq. 5.29 from the backbone self-stress of every seed (NaN when a seed had none)."""
    if "ellipse_slope" not in summary:
        return evaluate(target, math.nan, n=n, seeds=seeds, label=label,
                        detail=f"{size}; no seed has a self-stress to compute s_phi from")
    values = np.asarray(summary["ellipse_slope"].values, float)
    return evaluate(target, samples=values, n=n, seeds=seeds, label=label,
                    detail=f"{size}; per seed {', '.join(f'{v:.4f}' for v in values)}")


def strict_ls_rows(summaries) -> list[Row]:
    """The fraction of strictly jammed packings of each deforming-cell LS system (verdict
    summaries with the attribute ``d``) against Donev 2006, Sec. 4.7.2.3 ("typically" strictly
    jammed for small N).

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        Verdict summaries of deforming-cell LS systems.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for s in summaries:
        d = int(s.attrs["d"])
        tid = f"donev-4.7.2.3-deforming-ls-strict-d{d}"
        if tid not in targets:
            continue
        n, seeds = n_particles(s), s.sizes["sample"]
        strict = s["strict"].values
        detail = f"N = {n}, {seeds} seeds; strict verdicts {', '.join(map(str, strict))}"
        if notes := verdict_notes(s):
            detail += f"; {notes}"
        out.append(evaluate(targets[tid], verdict_fraction(strict), n=n, seeds=seeds,
                            label=s.attrs.get("ensemble", f"d = {d}"), detail=detail))
    return out
