"""``hardpack hgrid-cost``: analytic HGrid cost T/N versus the number of levels (Ogarko Figs. 2.12-2.16).

Writes a netCDF Dataset (``hardpack_kind = "hgrid_cost"``) with ``cost(rule, levels)`` for the
chosen cell-size rules and the single-level (linked-cell) reference as an attribute.
"""

from __future__ import annotations

import logging

from hardpack.hgrid import cost_model as cm

log = logging.getLogger(__name__)


def cmd_hgrid_cost(args) -> int:
    """Analytic HGrid cost T/N vs number of levels for power-law radii (Ogarko ch. 2.2, Fig. 2.15).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack hgrid-cost``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import write_dataset

    system = cm.PowerLawSystem(args.alpha, args.omega, args.nu, args.d)
    ds = cm.cost_dataset(system, args.rules, range(1, args.max_levels + 1), args.K, args.method)
    config = {k: getattr(args, k) for k in ("alpha", "omega", "nu", "d", "K", "method", "rules", "max_levels")}
    write_dataset(ds, args.out, config=config)
    for rule in args.rules:
        best = ds["cost"].sel(rule=rule)
        log.info("%s: minimum T/N = %.4g at L = %d", rule, float(best.min()), int(best.idxmin()))
    return 0


def register(subparsers) -> None:
    """Add the subcommand ``hgrid-cost`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser("hgrid-cost", help=cmd_hgrid_cost.__doc__.split("\n\n")[0])
    p.add_argument("--alpha", type=float, required=True, help="exponent of f(r) ~ r^alpha (0 US, -3 UV)")
    p.add_argument("--omega", type=float, required=True, help="r_max / r_min")
    p.add_argument("--nu", type=float, default=0.7, help="volume fraction (default 0.7)")
    p.add_argument("--d", type=int, default=3, help="dimension (default 3)")
    p.add_argument("--K", type=float, default=0.2, help="cell access / overlap test time ratio (default 0.2)")
    p.add_argument("--method", choices=cm.METHODS, default="top-down")
    p.add_argument("--rules", nargs="+", choices=cm.CELL_RULES, default=["linear", "exponential", "constant-m"])
    p.add_argument("--max-levels", type=int, default=30, help="levels 1..max (optimal: ~0.5 s per level)")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_hgrid_cost)
