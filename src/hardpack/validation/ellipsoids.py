"""Validation rows of the LS packings of hard ellipsoids (Donev 2006, Sec. 5.2, Figs. 5.1-5.2, and
Sec. 7.2).

Input: the contact summaries of the ellipsoid study (``ellipsoids/contacts3d``: one sample per
packing with coordinates ``beta``, ``alpha``, ``seed`` and the variables ``phi``, ``z_mean``,
``z_all``, ``nematic_S``). A claim about a maximum over alpha takes the alpha whose mean over seeds
is largest and judges that mean with its own standard error.
"""

from __future__ import annotations

import math

import numpy as np

from hardpack.jamming.result import Verdict
from hardpack.validation.rows import Row, evaluate, seed_statistics
from hardpack.validation.targets import load_targets

#: the M&M shape of Donev 2006, Fig. 5.1: oblate spheroids (beta = 1) of aspect ratio 1.9
MM = (1.0, 1.9)


def _cells(summary) -> dict:
    """{(beta, alpha): per-seed values} of every variable: ``{name: {(beta, alpha): array}}``."""
    beta = np.round(np.asarray(summary["beta"].values, float), 12)
    alpha = np.round(np.asarray(summary["alpha"].values, float), 12)
    keys = sorted(set(zip(beta.tolist(), alpha.tolist())))
    return {name: {k: np.asarray(summary[name].values, float)[(beta == k[0]) & (alpha == k[1])] for k in keys}
            for name in ("phi", "z_mean", "z_all", "nematic_S") if name in summary}


def _detail(cell: dict, key) -> str:
    return f"beta = {key[0]:g}, alpha = {key[1]:g}; per seed {', '.join(f'{v:.4f}' for v in cell[key])}"


def _largest(target, cell: dict, keys, n: int, label: str) -> Row:
    """The row of the (beta, alpha) with the largest mean among ``keys``."""
    keys = [k for k in keys if k in cell]
    if not keys:
        return evaluate(target, n=n, label=label, detail="no packing of these shapes in the study")
    best = max(keys, key=lambda k: seed_statistics(cell[k])[0])
    return evaluate(target, samples=cell[best], n=n, label=label, detail=_detail(cell, best))


def _summaries_3d(summaries):
    """(summary, smallest N) of the 3D summaries: the ellipse ones have no targets."""
    for s in summaries:
        if int(np.asarray(s["d"].values).ravel()[0]) == 3:
            yield s, int(np.asarray(s["N"].values).min())


