"""``hardpack slp``: densify a packing by sequential linear programming (Torquato & Jiao 2010)."""

from __future__ import annotations

import logging

import scipy

from hardpack.io import load_dataset, load_packing, save_packing, write_dataset
from hardpack.slp.driver import run_slp
from hardpack.slp.lp import METHODS, Bounds

log = logging.getLogger(__name__)


def cmd_slp(args) -> int:
    """Sequential-LP (adaptive shrinking cell) packing from a start configuration."""
    start = load_packing(args.init)
    bounds = Bounds(args.strain_bound, args.shear_bound, args.displacement_bound)
    result = run_slp(start, args.alpha, bounds, deforming=not args.isotropic, tol=args.tol,
                     max_steps=args.max_steps, method=args.lp_method, checkpoint=args.checkpoint,
                     checkpoint_interval=args.checkpoint_interval)
    params = {
        "generator": "slp", "alpha": args.alpha, "strain_bound": args.strain_bound,
        "shear_bound": args.shear_bound, "displacement_bound": args.displacement_bound,
        "cell": "isotropic" if args.isotropic else "deforming", "tol": args.tol,
        "lp_method": args.lp_method,
    }
    attrs = dict(args.attr or [])
    attrs.update(params, init=str(args.init), converged=result.converged, n_steps=result.n_steps,
                 n_rejected=result.n_rejected,
                 wall_seconds=result.wall_seconds, cpu_seconds=result.cpu_seconds, lp_solver=f"scipy {scipy.__version__} HiGHS ({args.lp_method})")
    init_attrs = load_dataset(args.init).attrs
    for key in ("seed", "ensemble", "distribution", "distribution_params", "init_phi"):
        if key in init_attrs:
            attrs.setdefault(key, init_attrs[key])
    save_packing(result.packing, args.out, attrs=attrs, config=params)
    if args.history:
        write_dataset(result.history, args.history, attrs=params)
    log.info("SLP %s: phi = %.8f after %d LPs (%d rejected), %.1f s, converged=%s",
             args.out, result.packing.phi, result.n_steps, result.n_rejected, result.wall_seconds,
             result.converged)
    return 0 if result.converged else 3


def register(subparsers) -> None:
    p = subparsers.add_parser("slp", help=cmd_slp.__doc__)
    p.add_argument("--init", required=True, help="start packing (netCDF), e.g. from `hardpack init`")
    p.add_argument("--out", required=True, help="output packing (netCDF)")
    p.add_argument("--history", help="optional per-LP history (netCDF)")
    p.add_argument("--alpha", type=float, default=1.5,
                   help="influence-sphere radius gamma / D_mn (1.5: MRJ-like; 3.5: densest)")
    p.add_argument("--strain-bound", type=float, default=0.1, help="|eps_aa| bound (compression)")
    p.add_argument("--shear-bound", type=float, default=0.1, help="|eps_ab| bound, a != b (shear)")
    p.add_argument("--displacement-bound", type=float, default=0.5,
                   help="|u| bound per component in units of the mean diameter")
    p.add_argument("--isotropic", action="store_true",
                   help="isotropic shrink only, no shear (the paper's isotropically shrinking cell)")
    p.add_argument("--lp-method", choices=METHODS, default="highs-ipm",
                   help="HiGHS solver (interior point with crossover: fastest on these degenerate LPs)")
    p.add_argument("--tol", type=float, default=1e-10,
                   help="stop when the predicted density gain is below this (paper: 1e-8; see hardpack.slp.driver)")
    p.add_argument("--max-steps", type=int, default=2000, help="maximum number of LPs")
    p.add_argument("--checkpoint", help="checkpoint file: written every --checkpoint-interval seconds, "
                   "resumed if present (same start and options), removed at the end")
    p.add_argument("--checkpoint-interval", type=float, default=300.0,
                   help="seconds between checkpoints (default 300)")
    p.add_argument("--attr", action="append", type=lambda t: tuple(t.split("=", 1)), metavar="KEY=VALUE")
    p.set_defaults(func=cmd_slp)
