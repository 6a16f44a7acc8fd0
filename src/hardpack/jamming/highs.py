"""scipy's HiGHS (``linprog``) with the tolerances and retries every jamming LP uses."""

from __future__ import annotations

from scipy.optimize import linprog

#: HiGHS tolerances: tighter than the defaults (1e-7) so that a jammed packing with exact
#: contacts returns displacements at round-off level instead of the feasibility tolerance.
HIGHS_OPTIONS = {
    "primal_feasibility_tolerance": 1e-10,
    "dual_feasibility_tolerance": 1e-10,
}


class LPFailure(RuntimeError):
    """HiGHS did not return an optimal solution (should not happen for a bounded LP)."""


#: solver attempts, in order: the dual simplex, then the interior-point method with crossover,
#: then both with HiGHS's default tolerances (rare numerical trouble on near-degenerate LPs)
ATTEMPTS = (("highs-ds", HIGHS_OPTIONS), ("highs-ipm", HIGHS_OPTIONS), ("highs-ds", {}), ("highs-ipm", {}))


def solve_lp(c, *, method: str = "highs-ds", options: dict | None = None, **kwargs):
    """scipy.optimize.linprog with HiGHS, retried with the other ATTEMPTS when HiGHS reports
    numerical trouble or a limit (status 1 or 4). ``options`` are added to every attempt's.
    An infeasible or unbounded verdict (status 2, 3) is confirmed without presolve: with the
    tight tolerances HiGHS's presolve has declared feasible LPs infeasible (the local jamming
    LP 4.15 of an SLP crystal, for which dr = 0 is feasible; tests/test_jamming_highs.py).
    Returns the optimal result; raises LPFailure for a confirmed infeasible or unbounded LP or
    after the last attempt."""
    attempts = [(m, o) for m, o in ATTEMPTS if m == method] + [a for a in ATTEMPTS if a[0] != method]
    res = None
    for m, base in attempts:
        opts = {**base, **(options or {})}
        res = linprog(c, method=m, options=opts, **kwargs)
        if res.status in (2, 3) and opts.get("presolve", True):
            res = linprog(c, method=m, options={**opts, "presolve": False}, **kwargs)
        if res.status in (0, 2, 3):
            break
    if res.status == 0:
        return res
    raise LPFailure(f"HiGHS returned status {res.status}: {res.message}")


__all__ = ["ATTEMPTS", "HIGHS_OPTIONS", "LPFailure", "solve_lp"]
