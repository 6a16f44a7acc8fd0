"""Per-shape summary of the jamming verdicts of the ellipsoid study (Donev 2006, Secs. 5.5-5.6).

Input: the verdicts of :func:`hardpack.jamming.second_order.verify_ellipsoids` combined over the
packings (``hardpack combine --index beta alpha seed``), one sample per packing with the variables
``jammed`` (1/0), ``order_code`` (:data:`~hardpack.jamming.second_order.ORDER_CODES`: 1 first,
2 second, 0 undetermined), ``hypostatic``, ``z_mean`` (backbone) and ``rattler_fraction``, and
optionally ``refined`` (1: tested at the jamming point of its contacts, :mod:`hardpack.jamming.refine`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from hardpack.jamming.second_order import ORDER_CODES

__all__ = ["verdict_fractions"]


def verdict_fractions(summary: xr.Dataset) -> xr.Dataset:
    """Fractions of the packings of each shape (beta, alpha) that are jammed, and that were decided
    at first order, at second order or not at all, with the mean backbone Z and rattler fraction.

    Parameters
    ----------
    summary : xarray.Dataset
        The combined verdicts (module docstring), dimension ``sample``.

    Returns
    -------
    xarray.Dataset
        Dimension ``shape`` with coordinates ``beta``, ``alpha`` and the variables ``n_packings``,
        ``fraction_jammed``, ``fraction_first``, ``fraction_second``, ``fraction_undetermined``,
        ``fraction_hypostatic``, ``z_backbone``, ``z_backbone_err`` (standard error over the
        packings, NaN for one), ``rattler_fraction``, ``fraction_refined`` (NaN without
        ``refined`` in the summary).
    """
    beta = np.round(np.asarray(summary["beta"].values, float), 12)
    alpha = np.round(np.asarray(summary["alpha"].values, float), 12)
    keys = sorted(set(zip(beta.tolist(), alpha.tolist())))
    rows = {name: [] for name in ("n_packings", "fraction_jammed", "fraction_first", "fraction_second",
                                  "fraction_undetermined", "fraction_hypostatic", "z_backbone",
                                  "z_backbone_err", "rattler_fraction", "fraction_refined")}

    def values(name, mask):
        return np.asarray(summary[name].values, float)[mask]

    for b, a in keys:
        mask = (beta == b) & (alpha == a)
        order = values("order_code", mask)
        z = values("z_mean", mask)
        rows["n_packings"].append(int(mask.sum()))
        rows["fraction_jammed"].append(float(values("jammed", mask).mean()))
        rows["fraction_first"].append(float((order == ORDER_CODES["first"]).mean()))
        rows["fraction_second"].append(float((order == ORDER_CODES["second"]).mean()))
        rows["fraction_undetermined"].append(float((order == ORDER_CODES["undetermined"]).mean()))
        rows["fraction_hypostatic"].append(float(values("hypostatic", mask).mean()))
        rows["z_backbone"].append(float(np.nanmean(z)) if np.isfinite(z).any() else float("nan"))
        finite = z[np.isfinite(z)]
        rows["z_backbone_err"].append(float(finite.std(ddof=1) / np.sqrt(finite.size)) if finite.size > 1
                                      else float("nan"))
        rows["rattler_fraction"].append(float(values("rattler_fraction", mask).mean()))
        rows["fraction_refined"].append(float(values("refined", mask).mean()) if "refined" in summary
                                        else float("nan"))
    coords = {"beta": ("shape", [k[0] for k in keys]), "alpha": ("shape", [k[1] for k in keys])}
    return xr.Dataset({name: ("shape", np.asarray(v)) for name, v in rows.items()}, coords=coords,
                      attrs={"hardpack_kind": "ellipsoid_verdict_fractions"})
