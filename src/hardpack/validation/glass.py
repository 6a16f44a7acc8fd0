"""Validation rows of the binary hard-disk glass study (Donev 2006, ch. 13): the mixing entropy,
the Eq. 13.3 and 13.4 fits of the compression EOS, the freezing point and s_c - s_mix of the SOC
glasses, and BCMD of the defect-free monodisperse crystal against its EOS."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hardpack.errors import InvalidInputError
from hardpack.glass.study import liquid_excess_at
from hardpack.glass.thermo import binned_excess_difference, mixing_entropy
from hardpack.validation.rows import NA, Row, evaluate, seed_statistics
from hardpack.validation.targets import load_targets


def smix_rows() -> list[Row]:
    """s_mix at x = 1/3 against the printed 0.6365 (analytic).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    return [evaluate(load_targets()["donev-13.4-smix"], mixing_entropy(1 / 3), detail="closed form")]


def _seeds(ds, branch) -> int:
    n = ds.sel(branch=branch)["n_runs"].values
    return int(n.max()) if n.size else 0


def eos_rows(ds) -> list[Row]:
    """The rows of a glass EOS summary: :func:`mono_eos_rows` for monodisperse disks, else
    :func:`binary_eos_rows`.

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary (attribute ``x_large``: 0 for monodisperse disks).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    if float(ds.attrs.get("x_large", 1.0)) == 0.0:
        return mono_eos_rows(ds)
    return binary_eos_rows(ds) + rate_rows(ds)


def _slowest(ds):
    rates = ds["growth_rate"].values
    comp = np.flatnonzero(np.isfinite(rates) & (rates > 0))
    if comp.size == 0:
        return None, []
    order = comp[np.argsort(rates[comp])]
    return str(ds["branch"].values[order[0]]), [str(ds["branch"].values[b]) for b in order[1:]]


def _z_at(row, phi: float, pole: float | None = None) -> tuple[float, float, str]:
    """Z and its error at ``phi`` by the quadratic through the three bins whose mean phi lie nearest
    (a linear interpolation of the convex EOS would be biased by Z'' h^2/8 ~ 3e-5 at phi = 0.2);
    with ``pole``, of Z (1 - phi/pole) instead, which removes a free-volume pole (the crystal's
    Z ~ 2/(1 - phi/phi_cp), whose quadratic interpolation is biased by ~5e-3 at phi = 0.84).
    NaN when the bins do not surround ``phi`` within two bins."""
    x, z, e = row["phi_mean"].values, row["Z"].values, row["Z_err"].values
    ok = np.flatnonzero(np.isfinite(x) & np.isfinite(z))
    near = np.sort(ok[np.argsort(np.abs(x[ok] - phi))[:3]]) if ok.size >= 3 else ok
    if near.size < 3 or not x[near[0]] <= phi <= x[near[-1]] or x[near[-1]] - x[near[0]] > 0.0105:
        return math.nan, math.nan, f"no three adjacent bins around phi = {phi}"
    xs = x[near]
    w = np.array([np.prod([(phi - xs[m]) / (xs[k] - xs[m]) for m in range(3) if m != k]) for k in range(3)])
    scale = np.ones(3) if pole is None else (1 - xs / pole) / (1 - phi / pole)
    w = w * scale
    return (float(w @ z[near]), float(np.sqrt(np.sum((w * e[near]) ** 2))),
            f"quadratic through the bins at phi = {', '.join(f'{v:.4f}' for v in xs)}"
            + ("" if pole is None else f" of Z (1 - phi/{pole:.4f})"))


def mono_eos_rows(ds) -> list[Row]:
    """Monodisperse disks (Donev 2006, sec. 13.1): Z of the slowest compression at phi = 0.20 and
    0.30 against the hard-disk virial series (:func:`hardpack.eos.theory.hard_disk_virial`), the
    liquid-solid transition region, the phi of the flattest EOS between 0.65 and 0.76, and Z of
    the decompressed crystal at phi = 0.80 and 0.84 against the crystal EOS of Alder, Hoover &
    Young (:func:`hardpack.eos.theory.hard_disk_solid`).

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary of the monodisperse system.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    from hardpack.eos.theory import hard_disk_solid, hard_disk_virial

    targets = load_targets()
    n = int(ds.attrs.get("N", 0))
    slow, _ = _slowest(ds)
    crystal = "decompression" if "decompression" in ds["branch"].values else None
    cp = math.pi / math.sqrt(12)
    out = [_z_row(targets["hard-disk-virial-z-0.20"], ds, slow, 0.20, float(hard_disk_virial(0.20)), None, n),
           _z_row(targets["hard-disk-virial-z-0.30"], ds, slow, 0.30, float(hard_disk_virial(0.30)), None, n),
           transition_row(ds, slow, n)]
    for phi, tid in ((0.80, "hard-disk-solid-z-0.80"), (0.84, "hard-disk-solid-z-0.84")):
        out.append(_z_row(targets[tid], ds, crystal, phi, float(hard_disk_solid(phi)[0]), cp, n))
    return out


