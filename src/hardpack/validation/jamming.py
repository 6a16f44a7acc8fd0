"""Validation rows of the jamming verdicts of the LS packings (Donev ch. 4 and ch. 9).

Input: ensemble jamming summaries (``jamming_summary`` rule: per seed z_mean, rattler_fraction,
collective, ...), matched to a published system by :func:`hardpack.validation.packings.system_key`.

- mean contact number after rattler removal: isostatic 2d (3D spheres 6, L1659-1661 of ch. 9;
  2D binary disks 4), tolerance 0.05 (the issue's band: an isostatic backbone of N_b particles has
  Z = 2d (1 - 1/N_b) + 2/N_b, within 0.01 of 2d for N_b >= 200);
- rattler fraction, 3D monodisperse: about 2.2 % (ch. 9 L1659-1661), tolerance 0.008 (<= 3 %);
- fraction of packings collectively jammed: 1 (LS packings at Z = 1e12 are, ch. 4 sec. 4.5).
"""

from __future__ import annotations

import math

import numpy as np

from hardpack.validation.packings import system_key
from hardpack.validation.rows import Row, mean_sem, within

CH9 = "Donev dissertation ch. 9 (seed 000, ch07-09)"
CH4 = "Donev dissertation ch. 4 (seed 000, ch04-05)"



def jamming_rows(summaries) -> list[Row]:
    """Contact number, rattler fraction and collective-jamming rate of recognised LS ensembles."""
    out = []
    for s in summaries:
        key = system_key(s)
        if key not in (("monodisperse", 3), ("binary_1.4_equimolar", 2)):
            continue
        name, d = s.attrs.get("ensemble", "?"), key[1]
        size = f"N = {int(s['N'].values[0])}, {s.sizes['sample']} seeds"
        z, z_sem = mean_sem(s["z_mean"].values)
        out.append(Row("jamming (LP verdicts)", f"{name}: contact number after rattlers, {key[0]} d = {d}",
                       f"{CH9} L1659-1661 (isostatic Z = 2d)", 2.0 * d, z, z_sem, 0.05,
                       "issue band; a finite isostatic backbone has 2d(1 - 1/N_b) + 2/N_b",
                       within(z, 2.0 * d, 0.05, z_sem),
                       f"{size}; isostaticity gaps {', '.join(str(int(g)) for g in s['isostaticity_gap'].values)}"))
        if key == ("monodisperse", 3):
            r, r_sem = mean_sem(s["rattler_fraction"].values)
            out.append(Row("jamming (LP verdicts)", f"{name}: rattler fraction, monodisperse d = 3",
                           f"{CH9} L1659-1661", 0.022, r, r_sem, 0.008, "issue: at most 3 %",
                           within(r, 0.022, 0.008, r_sem), size))
        collective = np.asarray(s["collective"].values) == 1
        out.append(Row("jamming (LP verdicts)", f"{name}: fraction collectively jammed",
                       f"{CH4} sec. 4.5", 1.0, float(collective.mean()), math.nan, 0.0,
                       "every LS packing at Z = 1e12 should pass the collective test",
                       bool(collective.all()), size))
    return out