def ellipsoid_rows(summaries) -> list[Row]:
    """Rows of the 3D ellipsoid summaries (module docstring); ellipse summaries have no targets.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        Ellipsoid packing summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for s, n in _summaries_3d(summaries):
        cells = _cells(s)
        phi, z = cells["phi"], cells["z_mean"]
        spheres = [k for k in phi if k[1] == 1.0]
        if spheres:
            per_seed = _sphere_point_per_seed(s)
            out.append(evaluate(targets["donev-5.2-phij-sphere-point"], samples=per_seed, n=n, label="alpha = 1",
                                detail=f"{len(spheres)} families, {per_seed.size} seeds (the seeds are the "
                                       f"independent samples); per seed {', '.join(f'{v:.4f}' for v in per_seed)}"))
        out.append(_largest(targets["donev-5.2-phij-max-self-dual"], phi, [k for k in phi if k[0] == 0.5], n,
                            "beta = 1/2"))
        out.append(_largest(targets["donev-5.2-z-plateau-spheroids"], z,
                            [k for k in z if k[0] in (0.0, 1.0) and k[1] > 1], n, "spheroids"))
        out.append(_largest(targets["donev-5.4-z-max-non-spheroids"], z,
                            [k for k in z if 0 < k[0] < 1 and k[1] > 1], n, "non-spheroids"))
        out.append(_duality(targets["donev-5.2-prolate-oblate-duality"], phi, n))
        for beta, name in ((0.0, "prolate"), (0.5, "self-dual"), (1.0, "oblate")):
            out.append(_maximum_location(targets["donev-5.2-phij-max-location"], phi, beta, n, name))
        if MM in phi:
            for tid, name in (("donev-fig5.1-mm-phi", "phi"), ("donev-fig5.1-mm-nematic", "nematic_S"),
                              ("donev-ch7-mm-z", "z_all")):
                out.append(evaluate(targets[tid], samples=cells[name][MM], n=n, label="M&M shape",
                                    detail=_detail(cells[name], MM)))
    return out


def _sphere_point_per_seed(summary) -> np.ndarray:
    """phi_J at alpha = 1 per seed, averaged over the families. At alpha = 1 every family holds
    spheres, so one seed gives the same start, and the same packing, in each family: the families
    are not independent samples (counting them as such shrinks the standard error by sqrt of
    their number). A seed with a missing value in any family is missing (NaN)."""
    alpha = np.round(np.asarray(summary["alpha"].values, float), 12)
    at_one = alpha == 1.0
    seeds = np.asarray(summary["seed"].values)[at_one]
    values = np.asarray(summary["phi"].values, float)[at_one]
    return np.array([values[seeds == k].mean() for k in np.unique(seeds)])


#: draws of the Monte Carlo error of the density maximum's location, and their seed
LOCATION_DRAWS, LOCATION_SEED = 2000, 52


def _maximum_location(target, phi: dict, beta: float, n: int, name: str) -> Row:
    """The aspect ratio of a family's largest phi_J: the vertex of the parabola through the densest
    grid point and its two neighbours (per-alpha means over seeds); its error from redrawing the
    three means within their standard errors. A maximum at the grid's end is that end (no error)
    when it lies outside the printed range, and undecided (n/a) when it does not."""
    label = f"{name} (beta = {beta:g})"
    alphas = sorted(k[1] for k in phi if k[0] == beta)
    stats = [seed_statistics(phi[(beta, a)]) for a in alphas]
    seeds = min((st[2] for st in stats), default=0)
    if len(alphas) < 3:
        return evaluate(target, n=n, seeds=0, label=label, detail=f"{len(alphas)} aspect ratios: need 3 or more")
    means = np.array([st[0] for st in stats])
    errors = np.array([st[1] for st in stats])
    k = int(np.argmax(means))
    grid = ", ".join(f"{a:g}: {m:.4f}" for a, m in zip(alphas, means))
    low, high = float(target.published) - target.tolerance, float(target.published) + target.tolerance
    if k in (0, len(alphas) - 1):
        edge = alphas[k]
        if low <= edge <= high:
            return evaluate(target, n=n, seeds=0, label=label,
                            detail=f"the densest point is the grid's end, alpha = {edge:g}: the maximum may "
                                   f"lie beyond; {grid}")
        return evaluate(target, edge, 0.0, n=n, seeds=seeds, label=label,
                        detail=f"the densest point is the grid's end, alpha = {edge:g}; {grid}")
    x = np.array(alphas[k - 1 : k + 2])

    def vertex(y):
        c2, c1, _ = np.polyfit(x, y, 2)
        return -c1 / (2.0 * c2) if c2 < 0 else math.nan

    value = vertex(means[k - 1 : k + 2])
    rng = np.random.default_rng(LOCATION_SEED)
    draws = np.array([vertex(means[k - 1 : k + 2] + errors[k - 1 : k + 2] * rng.standard_normal(3))
                      for _ in range(LOCATION_DRAWS)])
    draws = draws[np.isfinite(draws)]
    err = float(np.std(draws, ddof=1)) if draws.size > 1 and np.isfinite(errors[k - 1 : k + 2]).all() else math.nan
    return evaluate(target, float(value), err, n=n, seeds=seeds, label=label,
                    detail=f"parabola through alpha = {', '.join(f'{a:g}' for a in x)}; per-alpha mean phi_J {grid}")


def _duality(target, phi: dict, n: int) -> Row:
    """phi_J(prolate) - phi_J(oblate) at the aspect ratio where it is largest relative to its error."""
    pairs = sorted(k[1] for k in phi if k[0] == 0.0 and (1.0, k[1]) in phi and k[1] > 1)
    if not pairs:
        return evaluate(target, n=n, label="prolate - oblate", detail="no aspect ratio has both spheroids")
    rows = []
    for alpha in pairs:
        p_mean, p_err, p_seeds, _ = seed_statistics(phi[(0.0, alpha)])
        o_mean, o_err, o_seeds, _ = seed_statistics(phi[(1.0, alpha)])
        err = math.hypot(p_err, o_err)
        rows.append((abs(p_mean - o_mean) / err if err > 0 else math.inf, alpha, p_mean - o_mean, err,
                     min(p_seeds, o_seeds)))
    _, alpha, diff, err, seeds = max(rows)
    return evaluate(target, diff, err, n=n, seeds=seeds, label="prolate - oblate",
                    detail=f"alpha = {alpha:g}, the largest of {len(rows)} differences relative to its error")


CRYSTAL_DETAIL = "our laminate construction (contacts by the Perram-Wertheim function; the stretch by Eq. 8.3)"


def crystal_rows(families) -> list[Row]:
    """Rows of the laminate family (:func:`hardpack.geometry.ellipsoid_crystals.laminate_family`):
    the densest laminate at alpha = sqrt(3) (density, contacts), the stretch that gives alpha = 3
    and the density of the stretched laminate at the largest alpha of the family (Donev 2006, Sec.
    8.2, Eq. 8.3, Figs. 8.2-8.3). An alpha the family lacks leaves its row n/a.

    Parameters
    ----------
    families : iterable of xarray.Dataset
        Laminate families (variables over alpha).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for ds in families:
        alpha = np.asarray(ds["alpha"].values, float)
        densest = np.isclose(alpha, math.sqrt(3.0), rtol=0, atol=1e-12)
        three = np.isclose(alpha, 3.0, rtol=0, atol=1e-12)
        for tid, mask, name, label in (
                ("donev-8.2-phi-densest-laminate", densest, "phi_laminate", "alpha = sqrt(3)"),
                ("donev-8.2-contacts-densest-laminate", densest, "contacts_laminate", "alpha = sqrt(3)"),
                ("donev-8.3-stretch-alpha3", three, "stretch", "alpha = 3")):
            if mask.any():
                out.append(evaluate(targets[tid], float(ds[name].values[mask][0]), label=label, detail=CRYSTAL_DETAIL))
            else:
                out.append(evaluate(targets[tid], n=0, label=label, detail=f"the family has no {label}"))
        top = int(np.argmax(alpha))
        if alpha[top] > math.sqrt(3.0):
            out.append(evaluate(targets["donev-8.3-phi-stretched"], float(ds["phi_densest"].values[top]),
                                label=f"alpha = {alpha[top]:g}",
                                detail=f"stretch {float(ds['stretch'].values[top]):.6f}, "
                                       f"{float(ds['contacts_densest'].values[top]):g} contacts per particle"))
        else:
            out.append(evaluate(targets["donev-8.3-phi-stretched"], n=0, label="alpha > sqrt(3)",
                                detail="the family has no alpha beyond sqrt(3)"))
    return out


