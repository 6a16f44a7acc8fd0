"""Validation rows of the BCMD study: FCC excess free energy at melting and in the jamming limit."""

from __future__ import annotations

import math

import numpy as np

from hardpack.validation.rows import Row, within

SOURCE = "Donev dissertation ch. 6 (seed 000, ch06.txt)"
# (published value, lines, quantity attribute in the BCMD dataset)
TARGETS = {
    "melting": (5.91916, "L1008-1010", "excess", "FCC excess free energy at phi = 0.545"),
    "jamming": (2.160, "L1012-1018", "delta_f", "FCC jamming-limit constant f_J - f_c^J"),
}


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
            how if extrapolated else how + ": inconclusive, counted as not reproduced",
        ))
    return out