def _z_row(target, ds, branch, phi, published, pole, n) -> Row:
    """Z of ``branch`` at ``phi`` (:func:`_z_at`) against ``published``; n/a without the branch."""
    if branch is None:
        return evaluate(target, n=n, seeds=0, detail="no such branch in the summary")
    z, err, how = _z_at(ds.sel(branch=branch), phi, pole)
    seeds = _seeds(ds, branch)
    what = "decompression of the triangular crystal" if branch == "decompression" else f"Gamma = {branch}"
    return evaluate(target, z, err, n=n, seeds=seeds, published=published,
                    detail=f"N = {n}, {what}, {seeds} seed(s); {how}")


def transition_row(ds, branch, n) -> Row:
    """phi at the smallest slope dZ/dphi (central differences over the bins' mean phi) of
    ``branch`` between 0.65 and 0.76: the flat or looping part of the monodisperse EOS (Donev 2006,
    sec. 13.1, "transition region phi ~ 0.70-0.72"). The error is the spread of that phi over
    bootstrap replicas with every Z drawn from N(Z, Z_err); the decompression's value is reported.

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary of the monodisperse system.
    branch : str or None
        The compression branch judged (the slowest); None gives an n/a row.
    n : int
        Disks per system.

    Returns
    -------
    Row
        The validation row (:class:`hardpack.validation.rows.Row`).
    """
    target = load_targets()["donev-13.1-mono-transition"]
    if branch is None:
        return evaluate(target, n=n, seeds=0, detail="no compression")

    def flattest(x, z):
        slope = (z[2:] - z[:-2]) / (x[2:] - x[:-2])
        return float(x[1:-1][np.argmin(slope)]) if slope.size else math.nan

    def pick(name):
        row = ds.sel(branch=name)
        x, z, e = row["phi_mean"].values, row["Z"].values, row["Z_err"].values
        ok = np.isfinite(x) & np.isfinite(z) & (x >= 0.65) & (x <= 0.76)
        return x[ok], z[ok], np.nan_to_num(e[ok])

    x, z, e = pick(branch)
    if x.size < 3:
        return evaluate(target, n=n, seeds=0, detail=f"Gamma = {branch}: fewer than 3 bins in 0.65..0.76")
    rng = np.random.default_rng(20061)
    boot = [flattest(x, z + e * rng.standard_normal(z.size)) for _ in range(200)]
    seeds = _seeds(ds, branch)
    detail = f"N = {n}, Gamma = {branch}, {seeds} seed(s), bins of {ds.attrs.get('bin_width')}"
    if "decompression" in ds["branch"].values:
        xd, zd, _ = pick("decompression")
        if xd.size >= 3:
            detail += f"; decompression of the crystal: {flattest(xd, zd):.4f}"
    return evaluate(target, flattest(x, z), float(np.std(boot, ddof=1)), n=n, seeds=seeds, detail=detail)


