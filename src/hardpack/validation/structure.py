"""Validation rows of the structure study on the LS packings (Donev 2006, ch. 9-10).

Input: the per-packing structure Datasets (``hardpack structure``), grouped by their ``ensemble``
attribute (``hardpack structure --attr ensemble=NAME``). Rows are made for 3D monodisperse
ensembles, the systems the published numbers describe (targets ``donev-ch9-*`` and
``donev-ch10-s0``):

- the near-contact exponent alpha of Z(l) - Z_c = a l^alpha, rattlers removed, per seed;
- the split second peak of g2: the maxima of the seed-averaged g2(r / (r_i + r_j)) (bins of
  0.005) near sqrt(3) D and at 2 D, the latter with the drop just above 2 D that makes it a
  discontinuity;
- S(0) from one weighted linear fit over the small-k shells (kD < 2 pi 0.4) of all seeds of the
  ensemble (:func:`hardpack.structure.sk.extrapolate_s0`): one packing of N = 1e3 has only ~5
  shells in that range. The detail gives the Carnahan-Starling fluid S(0) at the same phi.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import replace

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.structure.analysis import S0_FIT_KD
from hardpack.structure.sk import extrapolate_s0
from hardpack.validation.rows import FAIL, PASS, Row, evaluate
from hardpack.validation.targets import load_targets


def fluid_s0(phi: float) -> float:
    """Carnahan-Starling S(0) = kT (d rho / d p) = (1 - phi)^4 / (1 + 4 phi + 4 phi^2 - 4 phi^3 + phi^4).

    Carnahan & Starling (1969) equation of state.

    Parameters
    ----------
    phi : float
        Volume fraction.

    Returns
    -------
    float
        S(0).
    """
    return (1 - phi) ** 4 / (1 + 4 * phi + 4 * phi**2 - 4 * phi**3 + phi**4)


def _ensemble(ds) -> str:
    """The ensemble a structure Dataset belongs to: its ``ensemble`` attribute."""
    if "ensemble" not in ds.attrs:
        raise InvalidInputError(
            f"the structure dataset of {ds.attrs.get('source', 'a packing')} has no 'ensemble' attribute, "
            "so its ensemble is unknown; write it with `hardpack structure ... --attr ensemble=NAME`")
    return str(ds.attrs["ensemble"])


def pooled_s0(members: list) -> tuple[float, float]:
    """S(0) and its error from one linear fit of the small-k shells of all ``members``; NaN when
    they have fewer than 3 shells in the fit range (small cells).

    Parameters
    ----------
    members : list of xarray.Dataset
        Structure-factor datasets (variables S and n_vectors over k).

    Returns
    -------
    s0 : float
        S(0).
    error : float
        Its standard error.
    """
    pooled = xr.concat([m[["S", "n_vectors"]] for m in members], dim="k")
    diameter = float(np.mean([m.attrs["mean_diameter"] for m in members]))
    try:
        s0, err, _ = extrapolate_s0(pooled, S0_FIT_KD / diameter, "linear")
    except InvalidInputError:
        return math.nan, math.nan
    return s0, err


def _peak(x, g, lo, hi) -> float:
    inside = (x >= lo) & (x <= hi)
    return float(x[inside][np.argmax(g[inside])])


def _rows(name: str, members: list) -> list[Row]:
    targets = load_targets()
    n, seeds = int(members[0].attrs["n_particles"]), len(members)
    size = f"N = {n}, {seeds} seeds"
    window = members[0].attrs.get("alpha_window", [math.nan, math.nan])
    x = members[0]["x"].values
    g2 = np.mean([m["g2_scaled"].values for m in members], axis=0)
    at_sqrt3, at_2 = _peak(x, g2, 1.62, 1.85), _peak(x, g2, 1.9, 2.1)
    below, above = g2[np.searchsorted(x, 2.0) - 1], float(np.mean(g2[(x > 2.0) & (x < 2.05)]))
    s0, s0_err = pooled_s0(members)
    phi = float(np.mean([m.attrs["phi"] for m in members]))
    fluid = fluid_s0(phi)
    peak_2 = evaluate(targets["donev-ch9-g2-peak-2"], at_2, n=n, seeds=seeds, label=name,
                      detail=f"{size}; g2(2-) = {below:.3g}, mean over (2, 2.05) {above:.3g}")
    if peak_2.status == PASS and not below > above:
        peak_2 = replace(peak_2, status=FAIL, detail=peak_2.detail + "; no drop above 2 D")
    return [
        evaluate(targets["donev-ch9-near-contact-exponent"], samples=[float(m["alpha"]) for m in members],
                 n=n, label=name,
                 detail=f"{size}; ML fit of Z(l) - Z_c = a l^alpha on l in [{window[0]:g}, {window[1]:g}]"),
        evaluate(targets["donev-ch9-g2-peak-sqrt3"], at_sqrt3, n=n, seeds=seeds, label=name,
                 detail=f"{size}; maximum of the seed-averaged g2 in [1.62, 1.85]"),
        peak_2,
        evaluate(targets["donev-ch10-s0"], s0, s0_err, n=n, seeds=seeds, label=name,
                 detail=f"{size}, shells of all seeds in one fit; Carnahan-Starling fluid at phi = "
                        f"{phi:.3f}: S(0) = {fluid:.3g}" + (f" ({fluid / s0:.1f} x ours)" if s0 > 0 else "")),
    ]


def structure_rows(datasets) -> list[Row]:
    """Rows for every 3D monodisperse ensemble among the structure Datasets.

    Parameters
    ----------
    datasets : iterable of xarray.Dataset
        Structure datasets.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    groups = defaultdict(list)
    for ds in datasets:
        if int(ds.attrs["dim"]) == 3 and float(ds.attrs.get("radius_ratio", math.inf)) < 1 + 1e-9:
            groups[_ensemble(ds)].append(ds)
    return [row for name, members in groups.items() for row in _rows(name, members)]
