"""``hardpack poly-equivalents``: moments and bi-/tridisperse equivalents of a distribution family;
``hardpack poly-jam`` / ``poly-fluid`` / ``poly-summary``: the runs of the EOS-vs-moments study
(:mod:`hardpack.eos.study`).

poly-equivalents:
Writes one netCDF Dataset (``hardpack_kind = "eos_equivalents"``) over the family parameter
(omega for uniform_size / uniform_volume / power_law, sigma for lognormal): O1, O2, delta,
skewness, kurtosis, the bidisperse equivalent (n1, R; Table 3.1) and the maximally equivalent
tridisperse system (n1, n2, delta1, delta2 and radii a1 >= a2 >= a3 in units of <a>; Tables 3.3-3.4).
"""

from __future__ import annotations

import json
import logging

from hardpack.eos.study import WIDTH as FAMILIES
from hardpack.eos.study import equivalents_dataset
from hardpack.errors import InvalidInputError

log = logging.getLogger(__name__)


def cmd_poly_equivalents(args) -> int:
    """Moments, O1/O2 and bi-/tridisperse equivalents of a distribution family (Ogarko Tables 3.1-3.4).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack poly-equivalents``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.io import write_dataset

    ds = equivalents_dataset(args.kind, args.values, args.alpha)
    write_dataset(ds, args.out, config={"kind": args.kind, "values": list(args.values), "alpha": args.alpha})
    log.info("wrote %s (%d %s values)", args.out, len(args.values), FAMILIES[args.kind])
    return 0


def _json_spec(text: str) -> dict:
    try:
        spec = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InvalidInputError(f"--distribution is not valid JSON ({exc}): {text!r}") from None
    return spec


def _check_outputs(systems, outputs, checkpoint=None):
    if len(systems) != len(outputs):
        raise InvalidInputError(f"give one --out per --systems entry ({len(systems)} systems, {len(outputs)} outputs)")
    if checkpoint is not None and len(systems) != 1:
        raise InvalidInputError(f"--checkpoint holds one compression: give one system, not {len(systems)} "
                                "(run the others as separate commands, each with its own checkpoint)")


def cmd_poly_jam(args) -> int:
    """Jam a distribution and/or its bi- and tridisperse equivalents (two-stage LS compression).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack poly-jam``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.eos.study import JamProtocol, jam
    from hardpack.io import checkpoint as ckpt

    spec = _json_spec(args.distribution)
    _check_outputs(args.systems, args.out, args.checkpoint)
    protocol = JamProtocol(n=args.n, init_phi=args.init_phi, growth_rate=args.growth_rate,
                           switch_pressure=args.switch_pressure, final_growth_rate=args.final_growth_rate,
                           max_pressure=args.max_pressure)
    for system, out in zip(args.systems, args.out):
        result = jam(spec, system, args.seed, protocol, checkpoint=args.checkpoint, keep_checkpoint=True)
        result.save(out, config={"distribution": spec, "system": system, "seed": args.seed,
                                 **{k: getattr(protocol, k) for k in protocol.__dataclass_fields__}})
        if args.checkpoint is not None:  # only now that the packing is safely written
            ckpt.remove(args.checkpoint)
        s = result.stats
        log.info("%s %s seed %d: phi_J = %.6f (Z = %.3g, %d collisions, %.1f s CPU, crystallinity %.3f)",
                 args.distribution, system, args.seed, s["phi"], s["Z"], s["collisions"], s["cpu_time"],
                 s["crystallinity"])
    return 0


