"""Validation rows of the structure study on the LS packings (Donev ch. 9-10).

Input: the per-packing structure Datasets (``hardpack structure``), grouped by ensemble (the
directory of their ``source`` packing). Rows are made for 3D monodisperse ensembles, the systems
the published numbers describe:

- near-contact exponent alpha of Z(l) - Z_c = a l^alpha, rattlers removed: 0.6 (ch. 9 L1788-1789,
  Z(l) - 6 ~ 11 l^0.6); band +-0.1 (the issue's acceptance band: the exponent moves between 0.5
  and 0.6 with the fit range and the rattler treatment, L1830-1841);
- the split second peak of g2: sub-peaks at r = sqrt(3) D and 2 D (L1857-1861), located on the
  seed-averaged g2(r / (r_i + r_j)) (bin 0.005); tolerance two bins for the peak at 2 D (a
  discontinuity) and 0.03 for the rounded one at sqrt(3) D;
- S(0) from the linear small-k fit, kD < 2 pi 0.4 (ch. 10 L178-181: S(k) ~ 6.1e-4 + 3.4e-3 kD,
  "vanishes to within 1e-3"); tolerance 1e-3. One packing of N = 1e3 has only ~5 shells in the
  fit range, so the fit pools the shells of all seeds of the ensemble (one weighted least-squares
  fit, :func:`hardpack.structure.sk.extrapolate_s0`) instead of averaging per-seed intercepts.
  The detail gives the Carnahan-Starling fluid S(0) at the same phi and the ratio.
"""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path

import numpy as np
import xarray as xr

from hardpack.errors import InvalidInputError
from hardpack.structure.analysis import S0_FIT_KD
from hardpack.structure.sk import extrapolate_s0
from hardpack.validation.rows import Row, mean_sem, within

CH9 = "Donev dissertation ch. 9 (seed 000, ch07-09)"
CH10 = "Donev dissertation ch. 10 (seed 000, ch10-14)"


def fluid_s0(phi: float) -> float:
    """Carnahan-Starling S(0) = kT (d rho / d p) = (1 - phi)^4 / (1 + 4 phi + 4 phi^2 - 4 phi^3 + phi^4)."""
    return (1 - phi) ** 4 / (1 + 4 * phi + 4 * phi**2 - 4 * phi**3 + phi**4)


def _ensemble(ds) -> str:
    parts = Path(str(ds.attrs.get("source", ""))).parts
    return parts[-3] if len(parts) >= 3 else "packings"



def pooled_s0(members: list) -> tuple[float, float]:
    """S(0) and its error from one linear fit of the small-k shells of all ``members``; NaN when
    they have fewer than 3 shells in the fit range (small cells)."""
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
    n, seeds = int(members[0].attrs["n_particles"]), len(members)
    size = f"N = {n}, {seeds} seeds"
    alpha, alpha_sem = mean_sem(float(m["alpha"]) for m in members)
    window = members[0].attrs.get("alpha_window", [math.nan, math.nan])
    x = members[0]["x"].values
    g2 = np.mean([m["g2_scaled"].values for m in members], axis=0)
    at_sqrt3, at_2 = _peak(x, g2, 1.62, 1.85), _peak(x, g2, 1.9, 2.1)
    below, above = g2[np.searchsorted(x, 2.0) - 1], float(np.mean(g2[(x > 2.0) & (x < 2.05)]))
    s0, s0_sem = pooled_s0(members)
    phi = float(np.mean([m.attrs["phi"] for m in members]))
    return [
        Row("structure", f"{name}: near-contact exponent alpha, rattlers removed", f"{CH9} L1788-1789",
            0.6, alpha, alpha_sem, 0.1, "issue band: the exponent moves within 0.5-0.6 with fit range and rattlers",
            within(alpha, 0.6, 0.1, alpha_sem),
            f"{size}; ML fit of Z(l) - Z_c = a l^alpha on l in [{window[0]:g}, {window[1]:g}]"),
        Row("structure", f"{name}: g2 second-peak sub-peak at sqrt(3) D", f"{CH9} L1857-1861",
            math.sqrt(3), at_sqrt3, math.nan, 0.03, "rounded sub-peak; bins of 0.005",
            within(at_sqrt3, math.sqrt(3), 0.03), f"{size}; seed-averaged g2 maximum in [1.62, 1.85]"),
        Row("structure", f"{name}: g2 second-peak sub-peak at 2 D", f"{CH9} L1857-1861",
            2.0, at_2, math.nan, 0.01, "a discontinuity: two bins of 0.005",
            within(at_2, 2.0, 0.01) and below > above,
            f"{size}; g2(2-) = {below:.3g} drops to {above:.3g} on (2, 2.05)"),
        Row("structure", f"{name}: S(0), linear fit kD < 2 pi 0.4", f"{CH10} L178-181",
            6.1e-4, s0, s0_sem, 1e-3, "the text: S(0) vanishes to within 1e-3",
            within(s0, 6.1e-4, 1e-3, s0_sem),
            f"{size}, shells pooled; Carnahan-Starling fluid at phi = {phi:.3f}: S(0) = {fluid_s0(phi):.3g} "
            f"({fluid_s0(phi) / s0:.1f} x the jammed value)" if s0 > 0 else f"{size}"),
    ]


def structure_rows(datasets) -> list[Row]:
    """Rows for every 3D monodisperse ensemble among the structure Datasets."""
    groups = defaultdict(list)
    for ds in datasets:
        if int(ds.attrs["dim"]) == 3 and float(ds.attrs.get("radius_ratio", math.inf)) < 1 + 1e-9:
            groups[_ensemble(ds)].append(ds)
    return [row for name, members in groups.items() for row in _rows(name, members)]
