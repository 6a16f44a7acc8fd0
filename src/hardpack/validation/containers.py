"""Validation rows of the finite-container study of spheres (Donev 2006, Sec. 7.3).

Inputs (the pipeline's ``containers`` summaries, told apart by ``hardpack_kind``):

- ``container_summary`` (:func:`hardpack.structure.containers.container_summary`): the Eq. 7.2
  intercept phi_0 +- its standard error against 0.642 +- 0.002 (Sec. 7.3.2.1), judged at the
  largest N of the fit with its number of sizes; the core density r <= R - core_margin a of the
  packings of the largest container against "about 0.64" (Fig. 7.5), over seeds; and, with the
  summary's periodic packings of the same protocol, their density against the same 0.642 +- 0.002
  (the bulk value phi_0 that the extrapolation estimates).
- ``ellipsoid_container_summary``
  (:func:`hardpack.structure.containers.ellipsoid_container_summary`): the Eq. 7.2 intercept of
  jammed ellipsoids in spherical containers, by the summary's ``shape_name``: M&M-shaped oblate
  spheroids (``mm``) against 0.700 +- 0.002 and ollipsoids (``ollipsoid``) against
  0.741 +- 0.002 (Sec. 7.3.2.1), judged at the largest N of the fit with its number of sizes;
  other shapes have no row.
- ``window_study`` (:func:`hardpack.structure.containers.window_study`): sigma_phi averaged over
  the packings, fitted by a power law over 2R/D >= fit_min_diameter
  (:func:`~hardpack.structure.containers.fit_window_power_law`): the exponent against -2 and the
  prefactor at exponent -2 against 0.1 (Fig. 7.3).
"""

from __future__ import annotations

import numpy as np

from hardpack.structure.containers import fit_window_power_law
from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import load_targets


def _bulk_rows(targets, summary) -> list[Row]:
    n = np.asarray(summary["N"].values)
    fitted = n[n >= summary.attrs["fit_min_n"]]
    largest = int(n.max())
    a = summary.attrs
    sizes = ", ".join(map(str, sorted(set(fitted.tolist()))))
    fit = evaluate(targets["donev-7.3-bulk-phi0"], float(a["phi0"]), float(a["phi0_err"]), n=int(fitted.max()),
                   sizes=int(a["n_sizes_fit"]), label="Eq. 7.2 intercept",
                   detail=f"linear fit over {a['n_fit']} packings, N = {sizes}; "
                          f"slope {a['slope']:.3f} +- {a['slope_err']:.3f}; {_wall_layer_detail(summary)}")
    core = np.asarray(summary["phi_core"].values, float)[n == largest]
    margin = a["core_margin"]
    rows = [fit, evaluate(targets["donev-fig7.5-core-phi"], samples=core, n=largest, label=f"N = {largest}",
                          detail=f"r <= R - {margin:g} a; per seed {', '.join(f'{v:.4f}' for v in core)}")]
    if "phi_bulk" in summary:
        bulk = np.asarray(summary["phi_bulk"].values, float)
        rows.append(evaluate(targets["donev-7.3-bulk-phi-periodic"], samples=bulk, n=int(a["bulk_N"]),
                             label=f"periodic, N = {a['bulk_N']}",
                             detail="the containers' compression protocol in a periodic cube; per seed "
                                    + ", ".join(f"{v:.4f}" for v in bulk)))
        if "phi0_fixed_layer" in a:
            diff = float(a["phi0_fixed_layer"]) - float(a["phi_bulk"])
            err = float(np.hypot(a["phi0_fixed_layer_err"], a["phi_bulk_err"]))
            rows.append(evaluate(targets["containers-fixed-wall-layer-vs-periodic"], diff, err,
                                 n=int(fitted.max()) if fitted.size else None, sizes=int(a["n_sizes_fit"]),
                                 seeds=int(a["n_bulk"]), label="Eq. 7.2, wall layer fixed",
                                 detail=f"intercept {a['phi0_fixed_layer']:.4f} +- {a['phi0_fixed_layer_err']:.4f} "
                                        f"(plain fit {a['phi0']:.4f}) against periodic "
                                        f"{a['phi_bulk']:.4f} +- {a['phi_bulk_err']:.4f}"))
    return rows


