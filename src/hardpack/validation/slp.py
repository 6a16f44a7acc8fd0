"""Validation rows of the SLP study (Torquato & Jiao 2010) from the pipeline's summaries."""

from __future__ import annotations

import math

import numpy as np

from hardpack.slp.published import (
    MRJ_2D_POLYDISPERSE,
    TABLE_I,
    TABLE_I_LINES,
    TABLE_II,
    TABLE_II_LINES,
)
from hardpack.validation.packings import system_key
from hardpack.validation.rows import Row, within

SOURCE = "Torquato & Jiao 2010 (seed 003)"


def densest_rows(summary) -> list[Row]:
    """Table II: best density over seeds from N = 3^d random starts, and the hit rate.

    d = 2, 3: the paper reaches the triangular lattice and FCC, so the best seed must too (to 1e-6,
    the SLP termination tolerance). d >= 4: the paper's SLP value is the target, within 0.005
    (its printed digits; our seed count is small).
    """
    out = []
    d_all = summary["d"].values.astype(int)
    phi_all = summary["phi"].values
    n_all = summary["N"].values.astype(int)
    for d in np.unique(d_all):
        phi = phi_all[d_all == d]
        n_ours = ", ".join(str(n) for n in np.unique(n_all[d_all == d]))
        n_pub, _, slp_pub, exact, name = TABLE_II[int(d)]
        best = float(phi.max())
        hits = int(np.sum(np.abs(phi - exact) < 1e-6))
        if d <= 3:
            tol, why, target = 1e-6, "the paper reaches the exact densest packing; SLP stops at a 1e-8 gain", exact
        else:
            tol, why, target = 5e-3, "printed to 4 digits; few seeds", slp_pub
        out.append(Row(
            "SLP densest packings (Table II)", f"d = {d}, N = {n_pub}: best phi over seeds ({name} = {exact:.7f})",
            f"{SOURCE} {TABLE_II_LINES}", target, best, math.nan, tol, why,
            abs(best - target) <= tol,
            f"N = {n_ours}: {hits} of {phi.size} seeds reach {name}; median phi {np.median(phi):.5f}",
        ))
    return out


def _pooled_fraction(values, n_particles: int) -> tuple[float, float]:
    """Mean of per-seed fractions and its uncertainty: the larger of the standard error over seeds
    and the binomial error of the pooled count (one seed of N spheres still has sqrt(f(1-f)/N))."""
    values = np.asarray(values, float)
    mean = float(values.mean())
    binomial = math.sqrt(max(mean * (1 - mean), 0.0) / (n_particles * values.size))
    sem = values.std(ddof=1) / math.sqrt(values.size) if values.size > 1 else 0.0
    return mean, max(binomial, sem)


def mrj_jamming_rows(summaries) -> list[Row]:
    """Table I rattler fractions, the 3D contact number and the strict-jamming rate of SLP packings.

    Input: ``slp_jamming`` summaries (``hardpack verify`` verdicts combined over seeds) of the SLP
    MRJ ensembles and SLP-only systems, matched by :func:`system_key`.

    - rattler fraction against Table I (SLP column), tolerance 3 printed standard deviations, plus
      2 sigma of ours (binomial: a few rattlers per packing at our N);
    - 3D backbone contact number against Z = 6 (L1763-1767): an isostatic strictly jammed backbone
      of N_b spheres has Z = 2d + d(d - 1) / N_b (d(N_b - 1) + d(d + 1)/2 contacts), so the
      tolerance is 0.05 + d(d - 1) / N_b;
    - every packing strictly jammed (L869-880: deforming-cell SLP packings are strictly jammed).
    """
    out = []
    for s in summaries:
        key = system_key(s)
        if key is None:
            continue
        name, d = s.attrs.get("ensemble", "?"), key[1]
        n = int(s["N"].values[0])
        size = f"N = {n}, {s.sizes['sample']} seeds"
        if key[0] == "monodisperse" and d in TABLE_I:
            _, _, _, _, (f_pub, f_err) = TABLE_I[d]
            source = f"{SOURCE} Table I, {TABLE_I_LINES}"
        elif key == ("us_omega2", 2):
            f_pub, f_err, source = MRJ_2D_POLYDISPERSE["rattler_fraction"], 0.0, f"{SOURCE} {MRJ_2D_POLYDISPERSE['lines']}"
        else:
            f_pub = None
        if f_pub is not None:
            f, f_unc = _pooled_fraction(s["rattler_fraction"].values, n)
            tol = 3 * f_err
            out.append(Row("SLP MRJ-like packings (Table I)", f"{name}: SLP rattler fraction, {key[0]} d = {d}",
                           source, f_pub, f, f_unc, tol,
                           "3 printed standard deviations; ours has the binomial error of a few rattlers",
                           within(f, f_pub, tol, f_unc), size))
        if key == ("monodisperse", 3):
            z, z_sem = float(np.mean(s["z_mean"].values)), (
                float(np.std(s["z_mean"].values, ddof=1) / math.sqrt(s.sizes["sample"])) if s.sizes["sample"] > 1 else math.nan)
            n_b = n * (1 - float(np.mean(s["rattler_fraction"].values)))
            tol = 0.05 + d * (d - 1) / n_b
            out.append(Row("SLP MRJ-like packings (Table I)", f"{name}: SLP backbone contact number, d = 3",
                           f"{SOURCE} L1763-1767 (Z = 6 at MRJ)", 6.0, z, z_sem, tol,
                           "isostatic strict backbone: Z = 2d + d(d-1)/N_b", within(z, 6.0, tol, z_sem), size))
        strict = np.asarray(s["strict"].values) == 1
        out.append(Row("SLP MRJ-like packings (Table I)", f"{name}: fraction strictly jammed, d = {d}",
                       f"{SOURCE} L869-880", 1.0, float(strict.mean()), math.nan, 0.0,
                       "deforming-cell SLP packings are strictly jammed (sequential LP test)", bool(strict.all()), size))
    return out


