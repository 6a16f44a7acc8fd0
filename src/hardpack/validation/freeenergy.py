"""Validation rows of the BCMD study (issue 7): FCC at melting and in the jamming limit (finite-N
extrapolation), FCC vs density (BCMD against the engine's EOS), LS packings against their exact
jamming simplex, and the cheap ladder checks. Each row's detail gives the cost of its point."""

from __future__ import annotations

import math

import numpy as np

from hardpack.freeenergy.crystal import (
    MELTING_EXCESS,
    MELTING_PHI,
    cell_offset,
    eos_excess,
)
from hardpack.validation.rows import Row, within

SOURCE = "Donev dissertation ch. 6 (seed 000, ch06.txt)"
STUDY = "BCMD free energies"
# (published value, lines, quantity attribute in the BCMD dataset)
TARGETS = {
    "melting": (5.91916, "L1008-1010", "excess", "FCC excess free energy at phi = 0.545"),
    "jamming": (2.160, "L1012-1018", "delta_f", "FCC jamming-limit constant f_J - f_c^J"),
}


def _cost(ds) -> str:
    """'k runs, E events, S s' from a summary's n_events / seconds variables (if present)."""
    parts = [f"{ds.sizes.get('sample', 1)} runs"]
    for var, unit in (("n_events", "events"), ("seconds", "s"), ("seconds_bcmd", "s")):
        if var in ds:
            parts.append(f"{float(ds[var].sum()):.3g} {unit}")
    return "cost " + ", ".join(parts)


