"""scipy's HiGHS (``linprog``) with the tolerances and retries every jamming LP uses, and the
record of the numerical fallbacks of a jamming verification (:func:`recording_fallbacks`)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

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


#: the numerical fallbacks a verification records (``JammingResult.fallbacks``), and what each
#: one means; counted by :func:`note_fallback`
FALLBACKS = {
    "lp_default_tolerances": "LPs that HiGHS solved only with its default tolerances (1e-7), after "
                             "the tight ones (1e-10) failed: their displacements and forces are "
                             "exact to 1e-7 only",
    "lp_working_set_to_highs": "LPs that the sparse-LU working set gave up and HiGHS solved (the "
                               "same optimum to the solver tolerances; slower)",
    "lp_volume_to_highs": "strict LPs whose working-set solution broke Tr eps <= 0 beyond the LP "
                          "accuracy and HiGHS solved again (with a strain description far from "
                          "the axes the working set's round-off can reach 1e-9 of the box)",
    "uniform_forces_lp_failed": "backbones whose most-uniform-force LP failed: the forces are those "
                                "of the jamming-gap LP, not the most uniform ones",
}
_RECORD: ContextVar[Counter | None] = ContextVar("hardpack_jamming_fallbacks", default=None)


@contextmanager
def recording_fallbacks() -> Iterator[Counter]:
    """Count the :data:`FALLBACKS` noted inside the block into the Counter it yields. Blocks
    nest: a fallback goes to the innermost one only (a loading sequence of the sequential test
    records its own, which its outcome carries, also from a worker process).

    Yields
    ------
    collections.Counter
        Fallback name -> count within the block.
    """
    counter = Counter()
    token = _RECORD.set(counter)
    try:
        yield counter
    finally:
        _RECORD.reset(token)


def note_fallback(name: str) -> None:
    """Count one fallback ``name`` (a key of :data:`FALLBACKS`) in the innermost record.

    Parameters
    ----------
    name : str
        A key of :data:`FALLBACKS`.

    Raises
    ------
    KeyError
        For an unknown name.
    """
    if name not in FALLBACKS:
        raise KeyError(f"unknown fallback {name!r}")
    counter = _RECORD.get()
    if counter is not None:
        counter[name] += 1


def solve_lp(c, *, method: str = "highs-ds", options: dict | None = None, **kwargs):
    """scipy.optimize.linprog with HiGHS, retried with the other ATTEMPTS when HiGHS reports
    numerical trouble or a limit (status 1 or 4). ``options`` are added to every attempt's.
    An infeasible or unbounded verdict (status 2, 3) is confirmed without presolve: with the
    tight tolerances HiGHS's presolve has declared feasible LPs infeasible (the local jamming
    LP 4.15 of an SLP crystal, for which dr = 0 is feasible; tests/test_jamming_highs.py).
    Returns the optimal result; raises LPFailure for a confirmed infeasible or unbounded LP or
    after the last attempt. A result found only with HiGHS's default tolerances is noted as the
    fallback "lp_default_tolerances" (:func:`note_fallback`).

    Parameters
    ----------
    c : array_like of float, shape (n,)
        Objective coefficients (minimised).
    method : str, optional
        The first HiGHS method tried ("highs-ds" or "highs-ipm").
    options : dict, optional
        Extra solver options.
    **kwargs
        The constraints and bounds of :func:`scipy.optimize.linprog` (A_ub, b_ub, A_eq, b_eq,
        bounds).

    Returns
    -------
    scipy.optimize.OptimizeResult
        The optimal result (status 0).

    Raises
    ------
    LPFailure
        As above.
    """
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
        if not base:
            note_fallback("lp_default_tolerances")
        return res
    raise LPFailure(f"HiGHS returned status {res.status}: {res.message}")


__all__ = ["ATTEMPTS", "FALLBACKS", "HIGHS_OPTIONS", "LPFailure", "note_fallback", "recording_fallbacks", "solve_lp"]