def crystal_search_rows(searches) -> list[Row]:
    """Rows of the small-cell crystal search at alpha = sqrt(3) (and the polished one at 1 / sqrt(3))
    (:func:`hardpack.md.crystal_search.crystal_search`): the density and the contacts per particle
    of the densest run over every cell size and seed (Donev 2006, Sec. 8.2.1), and the density of
    the densest run after the polish by the size ascent. Cells of fewer than 4 spheroids
    (Donev's smallest) leave the rows n/a.

    Parameters
    ----------
    searches : iterable of xarray.Dataset
        Search results, one per aspect ratio; those of other aspect ratios give no row.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    ids = ("donev-8.2-search-phi-best", "donev-8.2-search-contacts-best", "donev-8.2-search-phi-polished")
    at_peak = [ds for ds in searches if abs(float(ds.attrs["alpha"]) - math.sqrt(3.0)) < 1e-6]
    if not at_peak:
        return [evaluate(targets[tid], n=0, label="alpha = sqrt(3)", detail="no search at alpha = sqrt(3)")
                for tid in ids] + _oblate_rows(searches, targets)
    out = []
    for ds in at_peak:
        phi = np.asarray(ds["phi"].values, float)
        a, b = np.unravel_index(int(np.nanargmax(phi)), phi.shape)
        best = ds.isel(n=a, seed=b)
        n_max = int(ds["n"].max())
        runs = f"{phi.size} runs, {', '.join(str(int(n)) for n in ds['n'].values)} per cell"
        detail = (f"best of {runs}: n = {int(best['n'])}, seed {int(best['seed'])}, Z = {float(best['Z']):.3g}, "
                  f"contacts {int(best['min_contacts'])}-{int(best['max_contacts'])} per particle, "
                  f"{int(np.sum(ds['laminate'].values))} runs match the laminate")
        out.append(evaluate(targets[ids[0]], float(best["phi"]), n=n_max, label="alpha = sqrt(3)", detail=detail))
        out.append(evaluate(targets[ids[1]], float(best["contacts"]), n=n_max, label="alpha = sqrt(3)",
                            detail=detail))
        out.append(_polished_row(targets[ids[2]], ds, runs, n_max))
    return out + _oblate_rows(searches, targets)


def _oblate_rows(searches, targets) -> list[Row]:
    """The polished density of the search at alpha = 1 / sqrt(3), where the laminate of oblate
    spheroids has the same maximum (Donev 2006, Sec. 8.2, Fig. 8.2: phi(alpha) = phi(1 / alpha))."""
    target, label = targets["donev-8.2-search-phi-polished-oblate"], "alpha = 1/sqrt(3)"
    oblate = [ds for ds in searches if abs(float(ds.attrs["alpha"]) - 1.0 / math.sqrt(3.0)) < 1e-6]
    if not oblate:
        return [evaluate(target, n=0, label=label, detail="no search at alpha = 1/sqrt(3)")]
    rows = []
    for ds in oblate:
        runs = f"{ds['phi'].size} runs, {', '.join(str(int(n)) for n in ds['n'].values)} per cell"
        rows.append(_polished_row(target, ds, runs, int(ds["n"].max()), label=label))
    return rows


def _polished_row(target, search, runs: str, n_max: int, label: str = "alpha = sqrt(3)") -> Row:
    """The densest polished run of a search (n/a for a search run without the polish)."""
    polished = np.asarray(search["phi_polished"].values, float) if "phi_polished" in search else np.array([np.nan])
    if not np.isfinite(polished).any():
        return evaluate(target, n=0, label=label, detail="the search ran without the polish")
    a, b = np.unravel_index(int(np.nanargmax(polished)), polished.shape)
    best = search.isel(n=a, seed=b)
    detail = (f"best of {runs}, each polished: n = {int(best['n'])}, seed {int(best['seed'])}, contacts "
              f"{int(best['min_contacts_polished'])}-{int(best['max_contacts_polished'])} per particle, "
              f"{int(np.sum(search['laminate_polished'].values))} polished runs match the laminate")
    return evaluate(target, float(polished[a, b]), n=n_max, label=label, detail=detail)


#: aspect ratios "near the sphere point" of the second-order claim (Donev 2006, Sec. 5.6, Fig. 5.10:
#: semiaxes 1.025^-1 : 1 : 1.025)
NEAR_SPHERE_ALPHA = 1.1


def _sample_row(target, samples, n: int, label: str, detail: str) -> Row:
    """A row over per-packing samples; n/a (no seeds) when there are none."""
    if not len(samples):
        return evaluate(target, n=n, seeds=0, label=label, detail=f"no packing: {detail}")
    return evaluate(target, samples=samples, n=n, label=label, detail=detail)


def _every_packing_row(target, holds, n: int, label: str, detail: str) -> Row:
    """A per-packing claim ("every packing tested"): the fraction of packings for which it holds,
    judged without a sampling allowance, so one packing that breaks it fails the row; n/a when
    there is no packing."""
    if not len(holds):
        return evaluate(target, n=n, seeds=0, label=label, detail=f"no packing: {detail}")
    return evaluate(target, float(np.mean(holds)), n=n, seeds=len(holds), label=label, detail=detail)


def _certified(summary, mask) -> str:
    """"k second-order flexible at the jamming point, c of them certified ..." for the packings in
    ``mask`` (empty without such packings or the ``ascent_confirmed`` variable of
    :func:`hardpack.jamming.refine.verify_at_jamming_point`)."""
    if "ascent_confirmed" not in summary:
        return ""
    confirmed = np.asarray(summary["ascent_confirmed"].values)[mask]
    tried = int((confirmed >= 0).sum())
    return (f"{tried} second-order flexible at the jamming point, {int((confirmed == 1).sum())} of them "
            "certified by a denser packing without overlaps (size ascent)") if tried else ""


def ellipsoid_jamming_rows(summaries) -> list[Row]:
    """Rows of the jamming verdicts of the 3D ellipsoid packings (``ellipsoids/verdicts3d`` and
    ``ellipsoids/verdicts_near_sphere``: one sample per packing, coordinates ``beta``, ``alpha``,
    ``seed``, the variables of
    :meth:`hardpack.jamming.second_order.EllipsoidJammingResult.to_dataset`), judged against Donev
    2006, Sec. 5.6: the LS packings are second-order jammed even very close to the sphere point,
    where they are very hypostatic; their self-stress is unique and strictly positive; the smallest
    eigenvalue of A^T A lies 3-6 orders of magnitude below the next. The three claims about every
    packing are fractions that one failing packing fails; the eigenvalue gap is a mean over
    packings; a summary without the packings a row needs leaves it n/a.

    Parameters
    ----------
    summaries : iterable of xarray.Dataset
        Verdict summaries.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for s, n in _summaries_3d(summaries):
        alpha = np.asarray(s["alpha"].values, float)
        jammed = np.asarray(s["jammed"].values, float) > 0
        second = np.asarray(s["order_code"].values) == 2
        hypostatic = np.asarray(s["hypostatic"].values, float) > 0
        aspherical = alpha > 1.0
        near = aspherical & (alpha <= NEAR_SPHERE_ALPHA)
        out.append(_every_packing_row(
            targets["donev-5.6-ls-ellipsoids-jammed"], jammed[aspherical], n, "alpha > 1",
            f"{int(jammed[aspherical].sum())} of {int(aspherical.sum())} packings with alpha > 1 jammed"
            + (f" ({certified})" if (certified := _certified(s, aspherical)) else "")))
        near_ok = jammed & second & hypostatic
        undetermined = np.asarray(s["verdict"].values) == int(Verdict.UNDETERMINED)
        out.append(_every_packing_row(
            targets["donev-5.6-near-sphere-hypostatic-second-order"], near_ok[near], n,
            f"1 < alpha <= {NEAR_SPHERE_ALPHA:g}",
            f"{int(near_ok[near].sum())} of {int(near.sum())} packings near the sphere point "
            f"hypostatic and jammed at second order ({int(undetermined[near].sum())} undetermined"
            + (f"; {certified}" if (certified := _certified(s, near)) else "") + ")"))
        is_jammed = aspherical & jammed
        unique = np.asarray(s["n_stresses"].values) == 1
        out.append(_every_packing_row(
            targets["donev-5.6-unique-strict-self-stress"], unique[is_jammed], n, "jammed, alpha > 1",
            f"{int(unique[is_jammed].sum())} of {int(is_jammed.sum())} jammed packings with one self-stress"))
        gap = np.asarray(s["stress_gap"].values, float)
        approx = is_jammed & (np.asarray(s["approximate_stress"].values) > 0) & (gap > 0)
        out.append(_sample_row(targets["donev-5.6-stress-eigenvalue-gap"], -2.0 * np.log10(gap[approx]), n,
                               "jammed, alpha > 1", f"{int(approx.sum())} jammed packings with a near self-stress"))
    return out
