"""Validation rows of the binary hard-disk glass study (Donev 2006, ch. 13): the mixing entropy,
the Eq. 13.3 and 13.4 fits of the compression EOS, the freezing point and s_c - s_mix of the SOC
glasses."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hardpack.glass.thermo import mixing_entropy
from hardpack.validation.rows import NA, Row, evaluate
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
    """Eq. 13.3 coefficients (fit to the slowest compression) with their standard errors, phi~_J at
    0.75 of that compression, and alpha and phi_J of its glassy branch (Eq. 13.4).

    Parameters
    ----------
    ds : xarray.Dataset
        The glass EOS summary.

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
    out = []
    for k in range(4):
        out.append(evaluate(targets[f"donev-eq13.3-c{k}"], float(ds["cubic"][k]), float(ds["cubic_err"][k]),
                            n=n, seeds=seeds, detail=how))
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
    """phi_F and the precipitate density (Eq. 13.2) with their bootstrap standard errors
    (:func:`hardpack.glass.study.freezing_dataset`; NaN in a summary written without them).

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
                     n=n, detail=detail)]


def entropy_rows(ds) -> list[Row]:
    """s_c - s_mix of the snapshot at phi0 = 0.80 (binary) or 0.75 (monodisperse) of the slowest
    compression, mean and standard error over seeds.

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
    rate = float(np.min(ds["growth_rate"].values))
    sel = np.flatnonzero(np.isclose(ds["phi0"].values, phi0) & np.isclose(ds["growth_rate"].values, rate))
    n = int(ds["n_particles"].values.max())
    target = load_targets()[tid]
    if sel.size == 0:
        return [evaluate(target, n=n, detail=f"no snapshot at phi = {phi0}")]
    samples = ds["sc_minus_smix"].values[sel]
    detail = (f"N = {n}, Gamma = {rate:g}, phi = {phi0}: Delta f_g = "
              f"{np.round(ds['glass_excess'].values[sel], 4).tolist()}, Delta f_L = "
              f"{np.round(ds['liquid_excess'].values[sel], 4).tolist()}")
    return [evaluate(target, samples=samples, n=n, detail=detail)]


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