#: the Eq. 7.2 row of each named ellipsoid shape (``shape_name`` of the summary)
ELLIPSOID_CONTAINER_TARGETS = {"mm": "donev-7.3-mm-phi0", "ollipsoid": "donev-7.3-ollipsoid-phi0"}


def _ellipsoid_rows(targets, summary) -> list[Row]:
    name = summary.attrs.get("shape_name", "mm")
    if name not in ELLIPSOID_CONTAINER_TARGETS:
        return []  # a shape without a published bulk density
    n = np.asarray(summary["N"].values)
    a = summary.attrs
    fitted = n[n >= a["fit_min_n"]]
    sizes = ", ".join(map(str, sorted(set(fitted.tolist()))))
    axes = np.atleast_1d(np.asarray(a["semiaxes"], float))
    semiaxes = ":".join(f"{v:.3g}" for v in axes / axes.min())
    return [evaluate(targets[ELLIPSOID_CONTAINER_TARGETS[name]], float(a["phi0"]), float(a["phi0_err"]),
                     n=int(fitted.max()) if fitted.size else 0, sizes=int(a["n_sizes_fit"]),
                     label=f"Eq. 7.2 intercept, semiaxes {semiaxes}",
                     detail=f"linear fit over {a['n_fit']} packings, N = {sizes or 'none'}; "
                            f"slope {a['slope']:.3f} +- {a['slope_err']:.3f}; a/R = "
                            f"{float(np.min(summary['a_over_R'])):.3f}..{float(np.max(summary['a_over_R'])):.3f}")]


def _wall_layer_detail(summary) -> str:
    """Mean density of the layer within one a of the wall, and of the core, per container size
    (Eq. 7.1 takes the wall correction as independent of R and the core as the bulk; a trend of
    either with a/R moves the linear intercept away from the bulk density)."""
    if "phi_wall_layer" not in summary:
        return "no wall-layer densities"
    n = np.asarray(summary["N"].values)
    parts = [f"{np.mean(summary['phi_wall_layer'].values[n == k]):.3f} at a/R = "
             f"{np.mean(summary['a_over_R'].values[n == k]):.3f}" for k in sorted(set(n.tolist()))]
    cores = [f"{np.nanmean(summary['phi_core'].values[n == k]):.4f} at N = {k}" for k in sorted(set(n.tolist()))
             if np.isfinite(summary["phi_core"].values[n == k]).any()]
    return "wall-layer density " + ", ".join(parts) + ("; core density " + ", ".join(cores) if cores else "")


def _window_rows(targets, windows) -> list[Row]:
    x = windows["x"].values
    sigma = windows["sigma_phi"].values.mean(axis=0)
    x_min = float(windows.attrs.get("fit_min_diameter", 0.0))
    fit = fit_window_power_law(x, sigma, x_min)
    n = int(np.asarray(windows["N"].values).min())
    detail = (f"{windows.sizes['sample']} packing(s), {windows.attrs['n_windows']} windows per size, "
              f"{fit.n} sizes 2R/D = {x[x >= x_min].min():.3g}..{x.max():.3g}")
    return [evaluate(targets["donev-fig7.3-window-exponent"], fit.exponent, fit.exponent_err, n=n,
                     label="sigma_phi ~ (2R/D)^k", detail=detail),
            evaluate(targets["donev-fig7.3-window-prefactor"], fit.prefactor_fixed, fit.prefactor_fixed_err,
                     n=n, label="sigma_phi (2R/D)^2", detail=detail)]


def container_rows(datasets) -> list[Row]:
    """Rows of the container and window summaries (module docstring), in input order.

    Parameters
    ----------
    datasets : iterable of xarray.Dataset
        Summaries; those of kind container_summary, ellipsoid_container_summary and window_study
        are used.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    targets = load_targets()
    out = []
    for ds in datasets:
        kind = ds.attrs.get("hardpack_kind")
        if kind == "container_summary":
            out += _bulk_rows(targets, ds)
        elif kind == "ellipsoid_container_summary":
            out += _ellipsoid_rows(targets, ds)
        elif kind == "window_study":
            out += _window_rows(targets, ds)
    return out