def rate_rows(ds) -> list[Row]:
    """The mixture's compressions agree below phi = 0.775 and have separated by 0.80-0.825 (Donev
    2006, sec. 13.3: "all rates agree below 0.775"; kinetic glass transition phi_g ~ 0.8): the mean
    over the bins of each band of phi~_J(fastest) - phi~_J(slowest), with the error of that mean
    from the bins' standard errors (bins taken as independent; phi~_J varies slowly with phi, so
    the bins' different mean phi do not bias it).

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary of the mixture.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    n = int(ds.attrs.get("N", 0))
    slow, faster = _slowest(ds)
    agree, apart = targets["donev-13.3-rates-agree"], targets["donev-13.3-rates-separate"]
    if slow is None or not faster:
        why = "needs at least two compression rates"
        return [evaluate(agree, n=n, seeds=0, detail=why), evaluate(apart, n=n, seeds=0, detail=why)]
    fast = faster[-1]
    b = ds.sel(branch=slow)
    seeds = min(_seeds(ds, fast), _seeds(ds, slow))
    phi = ds["phi"].values

    def band(lo, hi, branch=fast):
        a = ds.sel(branch=branch)
        sel = (phi >= lo) & (phi < hi) & np.isfinite(a["phij"].values) & np.isfinite(b["phij"].values)
        diff = a["phij"].values[sel] - b["phij"].values[sel]
        err = np.hypot(a["phij_err"].values[sel], b["phij_err"].values[sel])
        if diff.size == 0:
            return math.nan, math.nan, 0
        return float(diff.mean()), float(np.sqrt(np.sum(err**2)) / diff.size), int(diff.size)

    how = f"N = {n}, Gamma = {fast} vs {slow}, {seeds} seed(s)"
    d1, e1, k1 = band(0.70, 0.775)
    d2, e2, k2 = band(0.80, 0.825)
    verdict = float(d2 < -2 * e2) if math.isfinite(e2) and k2 else math.nan
    others = "".join("; Gamma = {}: {:.5f} +- {:.5f}".format(r, *band(0.70, 0.775, r)[:2]) for r in faster[:-1])
    return [evaluate(agree, d1, e1, n=n, seeds=seeds, detail=f"{how}; {k1} bins in [0.70, 0.775){others}"),
            evaluate(apart, verdict, n=n, seeds=seeds,
                     detail=f"{how}; {k2} bins in [0.80, 0.825): mean difference {d2:.5f} +- {e2:.5f}")]


def binary_eos_rows(ds) -> list[Row]:
    """Eq. 13.3 coefficients (fit to the slowest compression) with their standard errors, phi~_J at
    0.75 of that compression, and alpha and phi_J of its glassy branch (Eq. 13.4).

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary of the mixture.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    n = int(ds.attrs.get("N", 0))
    slow = ds.attrs.get("cubic_branch")
    seeds = _seeds(ds, slow) if slow is not None else 0
    how = f"N = {n}, slowest Gamma = {slow}, {seeds} seed(s)"
    fit_to = ds.attrs.get("liquid_fit_max")
    fit_how = how if fit_to is None else (f"{how}; fitted up to phi = {fit_to:.4g} (above it Gamma = "
                                          f"{ds.attrs.get('liquid_fit_compared', '-')} separates)")
    out = []
    for k in range(4):
        out.append(evaluate(targets[f"donev-eq13.3-c{k}"], float(ds["cubic"][k]), float(ds["cubic_err"][k]),
                            n=n, seeds=seeds, detail=fit_how))
    value = err = math.nan
    if slow is not None:
        row = ds.sel(branch=slow)
        near = np.nanargmin(np.abs(row["phi"].values - 0.75)) if np.isfinite(row["phij"].values).any() else None
        if near is not None and abs(float(row["phi"][near]) - 0.75) < 1e-9 + ds.attrs["bin_width"]:
            value, err = float(row["phij"][near]), float(row["phij_err"][near])
            how_bin = f"{how}; bin centred at {float(row['phi'][near]):.4g}"
        else:
            how_bin = how
        out.append(evaluate(targets["donev-eq13.3-phij-0.75"], value, err, n=n, seeds=seeds, detail=how_bin))
        alpha, alpha_err = float(row["alpha"]), float(row["alpha_err"])
        phij, phij_err = float(row["glass_phi_j"]), float(row["glass_phi_j_err"])
    else:
        out.append(evaluate(targets["donev-eq13.3-phij-0.75"], n=n, seeds=seeds, detail=how))
        alpha = alpha_err = phij = phij_err = math.nan
    fit = f"{how}; glass fit over phi in {ds.attrs.get('glass_fit_range')}"
    out.append(evaluate(targets["donev-eq13.4-alpha"], alpha, alpha_err, n=n, seeds=seeds, detail=fit))
    out.append(evaluate(targets["donev-13.3-phij-glass"], phij, phij_err, n=n, seeds=seeds, detail=fit))
    return out