def cmd_poly_fluid(args) -> int:
    """Equilibrium Z(phi) of a distribution and its equivalents against BMCSL (one netCDF file).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack poly-fluid``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.eos.study import fluid_dataset, fluid_pressure
    from hardpack.io import write_dataset

    spec = _json_spec(args.distribution)
    rows = []
    for system in args.systems:
        for phi in args.phi:
            row = fluid_pressure(spec, system, phi, args.seed, n=args.n, collisions=args.collisions)
            log.info("%s %s phi = %.3f: Z = %.4f +- %.4f, BMCSL %.4f (%+.2f %%)", args.distribution, system,
                     phi, row["Z"], row["Z_err"], row["Z_bmcsl"], 100 * row["rel_dev"])
            rows.append(row)
    write_dataset(fluid_dataset(rows), args.out, seed=args.seed,
                  config={"distribution": spec, "systems": args.systems, "phi": args.phi, "n": args.n,
                          "collisions": args.collisions})
    return 0


def cmd_poly_summary(args) -> int:
    """Combine the study's jammed packings (one family; ``jam``: the equivalence runs,
    ``crystallisation``: the slow runs) or fluid files into one summary Dataset.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``hardpack poly-summary``.

    Returns
    -------
    int
        Exit status 0 (errors raise).
    """
    from hardpack.eos.study import fluid_summary, jam_summary
    from hardpack.io import load_dataset, write_dataset

    datasets = [load_dataset(p) for p in args.files]
    ds = fluid_summary(datasets) if args.kind == "fluid" else jam_summary(datasets, study=args.kind)
    write_dataset(ds, args.out)
    log.info("wrote %s from %d files", args.out, len(datasets))
    return 0


def register(subparsers) -> None:
    """Add the subcommands ``poly-jam``, ``poly-fluid``, ``poly-summary``, ``poly-equivalents`` to
    the ``hardpack`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The subcommand parsers of :func:`hardpack.cli.build_parser`.
    """
    p = subparsers.add_parser("poly-jam", help=cmd_poly_jam.__doc__.split("\n\n")[0])
    p.add_argument("--distribution", required=True,
                   help='size distribution as JSON, e.g. \'{"kind": "uniform_volume", "omega": 4}\'')
    p.add_argument("--systems", nargs="+", default=["poly", "bi", "tri"], choices=["poly", "bi", "tri"])
    p.add_argument("--seed", type=int, required=True, help="seed of the RSA start and the velocities")
    p.add_argument("--n", type=int, default=1000, help="number of particles (default 1000)")
    p.add_argument("--init-phi", type=float, default=0.2, help="RSA start density (default 0.2)")
    p.add_argument("--growth-rate", type=float, default=0.02, help="Gamma of the first stage (default 0.02)")
    p.add_argument("--switch-pressure", type=float, default=1e3, help="Z of the switch (default 1e3)")
    p.add_argument("--final-growth-rate", type=float, default=0.002, help="Gamma of the final stage (default 0.002)")
    p.add_argument("--max-pressure", type=float, default=1e12, help="final Z (default 1e12)")
    p.add_argument("--out", nargs="+", required=True, help="one packing netCDF per system")
    p.add_argument("--checkpoint", help="checkpoint file of the compression (one system only): written "
                   "every 5 min, resumed if present, removed at the end")
    p.set_defaults(func=cmd_poly_jam)

    p = subparsers.add_parser("poly-fluid", help=cmd_poly_fluid.__doc__.split("\n\n")[0])
    p.add_argument("--distribution", required=True, help="size distribution as JSON")
    p.add_argument("--systems", nargs="+", default=["poly", "bi", "tri"], choices=["poly", "bi", "tri"])
    p.add_argument("--phi", type=float, nargs="+", required=True, help="volume fractions (< 0.6)")
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--n", type=int, default=500, help="number of particles (default 500)")
    p.add_argument("--collisions", type=int, default=400_000, help="collisions averaged per run")
    p.add_argument("--out", required=True, help="output netCDF (system x phi)")
    p.set_defaults(func=cmd_poly_fluid)

    p = subparsers.add_parser("poly-summary", help=cmd_poly_summary.__doc__.split("\n\n")[0])
    p.add_argument("--kind", choices=["jam", "crystallisation", "fluid"], required=True,
                   help="jam: equivalence runs; crystallisation: slow runs (same files); fluid: poly-fluid files")
    p.add_argument("files", nargs="+", help="poly-jam packings of one family, or poly-fluid files")
    p.add_argument("--out", required=True, help="summary netCDF")
    p.set_defaults(func=cmd_poly_summary)

    p = subparsers.add_parser("poly-equivalents", help=cmd_poly_equivalents.__doc__.split("\n\n")[0])
    p.add_argument("--kind", required=True, choices=sorted(FAMILIES), help="distribution family")
    p.add_argument("--values", type=float, nargs="+", required=True, help="omega (or sigma for lognormal) values")
    p.add_argument("--alpha", type=float, help="exponent of the power_law family")
    p.add_argument("--out", required=True, help="output netCDF file")
    p.set_defaults(func=cmd_poly_equivalents)
