"""``hardpack compress`` (Lubachevsky-Stillinger packing), ``hardpack eos`` (equilibrium Z) and
``hardpack crystal-search`` (dense spheroid crystals from small deforming cells).

Both read a start packing written by ``hardpack init`` (or any packing netCDF). ``compress``
writes the final packing (with run statistics as attributes) and the per-window time series;
with ``--checkpoint`` a killed run started again with the same arguments resumes and ends with
the same packing as an uninterrupted run. ``eos`` optionally compresses to ``--phi`` first and
then measures the reduced pressure with block error bars at fixed phi (resumable likewise).
Both write their checkpoint on Ctrl-C or SIGTERM and remove it once the outputs are written.

Also runnable without the top-level CLI: ``python -m hardpack.md.cli compress ...``.
"""

from __future__ import annotations

import argparse
import logging
import sys

log = logging.getLogger(__name__)


def _optional_float(text: str):
    if text.lower() in ("none", "off"):
        return None
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or 'none', got {text!r}") from None


def cmd_compress(args) -> int:
    """LS compression of a start packing to jamming (event-driven MD with growing spheres, or
    ellipsoids and ellipses with rotation).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack md compress``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.errors import InvalidInputError
    from hardpack.io import checkpoint as ckpt
    from hardpack.io import load_packing
    from hardpack.md import StopCriteria, compress
    from hardpack.md.ellipsoid import compress_ellipsoids

    packing = load_packing(args.init)
    stop = StopCriteria(max_pressure=args.max_pressure, target_phi=args.target_phi,
                        max_collisions=args.max_collisions, max_wall_time=args.max_wall_time)
    common = dict(stop=stop, checkpoint=args.checkpoint, window=args.window,
                  checkpoint_interval=args.checkpoint_interval, final_growth_rate=args.final_growth_rate,
                  switch_pressure=args.switch_pressure, keep_checkpoint=True)
    ellipsoids = packing.shape.kind == "ellipsoid"
    deforming = _deforming_options(args, ellipsoids)
    if deforming is not None:
        from hardpack.md.deforming import compress_deforming

        result = compress_deforming(packing, args.growth_rate, args.seed, stop, window=args.window,
                                    final_growth_rate=args.final_growth_rate,
                                    switch_pressure=args.switch_pressure, **deforming)
    elif ellipsoids:
        if args.contact_forces:
            raise InvalidInputError("--contact-forces is implemented for spheres only; drop it for "
                                    f"{packing.shape.name}")
        result = compress_ellipsoids(packing, args.growth_rate, args.seed, eps_f=args.eps_f, **common)
    else:
        result = compress(packing, args.growth_rate, args.seed, contact_forces=args.contact_forces,
                          contact_windows=args.contact_windows, **common)
    config = {"init": str(args.init), "growth_rate": args.growth_rate, "seed": args.seed,
              "max_pressure": args.max_pressure, "target_phi": args.target_phi,
              "max_collisions": args.max_collisions, "window": args.window,
              "final_growth_rate": args.final_growth_rate,
              "switch_pressure": args.switch_pressure if args.final_growth_rate else None,
              "contact_windows": args.contact_windows if args.contact_forces else None,
              "eps_f": args.eps_f if ellipsoids else None}
    if deforming is not None:
        config.update(deforming_cell=True, applied_pressure=args.applied_pressure, cell_step=args.cell_step)
    result.save(args.out, args.timeseries, config=config)
    if args.checkpoint is not None:  # only now that the results are safely written
        ckpt.remove(args.checkpoint)
    s = result.stats
    log.info("wrote %s: phi=%.8f Z=%.4g phi_J_est=%.8f (%s, %d collisions, %.1f s)", args.out,
             s["phi"], s["Z"], s["phi_J_est"], s["stop_reason"], s["collisions"], s["wall_time"])
    return 0


def _deforming_options(args, ellipsoids: bool) -> dict | None:
    """Keyword arguments of :func:`hardpack.md.deforming.compress_deforming` for
    ``--deforming-cell`` (None without it); refuses the options it cannot combine with."""
    from hardpack.errors import InvalidInputError

    if not args.deforming_cell:
        if args.applied_pressure is not None or args.cell_step is not None:
            raise InvalidInputError("--applied-pressure and --cell-step need --deforming-cell")
        return None
    clash = [flag for flag, on in (("--checkpoint", args.checkpoint is not None),
                                   ("--contact-forces", args.contact_forces),
                                   ("--target-phi", args.target_phi is not None)) if on]
    if clash:
        raise InvalidInputError(f"--deforming-cell cannot be combined with {', '.join(clash)} (not "
                                "implemented for the deforming cell); drop it")
    from hardpack.md.deforming import CELL_STEP

    options = {"applied_pressure": args.applied_pressure,
               "cell_step": CELL_STEP if args.cell_step is None else args.cell_step}
    if ellipsoids:
        options["eps_f"] = args.eps_f
    return options


def cmd_eos(args) -> int:
    """Equilibrium reduced pressure Z = pV/(NkT) with a block error bar at fixed phi.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack md eos``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import checkpoint as ckpt
    from hardpack.io import load_packing, write_dataset
    from hardpack.md import StopCriteria, compress, equilibrate

    packing = load_packing(args.init)
    checkpoints = [] if args.checkpoint is None else [args.checkpoint, args.checkpoint + ".prep"]
    if args.phi is not None and args.phi != packing.phi:
        rate = args.prep_rate if args.phi > packing.phi else -args.prep_rate
        packing = compress(packing, rate, args.seed, stop=StopCriteria(max_pressure=None, target_phi=args.phi),
                           checkpoint=checkpoints[1] if checkpoints else None, keep_checkpoint=True,
                           checkpoint_interval=args.checkpoint_interval).packing
    res = equilibrate(packing, args.seed, args.collisions, n_blocks=args.blocks, n_equilibration=args.equilibration,
                      checkpoint=args.checkpoint,
                      checkpoint_interval=args.checkpoint_interval, keep_checkpoint=True)
    write_dataset(res.to_dataset(seed=args.seed, init=str(args.init)), args.out, seed=args.seed)
    for path in checkpoints:  # only now that the result is safely written
        ckpt.remove(path)
    log.info("wrote %s: phi=%.6f Z=%.5f +- %.5f", args.out, res.phi, res.Z, res.Z_err)
    return 0