def freezing_rows(ds) -> list[Row]:
    """phi_F and the precipitate density (Eq. 13.2), and the overall densities at which the
    phases of the fully phase-separated crystal melt (sec. 13.2.2.1), with their bootstrap
    standard errors (:func:`hardpack.glass.study.freezing_dataset`; NaN in a summary written
    without them).

    Parameters
    ----------
    ds : xarray.Dataset
        The freezing summary.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    n = int(ds.attrs.get("n_particles", 0))
    detail = f"N = {n}; {ds.attrs.get('status')}; mu~_B: {ds.attrs.get('mu_tilde')}"
    if "replicas_solved" in ds.attrs:
        detail += f"; error: bootstrap, {ds.attrs['replicas_solved']} of {ds.attrs.get('replicas')} replicas solved"

    def error(name):
        return float(ds[f"{name}_err"]) if f"{name}_err" in ds else math.nan

    return [evaluate(targets["donev-13.2-phi-freeze"], float(ds["phi_freeze"]), error("phi_freeze"), n=n,
                     detail=detail),
            evaluate(targets["donev-13.2-phi-precipitate"], float(ds["phi_precipitate"]), error("phi_precipitate"),
                     n=n, detail=detail),
            *_separated_rows(ds, targets, n)]


def _separated_rows(ds, targets, n) -> list[Row]:
    """The overall densities at which the phases of the fully phase-separated crystal melt."""
    rows = []
    for tid, name, phase in (("donev-13.2-separated-a-melts", "phi_a_melts", "A"),
                             ("donev-13.2-separated-b-melts", "phi_b_melts", "B")):
        if name not in ds:
            rows.append(evaluate(targets[tid], n=n, detail="the freezing summary has no separated crystal"))
            continue
        detail = (f"N = {n}; {ds.attrs.get('separated_status')}; phase {phase} at phi = "
                  f"{ds.attrs.get('phi_transition')}; error: bootstrap, {ds.attrs.get('separated_replicas_solved')} "
                  f"of {ds.attrs.get('replicas')} replicas solved; {ds.attrs.get('separated_span', '')}")
        rows.append(evaluate(targets[tid], float(ds[name]), float(ds[f"{name}_err"]), n=n, detail=detail))
    return rows


def relaxed_rows(ds) -> list[Row]:
    """phi_J of the fastest compression's glasses after relaxation and recompression against the
    printed ~0.847 (Donev 2006, sec. 13.3.1, Fig. 13.8), mean and standard error over seeds; the
    other rates and the unrelaxed phi_J in the detail.

    Parameters
    ----------
    ds : xarray.Dataset
        The relaxed-glass summary (:func:`hardpack.glass.study.relaxed_dataset`).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    target = load_targets()["donev-13.3-phij-relaxed"]
    n = int(ds.attrs.get("N", 0))
    rates = np.unique(ds["rate"].values)
    parts = []
    for rate in rates[::-1]:
        sel = ds["rate"].values == rate
        before, after = ds["phi_J_fast"].values[sel].mean(), ds["phi_J"].values[sel].mean()
        parts.append(f"Gamma = {rate:g}: {before:.4f} -> {after:.4f}")
    detail = (f"N = {n}; relaxed {ds.attrs.get('relax_collisions'):g} collisions per particle at fixed phi, "
              f"recompressed at {ds.attrs.get('recompress_rate'):g}; phi_J before -> after: {'; '.join(parts)}")
    fastest = ds["rate"].values == rates.max()
    return [evaluate(target, samples=ds["phi_J"].values[fastest], n=n, detail=detail, label=f"Gamma = {rates.max():g}")]