def finite_size_extrapolation(n, values) -> tuple[float, float, str]:
    """Infinite-N value from values(N) = a + b ln(N)/N (the leading correction, note sec. 5.4).

    With fewer than three sizes, the largest-N mean is returned with the size of the correction
    3 ln N / N as its uncertainty, and the caller must not count it as a reproduction.
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
        return float(coef[0]), math.sqrt(max(cov[0, 0], 0.0)), f"fit a + b ln N / N over N = {sizes.astype(int).tolist()}"
    big = sizes.max()
    return float(values[n == big].mean()), 3 * math.log(big) / big, f"largest N = {int(big)} only (no extrapolation)"


def bcmd_rows(summaries: dict) -> list[Row]:
    """One row per state in ``summaries`` (state name -> combined BCMD Dataset)."""
    out = []
    for state, ds in summaries.items():
        value, lines, var, label = TARGETS[state]
        est, err, how = finite_size_extrapolation(ds["n_particles"].values, ds[var].values)
        extrapolated = np.unique(ds["n_particles"].values).size >= 3
        out.append(Row(
            "BCMD free energies (FCC)", label, f"{SOURCE} {lines}", value, est, err, 0.005,
            "the issue's acceptance band after the finite-N correction; the +- is the fit error",
            extrapolated and within(est, value, 0.005, err),
            (how if extrapolated else how + ": inconclusive, counted as not reproduced")
            + f"; {_cost(ds)}",
        ))
    return out


def density_rows(density, eos) -> list[Row]:
    """BCMD's change of the FCC excess free energy from melting to the densest point against the
    integral of the engine's crystal EOS over the same range (both at the same N; the finite-N
    offsets of the two BCMD points cancel to O(ln N / N) of their difference).
    density: the BCMD summary over (phi, seed); eos: the MD summary over phi."""
    bcmd = density
    phi_b = bcmd["phi"].values
    excess = bcmd["excess"].values
    lo, hi = np.isclose(phi_b, MELTING_PHI, atol=1e-6), np.isclose(phi_b, phi_b.max())
    reproduced = float(excess[hi].mean() - excess[lo].mean())
    spread = [np.std(excess[m], ddof=1) / np.sqrt(m.sum()) for m in (lo, hi) if m.sum() > 1]
    err = float(np.hypot(*spread)) if len(spread) == 2 else math.nan
    phi_e, z = eos["phi"].values, eos["Z"].values
    integral = eos_excess(phi_e, z, excess0=0.0)[np.argmax(phi_e)]
    df_eos = float(cell_offset(phi_e.max()) - MELTING_EXCESS - integral)
    n = int(np.asarray(bcmd["n_particles"].values).ravel()[0])
    return [Row(
        STUDY, f"FCC excess(phi = {phi_b.max():.4g}) - excess(0.545): BCMD vs int (Z - 1) dphi/phi",
        "thermodynamic integration of the engine's crystal EOS (this pipeline)", float(integral),
        reproduced, err, 0.01,
        "two BCMD points with seed scatter ~0.004 each; EOS spline error < 1e-3",
        within(reproduced, float(integral), 0.01, err),
        f"N = {n}; Delta f(phi_max): BCMD {float(cell_offset(phi_b.max()) - excess[hi].mean()):.4f}"
        f", published 5.91916 + EOS integral {df_eos:.4f} (jamming limit 2.160); BCMD "
        f"{_cost(bcmd)}; EOS {eos.sizes['sample']} runs, "
        f"{float(eos['wall_time'].sum()):.3g} s",
    )]


def simplex_rows(ds) -> list[Row]:
    """BCMD of rattler-free LS packings vs their exact jamming simplex, one row per frozen mode
    (means over packings; the tolerance is the issue's 1 %)."""
    out = []
    for frozen in ("particle", "cm"):
        sel = ds.isel(sample=np.flatnonzero(ds["frozen"].values == frozen))
        iso = sel["isostatic"].values.astype(bool)
        n = sel["n_backbone"].values
        label = ("frozen particle" if frozen == "particle"
                 else "frozen centre of mass (exact + d ln N / N)")
        if not iso.any():
            gaps = sel["isostaticity_gap"].values.tolist()
            out.append(Row(
                STUDY, f"f_J - f_c^J of LS backbones, BCMD vs exact simplex, {label}",
                f"{SOURCE} Table 6.1 L1082-1139 (method)", math.nan, math.nan, math.nan, 0.01,
                "the issue's 1 %", False,
                f"no isostatic backbone (M - N_f - 1 = {gaps}): the simplex formula does not apply",
            ))
            continue
        exact = sel["exact"].values[iso]
        bcmd = sel["bcmd"].values[iso]
        rel = sel["rel_diff"].values[iso]
        diff = bcmd - exact  # the packings differ; their differences are the sample
        err = float(np.std(diff, ddof=1) / np.sqrt(diff.size)) if diff.size > 1 else math.nan
        shift = sel["dim"].values[iso] * np.log(n[iso]) / n[iso] if frozen == "cm" else None
        detail = (f"{iso.sum()} isostatic backbone(s), N_b = {n[iso].tolist()}, relative "
                  f"differences {np.round(rel, 4).tolist()}; {_cost(sel)}")
        if shift is not None:
            detail += f"; CM shift d ln N / N = {np.round(shift, 4).tolist()}"
        out.append(Row(
            STUDY, f"f_J - f_c^J of LS backbones, BCMD vs exact simplex, {label}",
            f"{SOURCE} Table 6.1 L1082-1139 (method; exact value from Eq. 6.5)",
            float(exact.mean()), float(bcmd.mean()), err, 0.01 * float(exact.mean()),
            "the issue's 1 % (the paper: ~0.05 % at N = 978)",
            bool(np.all(np.abs(rel) <= 0.01)), detail,
        ))
    return out


def ladder_rows(ds) -> list[Row]:
    """The cheap checks (hardpack.freeenergy.ladder): |value - exact| <= tolerance."""
    out = []
    for check in ds["check"].values:
        r = ds.sel(check=check)
        value, exact, tol = float(r["value"]), float(r["exact"]), float(r["tolerance"])
        out.append(Row(
            STUDY, str(check), "note bcmd_free_energy.md sec. 5.2 items 1-3 (exact values)",
            exact, value, math.nan, tol, str(r["why"].values),
            within(value, exact, tol), f"cost {float(r['seconds']):.2g} s",
        ))
    return out