def cmd_crystal_search(args) -> int:
    """Dense spheroid crystals from random starts in small deforming cells (Donev 2006, ch. 8).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack crystal-search``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import write_dataset
    from hardpack.md.crystal_search import crystal_search

    protocol = {k: getattr(args, k) for k in ("pressure", "equilibration", "growth_rate", "max_pressure", "polish")}
    ds = crystal_search(args.n, args.alpha, args.seeds, **protocol)
    write_dataset(ds, args.out)
    log.info("wrote %s: best phi %.6f (laminate %.6f), %d of %d runs match the laminate; polished: best %.7f, "
             "%d match", args.out, ds.attrs["phi_best"], ds.attrs["phi_laminate"], int(ds["laminate"].sum()),
             ds["laminate"].size, ds.attrs["phi_best_polished"], int(ds["laminate_polished"].sum()))
    return 0


def register(subparsers) -> None:
    """Add the subcommands ``compress``, ``eos``, ``crystal-search`` to the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    from hardpack.cli import add_checkpoint_options

    p = subparsers.add_parser("compress", help=cmd_compress.__doc__.split("\n\n")[0])
    p.add_argument("--init", required=True, help="start packing (netCDF), e.g. from 'hardpack init'")
    p.add_argument("--out", required=True, help="final packing (netCDF)")
    p.add_argument("--timeseries", help="per-window time series (netCDF)")
    p.add_argument("--growth-rate", type=float, required=True,
                   help="Gamma = (d<D>/dt)/sqrt(kT/m), mean-diameter growth in thermal speeds")
    p.add_argument("--seed", type=int, required=True, help="seed of the initial velocities")
    p.add_argument("--max-pressure", type=_optional_float, default=1e12,
                   help="stop at this reduced pressure pV/(NkT) (default 1e12; 'none' disables)")
    p.add_argument("--target-phi", type=float, help="stop exactly at this volume fraction")
    p.add_argument("--max-collisions", type=int, help="stop after this many collisions")
    p.add_argument("--max-wall-time", type=float, help="stop after this many seconds")
    add_checkpoint_options(p, "checkpoint file: written at sync points every --checkpoint-interval seconds and "
                           "on Ctrl-C or SIGTERM, resumed if present, removed once --out is written")
    p.add_argument("--window", type=float,
                   help="collisions per particle between velocity rescalings (default: from Gamma)")
    p.add_argument("--final-growth-rate", type=float,
                   help="two-stage protocol: grow at this (slow) Gamma once Z >= --switch-pressure "
                        "(isostatic, collectively jammed packings; e.g. 3e-4)")
    p.add_argument("--switch-pressure", type=float, default=1e3,
                   help="reduced pressure at which --final-growth-rate takes over (default 1e3)")
    p.add_argument("--contact-forces", action="store_true",
                   help="store the time-averaged MD contact forces (per-pair impulse sums over the "
                        "last --contact-windows windows) as md_contact_* variables in --out")
    p.add_argument("--contact-windows", type=int, default=10,
                   help="windows averaged for --contact-forces (default 10)")
    p.add_argument("--eps-f", type=float, default=1e-4,
                   help="ellipsoids: tolerance of the collision search on the contact function "
                        "(default 1e-4, Donev 2006 sec. 3.5.1)")
    p.add_argument("--deforming-cell", action="store_true",
                   help="let the periodic cell deform between windows so that the stress becomes "
                        "isotropic (Donev 2006 sec. 3.2.4.2; hardpack.md.deforming): strictly jammed "
                        "packings; the final cell is stored as the packing's lattice")
    p.add_argument("--applied-pressure", type=float,
                   help="with --deforming-cell: applied pressure P0 in kT per unit volume of the "
                        "packing's length unit (the volume changes too); default: shape only")
    p.add_argument("--cell-step", type=float,
                   help="with --deforming-cell: alpha of the strain rule, in (0, 1] (default 0.1)")
    p.set_defaults(func=cmd_compress)

    p = subparsers.add_parser("eos", help=cmd_eos.__doc__.split("\n\n")[0])
    p.add_argument("--init", required=True, help="start packing (netCDF)")
    p.add_argument("--out", required=True, help="output netCDF with Z, Z_err and block values")
    p.add_argument("--phi", type=float, help="compress (or expand) to this phi first")
    p.add_argument("--prep-rate", type=float, default=0.1,
                   help="|Gamma| of the preparation run to --phi (default 0.1)")
    p.add_argument("--seed", type=int, required=True, help="seed of the initial velocities")
    p.add_argument("--collisions", type=int, required=True, help="collisions to average over")
    p.add_argument("--blocks", type=int, default=20, help="number of blocks for the error bar")
    p.add_argument("--equilibration", type=int, default=None,
                   help="collisions discarded before the measurement (default a quarter of --collisions; "
                        "0 records the relaxation from the start, e.g. of a glass)")
    add_checkpoint_options(p, "checkpoint file (and CHECKPOINT.prep for the compression to --phi): written every "
                           "--checkpoint-interval seconds and on Ctrl-C or SIGTERM, resumed if present, removed "
                           "once --out is written")
    p.set_defaults(func=cmd_eos)

    from hardpack.md import crystal_search as cs

    p = subparsers.add_parser("crystal-search", help=cmd_crystal_search.__doc__.split("\n\n")[0])
    p.add_argument("--alpha", type=float, required=True, help="aspect ratio of the spheroids (alpha, 1, 1)")
    p.add_argument("--n", type=int, nargs="+", required=True, help="spheroids per cell (one search per value)")
    p.add_argument("--seeds", type=int, nargs="+", required=True, help="seeds (one run per n and seed)")
    p.add_argument("--pressure", type=float, default=cs.PRESSURE,
                   help=f"isobaric pressure p* = P v / kT of the ordering stage (default {cs.PRESSURE:g})")
    p.add_argument("--equilibration", type=int, default=cs.EQUILIBRATION,
                   help=f"collisions per particle of the ordering stage (default {cs.EQUILIBRATION})")
    p.add_argument("--growth-rate", type=float, default=cs.GROWTH_RATE,
                   help=f"LS growth rate of the final compression (default {cs.GROWTH_RATE:g})")
    p.add_argument("--max-pressure", type=float, default=cs.MAX_PRESSURE,
                   help=f"reduced pressure ending the compression (default {cs.MAX_PRESSURE:g})")
    p.add_argument("--no-polish", dest="polish", action="store_false",
                   help="skip the polish of each jammed packing by the SLP size ascent in the deforming cell")
    p.add_argument("--out", required=True, help="output netCDF (phi, contacts, laminate match per n and seed)")
    p.set_defaults(func=cmd_crystal_search)


def main(argv=None) -> int:
    """``python -m hardpack.md.cli``: the MD subcommands on their own (:func:`register`).

    Parameters
    ----------
    argv : list of str, optional
        The arguments; default the process's command line.

    Returns
    -------
    int
        Exit status (:func:`hardpack.cli.run_command`).
    """
    parser = argparse.ArgumentParser(prog="python -m hardpack.md.cli", description=__doc__.splitlines()[0])
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s",
                        datefmt="%H:%M:%S")
    from hardpack.cli import run_command

    return run_command(args)


if __name__ == "__main__":
    sys.exit(main())