def order_map_rows(summary) -> list[Row]:
    """Fig. 6: the density range of the SLP order map and the strict-jamming rate of its packings.

    Published range: [0.64, 0.74048] from dilute random starts, filled "essentially continuously"
    (L1573-1581, L1620-1624), and down to 0.6 over all protocols (abstract L31-33; the low end used
    the diluted-MRJ restarts, L1699-1719, which we do not run). Rows: the densest packing of the map
    against FCC (to 1e-4: a converged SLP FCC is exact to ~1e-8), the least dense against 0.60
    (within 0.03: our map only varies gamma, the bounds and N), the widest density gap between
    0.64 and FCC (at most 0.02, a fifth of the range, for a map of a few dozen packings), and every
    packing strictly jammed.
    """
    phi = summary["phi"].values
    t = summary["T"].values
    strict = np.asarray(summary["strict"].values) == 1
    sizes = ", ".join(str(n) for n in np.unique(summary["N"].values))
    size = f"{phi.size} packings, N = {sizes}"
    fcc = math.pi / math.sqrt(18)
    k_max, k_min = int(np.argmax(phi)), int(np.argmin(phi))
    inside = np.sort(np.concatenate([[0.64, fcc], phi[(phi > 0.64) & (phi < fcc)]]))
    k_gap = int(np.argmax(np.diff(inside)))
    gap = float(inside[k_gap + 1] - inside[k_gap])
    return [
        Row("SLP order map (Fig. 6)", "densest packing of the 3D order map", f"{SOURCE} L1620-1624", fcc,
            float(phi[k_max]), math.nan, 1e-4, "SLP reaches FCC from random starts (converged to 1e-8)",
            abs(phi[k_max] - fcc) <= 1e-4, f"{size}; its T = {t[k_max]:.3f}"),
        Row("SLP order map (Fig. 6)", "least dense jammed packing of the 3D order map", f"{SOURCE} L31-33, L1699-1719",
            0.60, float(phi[k_min]), math.nan, 0.03,
            "the paper's low end needs diluted-MRJ restarts, which we do not run",
            abs(phi[k_min] - 0.60) <= 0.03, f"{size}; its T = {t[k_min]:.3f}"),
        Row("SLP order map (Fig. 6)", "widest density gap of the order map between 0.64 and FCC",
            f"{SOURCE} L1573-1581", 0.0, gap, math.nan, 0.02,
            "the paper fills 0.64-0.74048 essentially continuously; a fifth of the range for our few dozen packings",
            gap <= 0.02, f"{size}; gap from {inside[k_gap]:.4f} to {inside[k_gap + 1]:.4f}"),
        Row("SLP order map (Fig. 6)", "fraction of order-map packings strictly jammed", f"{SOURCE} L1569-1572",
            1.0, float(strict.mean()), math.nan, 0.0, "Fig. 6 shows strictly jammed packings", bool(strict.all()), size),
    ]
