"""Validation rows computed from theory alone: Ogarko's moment tables and the HGrid cost model."""

from __future__ import annotations

import math

from hardpack.distributions import LogNormal, uniform_size, uniform_volume
from hardpack.eos import moments as mo
from hardpack.eos.published import (
    FIG_2_15,
    ONE_UNIT,
    TABLE_31_US,
    TABLE_31_UV,
    TABLE_33,
    TABLE_34,
    matches_printed,
    rows,
    ulp,
)
from hardpack.validation.rows import Row

OGARKO = "Ogarko dissertation (seed 002)"
ROUNDING = "reproduced value must round to the printed digits"


def _table_row(study, label, source, printed, values, names, exceptions=frozenset()):
    units = [1.0 if name in exceptions else 0.5 for name in names]
    ok = all(matches_printed(v, p, u) for v, p, u in zip(values, printed, units))
    worst = max(abs(v - float(p)) / ulp(p) for v, p in zip(values, printed))
    detail = ", ".join(f"{n} {p} vs {v:.6g}" for n, p, v in zip(names, printed, values))
    why = ROUNDING + (f"; one unit for {sorted(exceptions)} (printed digits truncated, see tests)" if exceptions else "")
    return Row(study, label, source, float(printed[0]), float(values[0]), math.nan,
               units[0] * ulp(printed[0]), why, ok, detail + f"; worst {worst:.2f} units of the last digit")


def moment_table_rows() -> list[Row]:
    """Tables 3.1 (US, UV), 3.3 (UV tridisperse) and 3.4 (log-normal tridisperse): one row per printed line."""
    out = []
    study = "EOS vs moments: equivalent mixtures (analytic)"
    for line in rows(TABLE_31_US):
        dist = uniform_size(float(line[0]))
        o1, o2 = mo.dimensionless_moments(dist)
        values = (o1, o2, mo.equivalent_bidisperse(dist).R, mo.polydispersity(dist))
        out.append(_table_row(study, f"Table 3.1 US omega={line[0]}: O1, O2, R_bi, delta",
                              f"{OGARKO} L5470-5516", line[1:], values, ("O1", "O2", "R_bi", "delta")))
    for line in rows(TABLE_31_UV):
        dist = uniform_volume(float(line[0]))
        o1, o2 = mo.dimensionless_moments(dist)
        bi = mo.equivalent_bidisperse(dist)
        values = (o1, o2, bi.R, bi.n1, mo.polydispersity(dist))
        out.append(_table_row(study, f"Table 3.1 UV omega={line[0]}: O1, O2, R_bi, n1_bi, delta",
                              f"{OGARKO} L5470-5516", line[1:], values, ("O1", "O2", "R_bi", "n1_bi", "delta")))
    for table, key, make, lines_ref in ((TABLE_33, "UV", uniform_volume, "L6466-6486"),
                                        (TABLE_34, "LN", LogNormal, "L6606-6652")):
        for line in rows(table):
            par = float(line[0])
            tri = mo.equivalent_tridisperse(make(par))
            values = (tri.n1, tri.n2, tri.delta1, tri.delta2)
            names = ("n1", "n2", "delta1", "delta2")
            exceptions = frozenset(n for n in names if (key, par, n) in ONE_UNIT)
            label = "omega" if key == "UV" else "sigma"
            tab = "3.3" if key == "UV" else "3.4"
            out.append(_table_row(study, f"Table {tab} {key} {label}={line[0]}: tridisperse n1, n2, delta1, delta2",
                                  f"{OGARKO} {lines_ref}", line[1:], values, names, exceptions))
    return out


def hgrid_rows() -> list[Row]:
    """Fig. 2.15 minima of the analytic HGrid cost (alpha = -3, omega = 100, nu = 0.7, d = 3, K = 0.2)."""
    from hardpack.hgrid.cost_model import PowerLawSystem, best_levels

    system = PowerLawSystem(alpha=-3.0, omega=100.0, nu=0.7, d=3)
    out = []
    for rule, (printed, levels) in FIG_2_15.items():
        l_max = 50 if rule != "optimal" else 12
        L, cost, _ = best_levels(system, rule, L_max=l_max)
        detail = f"minimum at L = {L}" + (f" (printed L = {levels})" if levels else "")
        ok = abs(cost - printed) <= 0.01 and (levels is None or L == levels)
        out.append(Row("Hierarchical grid cost model (analytic)", f"Fig. 2.15 minimum T/N, {rule} cell sizes",
                       f"{OGARKO} L3090-3112", printed, float(cost), math.nan, 0.01,
                       "printed to 2 decimals; the level count must match too", ok, detail))
    return out
