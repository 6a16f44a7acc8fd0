"""Validation rows of the BCMD study: FCC at melting and in the jamming limit (finite-N
extrapolation), FCC vs density (BCMD against the engine's EOS), LS packings against their exact
jamming simplex, and the cheap ladder checks. Each row's detail gives the cost of its point."""

from __future__ import annotations

import math

import numpy as np

from hardpack.freeenergy.crystal import MELTING_PHI, cell_offset, eos_excess
from hardpack.validation.jamming import largest_magnitude
from hardpack.validation.rows import Row, evaluate, seed_statistics
from hardpack.validation.targets import load_targets

#: state -> (target id, variable of the BCMD summary)
TARGETS = {
    "melting": ("donev-ch6-fcc-melting", "excess"),
    "jamming": ("donev-ch6-fcc-jamming", "delta_f"),
}


def _cost(ds) -> str:
    """'k runs, E events, S s' from a summary's n_events / seconds variables (if present)."""
    parts = [f"{ds.sizes.get('sample', 1)} runs"]
    for var, unit in (("n_events", "events"), ("seconds", "s"), ("seconds_bcmd", "s")):
        if var in ds:
            parts.append(f"{float(ds[var].sum()):.3g} {unit}")
    return "cost " + ", ".join(parts)


def finite_size_extrapolation(n, values) -> tuple[float, float, str]:
    """Infinite-N value from values(N) = a + b ln(N)/N (the leading finite-size correction of a
    free energy per particle, Donev 2006, Sec. 6.4.1), with the fit's standard error of a.

    With fewer than three sizes there is nothing to fit: the largest-N mean is returned with a
    NaN error (the caller reports the row n/a).

    Parameters
    ----------
    n : array_like of int, shape (k,)
        System size N of every value.
    values : array_like of float, shape (k,)
        The values.

    Returns
    -------
    estimate : float
        a, or the largest-N mean.
    error : float
        Standard error of a (NaN without a fit).
    how : str
        What was done, for a row's detail.
    """
    n = np.asarray(n, float)
    values = np.asarray(values, float)
    sizes = np.unique(n)
    if sizes.size >= 3:
        x = np.log(n) / n
        design = np.column_stack([np.ones_like(x), x])
        coef, res, *_ = np.linalg.lstsq(design, values, rcond=None)
        dof = max(len(values) - 2, 1)
        sigma2 = float(res[0]) / dof if res.size else 0.0
        cov = sigma2 * np.linalg.inv(design.T @ design)
        fit = f"fit a + b ln N / N over N = {sizes.astype(int).tolist()}"
        return float(coef[0]), math.sqrt(max(cov[0, 0], 0.0)), fit
    big = sizes.max()
    return float(values[n == big].mean()), math.nan, f"largest N = {int(big)} only (no extrapolation)"