def soc_rows(ds) -> list[Row]:
    """phi_J of the SOC solids from the lowest snapshot density, in their cells and after the cells
    are removed, against the printed ~0.83 and ~0.85 (Donev 2006, sec. 13.3.1, Fig. 13.9); mean and
    standard error over seeds, every snapshot density in the detail.

    Parameters
    ----------
    ds : xarray.Dataset
        The SOC summary (:func:`hardpack.glass.soc.soc_summary`).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    n = int(ds.attrs.get("N", 0))
    lowest = ds.sel(phi0=float(np.min(ds["phi0"].values)))
    per_phi0 = "; ".join(f"{float(p):g}: {float(np.nanmean(ds['phi_J_soc'].sel(phi0=p))):.4f} -> "
                         f"{float(np.nanmean(ds['phi_J_relaxed'].sel(phi0=p))):.4f}" for p in ds["phi0"].values)
    detail = (f"N = {n}; cells of Delta mu = {ds.attrs.get('dmu'):g} compressed at {ds.attrs.get('growth_rate'):g} "
              f"to Z = {ds.attrs.get('max_pressure'):g}, relaxed {ds.attrs.get('relax_collisions'):g} collisions per "
              f"disk; phi_J in cells -> relaxed per phi_0: {per_phi0}")
    label = f"phi_0 = {float(lowest['phi0']):g}"
    return [evaluate(targets["donev-13.3-soc-phij-liquid"], samples=lowest["phi_J_soc"].values, n=n, detail=detail,
                     label=label),
            evaluate(targets["donev-13.3-soc-phij-relaxed"], samples=lowest["phi_J_relaxed"].values, n=n,
                     detail=detail, label=label)]


def entropy_rows(ds) -> list[Row]:
    """s_c - s_mix of the snapshot at phi0 = 0.80 (binary) or 0.75 (monodisperse) of the slowest
    compression that has one, mean and standard error over seeds; for the monodisperse crystal
    the detail names each snapshot's coordination defects (the cause of a positive s_c).

    Parameters
    ----------
    ds : xarray.Dataset
        The configurational-entropy summary over seeds.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    mono = float(ds.attrs.get("x_large", 0.0)) == 0.0
    tid, phi0 = ("donev-13.4-sc-mono", 0.75) if mono else ("donev-13.4-sc-binary", 0.80)
    at_phi0 = np.isclose(ds["phi0"].values, phi0)
    n = int(ds["n_particles"].values.max())
    target = load_targets()[tid]
    if not at_phi0.any():
        return [evaluate(target, n=n, detail=f"no snapshot at phi = {phi0}")]
    rate = float(np.min(ds["growth_rate"].values[at_phi0]))
    sel = np.flatnonzero(at_phi0 & np.isclose(ds["growth_rate"].values, rate))
    samples = ds["sc_minus_smix"].values[sel]
    detail = (f"N = {n}, Gamma = {rate:g}, phi = {phi0}: Delta f_g = "
              f"{np.round(ds['glass_excess'].values[sel], 4).tolist()}, Delta f_L = "
              f"{np.round(ds['liquid_excess'].values[sel], 4).tolist()}")
    if mono and "coordination_defects" in ds:
        defects = ds["coordination_defects"].values[sel]
        if np.isfinite(defects).all():
            detail += f"; % of disks without six neighbours {np.round(100 * defects, 2).tolist()}"
    return [evaluate(target, samples=samples, n=n, detail=detail)]


