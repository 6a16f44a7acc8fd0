"""``hardpack slp``: densify a packing by sequential linear programming (Torquato & Jiao 2010);
``hardpack slp-dilute``: the diluted-MRJ protocol of their Sec. VI (:mod:`hardpack.slp.diluted`)."""

from __future__ import annotations

import logging
from pathlib import Path

import scipy

from hardpack.io import checkpoint as ckpt
from hardpack.io import load_dataset, load_packing, write_dataset
from hardpack.slp.diluted import run_diluted
from hardpack.slp.driver import run_slp
from hardpack.slp.lp import METHODS, Bounds

log = logging.getLogger(__name__)

#: attributes of the start packing carried over to the packings made from it
INHERITED = ("seed", "ensemble", "distribution", "distribution_params", "init_phi")


def _settings(args) -> dict:
    """The SLP settings of a run, as stored in its packings' attributes."""
    return {
        "generator": "slp", "alpha": args.alpha, "strain_bound": args.strain_bound,
        "shear_bound": args.shear_bound, "displacement_bound": args.displacement_bound,
        "cell": "isotropic" if args.isotropic else "deforming", "tol": args.tol,
        "lp_method": args.lp_method,
    }


def _bounds(args) -> Bounds:
    return Bounds(args.strain_bound, args.shear_bound, args.displacement_bound)


def _inherit(attrs: dict, path) -> dict:
    init_attrs = load_dataset(path).attrs
    for key in INHERITED:
        if key in init_attrs:
            attrs.setdefault(key, init_attrs[key])
    return attrs


def _solver(args) -> str:
    return f"scipy {scipy.__version__} HiGHS ({args.lp_method})"


def cmd_slp(args) -> int:
    """Sequential-LP (adaptive shrinking cell) packing from a start configuration.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack slp``.

    Returns
    -------
    int
        Exit status: 0, or 3 when the SLP did not converge (errors raise).
    """
    start = load_packing(args.init)
    result = run_slp(start, args.alpha, _bounds(args), deforming=not args.isotropic, tol=args.tol,
                     max_steps=args.max_steps, method=args.lp_method, checkpoint=args.checkpoint,
                     checkpoint_interval=args.checkpoint_interval, keep_checkpoint=True)
    params = _settings(args)
    attrs = dict(args.attr or [])
    attrs.update(params, init=str(args.init), lp_solver=_solver(args))
    write_dataset(result.to_dataset(**_inherit(attrs, args.init)), args.out, config=params)
    if args.history:
        write_dataset(result.history, args.history, attrs=params)
    if args.checkpoint is not None:  # only now that the results are safely written
        ckpt.remove(args.checkpoint)
    log.info("SLP %s: phi = %.8f after %d LPs (%d rejected), %.1f s, converged=%s",
             args.out, result.packing.phi, result.n_steps, result.n_rejected, result.wall_seconds,
             result.converged)
    return 0 if result.converged else 3


def cmd_slp_dilute(args) -> int:
    """Diluted-MRJ protocol (Torquato & Jiao 2010, Sec. VI): remove spheres at random, re-jam by SLP, repeat.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack slp-dilute``.

    Returns
    -------
    int
        Exit status: 0, or 3 when a round did not converge (errors raise).
    """
    start = load_packing(args.init)
    rounds = run_diluted(start, args.fraction, args.rounds, args.seed, args.alpha, _bounds(args),
                         deforming=not args.isotropic, tol=args.tol, max_steps=args.max_steps,
                         method=args.lp_method, checkpoint=args.checkpoint,
                         checkpoint_interval=args.checkpoint_interval, keep_checkpoint=True)
    params = {**_settings(args), "protocol": "diluted_mrj", "fraction": args.fraction, "rounds": args.rounds}
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    removed = 0
    for r, rnd in enumerate(rounds, start=1):
        removed += rnd.n_removed
        attrs = dict(args.attr or [])
        attrs.update(params, init=str(args.init), seed=args.seed, dilution_round=r, n_removed_total=removed,
                     N_start=start.n_particles, phi_start=start.phi, lp_solver=_solver(args))
        path = out_dir / f"round{r}.nc"
        write_dataset(rnd.to_dataset(**_inherit(attrs, args.init)), path, config=params)
        log.info("diluted round %d: %s, N = %d, phi = %.8f (%d LPs, converged=%s)", r, path,
                 rnd.packing.n_particles, rnd.packing.phi, rnd.n_steps, rnd.converged)
    if args.checkpoint is not None:  # only now that every round is safely written
        ckpt.remove(args.checkpoint)
    return 0 if all(rnd.converged for rnd in rounds) else 3


def _slp_options(p) -> None:
    """The SLP settings and checkpoint options shared by ``slp`` and ``slp-dilute``."""
    from hardpack.cli import add_checkpoint_options

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
    p.add_argument("--max-steps", type=int, default=2000, help="maximum number of LPs (per SLP run)")
    add_checkpoint_options(p, "checkpoint file: written every --checkpoint-interval seconds (slp-dilute: also "
                           "after every round), resumed if present (same start and options), removed at the end")
    p.add_argument("--attr", action="append", type=lambda t: tuple(t.split("=", 1)), metavar="KEY=VALUE")


def register(subparsers) -> None:
    """Add the subcommands ``slp``, ``slp-dilute`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser("slp", help=cmd_slp.__doc__.split("\n\n")[0])
    p.add_argument("--init", required=True, help="start packing (netCDF), e.g. from `hardpack init`")
    p.add_argument("--out", required=True, help="output packing (netCDF)")
    p.add_argument("--history", help="optional per-LP history (netCDF)")
    _slp_options(p)
    p.set_defaults(func=cmd_slp)

    p = subparsers.add_parser("slp-dilute", help=cmd_slp_dilute.__doc__.split("\n\n")[0])
    p.add_argument("--init", required=True, help="start packing (netCDF), a jammed SLP MRJ packing")
    p.add_argument("--out-dir", required=True, help="folder of the packings round1.nc ... round<R>.nc")
    p.add_argument("--fraction", type=float, required=True,
                   help="fraction f_s of the start's spheres removed per round (paper: 0.001-0.025)")
    p.add_argument("--rounds", type=int, required=True, help="number of rounds n_r (paper: 5-10)")
    p.add_argument("--seed", type=int, required=True, help="seed of the random removals")
    _slp_options(p)
    p.set_defaults(func=cmd_slp_dilute)