def bcmd_rows(summaries: dict) -> list[Row]:
    """One row per state in ``summaries`` (state name -> combined BCMD Dataset).

    Parameters
    ----------
    summaries : dict of str to xarray.Dataset
        State name (a key of :data:`TARGETS`) -> combined BCMD summary.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for state, ds in summaries.items():
        tid, var = TARGETS[state]
        n = ds["n_particles"].values
        est, err, how = finite_size_extrapolation(n, ds[var].values)
        out.append(evaluate(targets[tid], est, err, n=int(n.max()), sizes=np.unique(n).size,
                            detail=f"{how}; {_cost(ds)}"))
    return out


def eos_integral_error(phi, z, z_err) -> float:
    """Standard error of the EOS integral from phi.min() to phi.max(): the spline integral is
    linear in the measured Z, so each point's error enters through its exact sensitivity.

    Parameters
    ----------
    phi : array_like of float, shape (k,)
        Volume fractions.
    z : array_like of float, shape (k,)
        Reduced pressures Z = pV/(NkT).
    z_err : array_like of float, shape (k,)
        Their standard errors (non-finite or zero: no contribution).

    Returns
    -------
    float
        The standard error of the integral.
    """
    phi, z, z_err = (np.asarray(a, float) for a in (phi, z, z_err))
    top = np.argmax(phi)
    base = eos_excess(phi, z, excess0=0.0)[top]
    total = 0.0
    for i in range(z.size):
        if not (np.isfinite(z_err[i]) and z_err[i] > 0):
            continue
        dz = z.copy()
        dz[i] += z_err[i]
        total += (eos_excess(phi, dz, excess0=0.0)[top] - base) ** 2
    return math.sqrt(total)


def density_rows(density, eos) -> list[Row]:
    """BCMD's change of the FCC excess free energy from melting to the densest point minus the
    integral of the engine's crystal EOS over the same range (both at the same N; the finite-N
    offsets of the two BCMD points cancel to O(ln N / N) of their difference).

    density: the BCMD summary over (phi, seed); eos: the MD summary over phi (Z, Z_err).

    Parameters
    ----------
    density : xarray.Dataset
        BCMD summary over (phi, seed).
    eos : xarray.Dataset
        MD equation-of-state summary over phi.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    phi_b, excess = density["phi"].values, density["excess"].values
    lo, hi = np.isclose(phi_b, MELTING_PHI, atol=1e-6), np.isclose(phi_b, phi_b.max())
    low, low_err, n_low, _ = seed_statistics(excess[lo])
    high, high_err, n_high, _ = seed_statistics(excess[hi])
    phi_e, z = eos["phi"].values, eos["Z"].values
    z_err = eos["Z_err"].values if "Z_err" in eos else np.full_like(z, np.nan)
    integral = float(eos_excess(phi_e, z, excess0=0.0)[np.argmax(phi_e)])
    integral_err = eos_integral_error(phi_e, z, z_err)
    difference = (high - low) - integral
    err = math.sqrt(sum(e**2 for e in (low_err, high_err, integral_err) if math.isfinite(e)))
    n = int(np.asarray(density["n_particles"].values).ravel()[0])
    return [evaluate(
        load_targets()["bcmd-density-vs-eos"], difference, err, n=n, seeds=min(n_low, n_high),
        label=f"phi = {phi_b.max():.4g}",
        detail=f"N = {n}; BCMD {high - low:.4f} against the EOS integral {integral:.4f} +- "
               f"{integral_err:.2g}; Delta f(phi_max) by BCMD {float(cell_offset(phi_b.max())) - high:.4f}; "
               f"BCMD {_cost(density)}; EOS {eos.sizes['sample']} runs, {float(eos['wall_time'].sum()):.3g} s",
    )]


def simplex_rows(ds) -> list[Row]:
    """BCMD of rattler-free LS packings against their exact jamming simplex (Donev 2006, Table
    6.1), per frozen mode: the exact value against the published one of Table 6.1's packing, and
    the largest relative difference of BCMD from the exact value. Only isostatic backbones have a
    simplex; a mode without one fails with the isostaticity gaps in its detail.

    Parameters
    ----------
    ds : xarray.Dataset
        Simplex summary over sample.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for frozen, suffix in (("particle", "particle"), ("cm", "cm")):
        sel = ds.isel(sample=np.flatnonzero(ds["frozen"].values == frozen))
        iso = sel["isostatic"].values.astype(bool)
        n_b = sel["n_backbone"].values.astype(int)
        n = int(n_b.max()) if n_b.size else 0
        if not iso.any():
            detail = (f"no isostatic backbone (M - N_f - 1 = {sel['isostaticity_gap'].values.tolist()}): "
                      "the simplex formula does not apply")
            for tid in (f"donev-t6.1-exact-{suffix}", f"donev-t6.1-bcmd-vs-exact-{suffix}"):
                out.append(evaluate(targets[tid], math.nan, n=n, seeds=sel.sizes["sample"], detail=detail))
            continue
        rel = sel["rel_diff"].values[iso]
        detail = (f"{iso.sum()} isostatic backbone(s), N_b = {n_b[iso].tolist()}, BCMD / exact - 1 = "
                  f"{np.round(rel, 5).tolist()}; {_cost(sel)}")
        n_iso = int(n_b[iso].max())
        out.append(evaluate(targets[f"donev-t6.1-exact-{suffix}"], samples=sel["exact"].values[iso], n=n_iso,
                            detail=detail + ("; centre-of-mass value = exact + d ln N_b / N_b"
                                             if frozen == "cm" else "")))
        out.append(evaluate(targets[f"donev-t6.1-bcmd-vs-exact-{suffix}"], largest_magnitude(rel), n=n_iso,
                            seeds=int(iso.sum()), detail=detail))
    return out


def ladder_rows(ds) -> list[Row]:
    """The cheap checks (:func:`hardpack.freeenergy.ladder.ladder_dataset`): each check's
    deviation from its exact value against 0 with our standard error.

    Parameters
    ----------
    ds : xarray.Dataset
        The ladder dataset.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for check in ds["check"].values:
        r = ds.sel(check=check)
        out.append(evaluate(targets[str(check)], float(r["value"]), float(r["error"]),
                            seeds=int(r["n_samples"]), detail=f"cost {float(r['seconds']):.2g} s"))
    return out