def disk_crystal_rows(crystal_bcmd, eos) -> list[Row]:
    """BCMD of the defect-free triangular crystal against the integral of the crystal's EOS
    (Donev 2006, sec. 13.1: "BCMD and EOS integration agree in the solid"): the change of the
    BCMD excess free energy between the lowest and the highest density of ``crystal_bcmd`` minus
    int (Z - 1)/phi dphi of the decompression branch over the same range, summed over its bins
    (:func:`hardpack.glass.thermo.binned_excess_difference`; both at the same N, so the finite-N
    offsets of the two BCMD points cancel to O(ln N / N) of their difference).

    Parameters
    ----------
    crystal_bcmd : xarray.Dataset
        BCMD of the crystal over (phi, seed) with ``excess``, ``n_particles``, ``seconds``.
    eos : xarray.Dataset
        The monodisperse EOS summary (:func:`hardpack.glass.study.eos_dataset`) with a
        ``decompression`` branch.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    target = load_targets()["bcmd-disk-crystal-vs-eos"]
    phi = np.round(crystal_bcmd["phi"].values.astype(float), 6)
    excess = crystal_bcmd["excess"].values.astype(float)
    n = int(np.asarray(crystal_bcmd["n_particles"].values).max())
    lo, hi = float(phi.min()), float(phi.max())
    if lo == hi:
        return [evaluate(target, n=n, detail=f"BCMD at one density only (phi = {lo})")]
    if "decompression" not in eos["branch"].values:
        return [evaluate(target, n=n, detail="the EOS summary has no decompression branch")]
    low, low_err, n_low, _ = seed_statistics(excess[phi == lo])
    high, high_err, n_high, _ = seed_statistics(excess[phi == hi])
    row = eos.sel(branch="decompression")
    try:
        integral, integral_err = binned_excess_difference(
            eos["phi"].values, float(eos.attrs["bin_width"]), row["phi_mean"].values, row["Z"].values,
            row["Z_err"].values, lo, hi)
    except InvalidInputError as exc:
        return [evaluate(target, n=n, detail=f"the decompression EOS: {exc}")]
    difference = (high - low) - integral
    err = math.sqrt(sum(e**2 for e in (low_err, high_err, integral_err) if math.isfinite(e)))
    seconds = float(np.nansum(crystal_bcmd["seconds"].values))
    absolute = [f"{excess[phi == x].mean() - liquid_excess_at(eos, x)[0]:.4f}" for x in (lo, hi)]
    return [evaluate(
        target, difference, err, n=n, seeds=min(n_low, n_high), label=f"phi = {lo:g} .. {hi:g}",
        detail=f"N = {n}; BCMD {high - low:.4f} ({n_low} and {n_high} seeds) against the decompression "
               f"EOS integral {integral:.4f} +- {integral_err:.2g}; BCMD {seconds:.0f} CPU-s in all; BCMD minus the "
               f"slowest compression's EOS integral from the ideal gas (Fig. 13.2): {absolute[0]} at phi = {lo:g}, "
               f"{absolute[1]} at {hi:g}",
    )]


def microsegregated_rows(ds) -> list[Row]:
    """Micro-segregated packings (Donev 2006, sec. 13.5): phi_J of the uncorrelated labels
    (Fig. 13.13), phi~_J at the start of the growth (Fig. 13.14), the most clustered ensemble
    denser than the uncorrelated one, and s_c anticorrelated with phi_J over the ensembles
    (Figs. 13.16-13.17).

    Parameters
    ----------
    ds : xarray.Dataset
        The micro-segregated summary over ensembles.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    from scipy.stats import spearmanr

    targets = load_targets()
    n = int(ds.attrs.get("N", 0))
    names = [str(x) for x in ds["ensemble"].values]
    packings = int(ds["n_packings"].min())
    how = (f"N = {n}, {len(names)} label ensembles, >= {packings} packing(s) each, s_c from "
           f"{ds.attrs.get('s_c_window')} windows")
    out = []
    if "random" in names:
        row = ds.sel(ensemble="random")
        k = int(row["n_packings"])
        # the spread over packings: phi_J_err is the standard error of the mean over k packings
        sd = float(row["phi_J_err"]) * math.sqrt(k)
        out.append(evaluate(targets["donev-13.5-phij-random"], float(row["phi_J"]), sd * math.sqrt(1 + 1 / k),
                            n=n, seeds=k, detail=how))
    else:
        out.append(evaluate(targets["donev-13.5-phij-random"], n=n, seeds=packings, detail="no uncorrelated labels"))
    out.append(evaluate(targets["donev-13.5-phij-est-start"], float(ds["phi_J_est_start"].mean()), n=n,
                        detail=f"{how}; mean over ensembles of the first growth window"))
    clustered = [x for x in names if x != "random"]
    if "random" in names and clustered:
        top = max(clustered, key=lambda x: (float(ds.sel(ensemble=x)["R"]), float(ds.sel(ensemble=x)["nu"])))
        a, b = ds.sel(ensemble=top), ds.sel(ensemble="random")
        diff = float(a["phi_J"] - b["phi_J"])
        err = math.hypot(float(a["phi_J_err"]), float(b["phi_J_err"]))
        verdict = float(diff > 2 * err) if math.isfinite(err) else math.nan
        out.append(evaluate(targets["donev-13.5-clustered-denser"], verdict, n=n, seeds=packings,
                            detail=f"{how}; phi_J({top}) - phi_J(random) = {diff:.5f} +- {err:.5f}"))
    else:
        out.append(evaluate(targets["donev-13.5-clustered-denser"], n=n, seeds=packings,
                            detail="needs the uncorrelated and a clustered ensemble"))
    if len(names) >= 6:  # below, |rho| <= 1 cannot exceed 2 / sqrt(n - 1)
        rho = float(spearmanr(ds["s_c"].values, ds["phi_J"].values).statistic)
        null = 1 / math.sqrt(len(names) - 1)
        out.append(evaluate(targets["donev-13.5-sc-phij-anticorrelated"], float(rho < -2 * null), n=n, seeds=packings,
                            detail=f"{how}; Spearman rho = {rho:.3f}, null standard error {null:.3f}"))
    else:
        row = evaluate(targets["donev-13.5-sc-phij-anticorrelated"], n=n, seeds=packings)
        out.append(replace(row, status=NA, detail=f"n/a: needs at least 6 ensembles, has {len(names)}"))
    return out
