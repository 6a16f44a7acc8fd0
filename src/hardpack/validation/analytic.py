"""Validation rows computed from theory alone: Ogarko's moment tables and the HGrid cost model.

Every printed cell of Ogarko's Tables 3.1, 3.3, 3.4 and the minima of Fig. 2.15 is a target of
``targets.yaml``; each row puts our closed form beside it (it must round to the printed digits).
"""

from __future__ import annotations

from hardpack.distributions import LogNormal, uniform_size, uniform_volume
from hardpack.eos import moments as mo
from hardpack.validation.rows import Row, evaluate
from hardpack.validation.targets import load_targets


def _cells(prefix: str) -> dict[str, dict[str, object]]:
    """Targets of one printed table: {row label: {column: Target}} (e.g. "omega1.2": {"o1": ...})."""
    out: dict[str, dict[str, object]] = {}
    for tid, t in load_targets().items():
        if tid.startswith(prefix + "-"):
            label, _, column = tid[len(prefix) + 1:].rpartition("-")
            out.setdefault(label, {})[column] = t
    return out


def _parameter(label: str, name: str) -> float:
    return float(label.removeprefix(name))


def moment_values(family: str, width: float) -> dict[str, float]:
    """Our closed forms of every column of Tables 3.1 (US, UV), 3.3 (UV) and 3.4 (LN) at one width,
    keyed like the table columns (lower case).

    Parameters
    ----------
    family : str
        "us" (uniform size), "uv" (uniform volume) or "ln" (log-normal).
    width : float
        The family's width parameter (omega, or sigma for "ln").

    Returns
    -------
    dict of str to float
        o1, o2, r_bi, n1_bi, delta, n1, n2, delta1, delta2.
    """
    if family == "us":
        dist = uniform_size(width)
    elif family == "uv":
        dist = uniform_volume(width)
    else:
        dist = LogNormal(width)
    o1, o2 = mo.dimensionless_moments(dist)
    bi = mo.equivalent_bidisperse(dist)
    tri = mo.equivalent_tridisperse(dist)
    return {"o1": o1, "o2": o2, "r_bi": bi.R, "n1_bi": bi.n1, "delta": mo.polydispersity(dist),
            "n1": tri.n1, "n2": tri.n2, "delta1": tri.delta1, "delta2": tri.delta2}


def moment_table_rows() -> list[Row]:
    """One row per printed cell of Tables 3.1 (US, UV), 3.3 (UV tridisperse) and 3.4 (log-normal).

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    out = []
    for prefix, family, name in (("ogarko-t3.1-us", "us", "omega"), ("ogarko-t3.1-uv", "uv", "omega"),
                                 ("ogarko-t3.3-uv", "uv", "omega"), ("ogarko-t3.4-ln", "ln", "sigma")):
        for label, columns in _cells(prefix).items():
            values = moment_values(family, _parameter(label, name))
            for column, t in columns.items():
                out.append(evaluate(t, values[column]))
    return out


def hgrid_rows() -> list[Row]:
    """Fig. 2.15: minima of the analytic HGrid cost and their level counts (alpha = -3,
    omega = 100, nu = 0.7, d = 3, K = 0.2), one row per printed number.

    Returns
    -------
    list of Row
        Validation rows (:class:`hardpack.validation.rows.Row`).
    """
    from hardpack.hgrid.cost_model import PowerLawSystem, best_levels

    system = PowerLawSystem(alpha=-3.0, omega=100.0, nu=0.7, d=3)
    out = []
    for rule, columns in _cells("ogarko-fig2.15-min").items():
        levels, cost, _ = best_levels(system, rule, L_max=12 if rule == "optimal" else 50)
        values = {"cost": float(cost), "levels": float(levels)}
        for column, t in columns.items():
            out.append(evaluate(t, values[column], detail=f"minimum at L = {levels}"))
    return out