def ellipse_rows(ds) -> list[Row]:
    """Isostatic alpha = 2 ellipse packings (Donev 2006, sec. 6.4.3): the cell constant f_c^J, the
    exact f_J - f_c^J against the published packing's, and BCMD - exact, from a summary of
    ``hardpack bcmd-ellipse`` runs (variables over ``sample``: ``f_j_minus_fcj``, ``bcmd``,
    ``exact``, ``n_particles``, ``n_fixed_translation``; ``bcmd`` NaN for exact-only runs).

    Parameters
    ----------
    ds : xarray.Dataset
        The ellipse BCMD summary.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    from hardpack.freeenergy.ellipses import cell_log_volume

    targets = load_targets()
    n = int(np.max(ds["n_particles"].values))
    fixed = np.asarray(ds["n_fixed_translation"].values).astype(int).tolist()
    out = [evaluate(targets["donev-ch6-ellipse-fcj"], cell_log_volume(2.0),
                    detail="cell body of Eq. C1 cut by 4000 normals, Richardson step")]
    exact = ds["f_j_minus_fcj"].values
    out.append(evaluate(targets["donev-ch6-ellipse-exact"], samples=exact, n=n,
                        detail=f"{exact.size} packing(s), f_J - f_c^J = {np.round(exact, 4).tolist()}, "
                               f"frozen centroids {fixed}"))
    if "bcmd" not in ds:  # exact-only runs
        return out
    diff = ds["bcmd"].values - ds["exact"].values
    ran = np.isfinite(diff)
    if ran.any():
        mean, err, seeds, _ = seed_statistics(diff[ran])
        out.append(evaluate(targets["donev-ch6-ellipse-bcmd-vs-exact"], mean, err, n=n, seeds=seeds,
                            detail=f"BCMD - exact = {np.round(diff[ran], 4).tolist()}; {_cost(ds)}"))
        in_cells = ds["bcmd"].values[ran] - ds["exact_in_cells"].values[ran]
        mc = ds["inside_fraction_err"].values[ran] / ds["inside_fraction"].values[ran] / ds["n_eff"].values[ran]
        mean, err, seeds, _ = seed_statistics(in_cells)
        err = float(np.hypot(0.0 if not np.isfinite(err) else err, np.sqrt(np.mean(mc**2) / mc.size)))
        inside = np.round(ds["inside_fraction"].values[ran], 4).tolist()
        out.append(evaluate(targets["bcmd-ellipse-vs-exact-in-cells"], mean, err, n=n, seeds=seeds,
                            detail=f"BCMD - exact in cells = {np.round(in_cells, 4).tolist()}; simplex "
                                   f"fraction inside the cells {inside}"))
    return out


def ellipse_ladder_rows(ds) -> list[Row]:
    """Independent ellipses in shrinking cells (:func:`hardpack.freeenergy.ellipse_bcmd.disjoint_cells_check`):
    the relative deviation of (3/2) ln(K/K0) from 3 ln(dmu_0/dmu_1) over seeds.

    Parameters
    ----------
    ds : xarray.Dataset
        The disjoint-cells check over seeds (variable rel_dev).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    rel = ds["rel_dev"].values
    mean, err, seeds, _ = seed_statistics(rel)
    cost = float(ds["seconds"].sum())
    return [evaluate(load_targets()["bcmd-ellipse-disjoint-cells"], mean, err, seeds=seeds,
                     detail=f"{int(ds.attrs['n_particles'])} ellipses per run; cost {cost:.2g} s")]
